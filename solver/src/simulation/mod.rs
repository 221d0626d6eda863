//! The solver's public face: a case in, `advance_to(t)` and observations out.
//!
//! Absolute time is kept here in f64; the GPU only sees the time since the start of the
//! current chunk (f32 cannot resolve dt = 1e-5 s at t = 3600 s). The inlet (discharges, their
//! schedule, the particles it places) is in `inflow`.

mod chain;
mod chunk;
mod grid;
mod inflow;
mod pores;

use grid::{divisions_of, grid_for};

pub use inflow::{InflowSchedule, RefusedInflow};
pub use pores::PoreColumns;

use crate::backend::Backend;
use crate::config::{Case, Integrator, Viscosity, YieldCriterion};
use crate::contract::sim_params;
use crate::contract::*;
use crate::derived::{Derived, check_inflow, derive};
use crate::engine::{Engine, StageTime};
use crate::engine::{PipelineShape, by_id};
use crate::error::SolverError;
use crate::flume::FlumeState;
use crate::generate::{count, generate};
use crate::gpu::engine::GpuEngine;
use crate::health::{self, ExclusionLog, RHO_RATIO_MAX};
pub use crate::health::{Health, Recovery};
use crate::observe::{self, FlumeObservation, Observations};
use crate::particles::{ParticleRegion, Particles, SPLASH_ROOM, parked_phase};

/// Retries of one chunk after a blow-up, each from the chunk's start at half the CFL number of
/// the last try, before the blow-up is returned as an error.
pub const MAX_RECOVERIES_PER_CHUNK: u32 = 4;
/// Clean `advance_to` calls after which a CFL number lowered by a recovery is doubled again,
/// up to the case's own: a twin that runs for hours should not keep the smallest step of its
/// worst moment.
pub const CFL_RESTORE_AFTER_CHUNKS: u32 = 50;
/// Largest CFL number `set_cfl` accepts. Above about 1 the scheme is unstable: values up to
/// this are accepted so that an operator (or a test) can see the recovery bring it back down.
pub const MAX_CFL: f64 = 5.0;

pub struct Simulation {
    engine: Box<dyn Engine>,
    case: Case,
    derived: Derived,
    params: SimParams,
    probes: observe::ProbeLayout,
    time_s: f64,
    steps: u64,
    last_dt_s: f64,
    /// The last step actually taken, s (the Verlet leapfrog spans it and the next).
    dt_taken: f32,
    initial_particles: Particles,
    recoveries: Vec<Recovery>,
    /// The CFL number to come back to after a recovery lowered it (the case's, or as set).
    cfl_target: f32,
    clean_chunks: u32,
    /// The open flume's host state; None for a closed tank.
    flume: Option<FlumeState>,
    /// The dry bed's pores; None where the sand holds no water.
    pores: Option<PoreColumns>,
    /// Time and eroded mass (kg/m) at the previous observation, for the erosion rate.
    last_eroded: std::cell::Cell<(f64, f64)>,
    /// Exclusions in one submission beyond which the run has blown up.
    max_excluded: u32,
    exclusion_log: ExclusionLog,
}

/// The host's part of what a recovery rolls back to ([`Simulation::save`]).
struct Saved {
    time_s: f64,
    steps: u64,
    last_dt_s: f64,
    dt_taken: f32,
    flume: Option<FlumeState>,
    pores: Option<PoreColumns>,
}

