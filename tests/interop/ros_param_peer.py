#!/usr/bin/env python3
"""`ros2 param` and `ros2 service call` as they reach a node over rmw_cyclonedds, with only the
`cyclonedds` wheel (a DDS nobody here wrote, no ROS install), loopback only.

rmw_cyclonedds maps a service onto the topics `rq/<service>Request` and `rr/<service>Reply`,
types `<pkg>::srv::dds_::<Srv>_Request_` / `_Response_`, and puts a 16-byte header (the
client's 64-bit id and the request's sequence number) at the start of each payload; the
client keeps only the replies that echo its header. This peer does the same, runs the
session below against NODE, and prints one JSON line per answer for the test to judge:

  list, get, get_parameter_types and describe of the twin's parameters; a bad value set (it
  must be refused with the twin's reason) and a good one (its /parameter_events, then the
  twin's /diagnostics reporting it); pause (two /diagnostics a second apart at the same
  simulated time), step, resume and reset.

Usage: python3 tests/interop/ros_param_peer.py NODE   (for example /flume_cy/flume_twin)
"""

import random
import sys
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

# Loopback configuration, diagnostics' types and the JSON line writer, as the sensor peer has
# them; importing it sets CYCLONEDDS_URI before cyclonedds loads.
from dds_peer import DiagnosticArray, emit  # noqa: E402

from cyclonedds.core import Policy, Qos  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.idl import IdlStruct  # noqa: E402
from cyclonedds.idl import annotations as annotate  # noqa: E402
from cyclonedds.idl import types  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402

# Not `from __future__ import annotations`: cyclonedds would then resolve "types.uint64"
# against the standard library's `types`.


class ParameterType:
    """rcl_interfaces/msg/ParameterType constants."""
    NOT_SET = 0
    BOOL = 1
    INTEGER = 2
    DOUBLE = 3
    STRING = 4
    BYTE_ARRAY = 5
    BOOL_ARRAY = 6
    INTEGER_ARRAY = 7
    DOUBLE_ARRAY = 8
    STRING_ARRAY = 9


@dataclass
@annotate.final
class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: types.int32 = 0
    nanosec: types.uint32 = 0


