// Neighbour stencil over the sorted cell list; the importing stage declares `cell_starts`.
// Cells are 2h / CELL_DIVISIONS wide, so the stencil reaches R = CELL_DIVISIONS cells each way:
// rows of 2R + 1 contiguous cells, (2R + 1) rows in 2-D and (2R + 1)^2 in 3-D. Smaller cells
// (R = 2) visit fewer candidates outside the kernel support than cells of 2h (R = 1).

override CELL_DIVISIONS: u32 = 1u;
// Rows of the stencil: 2R + 1 in 2-D, (2R + 1)^2 in 3-D; fixed per pipeline.
override STENCIL_ROWS: u32 = 3u;

// First and one-past-last sorted index of the row `row` of the stencil around cell `c`;
// an empty range when the row lies outside the grid.
fn stencil_row(c: vec3<i32>, row: u32) -> vec2<u32> {
    let d = vec3<i32>(params.grid_dims.xyz);
    let reach = i32(CELL_DIVISIONS);
    let width = 2u * CELL_DIVISIONS + 1u;
    let cy = c.y + i32(row % width) - reach;
    // 2-D: the one plane z = 0; 3-D: planes z - R ..= z + R.
    let cz = c.z + i32(row / width) - select(0, reach, STENCIL_ROWS > width);
    if (cy < 0 || cy >= d.y || cz < 0 || cz >= d.z) {
        return vec2<u32>(0u, 0u);
    }
    let base = (u32(cz) * u32(d.y) + u32(cy)) * u32(d.x);
    let x0 = u32(max(c.x - reach, 0));
    let x1 = u32(min(c.x + reach, d.x - 1));
    return vec2<u32>(cell_starts[base + x0], cell_starts[base + x1 + 1u]);
}
