#!/usr/bin/env bash
# Runs every test of the workspace: formulas, shader validation, each GPU stage against its CPU
# oracle, the verification cases and the command line. Installs what it needs first.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
# An independent reader of our VTK snapshots, for the interop check in node/tests/cli.rs.
if ! python3 -c "import meshio" >/dev/null 2>&1; then
  python3 -m pip install --quiet --disable-pip-version-check meshio
fi
cargo test --release --workspace "$@"
