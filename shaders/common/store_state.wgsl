// The end of an integration step, shared by both integrators: the importing stage declares
// `state`, `regions`, `positions_out` and `vel_rho_out`.

// Mirrors REGION_HELD of shaders/common/sediment.wgsl.
const REGION_HELD_BIT: u32 = 256u;

// Whether the rheology pass held the particle of this id fixed (`regions` is by id).
fn is_held(id: u32) -> bool {
    return (regions[id] & REGION_HELD_BIT) != 0u;
}

// Raises health flags for a particle's new state.
fn check_health(x: vec3<f32>, v: vec3<f32>, rho: f32, rho0: f32) {
    var flags = 0u;
    let s = dot(x, x) + dot(v, v) + rho;
    // NaN compares false with everything; infinities exceed the largest finite f32.
    if (!(abs(s) <= 3.0e38)) {
        flags |= STATUS_NON_FINITE;
    } else if (abs(rho / rho0 - 1.0) > params.rho_ratio_max) {
        flags |= STATUS_DENSITY_RUNAWAY;
    }
    if (flags != 0u) {
        atomicOr(&state.status, flags);
    }
}

// Writes particle i's new position x, velocity v and density rho (p, vr: its old state).
// Walls (DBC) keep their position and velocity, and their density never drops below rho0 so
// that they never pull fluid in. Held sediment (`is_held`) keeps its position, at rest.
fn store_state(i: u32, p: vec4<f32>, vr: vec4<f32>, x: vec3<f32>, v: vec3<f32>, rho: f32, ph: Phase, held: bool) {
    if (ph.mobile > 0.5 && held) {
        positions_out[i] = p;
        vel_rho_out[i] = vec4<f32>(0.0, 0.0, 0.0, rho);
        check_health(p.xyz, vec3<f32>(0.0), rho, ph.rho0);
    } else if (ph.mobile > 0.5) {
        positions_out[i] = vec4<f32>(x, p.w);
        vel_rho_out[i] = vec4<f32>(v, rho);
        check_health(x, v, rho, ph.rho0);
    } else {
        positions_out[i] = p;
        vel_rho_out[i] = vec4<f32>(vr.xyz, max(rho, ph.rho0));
    }
}
