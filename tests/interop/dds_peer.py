"""A ROS 2 peer on Cyclone DDS (the `cyclonedds` wheel, a DDS nobody here wrote), loopback only:
plays the flume's sensors to the twin and records what the twin publishes.

It publishes, every 0.1 s of wall time for DURATION_S, a discharge on `<ns>/inflow`
(flume_msgs/Discharge, reliable) and a level on `<ns>/gauges/p1` (flume_msgs/WaterLevel, best
effort), each stamped with this machine's clock; in the middle it also sends what the twin must
refuse (a NaN and a negative discharge, a level above the flume, discharges stamped 10 s ahead
and 5 s behind, a std_msgs/String on the inflow topic). It subscribes to `<ns>/bed_profile`, `<ns>/eroded_mass`, `<ns>/gauges/predicted`,
`<ns>/particles`, `<ns>/bed_marker`, `/clock` and `/diagnostics`, and prints each message it receives as one JSON line, with what it
sent first (`{"sent": ...}` lines), until SECONDS have passed or the twin's last output came.

Usage: python3 tests/interop/dds_peer.py NAMESPACE DURATION_S SECONDS
"""

import json
import math
import struct
import os
import sys
import tempfile
import time
from dataclasses import dataclass

CONFIG = """<?xml version="1.0" encoding="UTF-8" ?>
<CycloneDDS xmlns="https://cdds.io/config">
  <Domain Id="any">
    <General>
      <Interfaces><NetworkInterface name="lo"/></Interfaces>
      <AllowMulticast>false</AllowMulticast>
    </General>
    <Discovery>
      <ParticipantIndex>auto</ParticipantIndex>
      <Peers><Peer Address="127.0.0.1"/></Peers>
    </Discovery>
  </Domain>
</CycloneDDS>
"""

# The URI must be set before cyclonedds loads its library.
_config = tempfile.NamedTemporaryFile("w", suffix=".xml", delete=False)
_config.write(CONFIG)
_config.close()
os.environ["CYCLONEDDS_URI"] = "file://" + _config.name

from cyclonedds.core import Qos, Policy  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.idl import IdlStruct  # noqa: E402
from cyclonedds.idl.types import float32, float64, int32, sequence, uint8, uint32, uint64  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
class Discharge(IdlStruct, typename="flume_msgs::msg::dds_::Discharge_"):
    header: Header
    discharge_m3_per_s: float64


@dataclass
class WaterLevel(IdlStruct, typename="flume_msgs::msg::dds_::WaterLevel_"):
    header: Header
    level_m: float64


@dataclass
class BedProfile(IdlStruct, typename="flume_msgs::msg::dds_::BedProfile_"):
    header: Header
    x_m: sequence[float64]
    zb_m: sequence[float64]
    zs_m: sequence[float64]
    zw_m: sequence[float64]


@dataclass
class ErodedMass(IdlStruct, typename="flume_msgs::msg::dds_::ErodedMass_"):
    header: Header
    eroded_kg_per_m: float64
    eroded_kg: float64
    rate_kg_per_s: float64
    particles: uint64


@dataclass
class GaugeResidual(IdlStruct, typename="flume_msgs::msg::dds_::GaugeResidual_"):
    name: str
    predicted_m: float64
    measured_m: float64
    residual_m: float64
    stale: bool


@dataclass
class GaugeComparison(IdlStruct, typename="flume_msgs::msg::dds_::GaugeComparison_"):
    header: Header
    gauges: sequence[GaugeResidual]


@dataclass
class Clock(IdlStruct, typename="rosgraph_msgs::msg::dds_::Clock_"):
    clock: Time


@dataclass
class KeyValue(IdlStruct, typename="diagnostic_msgs::msg::dds_::KeyValue_"):
    key: str
    value: str


