#!/usr/bin/env python3
"""A textbook bed-load rate on a flume run's own depths, beside the mass the run collected.

Usage: python3 scripts/bed_load.py RUN_DIR --gauge P3 --bed-m 0.054 [--from-s 5]
           [--q-m2-per-s 6.46e-3] [--d50-m 0.0004] [--ks-over-d50 3] [--rho-s 2710] > rate.csv

RUN_DIR holds `gauges.csv` and `eroded_mass.csv` as `flume-twin simulate` writes them. At each
output time from --from-s on, the depth h over the bed at the gauge is its level less --bed-m.
The flow's friction velocity follows from the depth-averaged rough log law, the model's
u = u*/kappa ln(30 z / ks) averaged over the depth: U / u* = ln(11 h / ks) / kappa, with
U = q / h. The Shields number is theta = u*^2 / ((s - 1) g d50), and Meyer-Peter & Mueller
(1948) give q* = 8 (theta - 0.047)^1.5 (nothing under 0.047), a volume rate
q* sqrt((s - 1) g d50^3) per metre of width, times rho_s as mass. The rate is integrated in
time (trapezoids) and written beside the run's eroded mass. The discharge is per metre of
width (2 m3/h over the ULBRA flume's 86 mm by default).

Writes CSV: time_s, depth_m, shields, mpm_kg_per_m_s, mpm_kg_per_m (integrated from the first
row), model_kg_per_m (the run's eroded mass); and on standard error the two over the same
span.
"""

import argparse
import csv
import math
import sys

G = 9.81
KARMAN = 0.41
CRITICAL = 0.047


def mpm_rate(depth_m, a):
    """(Shields number, MPM mass rate in kg/m/s) for a flow `depth_m` deep."""
    ks = a.ks_over_d50 * a.d50_m
    s = a.rho_s / 1000.0
    u = a.q_m2_per_s / depth_m
    u_star = KARMAN * u / math.log(11.0 * depth_m / ks)
    theta = u_star * u_star / ((s - 1.0) * G * a.d50_m)
    q_star = 8.0 * max(theta - CRITICAL, 0.0) ** 1.5
    return theta, q_star * math.sqrt((s - 1.0) * G * a.d50_m**3) * a.rho_s


def read_rows(path, needs):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"cannot read {path}: {e.strerror} (a directory `flume-twin simulate` wrote?)")
    missing = [c for c in needs if rows and c not in rows[0]]
    if not rows or missing:
        sys.exit(f"{path}: no rows or no column {missing or needs}")
    try:
        return [{c: float(r[c]) for c in needs} for r in rows]
    except ValueError as e:
        sys.exit(f"{path}: not a number: {e}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run_dir")
    p.add_argument("--gauge", required=True)
    p.add_argument("--bed-m", type=float, required=True)
    p.add_argument("--from-s", type=float, default=0.0)
    p.add_argument("--q-m2-per-s", type=float, default=5.5556e-4 / 0.086)
    p.add_argument("--d50-m", type=float, default=0.0004)
    p.add_argument("--ks-over-d50", type=float, default=3.0)
    p.add_argument("--rho-s", type=float, default=2710.0)
    a = p.parse_args()
    level = f"{a.gauge}_m"
    gauges = read_rows(f"{a.run_dir}/gauges.csv", ["time_s", level])
    eroded = {
        r["time_s"]: r["eroded_kg_per_m"]
        for r in read_rows(f"{a.run_dir}/eroded_mass.csv", ["time_s", "eroded_kg_per_m"])
    }
    out = csv.writer(sys.stdout, lineterminator="\n")
    out.writerow(["time_s", "depth_m", "shields", "mpm_kg_per_m_s", "mpm_kg_per_m",
                  "model_kg_per_m"])
    total, first, last = 0.0, None, None
    for r in gauges:
        t, depth = r["time_s"], r[level] - a.bed_m
        if t < a.from_s - 1e-9 or depth <= 0.0:
            continue
        theta, rate = mpm_rate(depth, a)
        if last is not None:
            total += 0.5 * (rate + last[1]) * (t - last[0])
        first = t if first is None else first
        last = (t, rate)
        model = eroded.get(t, "")
        out.writerow([f"{t:g}", f"{depth:.5f}", f"{theta:.4f}", f"{rate:.4e}", f"{total:.4e}",
                      model if model == "" else f"{model:.4f}"])
    if last is None:
        sys.exit(f"{a.run_dir}: no wet {a.gauge} from {a.from_s} s")
    at = lambda time: eroded[max((t for t in eroded if t <= time + 1e-9), default=0.0)]
    print(f"from {first:g} to {last[0]:g} s at {a.gauge}: Meyer-Peter & Mueller {total:.3f} "
          f"kg/m, the run collected {at(last[0]) - at(first):.3f} kg/m", file=sys.stderr)


if __name__ == "__main__":
    main()
