//! Gauges and pressure probes: Shepard-normalised SPH interpolation at a point (Shepard 1968), and
//! the free-surface level of DualSPHysics' SWL gauge, where the kernel "fullness"
//! `sum_j V_j W(x - x_j)` drops through a threshold (0.5 for a flat surface, since a symmetric
//! kernel cut in half sums to one half).

use super::Params;
use super::eos::{pressure, tait_b};
use super::interaction::phase_index;
use super::kernel::w;

/// Kernel sums at one point over the mobile particles within 2h.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProbeSums {
    /// `sum_j V_j W`, with `V_j = m_j / rho_j` (dimensionless; about 1 inside the fluid).
    pub fullness: f32,
    /// `sum_j V_j W p_j`, Pa.
    pub pressure_sum: f32,
    /// The fullness of each phase alone, by phase index (walls, index 0, stay 0): where a layer
    /// of one phase ends, its own fullness drops through one half.
    pub phase_fullness: [f32; 4],
}

impl ProbeSums {
    /// Shepard-interpolated pressure, Pa; `None` where the probe is nearly dry (fullness <= 0.1),
    /// because dividing by a small kernel sum amplifies the noise of one or two stray particles.
    pub fn pressure(&self) -> Option<f32> {
        (self.fullness > 0.1).then(|| self.pressure_sum / self.fullness)
    }
}

/// Kernel sums of the mobile particles around `point` (`[x, y, z]`, z = 0 in 2-D).
///
/// Panics if the slices differ in length or a phase index is outside `params.phases`.
pub fn probe(
    params: &Params,
    point: [f32; 3],
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
) -> ProbeSums {
    assert_eq!(
        pos.len(),
        vel_rho.len(),
        "positions and velocities differ in length"
    );
    let mut sums = ProbeSums::default();
    for (x, v) in pos.iter().zip(vel_rho) {
        add_particle(params, point, x, v, &mut sums);
    }
    sums
}

/// Adds particle `x`, `v` to the kernel sums at `point` and returns its weight `V W`:
/// nothing (zero) from a wall or from beyond the support 2h.
pub fn add_particle(
    params: &Params,
    point: [f32; 3],
    x: &[f32; 4],
    v: &[f32; 4],
    sums: &mut ProbeSums,
) -> f32 {
    let k = phase_index(x);
    let phase = &params.phases[k];
    if !phase.mobile {
        return 0.0;
    }
    let h = params.h;
    let d = [point[0] - x[0], point[1] - x[1], point[2] - x[2]];
    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if r2 >= 4.0 * h * h {
        return 0.0;
    }
    let rho = v[3];
    let vw = phase.mass / rho * w(r2.sqrt(), h, params.dim);
    sums.fullness += vw;
    sums.phase_fullness[k] += vw;
    sums.pressure_sum += vw * pressure(rho, phase.rho0, tait_b(params.c0, phase.rho0));
    vw
}

/// Water level on a vertical line sampled at ascending `heights` with kernel `fullness` values.
///
/// Returns the top-most height where fullness falls from `>= threshold` (below) to `< threshold`
/// (above), linearly interpolated between the two samples; the top height if the top sample is
/// still at or above the threshold (the gauge is submerged); `None` if no sample reaches the
/// threshold (dry). Only the first `min(heights.len(), fullness.len())` samples are used.
pub fn free_surface_level(heights: &[f64], fullness: &[f32], threshold: f32) -> Option<f64> {
    let n = heights.len().min(fullness.len());
    let (heights, fullness) = (&heights[..n], &fullness[..n]);
    let thr = f64::from(threshold);
    let top = n.checked_sub(1)?;
    if fullness[top] >= threshold {
        return Some(heights[top]);
    }
    // Scanning down from the top, the first wet sample marks the top-most crossing.
    let k = (0..top).rev().find(|&k| fullness[k] >= threshold)?;
    let (f_lo, f_hi) = (f64::from(fullness[k]), f64::from(fullness[k + 1]));
    let s = (f_lo - thr) / (f_lo - f_hi);
    Some(heights[k] + s * (heights[k + 1] - heights[k]))
}

#[cfg(test)]
mod tests {
    use super::super::kernel::smoothing_length;
    use super::super::{Phase, Viscosity};
    use super::*;

