//! Time integration as in DualSPHysics: `verlet` (Verlet 1967, one force pass a step), and
//! symplectic position-Verlet time integration in the DualSPHysics form (Leimkuhler et al. 1996;
//! Crespo et al. 2015, DualSPHysics): a predictor half step, a force pass at the half step, and a
//! corrector full step. Density uses the exact update `rho_new = rho_n (2 - eps) / (2 + eps)`,
//! `eps = -(d rho/dt / rho)_half dt`, which is exact for a constant d rho/dt.
//!
//! DBC walls (Crespo et al. 2007) never move and keep `rho >= rho0`, so a wall never sucks fluid
//! towards itself with negative pressure; under the generalised wall condition a wall's density
//! is the one its force pass gave (`physics::boundary`), kept at or above rest as well.

use super::Phase;
use super::interaction::phase_index;

/// A wall's new density: under the generalised wall condition the one its forces `f` carry,
/// else the integrated `rho`; never below rest either way.
fn wall_density(phase: &Phase, rho: f32, f: &[f32; 4]) -> f32 {
    let rho = if phase.generalised_wall { f[3] } else { rho };
    rho.max(phase.rho0)
}

/// A held sediment particle of a bed that stands as a wall (the Shields-only mode under the
/// generalised wall condition): at `x`, at rest, with the density its force pass gave it
/// (`f[3]`, `physics::boundary`), never below rest, as a wall. It replaces the integrator's
/// step for that particle (`held_bed_wall` in the WGSL integrators).
pub fn bed_wall(phase: &Phase, x: &[f32; 4], f: &[f32; 4]) -> Particle {
    (*x, [0.0, 0.0, 0.0, f[3].max(phase.rho0)])
}

/// One particle's predictor half step: its position and velocity-density at t + dt/2 from
/// those at t and its forces `f` at t. A wall keeps its position and velocity, and
/// `rho >= rho0`.
pub fn predict(phase: &Phase, dt: f32, x: &[f32; 4], v: &[f32; 4], f: &[f32; 4]) -> Particle {
    let half = 0.5 * dt;
    let rho = v[3] + half * f[3];
    if !phase.mobile {
        return (*x, [v[0], v[1], v[2], wall_density(phase, rho, f)]);
    }
    (
        [
            x[0] + half * v[0],
            x[1] + half * v[1],
            x[2] + half * v[2],
            x[3],
        ],
        [
            v[0] + half * f[0],
            v[1] + half * f[1],
            v[2] + half * f[2],
            rho,
        ],
    )
}

/// One particle's corrector full step: its state at t + dt from the state `x`, `v` at t, its
/// density `rho_half` at t + dt/2 and its forces `f` there.
pub fn correct(
    phase: &Phase,
    dt: f32,
    x: &[f32; 4],
    v: &[f32; 4],
    rho_half: f32,
    f: &[f32; 4],
) -> Particle {
    let eps = -(f[3] / rho_half) * dt;
    let rho = v[3] * (2.0 - eps) / (2.0 + eps);
    if !phase.mobile {
        return (*x, [v[0], v[1], v[2], wall_density(phase, rho, f)]);
    }
    let v_new = [v[0] + dt * f[0], v[1] + dt * f[1], v[2] + dt * f[2]];
    let step = dt * 0.5;
    (
        [
            x[0] + step * (v[0] + v_new[0]),
            x[1] + step * (v[1] + v_new[1]),
            x[2] + step * (v[2] + v_new[2]),
            x[3],
        ],
        [v_new[0], v_new[1], v_new[2], rho],
    )
}

