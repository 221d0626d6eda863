// Orders the particles inside each cell by their stable id (insertion sort; a cell holds about
// ten particles), so that two runs of a case sum neighbours in the same order: bit-identical.

@group(0) @binding(1) var<storage, read> cell_starts: array<u32>;
@group(0) @binding(2) var<storage, read> ids: array<u32>;
@group(0) @binding(3) var<storage, read_write> sorted_index: array<u32>;

@compute @workgroup_size(128)
fn cell_sort(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = gid.x;
    if (c >= params.n_cells) {
        return;
    }
    let start = cell_starts[c];
    let end = cell_starts[c + 1u];
    for (var k = start + 1u; k < end; k++) {
        let v = sorted_index[k];
        let key = ids[v];
        var m = k;
        loop {
            if (m <= start) {
                break;
            }
            let prev = sorted_index[m - 1u];
            if (ids[prev] <= key) {
                break;
            }
            sorted_index[m] = prev;
            m -= 1u;
        }
        sorted_index[m] = v;
    }
}
