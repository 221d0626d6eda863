//! The physical constants a case implies (h, c0, each phase's mass), derived once, and the
//! limits that need them: what a case asks of the inlet and of a bottom outlet must stay within
//! the weakly compressible range its c0 sets.

use crate::config::{Case, OpenFlume, SoundSpeed};
use crate::error::SolverError;

/// One phase as the solver sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseProps {
    pub rho0: f64,
    /// Mass per particle, kg (per metre of width in 2-D): rho0 dp^dim.
    pub mass: f64,
    pub viscosity_pa_s: f64,
    pub mobile: bool,
}

/// The physical constants every stage needs, derived once from the case.
#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    pub h: f64,
    pub c0: f64,
    /// Height of the fluid used for c0 with `coefsound`, m.
    pub fluid_height: f64,
    /// Index 0 is the wall.
    pub phases: Vec<PhaseProps>,
}

/// The Tait constant B = c0^2 rho0 / 7 (Eq. 4, gamma = 7), in f64 for case setup.
pub fn tait_b(c0: f64, rho0: f64) -> f64 {
    c0 * c0 * rho0 / 7.0
}

/// Monaghan's artificial-viscosity coefficient alpha that acts as the kinematic viscosity
/// `nu_m2_per_s` for a smoothing length `h` and sound speed `c0` in `dim` dimensions: the
/// term's shear viscosity is alpha h c0 / 8 in 2-D and / 10 in 3-D (Monaghan 2005, Rep. Prog.
/// Phys. 68:1703, Sec. 4.2).
pub fn monaghan_alpha(nu_m2_per_s: f64, h: f64, c0: f64, dim: usize) -> f64 {
    let factor = if dim == 3 { 10.0 } else { 8.0 };
    factor * nu_m2_per_s / (h * c0)
}

/// h, c0 and the phase table of a case.
pub fn derive(case: &Case) -> Derived {
    let d = case.dim();
    let dp = case.numerics.dp_m;
    let vmin = case.domain.min_m[d - 1];
    let top = case
        .fluid_blocks
        .iter()
        .map(|b| b.max_m[d - 1])
        .fold(vmin, f64::max);
    let fluid_height = top - vmin;
    let c0 = match case.numerics.sound_speed {
        SoundSpeed {
            c0_m_per_s: Some(c),
            ..
        } => c,
        // A validated case gives exactly one of the two; a case built in code without either
        // gets MODEL.md's usual c0 = 10 u_max.
        SoundSpeed { coefsound, .. } => crate::physics::eos::c0_from_coefsound(
            coefsound.unwrap_or(10.0),
            case.gravity_magnitude(),
            fluid_height,
        ),
    };
    let vol = dp.powi(d as i32);
    let mut phases = vec![PhaseProps {
        rho0: case.phases[0].rho0_kg_per_m3,
        mass: case.phases[0].rho0_kg_per_m3 * vol,
        viscosity_pa_s: case.phases[0].viscosity_pa_s,
        mobile: false,
    }];
    phases.extend(case.phases.iter().map(|p| PhaseProps {
        rho0: p.rho0_kg_per_m3,
        mass: p.rho0_kg_per_m3 * vol,
        viscosity_pa_s: p.viscosity_pa_s,
        mobile: true,
    }));
    if case.open_flume.is_some() {
        // Parked particles are water waiting out of the flow.
        let water = 1 + case.sediment_phases().map_or(0, |(_, w)| w);
        phases.push(PhaseProps {
            mobile: false,
            ..phases[water]
        });
    }
    Derived {
        h: case.smoothing_length_m(),
        c0,
        fluid_height,
        phases,
    }
}

/// Largest inlet velocity as a fraction of c0: weakly compressible SPH keeps the Mach number
/// near 0.1, and at 0.3 c0 the jet's dynamic pressure alone compresses the water by about
/// u^2 / (2 c0^2) = 4.5 %, half the 10 % bound of the weakly compressible range.
pub const MAX_INLET_MACH: f64 = 0.3;

/// The largest discharge the inlet of `f` carries with sound speed `c0`, m3/s:
/// `MAX_INLET_MACH` c0 through the opening.
pub fn max_inflow_m3_per_s(f: &OpenFlume, c0: f64) -> f64 {
    MAX_INLET_MACH * c0 * f.inlet.height_m * f.width_m
}

/// The largest discharge `case`'s inlet carries, m3/s, as `Simulation::set_boundary_conditions`
/// judges it; None for a case without an open flume. A twin asks this instead of knowing the
/// inlet's Mach bound and the sound speed.
pub fn inflow_limit_m3_per_s(case: &Case) -> Option<f64> {
    let f = case.open_flume.as_ref()?;
    Some(max_inflow_m3_per_s(f, derive(case).c0))
}

/// Refuses a case whose own discharge (`open_flume.inflow_m3_per_s`) the inlet cannot carry:
/// it would blow up in its first microseconds whatever the time step. Needs no GPU.
pub fn check_inflow(case: &Case) -> Result<(), SolverError> {
    let Some(f) = &case.open_flume else {
        return Ok(());
    };
    let c0 = derive(case).c0;
    let limit = max_inflow_m3_per_s(f, c0);
    if f.inflow_m3_per_s > limit {
        return Err(SolverError::InvalidParameter {
            name: "open_flume.inflow_m3_per_s",
            reason: format!(
                "{} m3/s is more than the inlet carries: at most {limit:.4e} m3/s, an inlet velocity of {MAX_INLET_MACH} c0 = {:.3} m/s through the {} m x {} m opening",
                f.inflow_m3_per_s,
                MAX_INLET_MACH * c0,
                f.inlet.height_m,
                f.width_m
            ),
        });
    }
    Ok(())
}

/// Refuses a bottom outlet whose duct velocity passes the inlet's bound, `MAX_INLET_MACH` c0:
/// the one check of a case file that needs its derived c0. The loader runs it after the checks
/// of `config`, so the rest of the case is valid by then; it returns the field and the reason,
/// as those do.
pub(crate) fn check_bottom_outlet(case: &Case) -> Result<(), (String, String)> {
    let Some(o) = case
        .open_flume
        .as_ref()
        .and_then(|f| f.bottom_outlet.as_ref())
    else {
        return Ok(());
    };
    let limit = MAX_INLET_MACH * derive(case).c0;
    if o.velocity_m_s > limit {
        return Err((
            "open_flume.bottom_outlet.velocity_m_s".into(),
            format!("must be at most {MAX_INLET_MACH} c0 = {limit:.3} m/s, as the inlet's"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::monaghan_alpha;

    /// By hand: the ULBRA flow's eddy viscosity, 3.9e-5 m2/s, at dp = 1 cm (h = 1.2 sqrt(2) dp
    /// = 0.016971 m) and c0 = 10 m/s is alpha = 8 x 3.9e-5 / 0.16971 = 0.001838; in 3-D the
    /// factor is 10: 0.002298.
    #[test]
    fn the_alpha_that_acts_as_a_given_viscosity() {
        let h = 1.2 * 2f64.sqrt() * 0.01;
        assert!((monaghan_alpha(3.9e-5, h, 10.0, 2) - 0.001_838).abs() < 1e-6);
        assert!((monaghan_alpha(3.9e-5, h, 10.0, 3) - 0.002_298).abs() < 1e-6);
    }
}
