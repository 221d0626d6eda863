#!/usr/bin/env bash
# Runs every test of the workspace: formulas, shader validation, each GPU stage against its CPU
# oracle, the verification cases and the command line. Installs what it needs first.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
cargo test --release --workspace "$@"
