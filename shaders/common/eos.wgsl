// Tait equation of state (Eq. 4), gamma = 7; reference: solver/src/physics/eos.rs.

fn tait_pressure(rho: f32, phase: u32) -> f32 {
    let x = rho / params.phases[phase].rho0;
    let x2 = x * x;
    let x4 = x2 * x2;
    let x7 = x4 * x2 * x;
    return params.tait_b[phase] * (x7 - 1.0);
}
