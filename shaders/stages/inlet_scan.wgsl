// What the open flume's inlet needs before it fills its new columns (`Simulation::feed_inlet`),
// without reading the state back: which of the spots to fill some particle that is not parked
// already occupies (within `radius2` of it, in x and y), and the storage slots of parked
// particles, lowest id first, one per spot at most. `inlet_mark` runs over the particles
// (the host clears `occupied` and `parked_bits` first); `inlet_pick` then walks the bitmap of
// parked ids on one invocation. Both answers are independent of thread timing.
// Reference: `CpuEngine::inlet_scan` (solver/src/cpu/mod.rs).

struct InletQuery {
    n_spots: u32,
    radius2: f32,            // m2
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(1) var<uniform> query: InletQuery;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> ids: array<u32>;
@group(0) @binding(4) var<storage, read> spots: array<vec2<f32>>;
@group(0) @binding(5) var<storage, read_write> occupied: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> parked_bits: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> slot_of: array<u32>;
// [count, slot, slot, ...]
@group(0) @binding(8) var<storage, read_write> picks: array<u32>;

@compute @workgroup_size(128)
fn inlet_mark(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_particles) {
        return;
    }
    let p = positions[i];
    if (bitcast<u32>(p.w) == params.flume.parked_phase) {
        let id = ids[i];
        slot_of[id] = i;
        atomicOr(&parked_bits[id / 32u], 1u << (id % 32u));
        return;
    }
    for (var s = 0u; s < query.n_spots; s++) {
        let d = p.xy - spots[s];
        if (d.x * d.x + d.y * d.y < query.radius2) {
            atomicOr(&occupied[s], 1u);
        }
    }
}

@compute @workgroup_size(128)
fn inlet_pick(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x != 0u) {
        return;
    }
    var count = 0u;
    let words = (params.n_particles + 31u) / 32u;
    for (var w = 0u; w < words && count < query.n_spots; w++) {
        var bits = atomicLoad(&parked_bits[w]);
        while (bits != 0u && count < query.n_spots) {
            let id = 32u * w + countTrailingZeros(bits);
            picks[1u + count] = slot_of[id];
            count += 1u;
            bits &= bits - 1u;
        }
    }
    picks[0] = count;
}
