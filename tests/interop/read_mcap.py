"""Reads a flume-twin recording with the Python `mcap` reader and mcap-ros2-support's ROS 2
decoder (readers written elsewhere) and prints what it found as one JSON document: the file's
profile and library, each channel (topic, schema name and encoding, message encoding, QoS
metadata, message count), and every message of the topics asked for, decoded from nothing but
the schema the file carries.

Usage: python3 tests/interop/read_mcap.py FILE [TOPIC ...]
A file cut short (a crash) is read up to its last whole chunk by streaming it; the JSON then
says where the reader stopped ("error").
"""

import json
import math
import sys
import types

from mcap.records import Channel, Header, Message, Schema
from mcap.stream_reader import StreamReader
from mcap_ros2.decoder import DecoderFactory


def plain(value):
    """A decoded message as JSON-like data: records as dicts, byte arrays as int lists, NaN as
    None (JSON has no NaN)."""
    if isinstance(value, types.SimpleNamespace) or hasattr(value, "__slots__"):
        fields = getattr(value, "__slots__", None) or vars(value).keys()
        return {f: plain(getattr(value, f)) for f in fields}
    if isinstance(value, (bytes, bytearray)):
        return list(value)
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, float) and math.isnan(value):
        return None
    return value


def main():
    path, wanted = sys.argv[1], set(sys.argv[2:])
    out = {"channels": {}, "messages": [], "error": None}
    decoders = DecoderFactory()
    decoder_of = {}
    schemas, channels = {}, {}
    with open(path, "rb") as f:
        # Streaming record by record needs no summary, so it reads a recording a crash cut short.
        try:
            for record in StreamReader(f, validate_crcs=True).records:
                if isinstance(record, Header):
                    out["profile"], out["library"] = record.profile, record.library
                elif isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    channels[record.id] = record
                elif isinstance(record, Message):
                    channel = channels[record.channel_id]
                    schema = schemas[channel.schema_id]
                    c = out["channels"].setdefault(
                        channel.topic,
                        {
                            "schema_name": schema.name,
                            "schema_encoding": schema.encoding,
                            "message_encoding": channel.message_encoding,
                            "qos": channel.metadata.get("offered_qos_profiles"),
                            "count": 0,
                        },
                    )
                    c["count"] += 1
                    if channel.topic not in wanted:
                        continue
                    if schema.id not in decoder_of:
                        decoder_of[schema.id] = decoders.decoder_for(
                            channel.message_encoding, schema
                        )
                    out["messages"].append(
                        {
                            "topic": channel.topic,
                            "log_time": record.log_time,
                            "publish_time": record.publish_time,
                            "msg": plain(decoder_of[schema.id](record.data)),
                        }
                    )
        except Exception as e:  # the reader's own errors: report where it stopped
            out["error"] = f"{type(e).__name__}: {e}"
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
