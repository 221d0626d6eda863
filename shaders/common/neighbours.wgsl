// Neighbour stencil over the sorted cell list; the importing stage declares `cell_starts`.

// Rows of the 3 x 3 (2-D) or 3 x 3 x 3 (3-D) stencil: 3 or 9, fixed per pipeline.
override STENCIL_ROWS: u32 = 3u;

// First and one-past-last sorted index of the row `row` of the stencil around cell `c`;
// an empty range when the row lies outside the grid.
fn stencil_row(c: vec3<i32>, row: u32) -> vec2<u32> {
    let d = vec3<i32>(params.grid_dims.xyz);
    let cy = c.y + i32(row % 3u) - 1;
    // 2-D: the one plane z = 0; 3-D: planes z - 1, z, z + 1.
    let cz = c.z + i32(row / 3u) - select(0, 1, STENCIL_ROWS == 9u);
    if (cy < 0 || cy >= d.y || cz < 0 || cz >= d.z) {
        return vec2<u32>(0u, 0u);
    }
    let base = (u32(cz) * u32(d.y) + u32(cy)) * u32(d.x);
    let x0 = u32(max(c.x - 1, 0));
    let x1 = u32(min(c.x + 1, d.x - 1));
    return vec2<u32>(cell_starts[base + x0], cell_starts[base + x1 + 1u]);
}
