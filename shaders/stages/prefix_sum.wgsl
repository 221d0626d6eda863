// Exclusive prefix sum (Blelloch 1990) of `data` in blocks of 512, in place; each block's
// total goes to `block_sums`, whose own scan is then added back by `prefix_sum_add`.

struct ScanInfo {
    n: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> scan: ScanInfo;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;
@group(0) @binding(2) var<storage, read_write> block_sums: array<u32>;

const BLOCK: u32 = 512u;
var<workgroup> tile: array<u32, 512>;

@compute @workgroup_size(256)
fn prefix_sum_block(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let base = wid.x * BLOCK;
    let a = base + 2u * lid;
    tile[2u * lid] = select(0u, data[a], a < scan.n);
    tile[2u * lid + 1u] = select(0u, data[a + 1u], a + 1u < scan.n);
    var offset = 1u;
    for (var d = BLOCK >> 1u; d > 0u; d = d >> 1u) {
        workgroupBarrier();
        if (lid < d) {
            let ai = offset * (2u * lid + 1u) - 1u;
            let bi = offset * (2u * lid + 2u) - 1u;
            tile[bi] += tile[ai];
        }
        offset = offset << 1u;
    }
    workgroupBarrier();
    if (lid == 0u) {
        block_sums[wid.x] = tile[BLOCK - 1u];
        tile[BLOCK - 1u] = 0u;
    }
    for (var d = 1u; d < BLOCK; d = d << 1u) {
        offset = offset >> 1u;
        workgroupBarrier();
        if (lid < d) {
            let ai = offset * (2u * lid + 1u) - 1u;
            let bi = offset * (2u * lid + 2u) - 1u;
            let t = tile[ai];
            tile[ai] = tile[bi];
            tile[bi] += t;
        }
    }
    workgroupBarrier();
    if (a < scan.n) {
        data[a] = tile[2u * lid];
    }
    if (a + 1u < scan.n) {
        data[a + 1u] = tile[2u * lid + 1u];
    }
}

@compute @workgroup_size(256)
fn prefix_sum_add(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let add = block_sums[wid.x];
    let a = wid.x * BLOCK + 2u * lid;
    if (a < scan.n) {
        data[a] += add;
    }
    if (a + 1u < scan.n) {
        data[a + 1u] += add;
    }
}
