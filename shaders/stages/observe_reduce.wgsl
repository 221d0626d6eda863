// Whole-state maxima for observations and health: the surge front (largest x of a fluid
// particle), the largest speed and the largest relative density error, over the sorted copy
// of the state and its active particles only (parked ones are out of the flow). Max-reductions
// are order-independent, so the result is deterministic.

struct Extremes {
    front_key: atomic<u32>,          // order-preserving key of the largest x
    max_speed_bits: atomic<u32>,     // f32 bits (non-negative)
    max_rho_err_bits: atomic<u32>,   // f32 bits (non-negative)
    fluid_count: atomic<u32>,
}

@group(0) @binding(1) var positions: texture_2d<f32>;
@group(0) @binding(2) var vel_rho: texture_2d<f32>;
@group(0) @binding(3) var<storage, read_write> extremes: Extremes;
@group(0) @binding(4) var<storage, read> cell_starts: array<u32>;

// Maps f32 to u32 so that unsigned order equals float order (negative values too).
fn order_key(x: f32) -> u32 {
    let b = bitcast<u32>(x);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

@compute @workgroup_size(128)
fn observe_reduce(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= cell_starts[params.n_cells]) {
        return;
    }
    let p = textureLoad(positions, texel(i), 0);
    let phase = bitcast<u32>(p.w);
    let ph = params.phases[phase];
    if (ph.mobile < 0.5) {
        return;
    }
    let vr = textureLoad(vel_rho, texel(i), 0);
    atomicMax(&extremes.front_key, order_key(p.x));
    atomicMax(&extremes.max_speed_bits, bitcast<u32>(length(vr.xyz)));
    atomicMax(&extremes.max_rho_err_bits, bitcast<u32>(abs(vr.w / ph.rho0 - 1.0)));
    atomicAdd(&extremes.fluid_count, 1u);
}