impl Simulation {
    pub fn new(backend: impl Into<Backend>, case: &Case) -> Result<Simulation, SolverError> {
        let backend = backend.into();
        let derived = derive(case);
        let count = count(case);
        let (grid_dims, _) = grid_for(case, derived.h, count)?;
        let n_cells = u64::from(grid_dims[3]);
        // Particle indices are u32 on the GPU, with headroom for index arithmetic.
        if count >= u64::from(u32::MAX / 2) {
            return Err(SolverError::TooManyParticles(count));
        }
        if let Backend::Gpu(gpu) = &backend {
            crate::gpu::state::GpuBuffers::check_limits(gpu, count, n_cells)?;
        }
        check_inflow(case)?;
        let particles = generate(case, &derived);
        // A sound speed too low for the fluid's height starts outside the weakly compressible
        // range: say so now, not as a blow-up at the first step.
        let worst = (0..particles.len())
            .filter(|&i| !particles.is_wall(i))
            .map(|i| {
                let rho0 = derived.phases[particles.phase(i) as usize].rho0;
                (f64::from(particles.vel_rho[i][3]) / rho0 - 1.0).abs()
            })
            .fold(0.0, f64::max);
        if worst > f64::from(RHO_RATIO_MAX) {
            return Err(SolverError::SoundSpeedTooLow {
                c0_m_per_s: derived.c0,
                fluid_height_m: derived.fluid_height,
                density_error: worst,
                // (1 + 7 g H / c0^2)^(1/7) - 1 stays below the bound for c0 above this.
                c0_needed_m_per_s: (7.0 * case.gravity_magnitude() * derived.fluid_height
                    / ((1.0 + f64::from(RHO_RATIO_MAX)).powi(7) - 1.0))
                    .sqrt(),
            });
        }
        Self::from_particles(backend, case, particles)
    }

    /// A simulation of `case` that starts from the given particles instead of the case's
    /// lattice (a restored snapshot, or a test's perturbed state); phases index the case's table.
    pub fn from_particles(
        backend: impl Into<Backend>,
        case: &Case,
        particles: Particles,
    ) -> Result<Simulation, SolverError> {
        let derived = derive(case);
        let (grid_dims, grid_origin) = grid_for(case, derived.h, particles.len() as u64)?;
        let n = particles.len() as u32;
        let probes = observe::ProbeLayout::new(case, derived.h);
        let params = sim_params(
            case,
            &derived,
            n,
            grid_dims,
            grid_origin,
            probes.points.len() as u32,
        );
        let multiphase = matches!(case.numerics.viscosity, Viscosity::Multiphase { .. });
        let drucker_prager = case
            .phases
            .iter()
            .filter_map(|p| p.sediment.as_ref())
            .any(|s| s.criterion == YieldCriterion::DruckerPragerShields);
        let shape = PipelineShape {
            dim: case.dimension,
            divisions: divisions_of(case, derived.h),
            verlet: matches!(case.numerics.integrator, Integrator::Verlet { .. }),
            multiphase,
            hold: multiphase && drucker_prager,
        };
        let engine: Box<dyn Engine> = match backend.into() {
            Backend::Gpu(gpu) => Box::new(GpuEngine::new(
                gpu,
                &params,
                &particles,
                &probes.points,
                shape,
            )?),
            Backend::Cpu { threads, awake_set } => Box::new(crate::cpu::CpuEngine::new(
                threads,
                awake_set,
                &params,
                derived.phases.len(),
                crate::contract::sediment_model(case, &derived),
                &particles,
                &probes.points,
                shape,
            )?),
        };
        let flume = FlumeState::new(case, &particles);
        let pores = PoreColumns::new(case, &particles, &params.flume);
        let max_excluded = health::max_excluded_per_chunk(
            (0..particles.len())
                .filter(|&i| !particles.is_wall(i))
                .count(),
        );
        Ok(Simulation {
            engine,
            case: case.clone(),
            derived,
            params,
            probes,
            time_s: 0.0,
            steps: 0,
            last_dt_s: 0.0,
            dt_taken: 0.0,
            initial_particles: particles,
            recoveries: Vec::new(),
            cfl_target: params.cfl,
            clean_chunks: 0,
            max_excluded,
            flume,
            pores,
            last_eroded: std::cell::Cell::new((0.0, 0.0)),
            exclusion_log: ExclusionLog::default(),
        })
    }

