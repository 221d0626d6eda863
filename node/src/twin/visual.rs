//! What rviz draws: a decimated particle cloud (`PointCloud2`: x, y, z float32, speed float32,
//! phase uint8) and the bed and water lines (`MarkerArray`). The flume frame has x along the
//! flume, y across it and z up: a 2-D case's vertical (its y) becomes z.

use flume_msgs::builtin_interfaces::Duration;
use flume_msgs::geometry_msgs::{Point, Pose, Vector3};
use flume_msgs::sensor_msgs::{PointCloud2, PointField};
use flume_msgs::std_msgs::{ColorRGBA, Header};
use flume_msgs::visualization_msgs::{Marker, MarkerArray};

/// A vector in the flume frame (z up): a 2-D case's (x, vertical) becomes (x, 0, z).
pub fn in_flume_frame(two_d: bool, [a, b, c]: [f32; 3]) -> [f32; 3] {
    if two_d { [a, 0.0, b] } else { [a, b, c] }
}

/// Bytes per point: x, y, z, speed (float32 at 0, 4, 8, 12), phase (uint8 at 16), 3 of padding
/// so that every point starts 4-byte aligned.
pub const POINT_STEP: u32 = 20;

/// One particle as the cloud carries it, in the flume frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudPoint {
    pub position: [f32; 3],
    pub speed: f32,
    pub phase: u8,
}

/// Every `stride`-th of `points` (at most `max_points` of them) as a PointCloud2.
pub fn point_cloud(header: Header, points: &[CloudPoint], max_points: usize) -> PointCloud2 {
    let stride = points.len().div_ceil(max_points.max(1)).max(1);
    let mut data =
        Vec::with_capacity(points.len() / stride * POINT_STEP as usize + POINT_STEP as usize);
    let mut n = 0u32;
    for p in points.iter().step_by(stride) {
        for v in p.position.iter().chain(std::iter::once(&p.speed)) {
            data.extend_from_slice(&v.to_le_bytes());
        }
        data.extend_from_slice(&[p.phase, 0, 0, 0]);
        n += 1;
    }
    let field = |name: &str, offset: u32, datatype: u8| PointField {
        name: name.into(),
        offset,
        datatype,
        count: 1,
    };
    PointCloud2 {
        header,
        height: 1,
        width: n,
        fields: vec![
            field("x", 0, PointField::FLOAT32),
            field("y", 4, PointField::FLOAT32),
            field("z", 8, PointField::FLOAT32),
            field("speed", 12, PointField::FLOAT32),
            field("phase", 16, PointField::UINT8),
        ],
        is_bigendian: false,
        point_step: POINT_STEP,
        row_step: POINT_STEP * n,
        data,
        is_dense: true,
    }
}

fn line(header: &Header, id: i32, ns: &str, color: ColorRGBA, xz: &[(f64, f64)]) -> Marker {
    Marker {
        header: header.clone(),
        ns: ns.into(),
        id,
        kind: Marker::LINE_STRIP,
        action: Marker::ADD,
        pose: Pose::default(),
        // A line strip's width, m.
        scale: Vector3 {
            x: 0.004,
            y: 0.0,
            z: 0.0,
        },
        color,
        lifetime: Duration::default(),
        frame_locked: false,
        points: xz.iter().map(|&(x, z)| Point { x, y: 0.0, z }).collect(),
        ..Marker::default()
    }
}

/// The bed surface (Zs) and the free surface (Zw) as two line strips; columns without the
/// interface are left out of its line.
pub fn bed_lines(header: &Header, x: &[f64], zs: &[f64], zw: &[f64]) -> MarkerArray {
    let pts = |z: &[f64]| -> Vec<(f64, f64)> {
        x.iter()
            .zip(z)
            .filter(|(_, z)| z.is_finite())
            .map(|(&x, &z)| (x, z))
            .collect()
    };
    MarkerArray {
        markers: vec![
            line(
                header,
                0,
                "bed",
                ColorRGBA {
                    r: 0.67,
                    g: 0.43,
                    b: 0.16,
                    a: 1.0,
                },
                &pts(zs),
            ),
            line(
                header,
                1,
                "water",
                ColorRGBA {
                    r: 0.1,
                    g: 0.4,
                    b: 0.9,
                    a: 1.0,
                },
                &pts(zw),
            ),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(k: usize) -> CloudPoint {
        CloudPoint {
            position: [k as f32, 0.0, 0.5 * k as f32],
            speed: 0.25,
            phase: (k % 3) as u8,
        }
    }

    #[test]
    fn the_cloud_is_decimated_to_its_cap_and_laid_out_as_its_fields_say() {
        let points: Vec<_> = (0..10).map(p).collect();
        let c = point_cloud(Header::default(), &points, 4);
        // Stride 3: particles 0, 3, 6, 9.
        assert_eq!(c.width, 4);
        assert_eq!(c.data.len(), 4 * POINT_STEP as usize);
        assert_eq!(c.row_step, 4 * POINT_STEP);
        let at = |k: usize, off: usize| {
            f32::from_le_bytes(
                c.data[k * 20 + off..k * 20 + off + 4]
                    .try_into()
                    .expect("4"),
            )
        };
        assert_eq!((at(1, 0), at(1, 8), at(1, 12)), (3.0, 1.5, 0.25));
        assert_eq!(c.data[2 * 20 + 16], 0, "particle 6, phase 0");
        assert_eq!(c.data[3 * 20 + 16], 0, "particle 9, phase 0");
        assert_eq!(c.data[20 + 16], 0, "particle 3, phase 0");
        let all = point_cloud(Header::default(), &points, 100);
        assert_eq!(all.width, 10);
        assert_eq!(all.data[20 + 16], 1, "particle 1, phase 1");
    }

    #[test]
    fn bed_lines_skip_columns_without_the_interface() {
        let m = bed_lines(
            &Header::default(),
            &[0.0, 0.1, 0.2],
            &[0.05, f64::NAN, 0.04],
            &[0.07, 0.07, 0.06],
        );
        assert_eq!(m.markers.len(), 2);
        assert_eq!(m.markers[0].points.len(), 2);
        assert_eq!(m.markers[1].points.len(), 3);
        assert_eq!(m.markers[0].points[1].z, 0.04);
        assert_eq!(m.markers[0].kind, Marker::LINE_STRIP);
    }
}
