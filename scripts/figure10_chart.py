#!/usr/bin/env python3
"""Figure 10 of Zubeldia et al. (2018) as the twin gives it: the eroded mass collected at 18 s
against ks/d50, each ladder's mean over its runs with the range of the runs as a whisker.

Usage: python3 scripts/figure10_chart.py LABEL=RUNS.csv [LABEL=RUNS.csv ...] > chart.svg

Each CSV has a row per run with the columns `ks_over_d50` and `eroded_kg_per_m` (as
`docs/scour/figure10_bed_slope.csv` and `figure10_ks_repeats.csv`); each becomes one bar per
ks/d50, in the order given. The y axis runs to 3 kg/m as the paper's does (further if a run
goes over, or would reach the legend), and the band at ks/d50 = 3 marks 0.5-3 kg/m, the paper's bar there matching the
experiment's. Writes SVG: it needs nothing beyond Python's standard library.
"""

import csv
import sys
from collections import defaultdict

from labelled_args import labelled_paths

WIDTH, HEIGHT = 720, 420
LEFT, RIGHT, TOP, BOTTOM = 70, 20, 40, 60
PLOT_W, PLOT_H = WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM
# The legend's first row, under the plot's top, and the height of a row, px.
LEGEND_Y0, LEGEND_ROW = 24, 16
COLOURS = ["#9e9e9e", "#1f77b4", "#ff7f0e", "#2ca02c"]
USAGE = "usage: python3 scripts/figure10_chart.py LABEL=RUNS.csv [LABEL=RUNS.csv ...] > chart.svg"
PAPER_AXIS_KG_PER_M = 3.0
AIM_AT_KS3 = (0.5, 3.0)


def ladder(path):
    """{ks/d50: [eroded kg/m of each run]} of one CSV."""
    runs = defaultdict(list)
    try:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                runs[float(row["ks_over_d50"])].append(float(row["eroded_kg_per_m"]))
    except OSError as e:
        sys.exit(f"cannot read {path}: {e.strerror}")
    except (KeyError, ValueError, TypeError) as e:
        sys.exit(f"{path}: not a ladder of runs (ks_over_d50, eroded_kg_per_m): {e!r}")
    if not runs:
        sys.exit(f"{path}: no runs")
    return runs


def parse_args(argv):
    ladders = [(label, ladder(path)) for label, path in labelled_paths(argv, USAGE, "RUNS.csv")]
    if len(ladders) > len(COLOURS):
        sys.exit(f"at most {len(COLOURS)} ladders")
    return ladders


class Frame:
    """The plot's scale: the y axis to `top` kg/m, a slot per ks/d50 value."""

    def __init__(self, top, slots):
        self.top = top
        self.plot_w, self.plot_h = PLOT_W, PLOT_H
        self.slot = self.plot_w / slots

    def y(self, v):
        return TOP + self.plot_h * (1 - v / self.top)


def svg(ladders):
    ks_values = sorted({k for _, runs in ladders for k in runs})
    top = max([PAPER_AXIS_KG_PER_M] + [max(v) for _, r in ladders for v in r.values()])
    # The bars in the legend's slots stay under its last row (one row spare).
    legend_px = LEGEND_Y0 + LEGEND_ROW * (len(ladders) + 1)
    first = legend_slot(ks_values)
    under_legend = [max(r[k]) for _, r in ladders for k in ks_values[first:] if k in r]
    top = max([top] + [v / (1 - legend_px / PLOT_H) for v in under_legend])
    frame = Frame(float(int(top * 2 + 0.999)) / 2, len(ks_values))
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" '
        'font-family="sans-serif" font-size="12">',
        f'<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/>',
        f'<text x="{WIDTH / 2}" y="20" text-anchor="middle" font-size="14">'
        "Eroded mass collected at 18 s against ks/d50 (ULBRA flume, dp = 4 mm)</text>",
    ]
    out += grid_lines(frame)
    if 3.0 in ks_values:
        x0 = LEFT + frame.slot * ks_values.index(3.0) + frame.slot * 0.1
        lo, hi = AIM_AT_KS3
        out.append(
            f'<rect x="{x0:.1f}" y="{frame.y(hi):.1f}" width="{frame.slot * 0.8:.1f}" '
            f'height="{frame.y(lo) - frame.y(hi):.1f}" fill="#2ca02c" fill-opacity="0.12"/>'
        )
    out += bars(frame, ks_values, ladders)
    out += labels(frame, ks_values, ladders)
    out.append("</svg>")
    return "\n".join(out) + "\n"


