"""Reads flume-twin's particle frames with the iceoryx2 Python binding (written elsewhere) from
shared memory, and checks each: the header's layout version, its particle count against the
slice, finite positions, velocities and densities, phases and regions in their ranges.

Usage: python3 tests/interop/iox2_frames.py SERVICE FRAMES [--hold]
Prints one JSON line per frame: {"version", "count", "slice_len" (bytes), "step", "t",
"parked_phase", "phases": {code: n}, "regions": {code: n}, "held", "finite", "units",
"latency_ms" (from the twin's send to this reader's first look)}. With --hold it keeps the
first frame's sample and sleeps, as a stuck visualiser would, until it is killed. Exits
non-zero if no frame comes within 120 s.
"""

import ctypes
import json
import math
import sys
import time

import iceoryx2 as iox2


class Particle(ctypes.Structure):
    """flume_twin::Particle (node/src/adapters/frames.rs), layout version 1."""

    _fields_ = [
        ("position", ctypes.c_float * 3),
        ("velocity", ctypes.c_float * 3),
        ("density", ctypes.c_float),
        ("phase", ctypes.c_uint8),
        ("region", ctypes.c_uint8),
        ("held", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8),
    ]

    @staticmethod
    def type_name() -> str:
        return "flume_twin::Particle"


class FrameHeader(ctypes.Structure):
    """flume_twin::FrameHeader."""

    _fields_ = [
        ("version", ctypes.c_uint32),
        ("parked_phase", ctypes.c_uint32),
        ("count", ctypes.c_uint64),
        ("step", ctypes.c_uint64),
        ("sim_time_s", ctypes.c_double),
        ("sent_unix_ns", ctypes.c_uint64),
        ("units", ctypes.c_uint8 * 32),
    ]

    @staticmethod
    def type_name() -> str:
        return "flume_twin::FrameHeader"


def open_with_retry(node, name, deadline):
    """The twin may still be starting: open its services once they exist."""
    while True:
        try:
            pubsub = (
                node.service_builder(name)
                .publish_subscribe(iox2.Slice[Particle])
                .user_header(FrameHeader)
                .open()
            )
            event = node.service_builder(name).event().open()
            return pubsub, event
        except Exception:  # the binding's open errors: not there yet
            if time.time() > deadline:
                raise
            time.sleep(0.2)


def check(sample):
    received_ns = time.time_ns()
    header = sample.user_header().contents
    payload = sample.payload()
    particles = (Particle * header.count).from_address(payload.as_ptr())
    phases, regions, held, finite = {}, {}, 0, True
    for p in particles:
        phases[p.phase] = phases.get(p.phase, 0) + 1
        regions[p.region] = regions.get(p.region, 0) + 1
        held += p.held
        values = list(p.position) + list(p.velocity) + [p.density]
        finite = finite and all(math.isfinite(v) for v in values)
    return {
        "version": header.version,
        "count": header.count,
        "slice_len": payload.len(),
        "step": header.step,
        "t": header.sim_time_s,
        "parked_phase": header.parked_phase,
        "phases": phases,
        "regions": regions,
        "held": held,
        "finite": finite,
        "units": bytes(header.units).split(b"\0")[0].decode(),
        "latency_ms": (received_ns - header.sent_unix_ns) * 1e-6,
    }


def main():
    service, wanted = sys.argv[1], int(sys.argv[2])
    hold = "--hold" in sys.argv[3:]
    deadline = time.time() + 120
    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
    pubsub, event = open_with_retry(node, iox2.ServiceName.new(service), deadline)
    subscriber = pubsub.subscriber_builder().create()
    listener = event.listener_builder().create()
    got, held = 0, []
    while got < wanted:
        if time.time() > deadline:
            sys.exit(f"only {got} of {wanted} frames in 120 s")
        listener.timed_wait(iox2.Duration.from_millis(500))
        while got < wanted:
            sample = subscriber.receive()
            if sample is None:
                break
            print(json.dumps(check(sample)), flush=True)
            got += 1
            if hold:
                held.append(sample)
                print("holding", flush=True)
                while True:
                    time.sleep(1)


if __name__ == "__main__":
    main()