/// One particle's Verlet step (see [`verlet`]): its state at n + 1 from the state `x`, `v` at
/// n, its velocity-density `v_prev` at n - 1 and its forces `f` at n.
#[allow(clippy::too_many_arguments)]
pub fn verlet_step(
    phase: &Phase,
    dt: f32,
    dt_prev: f32,
    euler: bool,
    x: &[f32; 4],
    v: &[f32; 4],
    v_prev: &[f32; 4],
    f: &[f32; 4],
) -> Particle {
    let (from, span) = if euler {
        (v, dt)
    } else {
        (v_prev, dt_prev + dt)
    };
    let rho = from[3] + span * f[3];
    if !phase.mobile {
        return (*x, [v[0], v[1], v[2], wall_density(phase, rho, f)]);
    }
    let half_dt2 = 0.5 * dt * dt;
    (
        [
            x[0] + dt * v[0] + half_dt2 * f[0],
            x[1] + dt * v[1] + half_dt2 * f[1],
            x[2] + dt * v[2] + half_dt2 * f[2],
            x[3],
        ],
        [
            from[0] + span * f[0],
            from[1] + span * f[1],
            from[2] + span * f[2],
            rho,
        ],
    )
}

/// A particle's position and velocity-density.
pub type Particle = ([f32; 4], [f32; 4]);

/// Predictor: state at t + dt/2 from the state and forces at t, by [`predict`].
///
/// Returns `(pos_half, vel_rho_half)`. Panics if the slices differ in length or a phase index is
/// outside `phases` (caller bugs).
pub fn predictor(
    phases: &[Phase],
    dt: f32,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    forces: &[[f32; 4]],
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    assert!(
        pos.len() == vel_rho.len() && pos.len() == forces.len(),
        "predictor inputs differ in length"
    );
    (0..pos.len())
        .map(|i| {
            predict(
                &phases[phase_index(&pos[i])],
                dt,
                &pos[i],
                &vel_rho[i],
                &forces[i],
            )
        })
        .unzip()
}

/// Corrector: state at t + dt from the state at t and the forces at t + dt/2, by [`correct`].
///
/// Returns `(pos_new, vel_rho_new)`. Panics if the slices differ in length or a phase index is
/// outside `phases` (caller bugs).
pub fn corrector(
    phases: &[Phase],
    dt: f32,
    pos_n: &[[f32; 4]],
    vel_rho_n: &[[f32; 4]],
    vel_rho_half: &[[f32; 4]],
    forces_half: &[[f32; 4]],
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let n = pos_n.len();
    assert!(
        vel_rho_n.len() == n && vel_rho_half.len() == n && forces_half.len() == n,
        "corrector inputs differ in length"
    );
    (0..n)
        .map(|i| {
            let phase = &phases[phase_index(&pos_n[i])];
            correct(
                phase,
                dt,
                &pos_n[i],
                &vel_rho_n[i],
                vel_rho_half[i][3],
                &forces_half[i],
            )
        })
        .unzip()
}

/// Positions, velocity-density and previous velocity-density of all particles.
pub type VerletState = (Vec<[f32; 4]>, Vec<[f32; 4]>, Vec<[f32; 4]>);

/// One Verlet step (Verlet 1967, as in DualSPHysics): from the state at n, the velocity and
/// density at n - 1 (`dt_prev` before) and the forces at n,
/// `x' = x + dt v + dt^2/2 a`, `v' = v_prev + (dt_prev + dt) a`,
/// `rho' = rho_prev + (dt_prev + dt) drho`;
/// with `euler`, `v' = v + dt a`, `rho' = rho + dt drho` instead (the periodic Euler step that
/// keeps the leapfrog's two sequences together). Walls keep position and velocity, and
/// `rho >= rho0`.
///
/// Returns `(positions, vel_rho, vel_rho_prev)` at n + 1. Panics if the slices differ in
/// length or a phase index is outside `phases` (caller bugs).
#[allow(clippy::too_many_arguments)]
pub fn verlet(
    phases: &[Phase],
    dt: f32,
    dt_prev: f32,
    euler: bool,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    vel_rho_prev: &[[f32; 4]],
    forces: &[[f32; 4]],
) -> VerletState {
    assert!(
        pos.len() == vel_rho.len() && pos.len() == vel_rho_prev.len() && pos.len() == forces.len()
    );
    let (pos_new, vel_new) = (0..pos.len())
        .map(|i| {
            let phase = &phases[phase_index(&pos[i])];
            let (x, v) = (&pos[i], &vel_rho[i]);
            verlet_step(
                phase,
                dt,
                dt_prev,
                euler,
                x,
                v,
                &vel_rho_prev[i],
                &forces[i],
            )
        })
        .unzip();
    (pos_new, vel_new, vel_rho.to_vec())
}

