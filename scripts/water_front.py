#!/usr/bin/env python3
"""The water front of flume runs, from the bed profiles `flume-twin simulate` writes.

Usage: python3 scripts/water_front.py [--depth-m D] RUN_DIR [RUN_DIR ...] > front.csv

For each run directory (holding `bed_profile.csv`) and each output time, the front is the
furthest profile column where the water stands at least D (default 4 mm) above the sand's top,
or above the bed's initial top where the column holds no sand (over the sill and the pit). The
front of a dam break is its furthest particle; over an erodible bed that would be the sand's
end, hence the profile. Writes CSV: time_s, then one column per run (empty where no column is
wet yet).
"""

import csv
import sys
from collections import defaultdict


def fronts(run_dir, depth_m):
    """{time_s: front x in m, or None} of one run."""
    path = f"{run_dir}/bed_profile.csv"
    try:
        return profile_fronts(path, depth_m)
    except OSError as e:
        sys.exit(f"cannot read {path}: {e.strerror} (a directory `flume-twin simulate` wrote?)")
    except (KeyError, ValueError) as e:
        sys.exit(f"{path}: not a bed profile (time_s,x_m,zb_m,zs_m,zw_m): {e!r}")


def profile_fronts(path, depth_m):
    columns = defaultdict(list)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            columns[float(row["time_s"])].append(row)
    if not columns:
        sys.exit(f"{path} holds no rows")
    first = columns[min(columns)]
    bed_top = max((float(r["zs_m"]) for r in first if r["zs_m"]), default=None)
    if bed_top is None:
        sys.exit(f"{path}: the first profile shows no sand")
    out = {}
    for t, rows in columns.items():
        wet = [
            float(r["x_m"])
            for r in rows
            if r["zw_m"]
            and float(r["zw_m"]) - max(float(r["zs_m"]) if r["zs_m"] else bed_top, bed_top)
            >= depth_m
        ]
        out[t] = max(wet) if wet else None
    return out


def main(argv):
    depth_m = 0.004
    if len(argv) >= 2 and argv[0] == "--depth-m":
        depth_m = float(argv[1])
        argv = argv[2:]
    if not argv:
        sys.exit(__doc__)
    runs = [fronts(d, depth_m) for d in argv]
    times = sorted(set().union(*runs))
    w = csv.writer(sys.stdout, lineterminator="\n")
    w.writerow(["time_s"] + [f"front_m {d.rstrip('/')}" for d in argv])
    for t in times:
        w.writerow([t] + ["" if r.get(t) is None else f"{r[t]:.3f}" for r in runs])


if __name__ == "__main__":
    main(sys.argv[1:])
