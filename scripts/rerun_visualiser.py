"""The reference visualiser: reads flume-twin's particle frames from shared memory (iceoryx2's
Python binding) and streams them to rerun, coloured by phase and, as a second entity, by the
paper's region, on a `sim_time` timeline.

Usage:
  python3 scripts/rerun_visualiser.py [--service flume_twin/particles]
                                      [--save FILE.rrd | --connect URL | --spawn] [--frames N]
                                      [--timeout S]
Without --save/--connect it spawns a rerun viewer. Needs `pip install rerun-sdk iceoryx2`.
The frame layout is node/src/adapters/frames.rs's (version 1), 32 bytes a particle.
"""

import argparse
import ctypes
import sys
import time

import iceoryx2 as iox2
import numpy as np
import rerun as rr

PARTICLE = np.dtype(
    [
        ("position", "<f4", 3),
        ("velocity", "<f4", 3),
        ("density", "<f4"),
        ("phase", "u1"),
        ("region", "u1"),
        ("held", "u1"),
        ("reserved", "u1"),
    ]
)
assert PARTICLE.itemsize == 32


class Particle(ctypes.Structure):
    """The slice's element type (node/src/adapters/frames.rs); read in bulk through PARTICLE."""

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


# Walls grey, water blue, sand ochre, parked water faint.
PHASE_COLOURS = np.array(
    [[128, 128, 128], [40, 110, 230], [200, 150, 60], [200, 220, 255]], dtype=np.uint8
)
# Regions 0-5: none/walls, un-yielded, yielded, bed load, suspended, water.
REGION_COLOURS = np.array(
    [[128, 128, 128], [120, 70, 20], [220, 120, 30], [240, 200, 40], [230, 60, 60], [40, 110, 230]],
    dtype=np.uint8,
)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--service", default="flume_twin/particles")
    sink = parser.add_mutually_exclusive_group()
    sink.add_argument("--save", metavar="FILE.rrd")
    sink.add_argument("--connect", metavar="URL")
    sink.add_argument("--spawn", action="store_true")
    parser.add_argument("--frames", type=int, default=0, help="stop after N frames (0: never)")
    parser.add_argument(
        "--timeout",
        type=float,
        default=0.0,
        help="exit with an error after S seconds without a frame (0: wait for the twin forever)",
    )
    args = parser.parse_args()

    rr.init("flume_twin")
    if args.save:
        rr.save(args.save)
    elif args.connect:
        rr.connect_grpc(args.connect)
    else:
        rr.spawn()

    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
    name = iox2.ServiceName.new(args.service)
    last_frame = time.monotonic()

    def waited_too_long():
        return args.timeout > 0 and time.monotonic() - last_frame > args.timeout

    while True:
        try:
            pubsub = (
                node.service_builder(name)
                .publish_subscribe(iox2.Slice[Particle])
                .user_header(FrameHeader)
                .open()
            )
            event = node.service_builder(name).event().open()
            break
        except Exception:  # the twin is not up yet
            if waited_too_long():
                sys.exit(f"no twin offered {args.service} within {args.timeout:g} s")
            time.sleep(0.5)
    subscriber = pubsub.subscriber_builder().create()
    listener = event.listener_builder().create()
    print(f"reading particle frames from {args.service}", flush=True)
    shown = 0
    while args.frames == 0 or shown < args.frames:
        listener.timed_wait(iox2.Duration.from_millis(500))
        sample = subscriber.receive()
        if sample is None:
            if waited_too_long():
                sys.exit(f"no frame on {args.service} for {args.timeout:g} s; {shown} shown")
            continue
        last_frame = time.monotonic()
        header = sample.user_header().contents
        if header.version != 1:
            sys.exit(f"frame layout version {header.version}; this visualiser reads version 1")
        raw = (ctypes.c_uint8 * (32 * header.count)).from_address(sample.payload().as_ptr())
        p = np.frombuffer(raw, dtype=PARTICLE).copy()
        del sample  # hand the shared memory back at once
        in_flow = p["phase"] != header.parked_phase
        p = p[in_flow]
        rr.set_time("sim_time", duration=header.sim_time_s)
        radii = np.full(len(p), 0.002, dtype=np.float32)
        rr.log(
            "flume/by_phase",
            rr.Points3D(p["position"], colors=PHASE_COLOURS[np.minimum(p["phase"], 3)], radii=radii),
        )
        rr.log(
            "flume/by_region",
            rr.Points3D(
                p["position"], colors=REGION_COLOURS[np.minimum(p["region"], 5)], radii=radii
            ),
        )
        rr.log("flume/speed_max_m_per_s", rr.Scalars(float(np.linalg.norm(p["velocity"], axis=1).max())))
        shown += 1
    rr.disconnect()


if __name__ == "__main__":
    main()
