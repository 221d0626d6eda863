// The workgroup counts of the passes that run over the active particles only (an open flume's
// parked ones sort after every cell): one invocation turns the active count the scan left in
// cell_starts[n_cells] into indirect dispatch arguments, so the count never leaves the GPU.
// Three (x, y, z) triples: the active particles in workgroups of SMALL_GROUP, of LARGE_GROUP,
// and the parked ones in workgroups of LARGE_GROUP (see `pipeline::Indirect`).

@group(0) @binding(1) var<storage, read> cell_starts: array<u32>;
@group(0) @binding(2) var<storage, read_write> dispatch: array<u32>;

override SMALL_GROUP: u32 = 64u;
override LARGE_GROUP: u32 = 128u;

fn workgroups(items: u32, size: u32) -> u32 {
    return (items + size - 1u) / size;
}

fn write_args(k: u32, groups: u32) {
    dispatch[3u * k] = groups;
    dispatch[3u * k + 1u] = 1u;
    dispatch[3u * k + 2u] = 1u;
}

@compute @workgroup_size(1)
fn active_dispatch() {
    let in_cells = cell_starts[params.n_cells];
    write_args(0u, workgroups(in_cells, SMALL_GROUP));
    write_args(1u, workgroups(in_cells, LARGE_GROUP));
    write_args(2u, workgroups(params.n_particles - in_cells, LARGE_GROUP));
}
