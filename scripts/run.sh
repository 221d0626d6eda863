#!/usr/bin/env bash
# Builds and runs flume-twin with the given arguments (default: the dam-break verification case).
# Installs what it needs first. Example: scripts/run.sh simulate launch_configs/dambreak_water.yaml
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
if [ "$#" -eq 0 ]; then
  set -- simulate launch_configs/dambreak_water.yaml
fi
cargo run --release --quiet --bin flume-twin -- "$@"
