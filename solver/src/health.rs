//! The step loop's health: what stops a run and what does not.
//!
//! A run is broken when a particle's state is not finite, when the stable step collapses, or
//! when many particles leave the density range at once. One particle out of range is not a
//! broken run. A lone splash particle meeting a dynamic boundary (DBC) wall is stopped by its
//! own compression alone: with nothing around it, the continuity equation raises its density
//! by the overlap of its kernel with the wall, and the kinetic energy 1/2 v^2 that its pressure
//! must absorb, c0^2 e^2 / 2, gives a density excess e of about its Mach number v / c0 (the
//! water-hammer relation). In the ULBRA flume c0 = 10 m/s, so a drop falling 1.2 m/s into the
//! empty collector pit comes out 10-12 % over rest density, whatever the time step: a bound of
//! 10 % on every particle stopped the twin at the first such splash. In an open flume such a
//! particle is therefore excluded, as DualSPHysics excludes particles whose density leaves
//! `RhopOutMin..RhopOutMax` (700..1300 kg/m3 for water, +/- 30 %): it is parked like water
//! spilling over the weir, so that the inlet recycles it and the particle count and mass stay
//! whole, counted and logged. A closed tank (a verification case, short, with nowhere to
//! recycle a particle) keeps the 10 % bound as a failure.

use crate::config::Case;
use crate::contract::ExcludedParticle;
use crate::particles::{Particles, WALL_PHASE, parked_phase};

/// |rho / rho0 - 1| above which a density is a runaway in a closed tank, and the start-up bound:
/// ten times the 1 % that a weakly compressible flow shows with c0 >= 10 u_max (Eq. 5).
pub const RHO_RATIO_MAX: f32 = 0.1;
/// |rho / rho0 - 1| above which a free particle of an open flume is excluded: DualSPHysics'
/// default `RhopOutMin..RhopOutMax` of 700..1300 kg/m3 for water, as a ratio.
pub const RHO_RATIO_EXCLUDE: f32 = 0.3;
/// Particles excluded in one submission beyond which the run counts as blown up: a splash
/// sends out one or two, an unstable step sends out hundreds. One in 200 fluid particles, and
/// at least 8.
pub fn max_excluded_per_chunk(fluid_particles: usize) -> u32 {
    u32::try_from(fluid_particles / 200)
        .unwrap_or(u32::MAX)
        .max(8)
}

/// Health flags raised by the step loop (on the GPU, and `MANY_EXCLUDED` by the host).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Health(pub u32);

impl Health {
    pub const NON_FINITE: u32 = 1;
    pub const DENSITY_RUNAWAY: u32 = 2;
    pub const DT_COLLAPSE: u32 = 4;
    pub const MANY_EXCLUDED: u32 = 8;
    pub fn is_ok(self) -> bool {
        self.0 == 0
    }
}

impl std::fmt::Display for Health {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut parts = Vec::new();
        if self.0 & Self::NON_FINITE != 0 {
            parts.push("a particle has a NaN or infinite position, velocity or density");
        }
        if self.0 & Self::DENSITY_RUNAWAY != 0 {
            parts.push("a density left the weakly compressible range");
        }
        if self.0 & Self::DT_COLLAPSE != 0 {
            parts.push("the stable time step collapsed");
        }
        if self.0 & Self::MANY_EXCLUDED != 0 {
            parts.push("many particles left the density range at once");
        }
        if parts.is_empty() {
            parts.push("healthy");
        }
        write!(f, "{}", parts.join("; "))
    }
}

/// A blow-up the solver recovered from by rolling back and shrinking the time step.
#[derive(Debug, Clone, PartialEq)]
pub struct Recovery {
    /// When it blew up, s, and what the GPU saw.
    pub failed_at_s: f64,
    pub health: Health,
    /// The time it rolled back to, s, and the CFL number it retried with.
    pub restored_to_s: f64,
    pub cfl: f64,
}

/// A particle named in a blow-up report or an exclusion: where it was and in what state.
#[derive(Debug, Clone, PartialEq)]
pub struct Culprit {
    pub id: u32,
    /// The phase's name in the case ("water", "sand"), or "parked".
    pub phase: String,
    pub position_m: [f32; 2],
    pub velocity_m_per_s: [f32; 2],
    pub density_kg_per_m3: f32,
    pub rest_density_kg_per_m3: f32,
    /// Excluded for its density in the chunk that failed (its state is from that moment).
    pub excluded: bool,
}

impl std::fmt::Display for Culprit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y] = self.position_m;
        let [u, v] = self.velocity_m_per_s;
        write!(
            f,
            "id {} ({}{}) at ({x:.3}, {y:.3}) m moving ({u:.2}, {v:.2}) m/s, {:.1} kg/m3 ({:+.1} % of rest)",
            self.id,
            self.phase,
            if self.excluded { ", excluded" } else { "" },
            self.density_kg_per_m3,
            100.0 * (self.density_kg_per_m3 / self.rest_density_kg_per_m3 - 1.0)
        )
    }
}

