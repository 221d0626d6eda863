//! Our CDR against ROS 2's: bytes computed by hand for a header, and every message type
//! decoded by an independent ROS 2 decoder (Python `mcap-ros2-support`) from its definition
//! text alone, field for field.

use flume_msgs::RosMessage;
use flume_msgs::builtin_interfaces::{Duration, Time};
use flume_msgs::diagnostic_msgs::{DiagnosticArray, DiagnosticStatus, KeyValue};
use flume_msgs::flume_msgs::{
    BedProfile, Discharge, ErodedMass, GaugeComparison, GaugeResidual, WaterLevel,
};
use flume_msgs::geometry_msgs::{Point, Pose, Quaternion, Vector3};
use flume_msgs::rosgraph_msgs::Clock;
use flume_msgs::sensor_msgs::{CompressedImage, PointCloud2, PointField, Range};
use flume_msgs::std_msgs::{ColorRGBA, Header};
use flume_msgs::visualization_msgs::{Marker, MarkerArray, MeshFile, UVCoordinate};
use serde::Serialize;
use std::path::PathBuf;
use std::process::Command;

fn cdr<T: Serialize>(msg: &T) -> Vec<u8> {
    cdr::serialize::<_, _, cdr::CdrLe>(msg, cdr::Infinite).expect("serialises")
}

fn header(sec: i32, frame: &str) -> Header {
    Header {
        stamp: Time {
            sec,
            nanosec: 250_000_000,
        },
        frame_id: frame.into(),
    }
}

/// The encapsulation header (CDR little endian), then each value aligned to its size counted
/// from after it; a string is its length with the NUL, the bytes and the NUL.
#[test]
fn a_header_is_the_bytes_ros_writes() {
    let h = Header {
        stamp: Time { sec: 1, nanosec: 2 },
        frame_id: "map".into(),
    };
    assert_eq!(
        cdr(&h),
        [
            0, 1, 0, 0, // CDR_LE
            1, 0, 0, 0, // sec
            2, 0, 0, 0, // nanosec
            4, 0, 0, 0, b'm', b'a', b'p', 0, // frame_id
        ]
    );
    // A float64 after the header string is aligned to 8: "map\0" ends at 16, so no padding;
    // "ma\0" ends at 15 and takes one byte of it.
    let d = Discharge {
        header: Header {
            stamp: Time::default(),
            frame_id: "ma".into(),
        },
        discharge_m3_per_s: 1.0,
    };
    let bytes = cdr(&d);
    assert_eq!(bytes.len(), 4 + 12 + 3 + 1 + 8);
    assert_eq!(bytes[19], 0, "padding");
    assert_eq!(bytes[20..], 1.0f64.to_le_bytes());
}

struct Case {
    schema: String,
    definition: String,
    cdr: Vec<u8>,
    expected: serde_json::Value,
}

fn case<T: Serialize + RosMessage>(msg: &T) -> Case {
    Case {
        schema: T::DEF.schema_name(),
        definition: T::DEF.full_text(),
        cdr: cdr(msg),
        expected: serde_json::to_value(msg).expect("json"),
    }
}

