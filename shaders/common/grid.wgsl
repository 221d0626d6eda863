// Cell-linked list geometry: cells of size 2h / CELL_DIVISIONS (see neighbours.wgsl), numbered
// x fastest, so the cells of one stencil row are contiguous in the sorted particle arrays.

fn cell_coords(p: vec3<f32>) -> vec3<i32> {
    let c = floor((p - params.grid_origin.xyz) * params.grid_origin.w);
    let hi = vec3<f32>(params.grid_dims.xyz) - 1.0;
    // Particles outside the grid are kept in its border cells: still found, never lost.
    return vec3<i32>(clamp(c, vec3<f32>(0.0), hi));
}

fn cell_index(c: vec3<i32>) -> u32 {
    let d = params.grid_dims;
    return (u32(c.z) * d.y + u32(c.y)) * d.x + u32(c.x);
}
