// Counting sort, pass 1: the cell of each particle and the number of particles per cell. An open
// flume's parked particles go to the slot after the last cell, so the exclusive scan leaves the
// count of active particles in cell_starts[n_cells] and no neighbour stencil ever reaches them.

@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> cell_of: array<u32>;
@group(0) @binding(3) var<storage, read_write> cell_counts: array<atomic<u32>>;

@compute @workgroup_size(128)
fn grid_count(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_particles) {
        return;
    }
    let p = positions[i];
    let f = params.flume;
    var c = params.n_cells;
    if (f.enabled == 0u || bitcast<u32>(p.w) != f.parked_phase) {
        c = cell_index(cell_coords(p.xyz));
    }
    cell_of[i] = c;
    atomicAdd(&cell_counts[c], 1u);
}
