// What the end of a step stores for a particle, as a function of its states alone (no
// buffer is read or written): `store_state.wgsl` applies it, and `tests/wgsl_functions.rs`
// holds it to the CPU backend's `Store::apply` input by input. Needs params.wgsl,
// step_state.wgsl (the status flags) and flume.wgsl.

// A particle's fate at the end of a step.
const STORED_KEPT: u32 = 0u;
// Parked: water past the outlet.
const STORED_PARKED: u32 = 1u;
// Parked and counted eroded: sediment past the outlet or in the collector.
const STORED_ERODED: u32 = 2u;
// Parked and counted excluded: a free particle whose density left the range.
const STORED_EXCLUDED: u32 = 3u;

// A particle as stored: its fate, its new position (phase in w) and velocity-density, and the
// health flags it raises.
struct Stored {
    fate: u32,
    pos: vec4<f32>,
    vel_rho: vec4<f32>,
    flags: u32,
}

// Whether a finite density is outside rho0 (1 +/- rho_ratio_max); NaN is not (health_flags).
fn out_of_range(rho: f32, rho0: f32) -> bool {
    return abs(rho / rho0 - 1.0) > params.rho_ratio_max;
}

// The health flags of a particle's new state.
fn health_flags(x: vec3<f32>, v: vec3<f32>, rho: f32, rho0: f32) -> u32 {
    let s = dot(x, x) + dot(v, v) + rho;
    // NaN compares false with everything; infinities exceed the largest finite f32.
    if (!(abs(s) <= 3.0e38)) {
        return STATUS_NON_FINITE;
    }
    if (out_of_range(rho, rho0)) {
        return STATUS_DENSITY_RUNAWAY;
    }
    return 0u;
}

// The state `x`, `v`, `rho` kept, with its health flags.
fn kept(x: vec4<f32>, v: vec3<f32>, rho: f32, rho0: f32) -> Stored {
    return Stored(STORED_KEPT, x, vec4<f32>(v, rho), health_flags(x.xyz, v, rho, rho0));
}

// Particle `id` parked at its spot as water, with fate `fate`.
fn parked(id: u32, fate: u32) -> Stored {
    let f = params.flume;
    let spot = vec2<f32>(
        f.parking_x0 + f32(id % f.parking_cols) * f.parking_dp,
        f.parking_y0 + f32(id / f.parking_cols) * f.parking_dp,
    );
    let rho0 = params.phases[f.parked_phase].rho0;
    return Stored(fate, vec4<f32>(spot, 0.0, bitcast<f32>(f.parked_phase)), vec4<f32>(0.0, 0.0, 0.0, rho0), 0u);
}

// Particle `id` stored after a step of `dt` from `p`, `vr` (its old state, phase in p.w), the
// integrator's free new state being `x`, `v`, `rho`, held fixed by the rheology pass or not.
// Walls (DBC) keep their position and velocity, and their density never drops below rho0 so
// that they never pull fluid in. Held sediment keeps its position, at rest, and without
// tension (clamp_pressure) its density stays at or above rest as a free particle's does: a
// held bed under sand sliding off it would otherwise thin out without end. In an open flume
// (whose parked particles never get here: the integrators run over the active ones only):
// fluid past the outlet and sediment in the collector are parked; the inlet buffer (water,
// or sediment that strayed into it) moves at the inlet velocity, at its density; water in a
// bottom outlet's duct moves at the valve's velocity; a free particle whose density leaves the
// range is excluded (a lone splash meeting a wall compresses by about its Mach number v / c0:
// that is one particle's fate, not a blow-up of the run).
fn store_rule(id: u32, p: vec4<f32>, vr: vec4<f32>, x: vec3<f32>, v: vec3<f32>, rho: f32, held: bool, dt: f32) -> Stored {
    let phase = bitcast<u32>(p.w);
    let ph = params.phases[phase];
    let f = params.flume;
    let clamped = clamped_density(rho, phase);
    if (ph.mobile <= 0.5) {
        return Stored(STORED_KEPT, p, vec4<f32>(vr.xyz, max(rho, ph.rho0)), 0u);
    }
    if (f.enabled != 0u) {
        let sediment = params.sediment.phase != 0u && phase == params.sediment.phase;
        if (x.x > f.outlet_x) {
            return parked(id, select(STORED_PARKED, STORED_ERODED, sediment));
        }
        if (sediment && x.x >= f.collector_x_min && x.x <= f.collector_x_max && x.y < f.collector_y_max) {
            return parked(id, STORED_ERODED);
        }
        if (carried_by_inlet(p.xyz, phase)) {
            // Imposed velocity, and the density it entered with: a buffer column drawing away
            // from the wall behind it would otherwise thin out until the next one enters.
            let u = vec3<f32>(f.inlet_u, 0.0, 0.0);
            return kept(vec4<f32>(p.xyz + dt * u, p.w), u, inlet_density(vr.w, rho, phase), ph.rho0);
        }
        if (phase == f.water_phase && in_duct(p.xyz)) {
            let u = vec3<f32>(f.duct_u, 0.0, 0.0);
            return kept(vec4<f32>(p.xyz + dt * u, p.w), u, clamped, ph.rho0);
        }
    }
    if (held) {
        return kept(p, vec3<f32>(0.0), clamped, ph.rho0);
    }
    if (f.enabled != 0u && out_of_range(clamped, ph.rho0) && abs(dot(x, x) + dot(v, v)) <= 3.0e38) {
        return parked(id, STORED_EXCLUDED);
    }
    return kept(vec4<f32>(x, p.w), v, clamped, ph.rho0);
}
