// The health check of a particle's new state; the importing stage declares `state`.

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