@dataclass
class DiagnosticStatus(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticStatus_"):
    level: uint8
    name: str
    message: str
    hardware_id: str
    values: sequence[KeyValue]


@dataclass
class DiagnosticArray(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticArray_"):
    header: Header
    status: sequence[DiagnosticStatus]


@dataclass
class String(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str


@dataclass
class PointField(IdlStruct, typename="sensor_msgs::msg::dds_::PointField_"):
    name: str
    offset: uint32
    datatype: uint8
    count: uint32


@dataclass
class PointCloud2(IdlStruct, typename="sensor_msgs::msg::dds_::PointCloud2_"):
    header: Header
    height: uint32
    width: uint32
    fields: sequence[PointField]
    is_bigendian: bool
    point_step: uint32
    row_step: uint32
    data: sequence[uint8]
    is_dense: bool


@dataclass
class Duration(IdlStruct, typename="builtin_interfaces::msg::dds_::Duration_"):
    sec: int32
    nanosec: uint32


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: float64
    y: float64
    z: float64


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: float64
    y: float64
    z: float64
    w: float64


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point
    orientation: Quaternion


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64
    y: float64
    z: float64


@dataclass
class ColorRGBA(IdlStruct, typename="std_msgs::msg::dds_::ColorRGBA_"):
    r: float32
    g: float32
    b: float32
    a: float32


@dataclass
class CompressedImage(IdlStruct, typename="sensor_msgs::msg::dds_::CompressedImage_"):
    header: Header
    format: str
    data: sequence[uint8]


@dataclass
class UVCoordinate(IdlStruct, typename="visualization_msgs::msg::dds_::UVCoordinate_"):
    u: float32
    v: float32


@dataclass
class MeshFile(IdlStruct, typename="visualization_msgs::msg::dds_::MeshFile_"):
    filename: str
    data: sequence[uint8]


@dataclass
class Marker(IdlStruct, typename="visualization_msgs::msg::dds_::Marker_"):
    header: Header
    ns: str
    id: int32
    type: int32
    action: int32
    pose: Pose
    scale: Vector3
    color: ColorRGBA
    lifetime: Duration
    frame_locked: bool
    points: sequence[Point]
    colors: sequence[ColorRGBA]
    texture_resource: str
    texture: CompressedImage
    uv_coordinates: sequence[UVCoordinate]
    text: str
    mesh_resource: str
    mesh_file: MeshFile
    mesh_use_embedded_materials: bool


@dataclass
class MarkerArray(IdlStruct, typename="visualization_msgs::msg::dds_::MarkerArray_"):
    markers: sequence[Marker]


def stamp(t: float) -> Header:
    sec = math.floor(t)
    return Header(Time(sec, int(round((t - sec) * 1e9)) % 1_000_000_000), "lab")


def secs(h: Header) -> float:
    return h.stamp.sec + h.stamp.nanosec * 1e-9


def fix(x):
    """JSON has no NaN: send it as null."""
    return None if isinstance(x, float) and math.isnan(x) else x


def emit(kind: str, body: dict) -> None:
    print(json.dumps({kind: body}), flush=True)


def main() -> None:
    ns, duration, seconds = sys.argv[1].rstrip("/"), float(sys.argv[2]), float(sys.argv[3])
    dp = DomainParticipant(0)
    reliable = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.History.KeepLast(10))
    latched = Qos(
        Policy.Reliability.Reliable(1_000_000_000),
        Policy.Durability.TransientLocal,
        Policy.History.KeepLast(1),
    )
    best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(5))
    inflow = DataWriter(dp, Topic(dp, f"rt{ns}/inflow", Discharge), reliable)
    wrong = DataWriter(dp, Topic(dp, f"rt{ns}/inflow", String), reliable)
    p1 = DataWriter(dp, Topic(dp, f"rt{ns}/gauges/p1", WaterLevel), best_effort)
    readers = {
        "bed_profile": DataReader(dp, Topic(dp, f"rt{ns}/bed_profile", BedProfile), latched),
        "eroded_mass": DataReader(dp, Topic(dp, f"rt{ns}/eroded_mass", ErodedMass), reliable),
        "predicted": DataReader(dp, Topic(dp, f"rt{ns}/gauges/predicted", GaugeComparison), reliable),
        "clock": DataReader(dp, Topic(dp, "rt/clock", Clock), best_effort),
        "diagnostics": DataReader(dp, Topic(dp, "rt/diagnostics", DiagnosticArray), reliable),
        "particles": DataReader(dp, Topic(dp, f"rt{ns}/particles", PointCloud2), best_effort),
        "bed_marker": DataReader(dp, Topic(dp, f"rt{ns}/bed_marker", MarkerArray), latched),
    }
    # Discovery first: samples sent before the twin's readers match would be lost.
    deadline = time.time() + 20.0
    def matched(writer) -> int:
        return writer.get_publication_matched_status().current_count

    while time.time() < deadline and (matched(inflow) == 0 or matched(p1) == 0):
        time.sleep(0.05)
    emit("matched", {"inflow": matched(inflow), "p1": matched(p1)})

    start = time.time()
    k = 0
    sent_bad = False
    next_send = start
    while time.time() - start < seconds:
        now = time.time()
        if now >= next_send and now - start <= duration:
            q = 5.0e-4 if now - start < duration / 2 else 6.0e-4
            level = 0.07 + 0.001 * (k % 5)
            inflow.write(Discharge(stamp(now), q))
            p1.write(WaterLevel(stamp(now), level))
            emit("sent", {"t": now, "q": q, "level": level})
            k += 1
            next_send += 0.1
            if not sent_bad and now - start > duration / 3:
                sent_bad = True
                inflow.write(Discharge(stamp(now), float("nan")))
                inflow.write(Discharge(stamp(now), -1.0e-4))
                p1.write(WaterLevel(stamp(now), 5.0))
                inflow.write(Discharge(stamp(now + 10.0), 5.0e-4))
                inflow.write(Discharge(stamp(now - 5.0), 5.0e-4))
                wrong.write(String("not a discharge"))
                emit("sent_bad", {"t": now})
        for kind, reader in readers.items():
            for s in reader.take(N=100):
                if not getattr(s.sample_info, "valid_data", True):
                    continue
                if kind == "bed_profile":
                    body = {"t": secs(s.header), "x": s.x_m, "zb": [fix(v) for v in s.zb_m],
                            "zs": [fix(v) for v in s.zs_m], "zw": [fix(v) for v in s.zw_m]}
                elif kind == "eroded_mass":
                    body = {"t": secs(s.header), "kg_per_m": s.eroded_kg_per_m, "kg": s.eroded_kg,
                            "particles": s.particles}
                elif kind == "predicted":
                    body = {"t": secs(s.header), "gauges": [
                        {"name": g.name, "predicted": fix(g.predicted_m),
                         "measured": fix(g.measured_m), "residual": fix(g.residual_m),
                         "stale": g.stale} for g in s.gauges]}
                elif kind == "particles":
                    data = bytes(s.data)
                    points = [struct.unpack_from("<ffffB", data, k * s.point_step)
                              for k in range(s.width)]
                    body = {"t": secs(s.header), "width": s.width, "point_step": s.point_step,
                            "fields": [[f.name, f.offset, f.datatype] for f in s.fields],
                            "finite": all(math.isfinite(v) for p in points for v in p[:4]),
                            "phases": sorted({p[4] for p in points}),
                            "max_speed": max((p[3] for p in points), default=0.0)}
                elif kind == "bed_marker":
                    body = {"t": secs(s.markers[0].header) if s.markers else None,
                            "markers": [{"ns": m.ns, "type": m.type, "points": len(m.points)}
                                        for m in s.markers]}
                elif kind == "clock":
                    body = {"t": s.clock.sec + s.clock.nanosec * 1e-9}
                else:
                    body = {"t": secs(s.header), "status": [
                        {"name": st.name, "level": st.level, "message": st.message,
                         "values": {kv.key: kv.value for kv in st.values}} for st in s.status]}
                emit(kind, body)
        time.sleep(0.01)


if __name__ == "__main__":
    main()