    pub fn case(&self) -> &Case {
        &self.case
    }
    pub fn derived(&self) -> &Derived {
        &self.derived
    }
    /// The backend and device the simulation runs on.
    pub fn backend_name(&self) -> String {
        self.engine.name()
    }
    /// Time per stage since the start; empty where the backend cannot time stages apart.
    pub fn stage_times(&self) -> Vec<StageTime> {
        self.engine.stage_times()
    }
    /// Counts the lane-pairs of every force pass from now (`on`), into [`Simulation::stage_times`],
    /// or no longer; a second walk over the neighbours, so not while timing.
    pub fn count_lanes(&mut self, on: bool) {
        self.engine.count_lanes(on);
    }
    pub fn particle_count(&self) -> usize {
        self.initial_particles.len()
    }
    /// Particles that are not walls (parked ones included: they are water out of the flow).
    pub fn fluid_count(&self) -> usize {
        (0..self.initial_particles.len())
            .filter(|&i| !self.initial_particles.is_wall(i))
            .count()
    }
    /// The phase code of parked particles, for readers of particle frames; none in a closed
    /// tank, which parks none.
    pub fn parked_phase(&self) -> Option<u32> {
        self.flume.as_ref().map(|_| parked_phase(&self.case))
    }
    pub fn time_s(&self) -> f64 {
        self.time_s
    }
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// The CFL time step of the last step taken, s (the step that lands on a target time may
    /// be shorter).
    pub fn last_dt_s(&self) -> f64 {
        self.last_dt_s
    }
    pub fn initial_particles(&self) -> &Particles {
        &self.initial_particles
    }

    /// Runs the GPU step loop until simulated time reaches `target_s` (exactly).
    ///
    /// The state at the start is kept on the GPU; if the chunk blows up (NaN, runaway density,
    /// collapsing step), the state is restored and the chunk retried with half the CFL number,
    /// up to `MAX_RECOVERIES_PER_CHUNK` times, each logged and listed in `recoveries`. The
    /// smaller CFL number stays in force until `CFL_RESTORE_AFTER_CHUNKS` clean calls, then
    /// doubles back towards the case's. Past the retries the blow-up is an error.
    pub fn advance_to(&mut self, target_s: f64) -> Result<(), SolverError> {
        if target_s < self.time_s {
            return Err(SolverError::TimeGoesBack {
                target_s,
                now_s: self.time_s,
            });
        }
        if !target_s.is_finite() {
            return Err(SolverError::InvalidParameter {
                name: "target time",
                reason: format!("must be a finite time in s, got {target_s}"),
            });
        }
        let saved = self.save();
        let mut tries = 0;
        // When the first try failed, and whether every retry failed at about the same time:
        // an unstable step fails after about as many steps whatever their length, so halving
        // the step moves the failure; a failure that stays put is not the step's doing.
        let mut first_failure: Option<(f64, f64)> = None;
        let mut same_time = true;
        loop {
            let err = match self.run_chunk(target_s) {
                Ok(()) => {
                    self.restore_cfl_when_calm();
                    return Ok(());
                }
                Err(e) => e,
            };
            let SolverError::BlowUp {
                time_s,
                step,
                health,
                culprits,
                ..
            } = err
            else {
                return Err(err);
            };
            let (first_s, tolerance_s) = *first_failure.get_or_insert_with(|| {
                // One step, or a tenth of the time from the restored state to the failure.
                (time_s, self.last_dt_s.max(0.1 * (time_s - saved.time_s)))
            });
            same_time &= (time_s - first_s).abs() <= tolerance_s;
            if tries >= MAX_RECOVERIES_PER_CHUNK {
                return Err(SolverError::BlowUp {
                    time_s,
                    step,
                    health,
                    culprits,
                    recurring_cfl: same_time.then_some(f64::from(self.params.cfl)),
                });
            }
            tries += 1;
            self.clean_chunks = 0;
            self.roll_back(&saved);
            self.params.cfl *= 0.5;
            self.engine.write_params(&self.params);
            log::warn!(
                "blow-up at t = {time_s:.6} s (step {step}): {health}; worst particles: {}; restored t = {:.6} s, retrying with CFL {}",
                health::list(&culprits),
                self.time_s,
                self.params.cfl
            );
            self.recoveries.push(Recovery {
                failed_at_s: time_s,
                health,
                restored_to_s: self.time_s,
                cfl: f64::from(self.params.cfl),
            });
        }
    }

