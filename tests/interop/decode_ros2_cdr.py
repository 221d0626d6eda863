"""Decodes flume-twin's CDR messages with mcap-ros2-support's ROS 2 decoder, a reader written
elsewhere, from nothing but each message's concatenated definition, and checks every field
against the values the Rust side serialised.

Usage: python3 tests/interop/decode_ros2_cdr.py CASES.jsonl
Each line: {"schema": "pkg/msg/Type", "definition": "...", "cdr_hex": "...", "expected": {...}}.
Exits non-zero, with the first difference, if anything is off.
"""

import json
import sys
import types

from mcap_ros2._dynamic import generate_dynamic


def plain(value):
    """The decoded message as JSON-like data: records as dicts, byte arrays as int lists."""
    if isinstance(value, types.SimpleNamespace) or hasattr(value, "__slots__"):
        fields = getattr(value, "__slots__", None) or vars(value).keys()
        return {f: plain(getattr(value, f)) for f in fields}
    if isinstance(value, (bytes, bytearray)):
        return list(value)
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def compare(path, got, want):
    if isinstance(want, dict):
        assert isinstance(got, dict), f"{path}: expected a message, got {got!r}"
        assert set(got) == set(want), f"{path}: fields {sorted(got)} vs {sorted(want)}"
        for k in want:
            compare(f"{path}.{k}", got[k], want[k])
    elif isinstance(want, list):
        assert isinstance(got, list) and len(got) == len(want), f"{path}: {got!r} vs {want!r}"
        for i, (g, w) in enumerate(zip(got, want)):
            compare(f"{path}[{i}]", g, w)
    else:
        assert got == want, f"{path}: decoded {got!r}, serialised {want!r}"


def main() -> None:
    count = 0
    with open(sys.argv[1]) as f:
        for line in f:
            case = json.loads(line)
            decoders = generate_dynamic(case["schema"], case["definition"])
            decoded = decoders[case["schema"]](bytes.fromhex(case["cdr_hex"]))
            compare(case["schema"], plain(decoded), case["expected"])
            count += 1
    print(f"{count} messages decoded and checked")


if __name__ == "__main__":
    main()