fn samples() -> Vec<Case> {
    let marker = Marker {
        header: header(3, "flume"),
        ns: "bed".into(),
        id: 2,
        kind: Marker::LINE_STRIP,
        action: Marker::ADD,
        pose: Pose {
            position: Point {
                x: 0.5,
                y: 0.0,
                z: 0.25,
            },
            orientation: Quaternion::default(),
        },
        scale: Vector3 {
            x: 0.01,
            y: 0.0,
            z: 0.0,
        },
        color: ColorRGBA {
            r: 0.5,
            g: 0.25,
            b: 0.0,
            a: 1.0,
        },
        lifetime: Duration { sec: 1, nanosec: 5 },
        frame_locked: true,
        points: vec![
            Point {
                x: 0.1,
                y: 0.0,
                z: 0.055,
            },
            Point {
                x: 0.2,
                y: 0.0,
                z: 0.05,
            },
        ],
        colors: vec![ColorRGBA::default()],
        texture_resource: String::new(),
        texture: CompressedImage {
            header: header(0, ""),
            format: "png".into(),
            data: vec![1, 2, 3],
        },
        uv_coordinates: vec![UVCoordinate { u: 0.5, v: 0.75 }],
        text: "bed".into(),
        mesh_resource: String::new(),
        mesh_file: MeshFile {
            filename: "m".into(),
            data: vec![9],
        },
        mesh_use_embedded_materials: false,
    };
    vec![
        case(&Discharge {
            header: header(10, "flume"),
            discharge_m3_per_s: 5.5556e-4,
        }),
        case(&WaterLevel {
            header: header(11, "p1"),
            level_m: 0.0687,
        }),
        case(&BedProfile {
            header: header(12, "flume"),
            x_m: vec![0.05, 0.1, 0.15],
            zb_m: vec![0.05, 0.049, 0.048],
            zs_m: vec![0.055, 0.054, 0.053],
            zw_m: vec![0.07, 0.069, 0.068],
        }),
        case(&ErodedMass {
            header: header(13, "flume"),
            eroded_kg_per_m: 0.7,
            eroded_kg: 0.0602,
            rate_kg_per_s: 0.001,
            particles: 12,
        }),
        case(&GaugeComparison {
            header: header(14, "flume"),
            gauges: vec![
                GaugeResidual {
                    name: "P1".into(),
                    predicted_m: 0.07,
                    measured_m: 0.068,
                    residual_m: 0.002,
                    stale: false,
                },
                GaugeResidual {
                    name: "P2".into(),
                    predicted_m: 0.065,
                    measured_m: 0.06,
                    residual_m: 0.005,
                    stale: true,
                },
            ],
        }),
        case(&Range {
            header: header(15, "p1"),
            radiation_type: Range::ULTRASOUND,
            field_of_view: 0.25,
            min_range: 0.03,
            max_range: 0.5,
            range: 0.2,
            variance: 0.0,
        }),
        case(&PointCloud2 {
            header: header(16, "flume"),
            height: 1,
            width: 2,
            fields: vec![
                PointField {
                    name: "x".into(),
                    offset: 0,
                    datatype: PointField::FLOAT32,
                    count: 1,
                },
                PointField {
                    name: "phase".into(),
                    offset: 12,
                    datatype: PointField::UINT8,
                    count: 1,
                },
            ],
            is_bigendian: false,
            point_step: 13,
            row_step: 26,
            data: (0..26).collect(),
            is_dense: true,
        }),
        case(&marker),
        case(&MarkerArray {
            markers: vec![marker.clone(), marker],
        }),
        case(&Clock {
            clock: Time {
                sec: 17,
                nanosec: 1,
            },
        }),
        case(&DiagnosticArray {
            header: header(18, ""),
            status: vec![DiagnosticStatus {
                level: DiagnosticStatus::WARN,
                name: "flume_twin: pacing".into(),
                message: "behind the sensors".into(),
                hardware_id: "llvmpipe".into(),
                values: vec![KeyValue {
                    key: "lag_s".into(),
                    value: "1.5".into(),
                }],
            }],
        }),
    ]
}

fn repo_file(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(rel)
}

#[test]
fn an_independent_ros2_decoder_reads_every_message_type() {
    let have_decoder = Command::new("python3")
        .args(["-c", "import mcap_ros2"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !have_decoder {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "python3 with mcap-ros2-support is required in CI (scripts/test.sh installs it)"
        );
        eprintln!("skipped: no python3 with mcap-ros2-support (pip install mcap-ros2-support)");
        return;
    }
    let lines: Vec<String> = samples()
        .into_iter()
        .map(|c| {
            serde_json::json!({
                "schema": c.schema,
                "definition": c.definition,
                "cdr_hex": c.cdr.iter().map(|b| format!("{b:02x}")).collect::<String>(),
                "expected": c.expected,
            })
            .to_string()
        })
        .collect();
    let path = std::env::temp_dir().join(format!("flume-msgs-cases-{}.jsonl", std::process::id()));
    std::fs::write(&path, lines.join("\n") + "\n").expect("writes the cases");
    let out = Command::new("python3")
        .arg(repo_file("tests/interop/decode_ros2_cdr.py"))
        .arg(&path)
        .output()
        .expect("python3 runs");
    std::fs::remove_file(&path).ok();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains(&format!("{} messages decoded", lines.len())),
        "{text}"
    );
}

/// The ROS package lists every .msg file the crate defines, so colcon builds what we send.
#[test]
fn the_ros_package_builds_every_flume_message() {
    let cmake = std::fs::read_to_string(repo_file("msgs/CMakeLists.txt")).expect("CMakeLists");
    for def in [
        &flume_msgs::flume_msgs::DISCHARGE,
        &flume_msgs::flume_msgs::WATER_LEVEL,
        &flume_msgs::flume_msgs::BED_PROFILE,
        &flume_msgs::flume_msgs::ERODED_MASS,
        &flume_msgs::flume_msgs::GAUGE_RESIDUAL,
        &flume_msgs::flume_msgs::GAUGE_COMPARISON,
    ] {
        assert!(
            cmake.contains(&format!("\"msg/{}.msg\"", def.name)),
            "msg/{}.msg is not in CMakeLists.txt",
            def.name
        );
    }
    let mut files: Vec<_> = std::fs::read_dir(repo_file("msgs/msg"))
        .expect("msg dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    files.sort();
    assert_eq!(files.len(), 6, "{files:?}");
}