    /// Saves what a recovery rolls back to: the engine's state (`Engine::save`) and the
    /// host's clock, inlet and pores.
    fn save(&mut self) -> Saved {
        self.engine.save();
        Saved {
            time_s: self.time_s,
            steps: self.steps,
            last_dt_s: self.last_dt_s,
            dt_taken: self.dt_taken,
            flume: self.flume.clone(),
            pores: self.pores.clone(),
        }
    }

    /// Rolls the run back to `saved`, the engine to its last save.
    fn roll_back(&mut self, saved: &Saved) {
        self.engine.restore();
        (self.time_s, self.steps) = (saved.time_s, saved.steps);
        (self.last_dt_s, self.dt_taken) = (saved.last_dt_s, saved.dt_taken);
        self.flume.clone_from(&saved.flume);
        self.pores.clone_from(&saved.pores);
    }

    fn restore_cfl_when_calm(&mut self) {
        if self.params.cfl >= self.cfl_target {
            return;
        }
        self.clean_chunks += 1;
        if self.clean_chunks >= CFL_RESTORE_AFTER_CHUNKS {
            self.clean_chunks = 0;
            self.params.cfl = (2.0 * self.params.cfl).min(self.cfl_target);
            self.engine.write_params(&self.params);
            log::info!(
                "{CFL_RESTORE_AFTER_CHUNKS} calm chunks: CFL back up to {}",
                self.params.cfl
            );
        }
    }

    /// Every blow-up recovered from so far, oldest first.
    pub fn recoveries(&self) -> &[Recovery] {
        &self.recoveries
    }

    /// The CFL number in force (the case's, or less after a recovery, or as set).
    pub fn cfl(&self) -> f64 {
        f64::from(self.params.cfl)
    }

    /// Changes the CFL number for the following steps; refuses values outside (0, MAX_CFL].
    pub fn set_cfl(&mut self, cfl: f64) -> Result<(), SolverError> {
        if !(cfl.is_finite() && cfl > 0.0 && cfl <= MAX_CFL) {
            return Err(SolverError::InvalidParameter {
                name: "cfl",
                reason: format!("must be in (0, {MAX_CFL}], got {cfl}"),
            });
        }
        self.params.cfl = cfl as f32;
        self.cfl_target = cfl as f32;
        self.engine.write_params(&self.params);
        Ok(())
    }

    /// The acoustic CFL bound on the time step, CFL h / c0, s: no step is longer, so a run
    /// to a few times this takes at least that many steps.
    pub fn acoustic_dt_bound_s(&self) -> f64 {
        self.case.numerics.cfl * self.derived.h / self.derived.c0
    }

    /// The open flume's host state (discharge, eroded and parked counts); None for a tank.
    pub fn flume(&self) -> Option<&FlumeState> {
        self.flume.as_ref()
    }

    /// The particles as they are now, in id order (index i holds the particle generated i-th).
    pub fn read_particles(&self) -> Result<Particles, SolverError> {
        let raw = self.engine.read_state()?;
        Ok(Particles {
            positions: by_id(&raw.positions, &raw.ids),
            vel_rho: by_id(&raw.vel_rho, &raw.ids),
            ids: (0..raw.ids.len() as u32).collect(),
        })
    }

    /// Region words of the last rheology pass (and release of held sediment), in id order: the
    /// region 1-5 of Figure 2 (0 for walls, and for every particle when the case has no
    /// multiphase viscosity), plus 256 for sediment held fixed in that pass.
    pub fn regions(&self) -> Result<Vec<u32>, SolverError> {
        self.engine.regions()
    }

    /// Sets the region words by particle id, as the next rheology pass reads them: a held bed
    /// already worn, for the tests that hold the two backends to the oracle.
    ///
    /// Panics unless there is one word a particle (a bug of the caller).
    pub fn set_regions(&mut self, words: &[u32]) {
        assert_eq!(
            words.len(),
            self.particle_count(),
            "one region word a particle"
        );
        self.engine.write_regions(words);
    }

    /// Forces and density rates (x, y, z acceleration, d rho/dt) of the current state, in id
    /// order, and the smallest stable step over particles (before the CFL factor), without
    /// advancing: the backend's side of the force-stage tests.
    pub fn compute_forces(&mut self) -> Result<(Vec<[f32; 4]>, f32), SolverError> {
        self.engine.forces()
    }

