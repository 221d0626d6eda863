//! Checks of the legacy VTK snapshots `simulate` writes: their header read byte by byte, and
//! the whole file read by meshio.

use std::path::Path;
use std::process::Command;

/// Reads a snapshot with meshio, a VTK reader nobody here wrote (tests/interop/read_vtk.py).
/// `scripts/test.sh` installs it; outside CI a machine without it skips with a note.
pub fn read_with_meshio(path: &Path, n: usize) {
    if !super::python_has("meshio", "meshio") {
        return;
    }
    let out = Command::new("python3")
        .arg(super::repo_file("tests/interop/read_vtk.py"))
        .arg(path)
        .arg(n.to_string())
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "meshio could not read {}: {}{}",
        path.display(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{}", String::from_utf8_lossy(&out.stdout).trim());
}

/// Splits the next text line (without its newline) off `bytes`.
fn take_line(bytes: &mut &[u8]) -> String {
    let end = bytes.iter().position(|b| *b == b'\n').expect("a newline");
    let line = String::from_utf8_lossy(&bytes[..end]).into_owned();
    *bytes = &bytes[end + 1..];
    line
}

/// The text lines of a legacy binary VTK file, and the first binary block's size.
pub fn check_vtk_header(bytes: &[u8], n: usize) {
    let mut rest = bytes;
    assert_eq!(take_line(&mut rest), "# vtk DataFile Version 3.0");
    assert!(take_line(&mut rest).contains("dambreak_water"));
    assert_eq!(take_line(&mut rest), "BINARY");
    assert_eq!(take_line(&mut rest), "DATASET UNSTRUCTURED_GRID");
    assert_eq!(take_line(&mut rest), format!("POINTS {n} float"));
    // n big-endian xyz triples, then the cell list on the next line.
    rest = &rest[12 * n..];
    assert_eq!(take_line(&mut rest), "");
    assert_eq!(take_line(&mut rest), format!("CELLS {n} {}", 2 * n));
    assert_eq!(i32::from_be_bytes(rest[..4].try_into().unwrap()), 1);
}