/// Applies the holds of the sediment model to a Verlet step taken by [`verlet`] from `pos`,
/// `vel_rho` at n: a held mobile particle keeps its position at rest in both of the leapfrog's
/// sequences (its `vel_rho_prev` at n is at rest too, so that released at n + 1 it does not
/// take back the velocity of n - 1), and with `clamp` (no tension) its density stays at or
/// above rho0, as `store_rule.wgsl` does.
///
/// Panics if the slices differ in length (caller bugs).
pub fn hold_at_rest(
    phases: &[Phase],
    clamp: bool,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    held: &[bool],
    step: &mut VerletState,
) {
    assert!(pos.len() == vel_rho.len() && pos.len() == held.len() && pos.len() == step.0.len());
    for i in (0..pos.len()).filter(|&i| held[i] && phases[phase_index(&pos[i])].mobile) {
        let rho0 = phases[phase_index(&pos[i])].rho0;
        let rho = step.1[i][3];
        step.0[i] = pos[i];
        step.1[i] = [0.0, 0.0, 0.0, if clamp { rho.max(rho0) } else { rho }];
        step.2[i] = [0.0, 0.0, 0.0, vel_rho[i][3]];
    }
}

#[cfg(test)]
mod tests {
    use super::super::interaction::interact;
    use super::super::{Params, Viscosity};
    use super::*;

    fn phases() -> Vec<Phase> {
        vec![
            Phase {
                rho0: 1000.0,
                mass: 0.1,
                mu: 1e-3,
                mobile: true,
                generalised_wall: false,
            },
            Phase {
                rho0: 1000.0,
                mass: 0.1,
                mu: 0.0,
                mobile: false,
                generalised_wall: false,
            },
        ]
    }

    #[test]
    fn free_fall_is_exact_parabola() {
        let params = Params {
            dim: 3,
            h: 0.02,
            c0: 20.0,
            gravity: [0.0, 0.0, -9.81],
            delta: 0.1,
            hydrostatic_diffusion: true,
            clamp_negative_pressure: false,
            generalised_walls: false,
            viscosity: Viscosity::Artificial { alpha: 0.01 },
            cfl: 0.2,
            phases: phases(),
        };
        let x0 = [0.3_f32, -0.2, 1.0];
        let v0 = [0.5_f32, 0.0, 2.0];
        let mut pos = vec![[x0[0], x0[1], x0[2], f32::from_bits(0)]];
        let mut vel_rho = vec![[v0[0], v0[1], v0[2], 1000.0]];
        let dt = 1e-3_f32;
        let steps = 1000;
        for _ in 0..steps {
            let f = interact(&params, &pos, &vel_rho).forces;
            let (pos_h, vel_h) = predictor(&params.phases, dt, &pos, &vel_rho, &f);
            let f_h = interact(&params, &pos_h, &vel_h).forces;
            (pos, vel_rho) = corrector(&params.phases, dt, &pos, &vel_rho, &vel_h, &f_h);
        }
        // The scheme is exact for constant acceleration; what remains is f32 rounding, at most
        // about half an ulp of the position per step.
        let t = f64::from(dt) * f64::from(steps);
        for k in 0..3 {
            let expected = f64::from(x0[k])
                + f64::from(v0[k]) * t
                + 0.5 * f64::from(params.gravity[k]) * t * t;
            let tol = f64::from(steps) * f64::from(f32::EPSILON) * 2.0;
            assert!(
                (f64::from(pos[0][k]) - expected).abs() < tol,
                "axis {k}: {} vs {expected}",
                pos[0][k]
            );
            let v_expected = f64::from(v0[k]) + f64::from(params.gravity[k]) * t;
            assert!(
                (f64::from(vel_rho[0][k]) - v_expected).abs() < tol,
                "axis {k} velocity"
            );
        }
        assert_eq!(pos[0][3].to_bits(), 0);
        assert_eq!(vel_rho[0][3], 1000.0);
    }

