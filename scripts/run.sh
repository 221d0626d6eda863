#!/usr/bin/env bash
# Builds and runs flume-twin with the given arguments. Installs what it needs first.
# Default: the twin of the ULBRA flume at CI size (dp = 1 cm, which a software adapter runs at a
# few percent of real time), with the walls, viscosity and pick-up that hold at a flow a few
# particles deep (README, levels section); with no sensors on the network the bundled session
# plays them.
# Example: scripts/run.sh simulate launch_configs/dambreak_water.yaml
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
if [ "$#" -eq 0 ]; then
  set -- run launch_configs/ulbra_flume.yaml --set numerics.dp_m=0.01 \
    --set open_flume.reservoir_particles=2500 \
    --set 'numerics.boundary={method: generalised}' \
    --set 'numerics.viscosity={method: multiphase, eddy_m2_per_s: 3.95e-5}' \
    --set phases.1.sediment.erosion=van_rijn_exner \
    --set phases.1.sediment.shields_speed=water \
    --set phases.1.sediment.comes_to_rest=beside_a_solid
fi
cargo run --release --quiet --bin flume-twin -- "$@"
