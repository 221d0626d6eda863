// The end of an integration step, shared by both integrators: the importing stage declares
// `state`, `regions`, `positions_out` and `vel_rho_out`.

// REGION_HELD of shaders/common/sediment.wgsl (checked by solver/tests/shaders_validate.rs).
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
    } else if (out_of_range(rho, rho0)) {
        flags |= STATUS_DENSITY_RUNAWAY;
    }
    if (flags != 0u) {
        atomicOr(&state.status, flags);
    }
}

// Parks particle i (id `id`) at its spot as water; counts it as eroded when it was sediment
// (that reached the collector, or left over the weir).
fn park(i: u32, id: u32, eroded: bool) {
    let f = params.flume;
    let spot = vec2<f32>(
        f.parking_x0 + f32(id % f.parking_cols) * f.parking_dp,
        f.parking_y0 + f32(id / f.parking_cols) * f.parking_dp,
    );
    positions_out[i] = vec4<f32>(spot, 0.0, bitcast<f32>(f.parked_phase));
    vel_rho_out[i] = vec4<f32>(0.0, 0.0, 0.0, params.phases[f.parked_phase].rho0);
    atomicAdd(&state.parked, 1u);
    if (eroded) {
        atomicAdd(&state.eroded, 1u);
    }
}

// Excludes free particle i (id `id`, phase `phase`) whose density left the range rho0 (1 +/-
// rho_ratio_max) (DualSPHysics' RhopOut): it is parked, as water over the weir is, so that the
// inlet recycles it, and counted, the first few of a chunk logged with their state.
fn exclude(i: u32, id: u32, phase: u32, x: vec3<f32>, v: vec3<f32>, rho: f32) {
    let k = atomicAdd(&state.excluded, 1u);
    if (k < EXCLUDED_LOG_LEN) {
        state.excluded_log[k] = ExcludedParticle(id, phase, x.x, x.y, v.x, v.y, rho, 0u);
    }
    if (params.sediment.phase != 0u && phase == params.sediment.phase) {
        atomicAdd(&state.excluded_sediment, 1u);
    }
    park(i, id, false);
}

// Whether a finite density is outside rho0 (1 +/- rho_ratio_max); NaN is not (check_health).
fn out_of_range(rho: f32, rho0: f32) -> bool {
    return abs(rho / rho0 - 1.0) > params.rho_ratio_max;
}

// Writes particle i's (id `id`) new position x, velocity v and density rho (p, vr: its old
// state). Walls (DBC) keep their position and velocity, and their density never drops below
// rho0 so that they never pull fluid in. Held sediment (`is_held`) keeps its position, at rest,
// and without tension (clamp_pressure) its density stays at or above rest as a free particle's
// does: a held bed under sand sliding off it would otherwise thin out without end.
// In an open flume (whose parked particles never get here: the integrators run over the active
// ones only): fluid past the outlet and sediment in the collector are parked; the inlet buffer moves at the inlet velocity, at its density; water in
// a bottom outlet's duct moves at the valve's velocity; a free particle whose density leaves
// the range is excluded (a lone splash meeting a wall compresses by about its Mach number
// v / c0: that is one particle's fate, not a blow-up of the run).
fn store_state(i: u32, id: u32, p: vec4<f32>, vr: vec4<f32>, x: vec3<f32>, v: vec3<f32>, rho: f32, ph: Phase) {
    let phase = bitcast<u32>(p.w);
    let f = params.flume;
    if (f.enabled != 0u && ph.mobile > 0.5) {
        let sediment = params.sediment.phase;
        if (x.x > f.outlet_x) {
            park(i, id, sediment != 0u && phase == sediment);
            return;
        }
        if (sediment != 0u && phase == sediment && x.x >= f.collector_x_min && x.x <= f.collector_x_max && x.y < f.collector_y_max) {
            park(i, id, true);
            return;
        }
        if (phase == f.water_phase && in_inlet(p.xyz)) {
            // Imposed velocity, and the density it entered with: a buffer column drawing away
            // from the wall behind it would otherwise thin out until the next one enters.
            let u = vec3<f32>(f.inlet_u, 0.0, 0.0);
            let moved = p.xyz + state.dt * u;
            let r = inlet_density(vr.w, rho, phase);
            positions_out[i] = vec4<f32>(moved, p.w);
            vel_rho_out[i] = vec4<f32>(u, r);
            check_health(moved, u, r, ph.rho0);
            return;
        }
        if (phase == f.water_phase && in_duct(p.xyz)) {
            let u = vec3<f32>(f.duct_u, 0.0, 0.0);
            let moved = p.xyz + state.dt * u;
            let r = select(rho, max(rho, ph.rho0), params.clamp_pressure != 0u);
            positions_out[i] = vec4<f32>(moved, p.w);
            vel_rho_out[i] = vec4<f32>(u, r);
            check_health(moved, u, r, ph.rho0);
            return;
        }
    }
    if (ph.mobile > 0.5 && is_held(id)) {
        let r = select(rho, max(rho, ph.rho0), params.clamp_pressure != 0u);
        positions_out[i] = p;
        vel_rho_out[i] = vec4<f32>(0.0, 0.0, 0.0, r);
        check_health(p.xyz, vec3<f32>(0.0), r, ph.rho0);
    } else if (ph.mobile > 0.5) {
        // Without tension (the case's clamp_negative_pressure) the density never falls below
        // rest: a sheet too thin for a full kernel would otherwise thin out without end.
        let r = select(rho, max(rho, ph.rho0), params.clamp_pressure != 0u);
        if (f.enabled != 0u && out_of_range(r, ph.rho0) && abs(dot(x, x) + dot(v, v)) <= 3.0e38) {
            exclude(i, id, phase, x, v, r);
            return;
        }
        positions_out[i] = vec4<f32>(x, p.w);
        vel_rho_out[i] = vec4<f32>(v, r);
        check_health(x, v, r, ph.rho0);
    } else {
        positions_out[i] = p;
        vel_rho_out[i] = vec4<f32>(vr.xyz, max(rho, ph.rho0));
    }
}
