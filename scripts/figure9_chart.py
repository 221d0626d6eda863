#!/usr/bin/env python3
"""Figure 9 of Zubeldia et al. (2018) as the twin gives it: the water front's position against
time, one line per run, beside the experiment's front, which reached the end of the channel 8 s
after the water entered.

Usage: python3 scripts/figure9_chart.py LABEL=FRONT.csv [LABEL=FRONT.csv ...] > chart.svg

Each CSV is what `scripts/water_front.py` writes (`time_s`, then a column `front_m RUN_DIR` per
run, empty where no column is wet yet), as `docs/scour/figure9_front.csv`. Each run becomes a
line labelled with LABEL and its directory's name; the lines of one CSV share a dash, a run's
place in its CSV picks its colour. The x axis runs to 8 s (further if a run does), the y axis
over the flume's 2.5 m, with the bed's end at 2.2 m marked. Writes SVG: it needs nothing
beyond Python's standard library.
"""

import csv
import sys

from labelled_args import labelled_paths

WIDTH, HEIGHT = 800, 420
LEFT, RIGHT, TOP, BOTTOM = 70, 290, 40, 60
PLOT_W, PLOT_H = WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM
COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"]
DASHES = ["", ' stroke-dasharray="7 4"', ' stroke-dasharray="2 3"']
USAGE = "usage: python3 scripts/figure9_chart.py LABEL=FRONT.csv [LABEL=FRONT.csv ...] > chart.svg"
EXPERIMENT_ARRIVAL_S = 8.0
FLUME_M, BED_END_M = 2.5, 2.2


def fronts(path):
    """[(run name, [(time s, front m)])] of one CSV, the dry times left out."""
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        sys.exit(f"cannot read {path}: {e.strerror}")
    if not rows or rows[0][:1] != ["time_s"] or len(rows[0]) < 2:
        sys.exit(f"{path}: not a front table (time_s, then a front_m column per run)")
    names = [h.removeprefix("front_m ").rstrip("/").rsplit("/", 1)[-1] for h in rows[0][1:]]
    runs = [(name, []) for name in names]
    try:
        for row in rows[1:]:
            t = float(row[0])
            for (_, points), value in zip(runs, row[1:]):
                if value:
                    points.append((t, float(value)))
    except (ValueError, IndexError) as e:
        sys.exit(f"{path}: not a front table (time_s, then a front_m column per run): {e!r}")
    return runs


def parse_args(argv):
    tables = [(label, fronts(path)) for label, path in labelled_paths(argv, USAGE, "FRONT.csv")]
    if len(tables) > len(DASHES):
        sys.exit(f"at most {len(DASHES)} tables")
    if any(len(runs) > len(COLOURS) for _, runs in tables):
        sys.exit(f"at most {len(COLOURS)} runs a table")
    return tables


class Frame:
    """The plot's scale: time to `t_max` s across, the flume's length up."""

    def __init__(self, t_max):
        self.t_max = t_max

    def x(self, t):
        return LEFT + PLOT_W * t / self.t_max

    def y(self, front):
        return TOP + PLOT_H * (1 - front / FLUME_M)


def svg(tables):
    t_last = max((t for _, runs in tables for _, p in runs for t, _ in p), default=0.0)
    frame = Frame(max(EXPERIMENT_ARRIVAL_S, float(int(t_last + 0.999))))
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" '
        'font-family="sans-serif" font-size="12">',
        f'<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/>',
        f'<text x="{WIDTH / 2}" y="20" text-anchor="middle" font-size="14">'
        "The water front over the bed against time (ULBRA flume, 2 m3/h)</text>",
    ]
    out += grid(frame)
    legend_y = TOP + 8
    for k, (label, runs) in enumerate(tables):
        for n, (name, points) in enumerate(runs):
            style = f'stroke="{COLOURS[n]}" stroke-width="1.5" fill="none"{DASHES[k]}'
            if points:
                path = " ".join(f"{frame.x(t):.1f},{frame.y(f):.1f}" for t, f in points)
                out.append(f'<polyline points="{path}" {style}/>')
            lx = WIDTH - RIGHT + 14
            out.append(
                f'<line x1="{lx}" x2="{lx + 24}" y1="{legend_y - 4}" y2="{legend_y - 4}" {style}/>'
                f'<text x="{lx + 30}" y="{legend_y}">{escape(label)}, {escape(name)}</text>'
            )
            legend_y += 16
    out.append("</svg>")
    return "\n".join(out) + "\n"


def grid(frame):
    """Axes, a line every second and every half metre, the bed's end and the experiment."""
    y0 = frame.y(0)
    out = []
    for s in range(int(frame.t_max) + 1):
        x = frame.x(s)
        out.append(f'<line x1="{x:.1f}" x2="{x:.1f}" y1="{TOP}" y2="{y0:.1f}" stroke="#eee"/>')
        out.append(f'<text x="{x:.1f}" y="{y0 + 18:.1f}" text-anchor="middle">{s}</text>')
    for k in range(int(FLUME_M * 2) + 1):
        y = frame.y(k / 2)
        out.append(
            f'<line x1="{LEFT}" x2="{frame.x(frame.t_max):.1f}" y1="{y:.1f}" y2="{y:.1f}" '
            'stroke="#eee"/>'
        )
        out.append(f'<text x="{LEFT - 8}" y="{y + 4:.1f}" text-anchor="end">{k / 2:g}</text>')
    bed, arrival = frame.y(BED_END_M), frame.x(EXPERIMENT_ARRIVAL_S)
    right = frame.x(frame.t_max)
    out += [
        f'<line x1="{LEFT}" x2="{right:.1f}" y1="{bed:.1f}" y2="{bed:.1f}" '
        'stroke="#555" stroke-dasharray="6 4"/>',
        f'<text x="{LEFT + 6}" y="{bed - 5:.1f}" fill="#555">the bed\'s end, 2.2 m</text>',
        f'<line x1="{arrival:.1f}" x2="{arrival:.1f}" y1="{TOP}" y2="{y0:.1f}" '
        'stroke="#000" stroke-dasharray="2 3"/>',
        f'<text x="{arrival - 6:.1f}" y="{TOP + 14}" text-anchor="end">'
        "the experiment's front at the channel's end, 8 s</text>",
        f'<line x1="{LEFT}" x2="{LEFT}" y1="{TOP}" y2="{y0:.1f}" stroke="black"/>'
        f'<line x1="{LEFT}" x2="{right:.1f}" y1="{y0:.1f}" y2="{y0:.1f}" stroke="black"/>',
        f'<text x="{LEFT + PLOT_W / 2}" y="{HEIGHT - 18}" text-anchor="middle">time, s</text>'
        f'<text transform="translate(18 {TOP + PLOT_H / 2}) rotate(-90)" '
        'text-anchor="middle">front, m (water 4 mm over the bed)</text>',
    ]
    return out


def escape(text):
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


if __name__ == "__main__":
    sys.stdout.write(svg(parse_args(sys.argv[1:])))
