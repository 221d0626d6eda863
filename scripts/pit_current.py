#!/usr/bin/env python3
"""The current over the collector pit, from the particle snapshots `flume-twin simulate` writes.

Usage: python3 scripts/pit_current.py RUN_DIR --dp DP [--from-s T] [--to-s T] [--x0 X]
                                      [--x1 X] [--width W] > pit.csv

Reads every `particles_NNNN.vtk` in RUN_DIR whose time lies in [--from-s, --to-s] (default all)
and, for each column W wide (default 2 cm) from x0 (default 2.1 m, over the bed's end) to x1
(default 2.49 m, the weir's face at dp = 1 cm), averages over the snapshots:

- the free surface, where the kernel fullness of water and sand falls through one half (the
  SWL gauge's rule: Wendland kernel, h = 1.2 sqrt(2) dp, as the twin's gauges use);
- the unit discharge through the column, sum u dp^2 / W, and the part of it flowing back;
- the energy head of the forward flow, the surface plus the discharge-weighted velocity head
  u |u|^2 / 2 g over u (hydrostatic pressure below the surface);
- the current's core: the dp-thick layer (centred on a multiple of dp) of the highest mean
  speed along x, its height and speed, and how many layers reach half that speed (its
  thickness).

Heights are in mm over the weir's crest: the top wall particle at x >= x1, plus dp / 2. A
current that crosses the pit at the crest's level keeps its core there; one that plunges into
the pit shows its core far under the crest. Writes CSV, a row per column.
"""

import glob
import math
import os
import re
import struct
import sys

GRAVITY = 9.81
WALL, WATER, SAND = 0, 1, 2
REST_DENSITY = {WATER: 1000.0, SAND: 2710.0}


def read_vtk(path):
    """(time_s, {field: tuple}) of one legacy binary VTK snapshot the twin wrote."""
    data = open(path, "rb").read()
    pos = 0

    def line():
        nonlocal pos
        end = data.index(b"\n", pos)
        text = data[pos:end].decode("ascii")
        pos = end + 1
        return text

    def take(count, kind):
        nonlocal pos
        values = struct.unpack(f">{count}{kind}", data[pos : pos + 4 * count])
        pos += 4 * count
        return values

    line()
    title = line()
    found = re.search(r"t = ([0-9.eE+-]+) s", title)
    if not found or line().strip() != "BINARY":
        raise ValueError("not a snapshot of flume-twin (binary legacy VTK)")
    fields, n = {}, 0
    while pos < len(data):
        words = line().split()
        if not words:
            continue
        if words[0] == "POINTS":
            n = int(words[1])
            fields["pos"] = take(3 * n, "f")
        elif words[0] == "CELLS":
            take(int(words[2]), "i")
        elif words[0] == "CELL_TYPES":
            take(int(words[1]), "i")
        elif words[0] == "VECTORS":
            fields[words[1]] = take(3 * n, "f")
        elif words[0] == "SCALARS":
            line()
            fields[words[1]] = take(n, "f" if words[2] == "float" else "i")
    for need in ("pos", "velocity", "density", "phase"):
        if need not in fields:
            raise ValueError(f"no {need} in the snapshot")
    return float(found.group(1)), fields


class Kernel:
    """The 2-D Wendland C2 kernel of smoothing length h."""

    def __init__(self, h):
        self.h = h
        self.norm = 7.0 / (4.0 * math.pi * h * h)

    def w(self, r):
        q = r / self.h
        return self.norm * (1.0 - q / 2.0) ** 4 * (2.0 * q + 1.0) if q < 2.0 else 0.0


def surface(kernel, dp, near, xc):
    """The top-most height on x = xc where the fullness falls through one half, or None."""
    step = dp / 10.0
    heights = [k * step for k in range(int(0.3 / step))]
    reach = 2.0 * kernel.h
    full = []
    for y in heights:
        close = (m for m in near if abs(y - m[1]) < reach)
        full.append(sum(v * kernel.w(math.hypot(x - xc, y - yj)) for x, yj, v in close))
    for k in range(len(heights) - 1, 0, -1):
        if full[k - 1] >= 0.5 > full[k]:
            s = (full[k - 1] - 0.5) / (full[k - 1] - full[k])
            return heights[k - 1] + s * step
    return None


