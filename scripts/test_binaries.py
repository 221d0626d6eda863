#!/usr/bin/env python3
"""Runs the test binaries cargo built, several at a time, and prints each one's output whole.

Usage: test_binaries.py ARTIFACTS [-- HARNESS_ARGS...]

ARTIFACTS holds the JSON lines of `cargo test --no-run --message-format=json`. `cargo test`
runs its binaries one after another; a lavapipe run keeps one core busy and the CPU backend's
runs at CI size on two threads about 1.2, so on two cores the second sat idle much of the time.
Here the binaries that only compute share a pool of one lane per core, longest first; those
that serve DDS, WebSockets or shared memory against wall-clock deadlines (the node's, but its
whole-session replay, which writes files) run afterwards one at a time, with the machine to
themselves, as cargo ran them. The two binaries whose runs grow to gigabytes on Mesa 22.3's
lavapipe (APART) never run at once. Each binary runs in its package's directory, as under
`cargo test`. The exit status is 1 when any binary failed, 2 on bad input, 130 when
interrupted (Ctrl-C or SIGTERM): each binary runs in a process group of its own, which is
killed whole, with whatever it started, and no binary starts after the interrupt.
"""

import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

# Seconds each binary took in the pool of a whole run on two cores (CI=true), to start the
# longest first; a binary not listed is taken as short. Only the order depends on these.
MEASURED_S = {
    "flume-solver tests/weir.rs": 562,
    "flume-twin tests/whole_session.rs": 371,
    "flume-solver tests/roughness.rs": 337,
    "flume-solver tests/scour.rs": 147,
    "flume-solver tests/awake_set.rs": 118,
    "flume-solver tests/whole_session.rs": 106,
    "flume-solver tests/cases.rs": 86,
    "flume-solver tests/erosion_chain.rs": 60,
    "flume-solver tests/front_step.rs": 47,
    "flume-solver tests/pickup.rs": 23,
    "flume-solver tests/gpu_vs_reference.rs": 20,
    "flume-solver tests/pores.rs": 10,
    "flume-solver tests/splash.rs": 12,
}
# The node's binaries that need no machine to themselves.
POOLED_NODE = {"flume-twin tests/whole_session.rs"}
# Binaries whose wgpu runs of the CI flume grow to 8-10 GB on Debian 12's own Mesa 22.3 (its
# lavapipe keeps memory for every rheology dispatch; the scripts install Mesa 25 where they
# install a driver, but a machine may already have 22.3): never two of them at once.
APART = {"flume-solver tests/whole_session.rs", "flume-solver tests/weir.rs"}


class Interrupted(Exception):
    pass


class Children:
    """The process groups of the binaries running now, killed whole on an interrupt; after
    it, nothing more starts."""

    def __init__(self):
        self.lock = threading.Lock()
        self.groups = set()
        self.stopped = False

    def start(self, argv, **kwargs):
        with self.lock:
            if self.stopped:
                raise Interrupted()
            child = subprocess.Popen(argv, start_new_session=True, **kwargs)
            self.groups.add(child.pid)
            return child

    def ended(self, child):
        with self.lock:
            self.groups.discard(child.pid)

    def stop(self):
        with self.lock:
            self.stopped = True
            for group in self.groups:
                try:
                    os.killpg(group, signal.SIGKILL)
                except ProcessLookupError:
                    pass


CHILDREN = Children()


class Binary:
    def __init__(self, package, source, executable, directory):
        self.label = f"{package} {source}"
        self.package = package
        self.executable = executable
        self.directory = directory

    def quiet(self):
        return self.package == "flume-twin" and self.label not in POOLED_NODE


def read_artifacts(path):
    """The test executables among cargo's JSON messages, with their package's directory."""
    binaries = []
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            if not line.startswith("{"):
                continue
            try:
                message = json.loads(line)
            except json.JSONDecodeError as e:
                raise ValueError(f"{path}:{number}: not a cargo message: {e}") from e
            if message.get("reason") != "compiler-artifact" or not message.get("executable"):
                continue
            if not message.get("profile", {}).get("test"):
                continue
            directory = os.path.dirname(message["manifest_path"])
            source = os.path.relpath(message["target"]["src_path"], directory)
            binaries.append(Binary(package_name(message), source, message["executable"], directory))
    return binaries


