//! Variable time step (Monaghan & Kos 1999, in the DualSPHysics form; Zubeldia et al. 2018):
//! `dt = C_CFL min(dt_force, dt_sound, dt_visc)`, with `dt_force = min_i sqrt(h / |a_i|)`,
//! `dt_sound = min_i h / (c0 + visc_max_i)` (both per particle in
//! [`Interaction::dt_limit`](super::interaction::Interaction::dt_limit)) and the explicit viscous
//! diffusion bound `dt_visc = 0.125 h^2 rho0 / mu`.

use super::{Params, Phase};

/// Time step, s: `cfl * min(min_i dt_limits[i], dt_visc)`.
///
/// Pass `dt_visc = f32::INFINITY` with artificial viscosity. With no mobile particle and no
/// viscous bound the result is infinite; the caller decides what that means.
pub fn step_size(params: &Params, dt_limits: &[f32], dt_visc: f32) -> f32 {
    let dt_min = dt_limits.iter().copied().fold(dt_visc, f32::min);
    params.cfl * dt_min
}

/// One particle's explicit viscous bound `0.125 h^2 rho / mu`, s, with its own density and
/// apparent viscosity (the multiphase model's); `f32::INFINITY` when `mu` is not positive.
pub fn particle_viscous_bound(h: f32, rho: f32, mu: f32) -> f32 {
    if mu > 0.0 {
        0.125 * h * h * rho / mu
    } else {
        f32::INFINITY
    }
}

/// Viscous stability bound, s: the smallest `0.125 h^2 rho0 / mu` over mobile phases with
/// `mu > 0`; `f32::INFINITY` if there is none.
pub fn viscous_dt_bound(h: f32, phases: &[Phase]) -> f32 {
    phases
        .iter()
        .filter(|ph| ph.mobile && ph.mu > 0.0)
        .map(|ph| 0.125 * h * h * ph.rho0 / ph.mu)
        .fold(f32::INFINITY, f32::min)
}

#[cfg(test)]
mod tests {
    use super::super::Viscosity;
    use super::*;

    fn params(phases: Vec<Phase>) -> Params {
        Params {
            dim: 2,
            h: 0.02,
            c0: 20.0,
            gravity: [0.0, -9.81, 0.0],
            delta: 0.1,
            hydrostatic_diffusion: true,
            clamp_negative_pressure: false,
            generalised_walls: false,
            viscosity: Viscosity::Laminar,
            cfl: 0.2,
            phases,
        }
    }

    fn phase(rho0: f32, mu: f32, mobile: bool) -> Phase {
        Phase {
            rho0,
            mass: 1.0,
            mu,
            mobile,
            generalised_wall: false,
        }
    }

    #[test]
    fn cfl_times_smallest_limit() {
        let p = params(Vec::new());
        assert_eq!(
            step_size(&p, &[1e-3, 5e-4, f32::INFINITY, 2e-3], f32::INFINITY),
            0.2 * 5e-4
        );
        assert_eq!(step_size(&p, &[1e-3, 5e-4], 1e-4), 0.2 * 1e-4);
        assert_eq!(step_size(&p, &[], f32::INFINITY), f32::INFINITY);
    }

    #[test]
    fn viscous_bound_by_hand() {
        // Water: 0.125 * 0.02^2 * 1000 / 1e-3 = 50 s, never limiting.
        // Sediment slurry: 0.125 * 0.02^2 * 1800 / 50 = 1.8e-3 s.
        let phases = vec![
            phase(1000.0, 1e-3, true),
            phase(1800.0, 50.0, true),
            phase(1000.0, 1e6, false), // walls do not diffuse momentum
            phase(1000.0, 0.0, true),
        ];
        let dt = viscous_dt_bound(0.02, &phases);
        assert!((dt - 1.8e-3).abs() < 1e-9, "{dt}");
        assert_eq!(viscous_dt_bound(0.02, &phases[2..]), f32::INFINITY);
        let water_only = viscous_dt_bound(0.02, &phases[..1]);
        assert!((water_only - 50.0).abs() < 1e-4, "{water_only}");
    }
}
