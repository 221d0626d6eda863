//! Variable time step (Monaghan & Kos 1999, in the DualSPHysics form; Zubeldia et al. 2018):
//! `dt = C_CFL min(dt_force, dt_sound, dt_visc)`, with `dt_force = min_i sqrt(h / |a_i|)`,
//! `dt_sound = min_i h / (c0 + visc_max_i)` (both per particle in
//! [`Interaction::dt_limit`](super::interaction::Interaction::dt_limit)) and the explicit viscous
//! diffusion bound `dt_visc = 0.125 h^2 rho / mu` of each particle's own density and apparent
//! viscosity ([`particle_viscous_bound`]).

/// One particle's explicit viscous bound `0.125 h^2 rho / mu`, s, with its own density and
/// apparent viscosity (the multiphase model's); `f32::INFINITY` when `mu` is not positive.
pub fn particle_viscous_bound(h: f32, rho: f32, mu: f32) -> f32 {
    if mu > 0.0 {
        0.125 * h * h * rho / mu
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viscous_bound_by_hand() {
        // Water: 0.125 * 0.02^2 * 1000 / 1e-3 = 50 s, never limiting.
        let water = particle_viscous_bound(0.02, 1000.0, 1e-3);
        assert!((water - 50.0).abs() < 1e-4, "{water}");
        // Sediment slurry: 0.125 * 0.02^2 * 1800 / 50 = 1.8e-3 s.
        let slurry = particle_viscous_bound(0.02, 1800.0, 50.0);
        assert!((slurry - 1.8e-3).abs() < 1e-9, "{slurry}");
        // No viscosity, no bound (artificial viscosity alone, or a held grain's zero).
        assert_eq!(particle_viscous_bound(0.02, 1000.0, 0.0), f32::INFINITY);
    }
}