@dataclass
@annotate.final
class ParameterValue_(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterValue_"):
    type: types.uint8 = ParameterType.NOT_SET
    bool_value: bool = False
    integer_value: types.int64 = 0
    double_value: types.float64 = 0.0
    string_value: str = ""
    byte_array_value: types.sequence[types.byte] = field(default_factory=list)
    bool_array_value: types.sequence[bool] = field(default_factory=list)
    integer_array_value: types.sequence[types.int64] = field(default_factory=list)
    double_array_value: types.sequence[types.float64] = field(default_factory=list)
    string_array_value: types.sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class Parameter_(IdlStruct, typename="rcl_interfaces::msg::dds_::Parameter_"):
    name: str = ""
    value: ParameterValue_ = field(default_factory=ParameterValue_)


@dataclass
@annotate.final
class SetParametersResult_(IdlStruct, typename="rcl_interfaces::msg::dds_::SetParametersResult_"):
    successful: bool = False
    reason: str = ""


@dataclass
@annotate.final
class FloatingPointRange_(IdlStruct, typename="rcl_interfaces::msg::dds_::FloatingPointRange_"):
    from_value: types.float64 = 0.0
    to_value: types.float64 = 0.0
    step: types.float64 = 0.0


@dataclass
@annotate.final
class IntegerRange_(IdlStruct, typename="rcl_interfaces::msg::dds_::IntegerRange_"):
    from_value: types.int64 = 0
    to_value: types.int64 = 0
    step: types.uint64 = 0


@dataclass
@annotate.final
class ParameterDescriptor_(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterDescriptor_"):
    name: str = ""
    type: types.uint8 = 0
    description: str = ""
    additional_constraints: str = ""
    read_only: bool = False
    dynamic_typing: bool = False
    # FloatingPointRange[<=1] / IntegerRange[<=1]: bounded sequences, same XCDR1
    # bytes as unbounded ones.
    floating_point_range: types.sequence[FloatingPointRange_, 1] = field(default_factory=list)
    integer_range: types.sequence[IntegerRange_, 1] = field(default_factory=list)


@dataclass
@annotate.final
class ListParametersResult_(IdlStruct, typename="rcl_interfaces::msg::dds_::ListParametersResult_"):
    names: types.sequence[str] = field(default_factory=list)
    prefixes: types.sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class ParameterEvent_(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterEvent_"):
    """Topic rt/parameter_events (ros2-client builtin_topics.rs parameter_events)."""
    stamp: Time_ = field(default_factory=Time_)
    node: str = ""
    new_parameters: types.sequence[Parameter_] = field(default_factory=list)
    changed_parameters: types.sequence[Parameter_] = field(default_factory=list)
    deleted_parameters: types.sequence[Parameter_] = field(default_factory=list)


# Service requests and replies with rmw_cyclonedds' request header in front: two ordinary
# 8-aligned members at the start of the payload, which XCDR1 writes as the 16 raw
# little-endian bytes rmw_cyclonedds writes there.


@dataclass
@annotate.final
class ListParameters_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::ListParameters_Request_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    prefixes: types.sequence[str] = field(default_factory=list)
    depth: types.uint64 = 0  # DEPTH_RECURSIVE = 0


@dataclass
@annotate.final
class ListParameters_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::ListParameters_Response_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    result: ListParametersResult_ = field(default_factory=ListParametersResult_)


@dataclass
@annotate.final
class GetParameters_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Request_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    names: types.sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class GetParameters_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Response_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    values: types.sequence[ParameterValue_] = field(default_factory=list)


@dataclass
@annotate.final
class SetParameters_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::SetParameters_Request_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    parameters: types.sequence[Parameter_] = field(default_factory=list)


@dataclass
@annotate.final
class SetParameters_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::SetParameters_Response_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    results: types.sequence[SetParametersResult_] = field(default_factory=list)


@dataclass
@annotate.final
class DescribeParameters_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::DescribeParameters_Request_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    names: types.sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class DescribeParameters_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::DescribeParameters_Response_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    descriptors: types.sequence[ParameterDescriptor_] = field(default_factory=list)


@dataclass
@annotate.final
class GetParameterTypes_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameterTypes_Request_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    names: types.sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class GetParameterTypes_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameterTypes_Response_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    types_: types.sequence[types.uint8] = field(default_factory=list)


@dataclass
@annotate.final
class Trigger_Request_(IdlStruct, typename="std_srvs::srv::dds_::Trigger_Request_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    # rosidl gives empty messages one uint8 member
    structure_needs_at_least_one_member: types.uint8 = 0


@dataclass
@annotate.final
class Trigger_Response_(IdlStruct, typename="std_srvs::srv::dds_::Trigger_Response_"):
    cdds_guid: types.uint64 = 0
    cdds_seq: types.int64 = 0
    success: bool = False
    message: str = ""


def reliable(depth: int, user_data: Optional[bytes] = None) -> Qos:
    """rmw_cyclonedds' service QoS: reliable, volatile, keep-last. XCDR1, the representation
    RustDDS readers take when they state none."""
    policies = [
        Policy.Reliability.Reliable(max_blocking_time=duration(seconds=1)),
        Policy.Durability.Volatile,
        Policy.History.KeepLast(depth=depth),
        Policy.DataRepresentation(use_cdrv0_representation=True),
    ]
    if user_data is not None:
        policies.append(Policy.Userdata(data=user_data))
    return Qos(*policies)


class Client:
    """One service client with rmw_cyclonedds' request/reply mapping."""

    def __init__(self, dp: DomainParticipant, service: str, request: type, reply: type):
        self.service = service
        self.request = request
        # rmw_cyclonedds marks both ends of a client with one id (USER_DATA "clientid=").
        clientid = ".".join(f"{b:x}" for b in random.getrandbits(128).to_bytes(16, "big"))
        user_data = f"clientid={clientid};".encode("ascii")
        qos = reliable(1000, user_data)
        self.writer = DataWriter(dp, Topic(dp, f"rq{service}Request", request), qos=qos)
        self.reader = DataReader(dp, Topic(dp, f"rr{service}Reply", reply), qos=qos)
        # rmw_cyclonedds sends its request writer's instance handle; the server only echoes it.
        self.guid = self.writer.get_instance_handle() & 0xFFFF_FFFF_FFFF_FFFF
        self.seq = 0

    def matched(self) -> bool:
        return bool(self.writer.get_matched_subscriptions()
                    and self.reader.get_matched_publications())

    def call(self, timeout_s: float = 3.0, attempts: int = 3, **fields: Any) -> Any:
        """Sends the request and waits for its reply, sending again after a timeout: the
        server's reply writer may match this reader after the request has gone
        (rmw_cyclonedds' own servers wait for that; a RustDDS server does not)."""
        for _ in range(attempts):
            self.seq += 1
            self.writer.write(self.request(cdds_guid=self.guid, cdds_seq=self.seq, **fields))
            end = time.monotonic() + timeout_s
            while time.monotonic() < end:
                for r in self.reader.take(N=16):
                    if r.cdds_guid == self.guid and r.cdds_seq == self.seq:
                        return r
                time.sleep(0.01)
        raise TimeoutError(f"{self.service}: no reply after {attempts} attempts")


def number(value: float) -> ParameterValue_:
    return ParameterValue_(type=ParameterType.DOUBLE, double_value=value)


def python_value(v: ParameterValue_) -> Any:
    return {ParameterType.NOT_SET: None, ParameterType.BOOL: v.bool_value,
            ParameterType.INTEGER: v.integer_value, ParameterType.DOUBLE: v.double_value,
            ParameterType.STRING: v.string_value}.get(v.type, f"<type {v.type}>")


class Diagnostics:
    """The twin's /diagnostics, as `key: value` of its status."""

    def __init__(self, dp: DomainParticipant, node: str):
        topic = Topic(dp, "rt/diagnostics", DiagnosticArray)
        self.reader = DataReader(dp, topic, qos=reliable(10))
        # Every twin on the network reports here; its status is named after its node.
        self.node = node

    def next_where(self, accept: Callable[[dict], bool], timeout_s: float) -> Optional[dict]:
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            for array in self.reader.take(N=16):
                for status in array.status:
                    if not status.name.startswith(self.node + ":"):
                        continue
                    values = {kv.key: kv.value for kv in status.values}
                    if "sim_time_s" in values and accept(values):
                        return values
            time.sleep(0.02)
        return None


def wait_for_event(reader: DataReader, name: str, timeout_s: float) -> Optional[dict]:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        for ev in reader.take(N=16):
            changed = {p.name: python_value(p.value) for p in ev.changed_parameters}
            if name in changed:
                return {"node": ev.node, "changed": changed}
        time.sleep(0.02)
    return None


def parameters(dp: DomainParticipant, node: str) -> None:
    services = {
        "list": ("list_parameters", ListParameters_Request_, ListParameters_Response_),
        "get": ("get_parameters", GetParameters_Request_, GetParameters_Response_),
        "types": ("get_parameter_types", GetParameterTypes_Request_,
                  GetParameterTypes_Response_),
        "describe": ("describe_parameters", DescribeParameters_Request_,
                     DescribeParameters_Response_),
        "set": ("set_parameters", SetParameters_Request_, SetParameters_Response_),
    }
    c = {k: Client(dp, f"{node}/{s}", q, r) for k, (s, q, r) in services.items()}
    # ros2-client's parameter events are transient-local; rclcpp's volatile: this matches both.
    events = DataReader(dp, Topic(dp, "rt/parameter_events", ParameterEvent_),
                        qos=reliable(1000))
    diagnostics = Diagnostics(dp, node)
    wait_until(lambda: all(x.matched() for x in c.values()), "the parameter services")
    emit("list", {"names": list(c["list"].call(prefixes=[], depth=0).result.names)})
    names = ["target_real_time_factor", "frame_id", "gauge_mount_height_m.p1", "no_such"]
    emit("get", {"values": [python_value(v) for v in c["get"].call(names=names).values]})
    emit("types", {"types": list(c["types"].call(names=names).types_)})
    described = c["describe"].call(names=["gauge_mount_height_m.p1", "no_such"]).descriptors
    emit("describe", {"descriptors": [
        {"name": d.name, "type": d.type, "description": d.description,
         "constraints": d.additional_constraints} for d in described]})
    for name, value in [("target_real_time_factor", number(-1.0)),
                        ("frame_id", ParameterValue_(type=ParameterType.INTEGER, integer_value=3)),
                        ("target_real_time_factor", number(0.25))]:
        r = c["set"].call(parameters=[Parameter_(name=name, value=value)]).results[0]
        emit("set", {"name": name, "value": python_value(value), "successful": r.successful,
                     "reason": r.reason})
    emit("event", {"event": wait_for_event(events, "target_real_time_factor", 5.0)})
    seen = diagnostics.next_where(lambda v: v.get("target_real_time_factor") == "0.25", 10.0)
    emit("diagnostics_after_set", {"values": seen})


def triggers(dp: DomainParticipant, node: str) -> None:
    c = {s: Client(dp, f"{node}/{s}", Trigger_Request_, Trigger_Response_)
         for s in ["pause", "step", "resume", "reset"]}
    diagnostics = Diagnostics(dp, node)
    wait_until(lambda: all(x.matched() for x in c.values()), "the trigger services")

    def call(name: str) -> None:
        r = c[name].call()
        emit("trigger", {"service": name, "success": r.success, "message": r.message})

    call("pause")
    first = diagnostics.next_where(lambda v: v.get("paused") == "true", 10.0)
    later = diagnostics.next_where(lambda v: True, 3.0)
    emit("paused", {"first": first, "later": later})
    call("step")
    call("resume")
    resumed = diagnostics.next_where(lambda v: v.get("paused") == "false", 10.0)
    moved = diagnostics.next_where(lambda v: True, 3.0)
    emit("resumed", {"first": resumed, "later": moved})
    call("reset")


def wait_until(ready: Callable[[], bool], what: str, timeout_s: float = 60.0) -> None:
    end = time.monotonic() + timeout_s
    while not ready():
        if time.monotonic() > end:
            raise TimeoutError(f"{what} were never matched")
        time.sleep(0.05)
    # The server's reply writers match this side's readers a moment later.
    time.sleep(0.5)


def main() -> None:
    node = sys.argv[1]
    dp = DomainParticipant(0)
    parameters(dp, node)
    triggers(dp, node)
    emit("done", {})


if __name__ == "__main__":
    main()
