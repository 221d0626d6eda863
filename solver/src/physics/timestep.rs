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

/// A mobile particle's stable step from its forces, s: `min(sqrt(h / |a|), h / (c0 + visc_max))`
/// with `accel` = |a| and `visc_max` the largest `h v.r / (r^2 + eta^2)` over its pairs. The
/// force bound is left out where the particle's velocity is imposed (`force_bound` false: its
/// acceleration means nothing) or it has none.
pub fn stable_step(h: f32, c0: f32, accel: f32, force_bound: bool, visc_max: f32) -> f32 {
    let dt_force = if accel > 0.0 && force_bound {
        (h / accel).sqrt()
    } else {
        f32::INFINITY
    };
    dt_force.min(h / (c0 + visc_max))
}

/// What the step loop does after the particles' stable steps are reduced to `stable`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NextStep {
    /// The chunk is over (its target reached, or the run unhealthy): no step.
    Stop,
    /// The step fell below the smallest allowed (or is NaN): the run collapses.
    Collapse,
    /// Step `dt` to `t_next`; `cfl_dt` is the CFL step before it was shortened to land on the
    /// target, which the next chunk's step count is estimated from.
    Step { dt: f32, t_next: f32, cfl_dt: f32 },
}

/// The variable step (DualSPHysics): `dt = cfl min(stable, dt_visc)`, landing exactly on the
/// chunk's target `t_target` from `t_rel`, in two equal steps rather than a full one and a
/// sliver; `halted` when a health flag is set. `dt_update` of both engines (`cpu/step.rs`,
/// `dt_update.wgsl` with `next_step` of `common/step_state.wgsl`).
pub fn next_step(
    cfl: f32,
    stable: f32,
    dt_visc: f32,
    dt_min: f32,
    t_rel: f32,
    t_target: f32,
    halted: bool,
) -> NextStep {
    let dt = cfl * stable.min(dt_visc);
    let remaining = t_target - t_rel;
    if halted || remaining <= 0.0 {
        return NextStep::Stop;
    }
    // NaN is a collapse too.
    if dt.is_nan() || dt < dt_min {
        return NextStep::Collapse;
    }
    let (dt_taken, t_next) = if dt >= remaining {
        (remaining, t_target)
    } else if 2.0 * dt > remaining {
        (0.5 * remaining, t_rel + 0.5 * remaining)
    } else {
        (dt, t_rel + dt)
    };
    NextStep::Step {
        dt: dt_taken,
        t_next,
        cfl_dt: dt,
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

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-6 * b.abs()
    }

    #[test]
    fn stable_step_by_hand() {
        // h = 1 cm, c0 = 10 m/s: the sound bound is 1 ms; 100 m/s2 allows 10 ms, 1e6 m/s2
        // 0.1 ms; an imposed particle's acceleration bounds nothing.
        assert!(close(stable_step(0.01, 10.0, 100.0, true, 0.0), 1e-3));
        assert!(close(stable_step(0.01, 10.0, 1e6, true, 0.0), 1e-4));
        assert!(close(stable_step(0.01, 10.0, 1e6, false, 0.0), 1e-3));
        // Approaching pairs (visc_max = 10 m/s) halve the sound bound.
        assert!(close(stable_step(0.01, 10.0, 0.0, true, 10.0), 5e-4));
    }

    /// Asserts a step of `dt` to `t_next` from a CFL step `cfl_dt`.
    fn assert_step(got: NextStep, dt: f32, t_next: f32, cfl_dt: f32) {
        let NextStep::Step {
            dt: d,
            t_next: t,
            cfl_dt: c,
        } = got
        else {
            panic!("{got:?} is no step");
        };
        assert!(
            close(d, dt) && close(t, t_next) && close(c, cfl_dt),
            "{got:?}"
        );
    }

    #[test]
    fn the_step_lands_on_the_target() {
        let step =
            |stable: f32, t_rel: f32| next_step(0.2, stable, f32::MAX, 1e-7, t_rel, 0.1, false);
        // CFL 0.2 of 0.1 s: 0.02 s, far from the end.
        assert_step(step(0.1, 0.0), 0.02, 0.02, 0.02);
        // 0.06 s of 0.1 s left: two halves of 0.05 s, not 0.06 and a sliver of 0.04.
        assert_step(step(0.3, 0.0), 0.05, 0.05, 0.06);
        // 0.02 s with 0.01 s left: exactly onto the target.
        assert_step(step(0.1, 0.09), 0.01, 0.1, 0.02);
        assert_eq!(step(0.1, 0.1), NextStep::Stop);
        // The viscous bound is the smaller: 0.2 of 2e-4 s.
        assert_step(
            next_step(0.2, 0.1, 2e-4, 1e-7, 0.0, 0.1, false),
            4e-5,
            4e-5,
            4e-5,
        );
        assert_eq!(
            next_step(0.2, 0.1, 2e-4, 1e-7, 0.0, 0.1, true),
            NextStep::Stop
        );
        assert_eq!(step(1e-7, 0.0), NextStep::Collapse);
    }
}
