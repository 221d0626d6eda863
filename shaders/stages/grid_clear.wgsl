// Zeroes the per-cell counters before the counting sort of this step.

@group(0) @binding(1) var<storage, read_write> cell_starts: array<u32>;
@group(0) @binding(2) var<storage, read_write> cell_cursor: array<u32>;

@compute @workgroup_size(128)
fn grid_clear(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = gid.x;
    if (c <= params.n_cells) {
        cell_starts[c] = 0u;
        cell_cursor[c] = 0u;
    }
}