    #[test]
    fn density_update_exact_for_constant_rate() {
        let ph = phases();
        let dt = 1e-3_f32;
        let pos = vec![[0.0, 0.0, 0.0, f32::from_bits(0)]];
        for (rho, drho) in [(1000.0_f32, 150.0_f32), (1003.0, -420.0), (998.5, 7.0)] {
            let vel_rho = vec![[0.0, 0.0, 0.0, rho]];
            let forces = vec![[0.0, 0.0, 0.0, drho]];
            let (_, vel_h) = predictor(&ph, dt, &pos, &vel_rho, &forces);
            let (_, vel_new) = corrector(&ph, dt, &pos, &vel_rho, &vel_h, &forces);
            let exact = f64::from(rho) + f64::from(dt) * f64::from(drho);
            // A few ulps of ~1000.
            assert!(
                (f64::from(vel_new[0][3]) - exact).abs() < 4.0 * 1000.0 * f64::from(f32::EPSILON)
            );
        }
    }

    #[test]
    fn walls_stay_put_and_never_drop_below_rest_density() {
        let ph = phases();
        let dt = 1e-3_f32;
        let pos = vec![[0.1, 0.2, 0.3, f32::from_bits(1)]];
        let vel_rho = vec![[0.0, 0.0, 0.0, 1000.05]];
        let forces = vec![[1.0, 2.0, 3.0, -1000.0]];
        let (pos_h, vel_h) = predictor(&ph, dt, &pos, &vel_rho, &forces);
        assert_eq!(pos_h, pos);
        assert_eq!(vel_h[0], [0.0, 0.0, 0.0, 1000.0]);
        let (pos_new, vel_new) = corrector(&ph, dt, &pos, &vel_rho, &vel_h, &forces);
        assert_eq!(pos_new, pos);
        assert_eq!(vel_new[0], [0.0, 0.0, 0.0, 1000.0]);
        // Compression is kept.
        let forces = vec![[0.0, 0.0, 0.0, 1000.0]];
        let (_, vel_h) = predictor(&ph, dt, &pos, &vel_rho, &forces);
        let (_, vel_new) = corrector(&ph, dt, &pos, &vel_rho, &vel_h, &forces);
        assert!((vel_new[0][3] - 1001.05).abs() < 1e-3);
    }

    #[test]
    fn verlet_free_fall_follows_the_parabola() {
        let phases = [Phase {
            rho0: 1000.0,
            mass: 1.0,
            mu: 0.0,
            mobile: true,
            generalised_wall: false,
        }];
        let g = -9.81f32;
        let dt = 1e-3f32;
        let mut pos = vec![[0.0, 1.0, 0.0, f32::from_bits(0)]];
        let mut vel = vec![[0.0, 0.0, 0.0, 1000.0]];
        let mut prev = vel.clone();
        let forces = vec![[0.0, g, 0.0, 0.0]];
        let steps = 200;
        for k in 0..steps {
            // Euler every 40 steps, as DualSPHysics does by default.
            let (p, v, vp) = verlet(&phases, dt, dt, k % 40 == 0, &pos, &vel, &prev, &forces);
            pos = p;
            vel = v;
            prev = vp;
        }
        let t = dt * steps as f32;
        // Constant acceleration: both the leapfrog and the Euler steps integrate it exactly,
        // up to f32 rounding accumulated over the steps.
        assert!((vel[0][1] - g * t).abs() < 1e-4, "v = {}", vel[0][1]);
        assert!(
            (pos[0][1] - (1.0 + 0.5 * g * t * t)).abs() < 1e-4,
            "y = {}",
            pos[0][1]
        );
        assert_eq!(vel[0][3], 1000.0);
    }
}
