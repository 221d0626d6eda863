//! Particle snapshots as legacy VTK 3.0 UNSTRUCTURED_GRID of vertex cells, binary: ParaView
//! and VisIt open it without plugins, and so do Python readers such as meshio (which reads no
//! POLYDATA; the tests read our snapshots with it).
//!
//! Legacy binary VTK is big-endian whatever the machine, and the points are always 3-D
//! (z = 0 in a 2-D case) because readers have no 2-D point type.

use flume_solver::{ParticleRegion, Particles};
use std::io::{self, Write};

/// Writes `particles` as one vertex cell per particle with velocity, density, phase, region,
/// held flag and id. `regions` are the solver's region words in id order
/// (`Simulation::regions`); missing entries count as 0 (no region, not held).
/// `title` goes on the header's comment line (VTK allows at most 255 characters, no newline).
/// When `marked` names ids (the particles a blow-up report names), a `culprit` field is 1 for
/// them and 0 elsewhere.
pub fn write_particles<W: Write>(
    mut w: W,
    title: &str,
    particles: &Particles,
    regions: &[u32],
    marked: &[u32],
) -> io::Result<()> {
    let n = particles.len();
    let count = i32::try_from(n)
        .map_err(|_| io::Error::other("more particles than VTK's 32-bit cell indices hold"))?;
    let title: String = title
        .chars()
        .filter(|c| *c != '\n' && *c != '\r')
        .take(255)
        .collect();
    write!(
        w,
        "# vtk DataFile Version 3.0\n{title}\nBINARY\nDATASET UNSTRUCTURED_GRID\n"
    )?;

    writeln!(w, "POINTS {n} float")?;
    for p in &particles.positions {
        put_f32s(&mut w, &p[..3])?;
    }
    writeln!(w)?;

    // Legacy 3.0 cell lists: each cell is its point count followed by its point indices.
    writeln!(w, "CELLS {n} {}", 2 * n)?;
    for i in 0..count {
        put_i32s(&mut w, &[1, i])?;
    }
    writeln!(w)?;
    writeln!(w, "CELL_TYPES {n}")?;
    for _ in 0..count {
        put_i32s(&mut w, &[VTK_VERTEX])?;
    }
    writeln!(w)?;

    writeln!(w, "POINT_DATA {n}")?;
    writeln!(w, "VECTORS velocity float")?;
    for v in &particles.vel_rho {
        put_f32s(&mut w, &v[..3])?;
    }
    writeln!(w)?;
    writeln!(w, "SCALARS density float 1\nLOOKUP_TABLE default")?;
    for v in &particles.vel_rho {
        put_f32s(&mut w, &[v[3]])?;
    }
    writeln!(w)?;
    writeln!(w, "SCALARS phase int 1\nLOOKUP_TABLE default")?;
    for i in 0..n {
        put_i32s(&mut w, &[particles.phase(i) as i32])?;
    }
    writeln!(w)?;
    let region = |i: usize| ParticleRegion::from_word(regions.get(i).copied().unwrap_or(0));
    writeln!(w, "SCALARS region int 1\nLOOKUP_TABLE default")?;
    for i in 0..n {
        put_i32s(&mut w, &[i32::from(region(i).number())])?;
    }
    writeln!(w)?;
    writeln!(w, "SCALARS held int 1\nLOOKUP_TABLE default")?;
    for i in 0..n {
        put_i32s(&mut w, &[i32::from(region(i).held)])?;
    }
    writeln!(w)?;
    writeln!(w, "SCALARS id int 1\nLOOKUP_TABLE default")?;
    for &id in &particles.ids {
        put_i32s(&mut w, &[id as i32])?;
    }
    writeln!(w)?;
    if !marked.is_empty() {
        writeln!(w, "SCALARS culprit int 1\nLOOKUP_TABLE default")?;
        for id in &particles.ids {
            put_i32s(&mut w, &[i32::from(marked.contains(id))])?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// VTK's cell type number of a single point.
const VTK_VERTEX: i32 = 1;

fn put_f32s<W: Write>(w: &mut W, values: &[f32]) -> io::Result<()> {
    for v in values {
        w.write_all(&v.to_be_bytes())?;
    }
    Ok(())
}

fn put_i32s<W: Write>(w: &mut W, values: &[i32]) -> io::Result<()> {
    for v in values {
        w.write_all(&v.to_be_bytes())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_particles() -> Particles {
        Particles {
            positions: vec![
                [1.0, 2.0, 0.0, f32::from_bits(0)],
                [0.5, -0.25, 0.0, f32::from_bits(1)],
            ],
            vel_rho: vec![[0.0, 0.0, 0.0, 1000.0], [3.0, -1.5, 0.0, 1002.5]],
            ids: vec![0, 1],
        }
    }

    /// Splits off the next text line (without its newline) from `bytes`.
    fn take_line<'a>(bytes: &mut &'a [u8]) -> &'a str {
        let end = bytes.iter().position(|b| *b == b'\n').expect("a newline");
        let line = std::str::from_utf8(&bytes[..end]).expect("ASCII header line");
        *bytes = &bytes[end + 1..];
        line
    }

    fn take<'a>(bytes: &mut &'a [u8], n: usize) -> &'a [u8] {
        let (head, tail) = bytes.split_at(n);
        *bytes = tail;
        head
    }

    fn be_f32s(bytes: &[u8]) -> Vec<f32> {
        bytes
            .chunks_exact(4)
            .map(|c| f32::from_be_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn be_i32s(bytes: &[u8]) -> Vec<i32> {
        bytes
            .chunks_exact(4)
            .map(|c| i32::from_be_bytes(c.try_into().unwrap()))
            .collect()
    }

    #[test]
    fn binary_layout_is_big_endian_legacy_3_0() {
        let mut buf = Vec::new();
        write_particles(&mut buf, "test t=0.5 s", &two_particles(), &[0, 257], &[]).unwrap();
        let mut b: &[u8] = &buf;

        assert_eq!(take_line(&mut b), "# vtk DataFile Version 3.0");
        assert_eq!(take_line(&mut b), "test t=0.5 s");
        assert_eq!(take_line(&mut b), "BINARY");
        assert_eq!(take_line(&mut b), "DATASET UNSTRUCTURED_GRID");

        assert_eq!(take_line(&mut b), "POINTS 2 float");
        // 1.0f32 big-endian is 3f 80 00 00: the first bytes pin the byte order.
        assert_eq!(&b[..4], &[0x3f, 0x80, 0x00, 0x00]);
        assert_eq!(be_f32s(take(&mut b, 24)), [1.0, 2.0, 0.0, 0.5, -0.25, 0.0]);
        assert_eq!(take_line(&mut b), "");

        assert_eq!(take_line(&mut b), "CELLS 2 4");
        assert_eq!(be_i32s(take(&mut b, 16)), [1, 0, 1, 1]);
        assert_eq!(take_line(&mut b), "");
        assert_eq!(take_line(&mut b), "CELL_TYPES 2");
        assert_eq!(be_i32s(take(&mut b, 8)), [1, 1]);
        assert_eq!(take_line(&mut b), "");

        assert_eq!(take_line(&mut b), "POINT_DATA 2");
        assert_eq!(take_line(&mut b), "VECTORS velocity float");
        assert_eq!(be_f32s(take(&mut b, 24)), [0.0, 0.0, 0.0, 3.0, -1.5, 0.0]);
        assert_eq!(take_line(&mut b), "");

        assert_eq!(take_line(&mut b), "SCALARS density float 1");
        assert_eq!(take_line(&mut b), "LOOKUP_TABLE default");
        assert_eq!(be_f32s(take(&mut b, 8)), [1000.0, 1002.5]);
        assert_eq!(take_line(&mut b), "");

        assert_eq!(take_line(&mut b), "SCALARS phase int 1");
        assert_eq!(take_line(&mut b), "LOOKUP_TABLE default");
        assert_eq!(take(&mut b, 8), &[0, 0, 0, 0, 0, 0, 0, 1]);
        assert_eq!(take_line(&mut b), "");

        assert_eq!(take_line(&mut b), "SCALARS region int 1");
        assert_eq!(take_line(&mut b), "LOOKUP_TABLE default");
        assert_eq!(be_i32s(take(&mut b, 8)), [0, 1]);
        assert_eq!(take_line(&mut b), "");

        assert_eq!(take_line(&mut b), "SCALARS held int 1");
        assert_eq!(take_line(&mut b), "LOOKUP_TABLE default");
        assert_eq!(be_i32s(take(&mut b, 8)), [0, 1]);
        assert_eq!(take_line(&mut b), "");

        assert_eq!(take_line(&mut b), "SCALARS id int 1");
        assert_eq!(take_line(&mut b), "LOOKUP_TABLE default");
        assert_eq!(be_i32s(take(&mut b, 8)), [0, 1]);
        assert_eq!(take_line(&mut b), "");
        assert!(b.is_empty(), "{} trailing bytes", b.len());
    }

    #[test]
    fn title_cannot_break_the_header() {
        let mut buf = Vec::new();
        write_particles(&mut buf, "two\nlines", &Particles::default(), &[], &[]).unwrap();
        assert!(buf.starts_with(b"# vtk DataFile Version 3.0\ntwolines\nBINARY\n"));
    }

    #[test]
    fn a_blow_up_marks_the_particles_it_names() {
        let mut buf = Vec::new();
        write_particles(&mut buf, "failed", &two_particles(), &[], &[1]).unwrap();
        let tail = b"SCALARS culprit int 1\nLOOKUP_TABLE default\n\0\0\0\0\0\0\0\x01\n";
        assert!(buf.ends_with(tail), "no culprit field marking id 1 alone");
    }
}
