//! The native CPU backend: the stages of `pipeline.rs` in the same order on the same uniform,
//! written in plain Rust over the particle state in cell order and shared out among threads
//! with rayon. The formulas are those of `solver::physics` (pair terms, integrators, probes),
//! called per pair and per particle: the backend adds the loops, not the physics.
//!
//! It runs the water model (closed tanks, artificial or laminar viscosity, either
//! integrator); `unsupported` names what it does not run yet, and `Backend::choose` sends
//! those cases to a wgpu adapter.

mod forces;
mod grid;
mod observe;
mod step;

use crate::case::Particles;
use crate::config::{Case, Viscosity};
use crate::engine::{Engine, RawState, StageTime};
use crate::gpu::engine::{PipelineShape, by_id};
use crate::gpu::params::{Extremes, SimParams, StepState};
use crate::physics;
use crate::simulation::SolverError;
use grid::Grid;

/// Why the CPU backend cannot run `case`, or None when it can.
pub fn unsupported(case: &Case) -> Option<String> {
    if matches!(case.numerics.viscosity, Viscosity::Multiphase { .. }) {
        return Some("does not run the multiphase (sediment) model yet".into());
    }
    if case.open_flume.is_some() {
        return Some("does not run open flumes (inlet, outlet, collector) yet".into());
    }
    None
}

/// The line naming the CPU backend on `threads` threads (0: one per core).
pub fn describe(threads: usize) -> String {
    let n = if threads == 0 {
        rayon::current_num_threads()
    } else {
        threads
    };
    format!(
        "native CPU backend ({n} threads, {})",
        std::env::consts::ARCH
    )
}

/// One copy of the particle state, in storage order.
#[derive(Clone, Default)]
struct State {
    positions: Vec<[f32; 4]>,
    vel_rho: Vec<[f32; 4]>,
    ids: Vec<u32>,
    /// Velocity and density of the step before (the Verlet integrator's second sequence).
    vel_rho_prev: Vec<[f32; 4]>,
}

impl State {
    fn gather(&self, order: &[u32]) -> State {
        State {
            positions: grid::gather(&self.positions, order),
            vel_rho: grid::gather(&self.vel_rho, order),
            ids: grid::gather(&self.ids, order),
            vel_rho_prev: grid::gather(&self.vel_rho_prev, order),
        }
    }
}

/// The stages timed apart, in step order.
const STAGES: [&str; 4] = ["sort", "forces", "integrate", "observe"];

pub struct CpuEngine {
    pool: rayon::ThreadPool,
    threads: usize,
    params: SimParams,
    model: physics::Params,
    shape: PipelineShape,
    a: State,
    snapshot: State,
    probe_points: Vec<[f32; 4]>,
    /// Seconds spent in each of `STAGES`.
    seconds: std::cell::Cell<[f64; 4]>,
}

impl CpuEngine {
    pub fn new(
        threads: usize,
        params: &SimParams,
        n_phases: usize,
        particles: &Particles,
        probe_points: &[[f32; 4]],
        shape: PipelineShape,
    ) -> Result<CpuEngine, SolverError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|k| format!("flume-cpu-{k}"))
            .build()
            .map_err(|e| SolverError::CpuUnsupported(format!("cannot start its threads: {e}")))?;
        let a = State {
            positions: particles.positions.clone(),
            vel_rho: particles.vel_rho.clone(),
            ids: particles.ids.clone(),
            vel_rho_prev: particles.vel_rho.clone(),
        };
        Ok(CpuEngine {
            threads: pool.current_num_threads(),
            pool,
            params: *params,
            model: params.physics(shape.dim, n_phases),
            shape,
            snapshot: a.clone(),
            a,
            probe_points: probe_points.to_vec(),
            seconds: std::cell::Cell::new([0.0; 4]),
        })
    }

    fn grid(&self) -> Grid {
        Grid::new(&self.params, self.shape.divisions)
    }

    /// Adds the time since `start` to stage `k` of `STAGES`.
    fn timed(&self, k: usize, start: std::time::Instant) {
        let mut s = self.seconds.get();
        s[k] += start.elapsed().as_secs_f64();
        self.seconds.set(s);
    }
}

impl Engine for CpuEngine {
    fn name(&self) -> String {
        describe(self.threads)
    }

    fn write_params(&mut self, params: &SimParams) {
        self.params = *params;
        self.model = params.physics(self.shape.dim, self.model.phases.len());
    }

    fn save(&mut self) {
        self.snapshot.clone_from(&self.a);
    }

    fn restore(&mut self) {
        self.a.clone_from(&self.snapshot);
    }

    fn run(&mut self, init: StepState, steps: u32) -> Result<StepState, SolverError> {
        let mut state = init;
        for _ in 0..steps {
            if !self.step(&mut state) {
                break;
            }
        }
        Ok(state)
    }

    fn read_state(&self) -> Result<RawState, SolverError> {
        Ok(RawState {
            positions: self.a.positions.clone(),
            vel_rho: self.a.vel_rho.clone(),
            ids: self.a.ids.clone(),
        })
    }

    fn place(&mut self, slot: usize, position: [f32; 4], vel_rho: [f32; 4]) {
        self.a.positions[slot] = position;
        self.a.vel_rho[slot] = vel_rho;
        self.a.vel_rho_prev[slot] = vel_rho;
    }

    fn regions(&self) -> Result<Vec<u32>, SolverError> {
        // No multiphase model: no regions and no holds.
        Ok(vec![0; self.a.ids.len()])
    }

    fn forces(&self) -> Result<(Vec<[f32; 4]>, f32), SolverError> {
        let mut grid = self.grid();
        let b = self.a.gather(&grid.sort(&self.a.positions, &self.a.ids));
        let (forces, dt_limit) = self.force_pass(&grid, &b.positions, &b.vel_rho);
        Ok((by_id(&forces, &b.ids), forces::min_dt(&dt_limit)))
    }

    fn cell_list(&self) -> Result<(Vec<u32>, Vec<u32>), SolverError> {
        let mut grid = self.grid();
        let order = grid.sort(&self.a.positions, &self.a.ids);
        Ok((grid.starts, grid::gather(&self.a.ids, &order)))
    }

    fn observe(&self) -> Result<(Vec<[f32; 4]>, Extremes), SolverError> {
        let start = std::time::Instant::now();
        let mut grid = self.grid();
        let b = self.a.gather(&grid.sort(&self.a.positions, &self.a.ids));
        let sums = self.probe_points.iter().map(|p| {
            observe::probe_sums(
                &self.model,
                &grid,
                [p[0], p[1], p[2]],
                &b.positions,
                &b.vel_rho,
            )
        });
        let out = (
            sums.collect(),
            observe::extremes(&self.model, &self.a.positions, &self.a.vel_rho),
        );
        self.timed(3, start);
        Ok(out)
    }

    fn stage_times(&self) -> Vec<StageTime> {
        STAGES
            .iter()
            .zip(self.seconds.get())
            .map(|(&stage, seconds)| StageTime { stage, seconds })
            .collect()
    }
}
