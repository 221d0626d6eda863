// Counting sort, pass 3: each particle takes a slot in its cell's range of the sorted order.
// The slot order inside a cell depends on thread timing; `cell_sort` makes it deterministic.

@group(0) @binding(1) var<storage, read> cell_of: array<u32>;
@group(0) @binding(2) var<storage, read> cell_starts: array<u32>;
@group(0) @binding(3) var<storage, read_write> cell_cursor: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> sorted_index: array<u32>;

@compute @workgroup_size(128)
fn grid_scatter(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_particles) {
        return;
    }
    let c = cell_of[i];
    let slot = cell_starts[c] + atomicAdd(&cell_cursor[c], 1u);
    sorted_index[slot] = i;
}