    fn params(h: f32, mass: f32) -> Params {
        Params {
            dim: 2,
            h,
            c0: 20.0,
            gravity: [0.0, -9.81, 0.0],
            delta: 0.1,
            hydrostatic_diffusion: true,
            clamp_negative_pressure: false,
            generalised_walls: false,
            viscosity: Viscosity::Artificial { alpha: 0.01 },
            cfl: 0.2,
            phases: vec![
                Phase {
                    rho0: 1000.0,
                    mass,
                    mu: 1e-3,
                    mobile: true,
                    generalised_wall: false,
                },
                Phase {
                    rho0: 1000.0,
                    mass,
                    mu: 0.0,
                    mobile: false,
                    generalised_wall: false,
                },
            ],
        }
    }

    /// Fluid filling [0, 0.6] x [0, 0.5] on a cell-centred lattice of spacing dp, with a row of
    /// wall particles below y = 0 (they must not count).
    fn tank(dp: f32) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
        let mut pos = Vec::new();
        for iy in -3..50 {
            for ix in 0..60 {
                let phase: u32 = if iy < 0 { 1 } else { 0 };
                pos.push([
                    (ix as f32 + 0.5) * dp,
                    (iy as f32 + 0.5) * dp,
                    0.0,
                    f32::from_bits(phase),
                ]);
            }
        }
        let vel_rho = vec![[0.0, 0.0, 0.0, 1000.0]; pos.len()];
        (pos, vel_rho)
    }

    #[test]
    fn gauge_finds_the_surface_of_a_still_tank() {
        let dp = 0.01_f32;
        let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
        let params = params(h, 1000.0 * dp * dp);
        let (pos, vel_rho) = tank(dp);
        let heights: Vec<f64> = (0..=600).map(|k| f64::from(k) * 1e-3).collect();
        let fullness: Vec<f32> = heights
            .iter()
            .map(|&z| probe(&params, [0.3, z as f32, 0.0], &pos, &vel_rho).fullness)
            .collect();
        let level = free_surface_level(&heights, &fullness, 0.5);
        let level = level.unwrap_or_else(|| panic!("no surface found"));
        assert!((level - 0.5).abs() < f64::from(dp) / 2.0, "level {level}");
        // Inside the fluid the kernel is full.
        let mid = probe(&params, [0.3, 0.25, 0.0], &pos, &vel_rho);
        assert!((mid.fullness - 1.0).abs() < 0.02, "{}", mid.fullness);
    }

    #[test]
    fn shepard_pressure() {
        let dp = 0.01_f32;
        let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
        let params = params(h, 1000.0 * dp * dp);
        let (pos, mut vel_rho) = tank(dp);
        for v in &mut vel_rho {
            v[3] = 1010.0;
        }
        // Uniform density: the interpolated pressure is the particles' pressure, wet or half wet.
        let p = pressure(1010.0, 1000.0, tait_b(20.0, 1000.0));
        for z in [0.25_f32, 0.5] {
            let sums = probe(&params, [0.3, z, 0.0], &pos, &vel_rho);
            let interp = sums
                .pressure()
                .unwrap_or_else(|| panic!("probe at {z} is dry"));
            assert!((interp - p).abs() < 1e-4 * p, "{interp} vs {p}");
        }
        // Above the water: dry.
        let dry = probe(&params, [0.3, 0.6, 0.0], &pos, &vel_rho);
        assert_eq!(dry, ProbeSums::default());
        assert_eq!(dry.pressure(), None);
    }

    #[test]
    fn level_from_samples_by_hand() {
        let z = [0.0, 0.1, 0.2, 0.3, 0.4];
        // Crossing between 0.1 (0.8) and 0.2 (0.4): 0.1 + 0.1 * (0.8 - 0.5) / 0.4 = 0.175.
        let level = free_surface_level(&z, &[1.0, 0.8, 0.4, 0.0, 0.0], 0.5);
        assert!(level.is_some_and(|l| (l - 0.175).abs() < 1e-6), "{level:?}");
        // A splash above an earlier crossing: the top-most crossing wins.
        let level = free_surface_level(&z, &[1.0, 0.2, 0.0, 0.9, 0.0], 0.5);
        assert!(
            level.is_some_and(|l| (l - (0.3 + 0.1 * 0.4 / 0.9)).abs() < 1e-6),
            "{level:?}"
        );
        // Submerged gauge, dry gauge, no samples, mismatched lengths.
        assert_eq!(
            free_surface_level(&z, &[1.0, 1.0, 1.0, 0.9, 0.5], 0.5),
            Some(0.4)
        );
        assert_eq!(
            free_surface_level(&z, &[0.4, 0.1, 0.0, 0.0, 0.0], 0.5),
            None
        );
        assert_eq!(free_surface_level(&[], &[], 0.5), None);
        assert_eq!(
            free_surface_level(&z[..2], &[1.0, 1.0, 0.0], 0.5),
            Some(0.1)
        );
    }
}
