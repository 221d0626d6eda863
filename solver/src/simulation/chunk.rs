//! A run's steps in chunks, what the host books between them (the flume's counts, the inlet, the
//! pores), and the particles a blow-up names.

use super::Simulation;
use crate::contract::StepState;
use crate::error::SolverError;
use crate::health::{self, Culprit, Health};

/// Largest number of steps recorded into one submission.
const MAX_STEPS_PER_SUBMIT: u32 = 400;

impl Simulation {
    /// Steps to `target_s` in submissions of up to `MAX_STEPS_PER_SUBMIT` steps. Each
    /// submission is a GPU chunk whose time starts at zero, so f32 only ever holds the time
    /// of a few hundred steps; the host adds it to its f64 clock.
    pub(super) fn run_chunk(&mut self, target_s: f64) -> Result<(), SolverError> {
        let dp = self.case.numerics.dp_m;
        while target_s > self.time_s {
            let remaining = target_s - self.time_s;
            let max_span = self
                .flume
                .as_ref()
                .map_or(f64::INFINITY, |f| f.max_span_s(dp));
            let span = remaining.min(max_span);
            let euler_every = u64::from(self.params.euler_every);
            // The run's step count wraps in the block: the pick-up draws only need it to differ
            // from step to step.
            let init = StepState::chunk(
                span as f32,
                (self.last_dt_s as f32, self.dt_taken),
                (self.steps as u32, (self.steps % euler_every) as u32),
            );
            let state = self.engine.run(init, self.steps_for(span))?;
            self.steps += u64::from(state.steps);
            self.last_dt_s = f64::from(state.last_dt);
            self.dt_taken = state.dt_taken;
            let mut health = Health(state.status);
            if state.excluded > self.max_excluded {
                health.0 |= Health::MANY_EXCLUDED;
            }
            if !health.is_ok() {
                self.time_s += f64::from(state.t_rel);
                return Err(SolverError::BlowUp {
                    time_s: self.time_s,
                    step: self.steps,
                    health,
                    culprits: self.culprits(&state)?,
                    recurring_cfl: None,
                });
            }
            let reached = state.t_rel >= state.t_target;
            let advanced = if reached {
                span
            } else {
                f64::from(state.t_rel)
            };
            self.time_s = if reached && span == remaining {
                target_s
            } else {
                self.time_s + advanced
            };
            // Only a chunk with exclusions has particles to name.
            let rest = if state.excluded > 0 {
                self.rest_densities()
            } else {
                Vec::new()
            };
            if let Some(f) = &mut self.flume {
                f.eroded_particles += u64::from(state.eroded);
                f.parked_particles += u64::from(state.parked);
                f.excluded_particles += u64::from(state.excluded);
                f.excluded_sediment += u64::from(state.excluded_sediment);
                let logged = (state.excluded as usize).min(state.excluded_log.len());
                let excluded = state.excluded_log[..logged]
                    .iter()
                    .map(|e| health::from_log(&self.case, &rest, e));
                self.exclusion_log.note(
                    self.time_s,
                    state.excluded,
                    excluded,
                    f.excluded_particles,
                );
            }
            self.feed_inlet(advanced)?;
            self.soak_pores(advanced)?;
        }
        Ok(())
    }

    /// The particles to name in a blow-up report: those excluded in the failed chunk, then
    /// the moving ones furthest from health, 8 in all.
    fn culprits(&self, state: &StepState) -> Result<Vec<Culprit>, SolverError> {
        const NAMED: usize = 8;
        let rest = self.rest_densities();
        let logged = (state.excluded as usize).min(state.excluded_log.len());
        let mut out: Vec<Culprit> = state.excluded_log[..logged]
            .iter()
            .map(|e| health::from_log(&self.case, &rest, e))
            .collect();
        let particles = self.read_particles()?;
        let worst = health::worst_particles(&self.case, &rest, &particles, NAMED);
        out.extend(worst.into_iter().take(NAMED.saturating_sub(out.len())));
        Ok(out)
    }

    /// Rest density of each GPU phase (walls and parked particles included), kg/m3.
    fn rest_densities(&self) -> Vec<f64> {
        self.derived.phases.iter().map(|p| p.rho0).collect()
    }

    /// Steps estimated to cover `span_s` at the last CFL step (or the acoustic bound before
    /// the first step), clamped to one submission.
    fn steps_for(&self, span_s: f64) -> u32 {
        let dt = if self.last_dt_s > 0.0 {
            self.last_dt_s
        } else {
            f64::from(self.params.cfl * self.params.h / self.params.c0)
        };
        (span_s / dt)
            .ceil()
            .clamp(1.0, f64::from(MAX_STEPS_PER_SUBMIT)) as u32
    }
}
