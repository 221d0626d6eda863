"""Reads a flume-twin recording with the `rosbags` library (a rosbag2 reader written elsewhere,
pure Python) and prints what it found as one JSON document: the bag's metadata (message count,
start, duration), each topic (type, the count the metadata gives, the messages actually read,
the offered QoS), and every message of the topics asked for, decoded with the types rosbags
builds from the definitions the recording carries.

Usage: python3 tests/interop/read_rosbag.py BAG [TOPIC ...]
BAG is a bag directory (rosbags then needs its metadata.yaml) or an MCAP file. Any error rosbags
raises is reported in "error" instead of a traceback, so a test can say what went wrong.
"""

import dataclasses
import json
import math
import sys
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore


def plain(value):
    """A decoded message as JSON-like data: dataclasses as dicts, arrays as lists, NaN as None
    (JSON has no NaN)."""
    if dataclasses.is_dataclass(value):
        return {
            f.name: plain(getattr(value, f.name))
            for f in dataclasses.fields(value)
            if not f.name.startswith("__")
        }
    if hasattr(value, "tolist"):
        return plain(value.tolist())
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, float) and math.isnan(value):
        return None
    return value


def main():
    path, wanted = Path(sys.argv[1]), set(sys.argv[2:])
    out = {"topics": {}, "messages": [], "error": None}
    try:
        typestore = get_typestore(Stores.ROS2_JAZZY)
        with AnyReader([path], default_typestore=typestore) as reader:
            out["message_count"] = reader.message_count
            out["start_ns"] = reader.start_time
            out["duration_ns"] = reader.duration
            for conn in reader.connections:
                out["topics"][conn.topic] = {
                    "type": conn.msgtype,
                    "metadata_count": conn.msgcount,
                    "read": 0,
                    "qos": [
                        {
                            "reliability": q.reliability.name.lower(),
                            "durability": q.durability.name.lower(),
                            "depth": q.depth,
                        }
                        for q in conn.ext.offered_qos_profiles
                    ],
                }
            for conn, log_ns, raw in reader.messages():
                out["topics"][conn.topic]["read"] += 1
                if conn.topic in wanted:
                    msg = reader.deserialize(raw, conn.msgtype)
                    out["messages"].append(
                        {"topic": conn.topic, "log_ns": log_ns, "msg": plain(msg)}
                    )
    except Exception as e:  # noqa: BLE001 - whatever rosbags refuses is the answer
        out["error"] = f"{type(e).__name__}: {e}"
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
