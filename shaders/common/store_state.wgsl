// The end of an integration step, shared by both integrators: `store_rule` (store_rule.wgsl)
// applied to the state buffers. The importing stage declares `state`, `regions`,
// `positions_out` and `vel_rho_out`.

// REGION_HELD of shaders/common/sediment.wgsl (checked by solver/tests/shaders_validate.rs).
const REGION_HELD_BIT: u32 = 256u;

// Whether the rheology pass held the particle of this id fixed (`regions` is by id).
fn is_held(id: u32) -> bool {
    return (regions[id] & REGION_HELD_BIT) != 0u;
}

// Logs particle `id` (phase `phase`) excluded with its free state x, v, rho (DualSPHysics'
// RhopOut), the first few of a chunk, and counts it.
fn log_excluded(id: u32, phase: u32, x: vec3<f32>, v: vec3<f32>, rho: f32) {
    let k = atomicAdd(&state.excluded, 1u);
    if (k < EXCLUDED_LOG_LEN) {
        state.excluded_log[k] = ExcludedParticle(id, phase, x.x, x.y, v.x, v.y, rho, 0u);
    }
    if (params.sediment.phase != 0u && phase == params.sediment.phase) {
        atomicAdd(&state.excluded_sediment, 1u);
    }
}

// Writes particle i's (id `id`) state as `store_rule` stores it (p, vr: its old state; x, v,
// rho: the integrator's free new one), and counts what happened to it.
fn store_state(i: u32, id: u32, p: vec4<f32>, vr: vec4<f32>, x: vec3<f32>, v: vec3<f32>, rho: f32) {
    let s = store_rule(id, p, vr, x, v, rho, is_held(id), state.dt);
    positions_out[i] = s.pos;
    vel_rho_out[i] = s.vel_rho;
    if (s.flags != 0u) {
        atomicOr(&state.status, s.flags);
    }
    if (s.fate == STORED_KEPT) {
        return;
    }
    atomicAdd(&state.parked, 1u);
    if (s.fate == STORED_ERODED) {
        atomicAdd(&state.eroded, 1u);
    }
    if (s.fate == STORED_EXCLUDED) {
        let phase = bitcast<u32>(p.w);
        log_excluded(id, phase, x, v, clamped_density(rho, phase));
    }
}