/// The culprits as one line, "; "-separated.
pub fn list(culprits: &[Culprit]) -> String {
    let names: Vec<String> = culprits.iter().map(Culprit::to_string).collect();
    names.join("; ")
}

/// Name of GPU phase `phase` of `case`.
pub fn phase_name(case: &Case, phase: u32) -> String {
    match phase {
        WALL_PHASE => "wall".into(),
        p => case
            .phases
            .get(p as usize - 1)
            .map_or_else(|| "parked".into(), |ph| ph.name.clone()),
    }
}

/// A logged exclusion as a culprit.
pub fn from_log(case: &Case, rest: &[f64], e: &ExcludedParticle) -> Culprit {
    Culprit {
        id: e.id,
        phase: phase_name(case, e.phase),
        position_m: [e.x, e.y],
        velocity_m_per_s: [e.u, e.v],
        density_kg_per_m3: e.rho,
        rest_density_kg_per_m3: rest.get(e.phase as usize).copied().unwrap_or(1.0) as f32,
        excluded: true,
    }
}

/// The `count` moving particles furthest from health, worst first: those with a non-finite
/// state, then by |rho / rho0 - 1|. Walls and parked particles are left out. `rest` is the
/// rest density of each GPU phase.
pub fn worst_particles(
    case: &Case,
    rest: &[f64],
    particles: &Particles,
    count: usize,
) -> Vec<Culprit> {
    let parked = parked_phase(case);
    let badness = |i: usize| -> f32 {
        let (p, v) = (particles.positions[i], particles.vel_rho[i]);
        if !p.iter().chain(&v).all(|x| x.is_finite()) {
            return f32::INFINITY;
        }
        let rho0 = rest
            .get(particles.phase(i) as usize)
            .copied()
            .unwrap_or(1.0) as f32;
        (v[3] / rho0 - 1.0).abs()
    };
    let mut moving: Vec<(usize, f32)> = (0..particles.len())
        .filter(|&i| {
            let ph = particles.phase(i);
            ph != WALL_PHASE && !(case.open_flume.is_some() && ph == parked)
        })
        .map(|i| (i, badness(i)))
        .collect();
    // Ties broken by id so that the report is the same run to run.
    moving.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    moving
        .into_iter()
        .take(count)
        .map(|(i, _)| {
            let (p, v) = (particles.positions[i], particles.vel_rho[i]);
            let phase = particles.phase(i);
            Culprit {
                id: i as u32,
                phase: phase_name(case, phase),
                position_m: [p[0], p[1]],
                velocity_m_per_s: [v[0], v[1]],
                density_kg_per_m3: v[3],
                rest_density_kg_per_m3: rest.get(phase as usize).copied().unwrap_or(1.0) as f32,
                excluded: false,
            }
        })
        .collect()
}

/// Wall time between two log lines about excluded particles: a flume that splashes often must
/// not flood the log, and each line says how many went since the last.
const EXCLUSION_LOG_EVERY: std::time::Duration = std::time::Duration::from_secs(10);

/// The rate-limited log of excluded particles.
#[derive(Debug, Default)]
pub struct ExclusionLog {
    last_line: Option<std::time::Instant>,
    /// Excluded since the last line, and the first few of them.
    pending: u64,
    named: Vec<Culprit>,
}

impl ExclusionLog {
    /// Notes `count` particles excluded in a chunk that ended at `time_s`, `logged` the first
    /// of them, `total` the count since the start; writes a line when one is due.
    pub fn note(
        &mut self,
        time_s: f64,
        count: u32,
        logged: impl Iterator<Item = Culprit>,
        total: u64,
    ) {
        const NAMED: usize = 3;
        if count == 0 {
            return;
        }
        self.pending += u64::from(count);
        let room = NAMED.saturating_sub(self.named.len());
        self.named.extend(logged.take(room));
        if self
            .last_line
            .is_some_and(|t| t.elapsed() < EXCLUSION_LOG_EVERY)
        {
            return;
        }
        log::warn!(
            "t = {time_s:.3} s: {} particle(s) excluded for a density out of rho0 +/- {:.0} % and recycled through the inlet ({total} since the start): {}",
            self.pending,
            100.0 * RHO_RATIO_EXCLUDE,
            list(&self.named)
        );
        self.last_line = Some(std::time::Instant::now());
        self.pending = 0;
        self.named.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_culprit_reads_as_the_issue_would_name_it() {
        let c = Culprit {
            id: 2065,
            phase: "water".into(),
            position_m: [2.248, 0.016],
            velocity_m_per_s: [0.1, -1.2],
            density_kg_per_m3: 1100.0,
            rest_density_kg_per_m3: 1000.0,
            excluded: false,
        };
        assert_eq!(
            c.to_string(),
            "id 2065 (water) at (2.248, 0.016) m moving (0.10, -1.20) m/s, 1100.0 kg/m3 (+10.0 % of rest)"
        );
    }

    #[test]
    fn the_exclusion_limit_scales_with_the_fluid_and_has_a_floor() {
        assert_eq!(max_excluded_per_chunk(100), 8);
        assert_eq!(max_excluded_per_chunk(20_000), 100);
    }
}