def snapshot_columns(fields, dp, x0, x1, width, kernel):
    """Per column: its surface and its water particles (y, u, v); and the crest."""
    p, vel, rho, phase = fields["pos"], fields["velocity"], fields["density"], fields["phase"]
    n = len(phase)
    weir = [p[3 * i + 1] for i in range(n) if phase[i] == WALL and p[3 * i] >= x1]
    if not weir:
        raise ValueError(f"no wall particle at x >= {x1} m: where is the weir?")
    crest = max(weir) + dp / 2.0
    columns = int(round((x1 - x0) / width))
    reach = 2.0 * kernel.h
    mobile = [
        (p[3 * i], p[3 * i + 1], dp * dp * REST_DENSITY[phase[i]] / rho[i])
        for i in range(n)
        if phase[i] in REST_DENSITY and x0 - reach < p[3 * i] < x1 + reach
    ]
    out = []
    for k in range(columns):
        lo = x0 + k * width
        xc = lo + width / 2.0
        near = [m for m in mobile if abs(m[0] - xc) < reach]
        water = [
            (p[3 * i + 1], vel[3 * i], vel[3 * i + 1])
            for i in range(n)
            if phase[i] == WATER and lo <= p[3 * i] < lo + width
        ]
        out.append((surface(kernel, dp, near, xc), water))
    return crest, out


def column_row(x, surfaces, water, dp, width, snapshots, crest):
    """The CSV row of one column, from its surfaces and water over every snapshot."""
    wet = [s for s in surfaces if s is not None]
    if not wet or not water:
        return [f"{x:.3f}"] + [""] * 8
    level = sum(wet) / len(wet)
    area = dp * dp / width / snapshots
    q = sum(u for _, u, _ in water) * area
    back = sum(u for _, u, _ in water if u < 0.0) * area
    forward = sum(u for _, u, _ in water if u > 0.0) * area
    head = sum(u * (u * u + v * v) for _, u, v in water if u > 0.0) * area / (2.0 * GRAVITY)
    energy = level + head / forward if forward > 0.0 else level
    layers = {}
    for y, u, _ in water:
        layers.setdefault(round(y / dp), []).append(u)
    means = {k: sum(us) / len(us) for k, us in layers.items() if len(us) >= snapshots}
    if not means:
        means = {k: sum(us) / len(us) for k, us in layers.items()}
    core = max(means, key=means.get)
    speed = means[core]
    thick = sum(1 for u in means.values() if u > 0.5 * speed) * dp
    mm = lambda z: f"{1e3 * (z - crest):.2f}"
    return [
        f"{x:.3f}",
        mm(level),
        f"{q:.5f}",
        f"{back:.5f}",
        mm(energy),
        mm(core * dp),
        f"{speed:.3f}",
        f"{1e3 * thick:.0f}",
        str(len(wet)),
    ]


def arguments(argv):
    opts = {"--dp": None, "--from-s": "-inf", "--to-s": "inf", "--x0": "2.1", "--x1": "2.49",
            "--width": "0.02"}
    rest = []
    while argv:
        a = argv.pop(0)
        if a in opts:
            if not argv:
                sys.exit(f"{a} needs a value")
            opts[a] = argv.pop(0)
        else:
            rest.append(a)
    if len(rest) != 1 or opts["--dp"] is None:
        sys.exit(__doc__)
    try:
        values = {k: float(v) for k, v in opts.items()}
    except ValueError as e:
        sys.exit(f"not a number: {e}")
    if not (values["--dp"] > 0.0 and values["--width"] > 0.0 and values["--x1"] > values["--x0"]):
        sys.exit("--dp and --width must be positive and --x1 beyond --x0")
    return rest[0], values


def main(argv):
    run_dir, o = arguments(list(argv))
    dp, x0, x1, width = o["--dp"], o["--x0"], o["--x1"], o["--width"]
    paths = sorted(glob.glob(os.path.join(run_dir, "particles_*.vtk")))
    if not paths:
        sys.exit(f"no particles_*.vtk in {run_dir} (a directory `flume-twin simulate` wrote?)")
    kernel = Kernel(1.2 * math.sqrt(2.0) * dp)
    surfaces, waters, crest, used = None, None, None, 0
    for path in paths:
        try:
            t, fields = read_vtk(path)
            if not o["--from-s"] <= t <= o["--to-s"]:
                continue
            crest, columns = snapshot_columns(fields, dp, x0, x1, width, kernel)
        except (OSError, ValueError, struct.error) as e:
            sys.exit(f"{path}: {e}")
        surfaces = surfaces or [[] for _ in columns]
        waters = waters or [[] for _ in columns]
        for k, (s, water) in enumerate(columns):
            surfaces[k].append(s)
            waters[k].extend(water)
        used += 1
    if not used:
        sys.exit(f"no snapshot in {run_dir} lies between {o['--from-s']} and {o['--to-s']} s")
    print(f"# {used} snapshots; crest {crest:.4f} m; heights in mm over the crest")
    print("x_m,surface_mm,q_m2_per_s,q_back_m2_per_s,energy_mm,core_mm,core_m_per_s,"
          "core_thickness_mm,wet_snapshots")
    for k in range(len(surfaces)):
        x = x0 + (k + 0.5) * width
        print(",".join(column_row(x, surfaces[k], waters[k], dp, width, used, crest)))


if __name__ == "__main__":
    main(sys.argv[1:])
