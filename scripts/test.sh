#!/usr/bin/env bash
# Runs every test of the workspace: formulas, shader validation, each GPU stage against its CPU
# oracle, the verification cases and the command line. Installs what it needs first.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
# Independent readers: meshio for our VTK snapshots (node/tests/cli.rs), Python's mcap and
# mcap-ros2-support for our CDR messages and recordings (msgs/tests/cdr_interop.rs,
# node/tests/replay.rs, node/tests/record.rs).
if ! python3 -c "import meshio" >/dev/null 2>&1; then
  python3 -m pip install --quiet --disable-pip-version-check meshio
fi
if ! python3 -c "import mcap_ros2" >/dev/null 2>&1; then
  python3 -m pip install --quiet --disable-pip-version-check mcap mcap-ros2-support
fi
# rosbags, a rosbag2 reader, for our bag directories (node/tests/record.rs).
if ! python3 -c "import rosbags" >/dev/null 2>&1; then
  python3 -m pip install --quiet --disable-pip-version-check rosbags==0.11.9
fi
# A DDS nobody here wrote, for the ROS 2 interop test (node/tests/ros_interop.rs).
if ! python3 -c "import cyclonedds" >/dev/null 2>&1; then
  python3 -m pip install --quiet --disable-pip-version-check cyclonedds
fi
# iceoryx2's own Python binding, the reader of our particle frames, and the rerun SDK of the
# reference visualiser (node/tests/frames.rs).
if ! python3 -c "import iceoryx2" >/dev/null 2>&1; then
  python3 -m pip install --quiet --disable-pip-version-check iceoryx2==0.10.0
fi
if ! python3 -c "import rerun" >/dev/null 2>&1; then
  python3 -m pip install --quiet --disable-pip-version-check rerun-sdk==0.41.0
fi
# Foxglove's own WebSocket client and ROS 2 decoders, under Node, for the live view's test
# (node/tests/foxglove.rs), at the versions the lock file pins.
if command -v npm >/dev/null && [ ! -d tests/interop/foxglove_client/node_modules ]; then
  npm ci --prefix tests/interop/foxglove_client --no-audit --no-fund --loglevel=error
fi
# Arguments before a `--` select what cargo builds (`-p flume-solver --test weir`); those after
# it go to each test binary (`--nocapture`, a test's name).
cargo_args=()
while [ "$#" -gt 0 ] && [ "$1" != "--" ]; do
  cargo_args+=("$1")
  shift
done
if [ "$#" -gt 0 ]; then shift; fi
if [ "${#cargo_args[@]}" -eq 0 ]; then cargo_args=(--workspace); fi
# Built once; scripts/test_binaries.py then runs the binaries side by side, as many as there
# are cores, and the doc tests last (cargo runs them only for a whole package). A last line sums
# the whole suite.
log="$(mktemp)"
artifacts="$(mktemp)"
status=0
cargo test --release --no-run --message-format=json-render-diagnostics "${cargo_args[@]}" \
  >"$artifacts" || status=$?
if [ "$status" -eq 0 ]; then
  python3 scripts/test_binaries.py "$artifacts" -- "$@" 2>&1 | tee "$log" || status=$?
  if [ "${cargo_args[*]}" = "--workspace" ]; then
    cargo test --release --workspace --doc -- "$@" 2>&1 | tee -a "$log" || status=$?
  fi
fi
awk '/^test result:/ {
  for (i = 2; i <= NF; i++) {
    if ($i == "passed;") p += $(i - 1)
    if ($i == "failed;") f += $(i - 1)
    if ($i == "ignored;") s += $(i - 1)
  }
} END { printf "%d passed, %d failed, %d skipped\n", p, f, s }' "$log"
rm -f "$log" "$artifacts"
exit "$status"