def package_name(message):
    """The package's name: a path package's id ends `dir#name@version`, or `name#version`
    where the name is the directory's."""
    path, _, fragment = message["package_id"].partition("#")
    name = fragment.split("@")[0] if "@" in fragment else path.rstrip("/").rsplit("/", 1)[-1]
    if not name:
        raise ValueError(f"no package name in {message['package_id']!r}")
    return name


def run(binary, args):
    """Runs one binary to its end: (exit status, output, wall s, CPU s of it and its children,
    the largest resident size of it or a child, GB)."""
    with tempfile.TemporaryFile() as out:
        started = time.monotonic()
        try:
            child = CHILDREN.start(
                [binary.executable, *args],
                cwd=binary.directory,
                stdout=out,
                stderr=subprocess.STDOUT,
            )
        except OSError as e:
            return 127, f"cannot run {binary.executable}: {e}\n", 0.0, 0.0, 0.0
        try:
            _, status, usage = os.wait4(child.pid, 0)
        finally:
            CHILDREN.ended(child)
        child.returncode = os.waitstatus_to_exitcode(status)
        wall = time.monotonic() - started
        out.seek(0)
        text = out.read().decode("utf-8", errors="replace")
    cpu = usage.ru_utime + usage.ru_stime
    return child.returncode, text, wall, cpu, usage.ru_maxrss / 1e6


class Report:
    """Prints each binary's output whole as it ends, and keeps the failures."""

    def __init__(self):
        self.lock = threading.Lock()
        self.failed = []
        self.times = []

    def ended(self, binary, code, text, wall, cpu, gb):
        with self.lock:
            print(f"     Running {binary.label} ({binary.executable})", flush=False)
            print(text, end="" if text.endswith("\n") else "\n")
            print(
                f"     {binary.label}: exit {code}, {wall:.1f} s wall, {cpu:.1f} s CPU, {gb:.2f} GB",
                flush=True,
            )
            self.times.append((wall, cpu, gb, binary.label))
            if code != 0:
                self.failed.append(binary.label)

    def table(self):
        """The binaries that took over a second, longest first: where the suite's time goes."""
        for wall, cpu, gb, label in sorted(self.times, reverse=True):
            if wall >= 1.0:
                print(f"{wall:8.1f} s wall {cpu:8.1f} s CPU {gb:6.2f} GB  {label}")


def run_pool(binaries, args, lanes, report):
    """Each lane takes the longest binary left that may start: one of APART only while no
    other of them runs."""
    waiting = sorted(binaries, key=lambda b: -MEASURED_S.get(b.label, 0))
    apart_running = False
    changed = threading.Condition()

    def take():
        nonlocal apart_running
        with changed:
            while waiting:
                for k, b in enumerate(waiting):
                    if b.label not in APART or not apart_running:
                        apart_running |= b.label in APART
                        return waiting.pop(k)
                changed.wait()
            return None

    def lane():
        nonlocal apart_running
        while (b := take()) is not None:
            try:
                report.ended(b, *run(b, args))
            except Interrupted:
                return
            finally:
                with changed:
                    apart_running &= b.label not in APART
                    changed.notify_all()

    threads = [threading.Thread(target=lane) for _ in range(lanes)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()


def interrupt(signum, frame):
    raise KeyboardInterrupt()


def main(argv):
    if len(argv) < 2 or (len(argv) > 2 and argv[2] != "--"):
        print(__doc__, file=sys.stderr)
        return 2
    try:
        binaries = read_artifacts(argv[1])
    except (OSError, ValueError, KeyError) as e:
        print(f"test_binaries.py: cannot read the test binaries: {e}", file=sys.stderr)
        return 2
    args = argv[3:]
    try:
        lanes = int(os.environ.get("TEST_LANES", "0")) or os.cpu_count() or 1
    except ValueError:
        print("test_binaries.py: TEST_LANES is not a number", file=sys.stderr)
        return 2
    report = Report()
    started = time.monotonic()
    signal.signal(signal.SIGTERM, interrupt)
    try:
        run_pool([b for b in binaries if not b.quiet()], args, lanes, report)
        run_pool([b for b in binaries if b.quiet()], args, 1, report)
    except KeyboardInterrupt:
        CHILDREN.stop()
        print("test_binaries.py: interrupted; the running binaries were killed", flush=True)
        return 130
    report.table()
    cpu = sum(t[1] for t in report.times)
    wall = time.monotonic() - started
    print(f"{len(binaries)} test binaries in {wall:.0f} s on {lanes} lanes, {cpu:.0f} s CPU")
    if report.failed:
        print("failed: " + ", ".join(report.failed))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
