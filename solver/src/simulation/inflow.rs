//! The open flume's inlet: the discharge in force, a schedule of discharges applied each at its
//! own time, and the parked particles placed at the inlet as the inflow calls for them.

use super::Simulation;
use crate::derived::{MAX_INLET_MACH, max_inflow_m3_per_s};
use crate::error::SolverError;
use crate::flume::BoundaryConditions;
use crate::flume::{blocked_share, inlet_velocity};

/// Discharges to apply on the way to a time: `(time s, discharge m3/s)` in time order, each
/// in force from its own time on (one stamped before the simulation's time applies at once).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InflowSchedule {
    changes: Vec<(f64, f64)>,
}

impl InflowSchedule {
    pub fn new(changes: Vec<(f64, f64)>) -> InflowSchedule {
        InflowSchedule { changes }
    }

    pub fn changes(&self) -> &[(f64, f64)] {
        &self.changes
    }
}

/// A discharge of a schedule that the inlet refused; the one before it stayed in force.
#[derive(Debug)]
pub struct RefusedInflow {
    pub time_s: f64,
    pub inflow_m3_per_s: f64,
    pub error: SolverError,
}

impl Simulation {
    /// Fills the inlet columns due after `span_s` more of inflow with parked particles, lowest
    /// id first. The backend answers which spots are taken and which slots to fill in one
    /// small scan (`Engine::inlet_scan`): the state is not read back.
    pub(super) fn feed_inlet(&mut self, span_s: f64) -> Result<(), SolverError> {
        let dp = self.case.numerics.dp_m;
        let x_min = self.case.domain.min_m[0];
        let Some(f) = &mut self.flume else {
            return Ok(());
        };
        let injection = f.advance(span_s, dp, x_min);
        if injection.columns_x_m.is_empty() {
            return Ok(());
        }
        let heights = f.column_heights(dp);
        let spots: Vec<[f32; 2]> = injection
            .columns_x_m
            .iter()
            .flat_map(|&x| heights.iter().map(move |&y| [x as f32, y as f32]))
            .collect();
        let u = f.inlet_velocity(dp) as f32;
        let fl = self.params.flume;
        // The buffer keeps the density its particles enter with (store_state.wgsl): rest.
        let rho = self.params.phases[fl.water_phase as usize].rho0;
        // A spot some particle has wandered into (within dp / 2) stays empty this time: a
        // particle placed on top of another would send both densities out of range.
        let scan = self.engine.inlet_scan(&spots, (0.5 * dp) as f32)?;
        let mut free = scan.parked_slots.into_iter();
        let mut starved = 0u64;
        let mut placed = 0u64;
        let blocked_before = f.blocked_particles;
        for (spot, occupied) in spots.iter().zip(scan.occupied) {
            if occupied {
                f.blocked_particles += 1;
                continue;
            }
            let Some(slot) = free.next() else {
                starved += 1;
                continue;
            };
            let pos = [spot[0], spot[1], 0.0, f32::from_bits(fl.water_phase)];
            self.engine.place(slot, pos, [u, 0.0, 0.0, rho]);
            placed += 1;
        }
        f.parked_particles = f.parked_particles.saturating_sub(placed);
        f.injected_particles += placed;
        // At each doubling (the count only grows): a bed that keeps the buffer busy is told of
        // a few times, not at every column.
        if f.blocked_particles.checked_ilog2() != blocked_before.checked_ilog2() {
            log::warn!(
                "t = {:.3} s: {} inlet spots left empty since the start, a particle sitting on each ({:.2} % of the inflow not placed)",
                self.time_s,
                f.blocked_particles,
                100.0 * blocked_share(f.blocked_particles, f.injected_particles)
            );
        }
        if starved > 0 {
            f.starved_particles += starved;
            log::warn!(
                "t = {:.3} s: the inlet is short of {starved} particles: none is parked (the flume holds all it can; raise open_flume.reservoir_particles)",
                self.time_s
            );
        }
        Ok(())
    }

    /// Sets the discharge of an open flume's inlet from the next step on. Refuses a negative or
    /// non-finite discharge, one whose inlet velocity passes `MAX_INLET_MACH` c0, and a case
    /// without an open flume.
    pub fn set_boundary_conditions(&mut self, bc: BoundaryConditions) -> Result<(), SolverError> {
        let c0 = self.derived.c0;
        let Some(f) = &mut self.flume else {
            return Err(SolverError::InvalidParameter {
                name: "inflow",
                reason: "the case has no open flume".into(),
            });
        };
        let q = bc.inflow_m3_per_s;
        if !(q.is_finite() && q >= 0.0) {
            return Err(SolverError::InvalidParameter {
                name: "inflow",
                reason: format!("must be a finite discharge >= 0 m3/s, got {q}"),
            });
        }
        let u = inlet_velocity(&f.config, q, self.case.numerics.dp_m);
        if q > max_inflow_m3_per_s(&f.config, c0) {
            return Err(SolverError::InvalidParameter {
                name: "inflow",
                reason: format!(
                    "{q} m3/s gives an inlet velocity of {u:.3} m/s, above {MAX_INLET_MACH} c0 = {:.3} m/s",
                    MAX_INLET_MACH * c0
                ),
            });
        }
        f.inflow_m3_per_s = q;
        self.params.flume.inlet_u = u as f32;
        self.engine.write_params(&self.params);
        Ok(())
    }

    /// Advances to `target_s`, stopping at each change of `schedule` on the way to apply it at
    /// its own time. A discharge `set_boundary_conditions` refuses leaves the one before in
    /// force and comes back in the list, so that a twin fed by sensors runs on; a failure of
    /// the run itself is the error.
    pub fn advance_through(
        &mut self,
        target_s: f64,
        schedule: &InflowSchedule,
    ) -> Result<Vec<RefusedInflow>, SolverError> {
        let mut refused = Vec::new();
        for &(t, q) in schedule.changes() {
            if t > self.time_s {
                self.advance_to(t)?;
            }
            let bc = BoundaryConditions { inflow_m3_per_s: q };
            if let Err(error) = self.set_boundary_conditions(bc) {
                refused.push(RefusedInflow {
                    time_s: t,
                    inflow_m3_per_s: q,
                    error,
                });
            }
        }
        if target_s > self.time_s {
            self.advance_to(target_s)?;
        }
        Ok(refused)
    }
}
