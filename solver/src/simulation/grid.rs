//! The cell grid a case runs on.

use super::SPLASH_ROOM;
use crate::config::Case;
use crate::error::SolverError;
use crate::particles::Parking;

pub(super) fn divisions_of(case: &Case, h: f64) -> u32 {
    crate::gpu::pipeline::cell_divisions(case.dimension, h / case.numerics.dp_m)
}

/// Grid of cells of size 2h / cell_divisions covering the tank, its walls and a margin above it.
pub(super) fn grid_for(case: &Case, h: f64, n: u64) -> Result<([u32; 4], [f32; 4]), SolverError> {
    let d = case.dim();
    let cell = 2.0 * h / f64::from(divisions_of(case, h));
    let margin = f64::from(case.walls.layers) * case.numerics.dp_m + cell;
    let mut dims = [1u32; 4];
    let mut origin = [0.0f32; 4];
    for k in 0..d {
        let lo = case.domain.min_m[k] - margin;
        let mut hi = case.domain.max_m[k] + margin;
        if k == d - 1 {
            // Room above the tank for splashes; particles above the grid still live in its top row.
            hi += SPLASH_ROOM * (case.domain.max_m[k] - case.domain.min_m[k]);
            if case.open_flume.is_some() {
                hi = hi.max(Parking::new(case, h).top(n) + margin);
            }
        }
        dims[k] = ((hi - lo) / cell).ceil().clamp(1.0, f64::from(u32::MAX)) as u32;
        origin[k] = lo as f32;
    }
    let cells = u64::from(dims[0]) * u64::from(dims[1]) * u64::from(dims[2]);
    // Cell indices and the cell-start table (cells + 1 entries) are u32 on the GPU.
    dims[3] = u32::try_from(cells)
        .ok()
        .filter(|c| *c < u32::MAX)
        .ok_or(SolverError::TooManyCells(cells))?;
    origin[3] = (1.0 / cell) as f32;
    Ok((dims, origin))
}
