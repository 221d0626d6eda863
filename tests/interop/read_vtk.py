"""Reads a flume-twin particle snapshot with meshio, a VTK reader written elsewhere, and checks
what a ParaView user would see: one vertex per particle, the four point arrays, sane values.

Usage: python3 tests/interop/read_vtk.py SNAPSHOT.vtk N_PARTICLES
Exits non-zero, with the reason, if anything is off.
"""

import sys

import meshio
import numpy as np


def main() -> None:
    path, n = sys.argv[1], int(sys.argv[2])
    mesh = meshio.read(path)
    assert mesh.points.shape == (n, 3), f"points {mesh.points.shape}, expected ({n}, 3)"
    vertices = [block.data for block in mesh.cells if block.type == "vertex"]
    assert vertices and sum(len(v) for v in vertices) == n, "one vertex cell per particle"
    data = mesh.point_data
    for name in ("velocity", "density", "phase", "region", "held", "id"):
        assert name in data, f"point array {name!r} missing; has {sorted(data)}"
    assert data["velocity"].shape == (n, 3)
    assert np.isfinite(mesh.points).all() and np.isfinite(data["velocity"]).all()
    density = data["density"]
    assert ((density > 900.0) & (density < 1200.0)).all(), f"density {density.min()}..{density.max()}"
    assert set(np.unique(data["phase"])) <= {0, 1}, f"phases {np.unique(data['phase'])}"
    assert sorted(data["id"].astype(int)) == list(range(n)), "ids are not 0..n-1"
    print(f"meshio {meshio.__version__} read {path}: {n} particles, "
          f"phases {np.unique(data['phase']).tolist()}, density {density.min():.1f}..{density.max():.1f}")


if __name__ == "__main__":
    main()