    /// The cell list of the current state: (cell starts, particle ids in sorted order).
    pub fn cell_list(&self) -> Result<(Vec<u32>, Vec<u32>), SolverError> {
        self.engine.cell_list()
    }

    /// Which of `spots` (x, y, m) a particle that is not parked is nearer to than `radius`, and
    /// the ids of the parked particles the inlet would fill them with, lowest first: the
    /// backend's side of the inlet test.
    pub fn inlet_scan(
        &mut self,
        spots: &[[f32; 2]],
        radius: f32,
    ) -> Result<(Vec<bool>, Vec<u32>), SolverError> {
        let scan = self.engine.inlet_scan(spots, radius)?;
        let ids = self.engine.read_state()?.ids;
        let parked = scan.parked_slots.iter().map(|&k| ids[k]).collect();
        Ok((scan.occupied, parked))
    }

    pub fn params(&self) -> &SimParams {
        &self.params
    }

    /// Under `van_rijn_exner`, the mass worn off the sand as bed load, in particles, from the
    /// region words `words` (by id) of the particles that are sand now: a grain collected in the
    /// last step keeps its word until the next rheology pass, and it is counted collected. 0
    /// under any other erosion, whose wear is not conserved.
    fn worn_grains(&self, words: &[u32]) -> Result<f64, SolverError> {
        let sand = match self.case.sediment_phases() {
            Some((k, _)) if self.case.wears_by_exner() => k as u32 + 1,
            _ => return Ok(0.0),
        };
        let raw = self.engine.read_state()?;
        let worn = raw
            .positions
            .iter()
            .zip(&raw.ids)
            .filter(|(x, _)| x[3].to_bits() == sand)
            .map(|(_, &id)| ParticleRegion::from_word(words[id as usize]).worn(true))
            .sum();
        Ok(worn)
    }

    /// Gauges, probes, front and health at the current time.
    pub fn observe(&self) -> Result<Observations, SolverError> {
        let (sums, ext) = self.engine.observe()?;
        let mut obs =
            self.probes
                .observations(self.time_s, self.steps, self.last_dt_s, &sums, &ext);
        obs.recoveries = self.recoveries.len() as u32;
        obs.cfl = self.cfl();
        // Without the multiphase viscosity no particle has a region, nor any wear.
        let mut worn = 0.0;
        if self.params.viscosity_mode == VISCOSITY_MULTIPHASE {
            let words = self.regions()?;
            let mut counts = [0u32; 6];
            for &w in &words {
                counts[usize::from(ParticleRegion::from_word(w).number())] += 1;
            }
            obs.region_counts = Some(counts);
            worn = self.worn_grains(&words)?;
        }
        if let Some(f) = &self.flume {
            let sediment_mass = self
                .case
                .sediment_phases()
                .map_or(0.0, |(k, _)| self.derived.phases[k + 1].mass);
            let kg_per_m = f.eroded_kg_per_m(sediment_mass) + worn * sediment_mass;
            let kg = kg_per_m * f.config.width_m;
            let (t_prev, kg_prev) = self.last_eroded.replace((self.time_s, kg));
            let rate = if self.time_s > t_prev {
                (kg - kg_prev) / (self.time_s - t_prev)
            } else {
                0.0
            };
            obs.flume = Some(FlumeObservation {
                inflow_m3_per_s: f.inflow_m3_per_s,
                eroded_particles: f.eroded_particles,
                worn_particles: worn,
                eroded_kg_per_m: kg_per_m,
                eroded_kg: kg,
                eroded_rate_kg_per_s: rate,
                parked_particles: f.parked_particles,
                starved_particles: f.starved_particles,
                blocked_particles: f.blocked_particles,
                injected_particles: f.injected_particles,
                soaked_particles: f.soaked_particles,
                excluded_particles: f.excluded_particles,
                excluded_sediment: f.excluded_sediment,
            });
        }
        Ok(obs)
    }
}

#[cfg(test)]
mod tests;