def grid_lines(frame):
    """A line and a label every 0.5 kg/m, the paper's axis top dashed."""
    out = []
    for k in range(int(frame.top * 2) + 1):
        v, y = k / 2, frame.y(k / 2)
        axis_top = v == PAPER_AXIS_KG_PER_M
        style = 'stroke="#555" stroke-dasharray="6 4"' if axis_top else 'stroke="#ddd"'
        out.append(f'<line x1="{LEFT}" x2="{WIDTH - RIGHT}" y1="{y:.1f}" y2="{y:.1f}" {style}/>')
        out.append(f'<text x="{LEFT - 8}" y="{y + 4:.1f}" text-anchor="end">{v:g}</text>')
    return out


def bars(frame, ks_values, ladders):
    """Each ks/d50's label, and per ladder its runs' mean as a bar and their range as a
    whisker."""
    out = []
    width = frame.slot * 0.7 / len(ladders)
    for i, ks in enumerate(ks_values):
        centre = LEFT + frame.slot * (i + 0.5)
        out.append(
            f'<text x="{centre:.1f}" y="{HEIGHT - BOTTOM + 18}" text-anchor="middle">{ks:g}</text>'
        )
        for n, (_, runs) in enumerate(ladders):
            values = runs.get(ks)
            if not values:
                continue
            mean = sum(values) / len(values)
            x = centre - width * len(ladders) / 2 + width * n
            out.append(
                f'<rect x="{x + 1:.1f}" y="{frame.y(mean):.1f}" width="{width - 2:.1f}" '
                f'height="{frame.y(0) - frame.y(mean):.1f}" fill="{COLOURS[n]}"/>'
            )
            mid = x + width / 2
            out.append(
                f'<line x1="{mid:.1f}" x2="{mid:.1f}" y1="{frame.y(min(values)):.1f}" '
                f'y2="{frame.y(max(values)):.1f}" stroke="black"/>'
            )
    return out


def legend_slot(ks_values):
    """The slot the legend starts over: the fourth, right of the band at ks/d50 = 3 on the
    paper's ladder, or the last of a shorter one. `svg` keeps the bars from there on under it."""
    return min(3, len(ks_values) - 1)


def labels(frame, ks_values, ladders):
    """The axes, their titles and the legend."""
    y0 = frame.y(0)
    out = [
        f'<line x1="{LEFT}" x2="{LEFT}" y1="{TOP}" y2="{y0:.1f}" stroke="black"/>'
        f'<line x1="{LEFT}" x2="{WIDTH - RIGHT}" y1="{y0:.1f}" y2="{y0:.1f}" stroke="black"/>',
        f'<text x="{LEFT + frame.plot_w / 2}" y="{HEIGHT - 18}" text-anchor="middle">ks / d50</text>'
        f'<text transform="translate(18 {TOP + frame.plot_h / 2}) rotate(-90)" '
        'text-anchor="middle">eroded mass, kg/m (Eq. 34)</text>',
    ]
    legend = [(label, COLOURS[n]) for n, (label, _) in enumerate(ladders)]
    legend.append(("the aim at ks/d50 = 3: 0.5-3 kg/m", "#cfe8cf"))
    lx = LEFT + frame.slot * legend_slot(ks_values) + 10
    for n, (label, colour) in enumerate(legend):
        ly = TOP + LEGEND_Y0 + LEGEND_ROW * n
        out.append(
            f'<rect x="{lx:.1f}" y="{ly - 9}" width="12" height="10" fill="{colour}"/>'
            f'<text x="{lx + 18:.1f}" y="{ly}">{escape(label)}</text>'
        )
    out.append(
        f'<text x="{WIDTH - RIGHT - 4}" y="{frame.y(PAPER_AXIS_KG_PER_M) - 4:.1f}" '
        'text-anchor="end" fill="#555">top of the paper\'s axis</text>'
    )
    return out


def escape(text):
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


if __name__ == "__main__":
    sys.stdout.write(svg(parse_args(sys.argv[1:])))
