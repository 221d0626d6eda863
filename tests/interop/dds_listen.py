"""A ROS 2 listener on Cyclone DDS (the `cyclonedds` wheel), loopback only: what a player puts on
the wire for a twin on simulated time. It subscribes to `/clock` and to the flume's sensor topics
(`<ns>/inflow`, `<ns>/gauges/p1`..`p3`) and prints each message as one JSON line,
`{"clock": t}`, `{"inflow": {"stamp": t, "q": q}}` or `{"p1": {"stamp": t, "level": h}}`, t in s
since the epoch, until SECONDS of wall time have passed or nothing came for IDLE_S after the
first message.

Usage: python3 tests/interop/dds_listen.py DOMAIN NAMESPACE SECONDS IDLE_S
"""

import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

# dds_peer sets Cyclone's loopback configuration before the library loads.
from dds_peer import Clock, Discharge, WaterLevel, secs  # noqa: E402
from cyclonedds.core import Policy, Qos  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.internal import InvalidSample  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402


def main() -> None:
    domain, ns = int(sys.argv[1]), sys.argv[2].rstrip("/")
    seconds, idle = float(sys.argv[3]), float(sys.argv[4])
    dp = DomainParticipant(domain)
    reliable = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.History.KeepLast(100))
    best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(100))
    readers = {
        "clock": DataReader(dp, Topic(dp, "rt/clock", Clock), best_effort),
        "inflow": DataReader(dp, Topic(dp, f"rt{ns}/inflow", Discharge), reliable),
    }
    for g in ("p1", "p2", "p3"):
        readers[g] = DataReader(dp, Topic(dp, f"rt{ns}/gauges/{g}", WaterLevel), best_effort)
    print(json.dumps({"listening": list(readers)}), flush=True)
    end = time.time() + seconds
    last = None
    while time.time() < end and (last is None or time.time() - last < idle):
        got = False
        for name, reader in readers.items():
            for m in reader.take(N=100):
                got = True
                # A writer that leaves sends a sample with no data (its unregistration).
                if isinstance(m, InvalidSample):
                    continue
                if name == "clock":
                    body = m.clock.sec + m.clock.nanosec * 1e-9
                elif name == "inflow":
                    body = {"stamp": secs(m.header), "q": m.discharge_m3_per_s}
                else:
                    body = {"stamp": secs(m.header), "level": m.level_m}
                print(json.dumps({name: body}), flush=True)
        if got:
            last = time.time()
        else:
            time.sleep(0.01)


if __name__ == "__main__":
    main()
