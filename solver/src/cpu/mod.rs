//! The native CPU backend: the stages of `gpu/pipeline.rs` in the same order on the same uniform,
//! written in plain Rust over the particle state in cell order and shared out among threads
//! with rayon. The formulas are those of `solver::physics` (pair terms, rheology, release,
//! integrators, probes), called per pair and per particle: the backend adds the loops, not the
//! physics.
//!
//! It runs every case the wgpu backend runs: the water model, the water-sediment model with
//! its holds, and the open flume. An open flume's parked particles sort after every cell and
//! take no part in the neighbour passes or the integrators.

mod by_id;
#[cfg(test)]
mod fixture;
mod forces;
mod grid;
mod heap;
mod multiphase;
mod observe;
mod simd;
mod step;
pub(crate) mod store;

use crate::contract::{Extremes, SimParams, StepState, VISCOSITY_MULTIPHASE};
use crate::engine::{Engine, InletScan, RawState, StageTime};
use crate::engine::{PipelineShape, by_id};
use crate::error::SolverError;
use crate::particles::Particles;
use crate::physics;
use crate::physics::sediment::pass::SedimentModel;
use crate::physics::sediment::suspension::Region;
use by_id::ById;
use grid::Grid;
use rayon::prelude::*;
use std::sync::Arc;

/// The line naming the CPU backend on `threads` threads (0: one per core), with its awake
/// set or without.
pub fn describe(threads: usize, awake_set: bool) -> String {
    let n = if threads == 0 {
        rayon::current_num_threads()
    } else {
        threads
    };
    let full = if awake_set {
        ""
    } else {
        ", every particle in full"
    };
    format!(
        "native CPU backend ({n} threads, {}{full})",
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

/// What a blow-up rolls back to (`Engine::save`, `Engine::restore`).
struct Snapshot {
    a: State,
    by_id: ById,
}

impl State {
    /// The state in sorted order: slot k holds storage index `order[k]`'s particle. One
    /// parallel region for the four arrays, not four: each wakes the pool's threads. Each
    /// chunk writes its slots in place: collecting the four as a tuple goes through rayon's
    /// `unzip`, which joins the threads' pieces on one thread (README, speed).
    /// The buffers of `b` are reused: every slot is written, so only the ones a longer order
    /// adds are set first; or, where `b` is already the order's length, the slots from
    /// `kept` on are taken to hold their particles already (the engine's `still` tail).
    fn gather(&self, order: &[u32], mut b: State, kept: usize) -> State {
        let n = order.len();
        let kept = if b.positions.len() == n {
            kept.min(n)
        } else {
            n
        };
        let order = &order[..kept];
        b.positions.resize(n, [0.0; 4]);
        b.vel_rho.resize(n, [0.0; 4]);
        b.ids.resize(n, 0);
        b.vel_rho_prev.resize(n, [0.0; 4]);
        let chunk = grid::PAR_MIN;
        let motion = b
            .positions
            .par_chunks_mut(chunk)
            .zip(b.vel_rho.par_chunks_mut(chunk));
        let rest = b
            .ids
            .par_chunks_mut(chunk)
            .zip(b.vel_rho_prev.par_chunks_mut(chunk));
        let chunks = order.par_chunks(chunk).zip(motion.zip(rest));
        chunks.for_each(|(order, ((x, v), (id, prev)))| {
            for (k, &i) in order.iter().enumerate() {
                let i = i as usize;
                (x[k], v[k]) = (self.positions[i], self.vel_rho[i]);
                (id[k], prev[k]) = (self.ids[i], self.vel_rho_prev[i]);
            }
        });
        b
    }
}

/// The stages timed apart, in step order; "rheology" includes the release of held sand.
const STAGES: [&str; 4] = ["sort", "rheology", "forces", "integrate"];
const STAGE_SORT: usize = 0;
const STAGE_RHEOLOGY: usize = 1;
const STAGE_FORCES: usize = 2;
const STAGE_INTEGRATE: usize = 3;

pub struct CpuEngine {
    /// Shared so that a whole run can go to the pool at once (see `Engine::run`).
    pool: Arc<rayon::ThreadPool>,
    threads: usize,
    params: SimParams,
    model: physics::Params,
    shape: PipelineShape,
    /// The sediment model, None without the multiphase viscosity.
    sediment: Option<SedimentModel>,
    a: State,
    /// The buffers of the last step's sorted copy, which the next sort fills (`step.rs`):
    /// writing into memory a step has just used spares the allocator's zeroing of fresh
    /// memory.
    spare: State,
    side_buffers: step::SideBuffers,
    /// Storage slots from `still` on hold parked particles that `a` and `spare` hold alike
    /// at the same slots: the sort keeps them where they are, and neither its gather nor the
    /// integrator copies them (`step.rs`). The state's length where nothing is known, and
    /// always without the awake set.
    still: usize,
    /// What the rheology passes leave each particle for the next, by id.
    by_id: ById,
    snapshot: Snapshot,
    probe_points: Vec<[f32; 4]>,
    /// Seconds spent in each of `STAGES`, and of them in its walk (`StageTime::walk_seconds`).
    seconds: [f64; STAGES.len()],
    walk_seconds: [f64; STAGES.len()],
    /// Whether walls and held grains far from moving fluid or deep under it sleep
    /// (`forces.rs`, `multiphase.rs`); false computes every particle in full, to the same bits.
    awake_set: bool,
    /// Particles each neighbour pass of `STAGES` took, and how many of them slept.
    passed: [u64; STAGES.len()],
    asleep: [u64; STAGES.len()],
    /// Whether each force pass is followed by a count of its lane-pairs (`bench`), and the
    /// count so far.
    count_lanes: bool,
    lanes: forces::LaneUse,
}

impl CpuEngine {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        threads: usize,
        awake_set: bool,
        params: &SimParams,
        n_phases: usize,
        sediment: Option<SedimentModel>,
        particles: &Particles,
        probe_points: &[[f32; 4]],
        shape: PipelineShape,
    ) -> Result<CpuEngine, SolverError> {
        heap::keep_freed_memory();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|k| format!("flume-cpu-{k}"))
            .build()
            .map_err(|e| SolverError::CpuThreads(e.to_string()))?;
        let a = State {
            positions: particles.positions.clone(),
            vel_rho: particles.vel_rho.clone(),
            ids: particles.ids.clone(),
            vel_rho_prev: particles.vel_rho.clone(),
        };
        let by_id = ById::new(particles.len());
        Ok(CpuEngine {
            threads: pool.current_num_threads(),
            pool: Arc::new(pool),
            params: *params,
            model: params.physics(shape.dim, n_phases),
            shape,
            sediment: sediment.filter(|_| params.viscosity_mode == VISCOSITY_MULTIPHASE),
            snapshot: Snapshot {
                a: a.clone(),
                by_id: by_id.clone(),
            },
            still: a.positions.len(),
            a,
            spare: State::default(),
            side_buffers: step::SideBuffers::default(),
            by_id,
            probe_points: probe_points.to_vec(),
            seconds: [0.0; STAGES.len()],
            walk_seconds: [0.0; STAGES.len()],
            awake_set,
            passed: [0; STAGES.len()],
            asleep: [0; STAGES.len()],
            count_lanes: false,
            lanes: forces::LaneUse::default(),
        })
    }

    fn grid(&self) -> Grid {
        Grid::new(&self.params, self.shape.divisions)
    }

    /// Counts a pass of stage `k` over `particles`, `asleep` of which slept.
    fn count(&mut self, k: usize, particles: usize, asleep: usize) {
        self.passed[k] += particles as u64;
        self.asleep[k] += asleep as u64;
    }

    /// Adds the time since `start` to stage `k` of `STAGES`.
    fn timed(&mut self, k: usize, start: std::time::Instant) {
        self.seconds[k] += start.elapsed().as_secs_f64();
    }

    /// The parked phase of an open flume, None for a closed tank.
    fn parked_phase(&self) -> Option<u32> {
        (self.params.flume.enabled != 0).then_some(self.params.flume.parked_phase)
    }

    /// Whether sorted slot `k` of `b` is un-yielded sediment (region 1): the probes' fourth
    /// sum, whose top is the bed interface Zb.
    fn unyielded_sediment(&self, b: &State, k: usize) -> bool {
        let sediment = self.params.sediment.phase;
        sediment != 0
            && b.positions[k][3].to_bits() == sediment
            && self.by_id.regions[b.ids[k] as usize] & 255 == Region::Unyielded as u32
    }
}

impl Engine for CpuEngine {
    fn name(&self) -> String {
        describe(self.threads, self.awake_set)
    }

    fn write_params(&mut self, params: &SimParams) {
        let parked = self.parked_phase();
        self.params = *params;
        if self.parked_phase() != parked {
            self.still = self.a.positions.len();
        }
        self.model = params.physics(self.shape.dim, self.model.phases.len());
    }

    fn save(&mut self) {
        let s = &mut self.snapshot;
        s.a.clone_from(&self.a);
        s.by_id.clone_from(&self.by_id);
    }

    fn restore(&mut self) {
        let s = &self.snapshot;
        self.a.clone_from(&s.a);
        self.by_id.clone_from(&s.by_id);
        self.still = self.a.positions.len();
    }

    fn run(&mut self, init: StepState, steps: u32) -> Result<StepState, SolverError> {
        // The steps run on one of the pool's own threads: each parallel pass inside is then
        // a fork among the pool's threads, rather than a hand-off from this thread to the
        // pool and back (two futex round trips, some ten times a step).
        let pool = Arc::clone(&self.pool);
        let state = pool.install(|| {
            let mut state = init;
            for _ in 0..steps {
                if !self.step(&mut state) {
                    break;
                }
            }
            state
        });
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
        // The spare copy no longer holds this slot's particle.
        self.still = self.still.max(slot + 1);
        // A particle placed from outside has taken no walk where it now stands.
        let id = self.a.ids[slot] as usize;
        if let Some(r) = self.by_id.records.get_mut(id) {
            *r = f32::NAN;
        }
        if let Some(d) = self.by_id.dry.get_mut(id) {
            *d = false;
        }
    }

    fn inlet_scan(&mut self, spots: &[[f32; 2]], radius: f32) -> Result<InletScan, SolverError> {
        let (a, parked) = (&self.a, self.params.flume.parked_phase);
        let scan = crate::engine::inlet_scan(&a.positions, &a.ids, parked, spots, radius);
        Ok(scan)
    }

    fn regions(&self) -> Result<Vec<u32>, SolverError> {
        Ok(self.by_id.regions.clone())
    }

    fn write_regions(&mut self, words: &[u32]) {
        self.by_id.set_regions(words);
    }

    fn forces(&mut self) -> Result<(Vec<[f32; 4]>, f32), SolverError> {
        let (grid, b) = self.sorted();
        let mut pass = self.force_pass(&grid, &b, (&b.positions, &b.vel_rho), None);
        // Parked particles feel nothing.
        pass.forces.resize(b.ids.len(), [0.0; 4]);
        Ok((by_id(&pass.forces, &b.ids), forces::min_dt(&pass.dt_limit)))
    }

    fn cell_list(&self) -> Result<(Vec<u32>, Vec<u32>), SolverError> {
        let (grid, b) = self.sorted();
        Ok((grid.starts, b.ids))
    }

    fn observe(&self) -> Result<(Vec<[f32; 4]>, Extremes), SolverError> {
        let (grid, b) = self.sorted();
        let unyielded = |k: usize| self.unyielded_sediment(&b, k);
        let sums = self.probe_points.iter().map(|p| {
            let point = [p[0], p[1], p[2]];
            observe::probe_sums(&self.model, &grid, point, &b, &unyielded)
        });
        let extremes = observe::extremes(&self.model, &self.a.positions, &self.a.vel_rho);
        Ok((sums.collect(), extremes))
    }

    fn stage_times(&self) -> Vec<StageTime> {
        (0..STAGES.len())
            .map(|k| {
                let lanes = if k == STAGE_FORCES {
                    self.lanes
                } else {
                    forces::LaneUse::default()
                };
                StageTime {
                    stage: STAGES[k],
                    seconds: self.seconds[k],
                    walk_seconds: self.walk_seconds[k],
                    particles: self.passed[k],
                    asleep: self.asleep[k],
                    lane_pairs: lanes.evaluated,
                    useful_pairs: lanes.useful,
                }
            })
            .collect()
    }

    fn count_lanes(&mut self, on: bool) {
        self.count_lanes = on;
    }
}

#[cfg(test)]
mod tests {
    use super::State;
    use super::grid::gather;

    /// Gathered into the buffers of an earlier copy, longer or shorter and holding other
    /// values, the state is what a gather slot by slot gives, every array the order's length.
    #[test]
    fn a_gather_into_used_buffers_is_a_fresh_one() {
        let n = 3000;
        let a = State {
            positions: (0..n).map(|k| [k as f32, 1.0, 2.0, 0.0]).collect(),
            vel_rho: (0..n).map(|k| [0.5, k as f32, 0.0, 1000.0]).collect(),
            ids: (0..n as u32).map(|k| (k * 7) % n as u32).collect(),
            vel_rho_prev: (0..n).map(|k| [0.0, 0.0, k as f32, 999.0]).collect(),
        };
        let order: Vec<u32> = (0..n as u32).map(|k| (k * 1237) % n as u32).collect();
        let junk = |len: usize| State {
            positions: vec![[-1.0; 4]; len],
            vel_rho: vec![[-2.0; 4]; len],
            ids: vec![u32::MAX; len],
            vel_rho_prev: vec![[-3.0; 4]; len],
        };
        for spare in [State::default(), junk(n + 500), junk(n / 3)] {
            let b = a.gather(&order, spare, n);
            assert_eq!(b.positions, gather(&a.positions, &order));
            assert_eq!(b.vel_rho, gather(&a.vel_rho, &order));
            assert_eq!(b.ids, gather(&a.ids, &order));
            assert_eq!(b.vel_rho_prev, gather(&a.vel_rho_prev, &order));
        }
    }

    /// Told that its slots from `kept` on hold their particles, a gather into buffers of the
    /// order's length leaves them be and writes the rest; into buffers of another length it
    /// writes every slot whatever it is told.
    #[test]
    fn a_gather_leaves_the_kept_slots_only_in_buffers_of_its_length() {
        let (n, kept) = (3000usize, 2000usize);
        let state = |shift: f32| State {
            positions: (0..n).map(|k| [k as f32 + shift, 1.0, 2.0, 0.0]).collect(),
            vel_rho: (0..n)
                .map(|k| [0.5, k as f32 + shift, 0.0, 1000.0])
                .collect(),
            ids: (0..n as u32)
                .map(|k| (k * 7 + (shift * 4.0) as u32) % n as u32)
                .collect(),
            vel_rho_prev: (0..n)
                .map(|k| [0.0, 0.0, k as f32 + shift, 999.0])
                .collect(),
        };
        let order: Vec<u32> = (0..n as u32)
            .map(|k| {
                if k < kept as u32 {
                    (k * 1237) % kept as u32
                } else {
                    k
                }
            })
            .collect();
        let fresh = |a: &State| a.gather(&order, State::default(), n);
        let (before, after) = (state(0.0), state(0.25));
        let b = after.gather(&order, fresh(&before), kept);
        let mut expected = fresh(&after);
        let tail = kept..n;
        expected.positions[tail.clone()].copy_from_slice(&before.positions[tail.clone()]);
        expected.vel_rho[tail.clone()].copy_from_slice(&before.vel_rho[tail.clone()]);
        expected.vel_rho_prev[tail.clone()].copy_from_slice(&before.vel_rho_prev[tail.clone()]);
        expected.ids[tail.clone()].copy_from_slice(&before.ids[tail]);
        assert_eq!(b.positions, expected.positions);
        assert_eq!(b.ids, expected.ids);
        assert_eq!(b.vel_rho, expected.vel_rho);
        assert_eq!(b.vel_rho_prev, expected.vel_rho_prev);
        let mut longer = fresh(&before);
        longer.positions.push([9.0; 4]);
        let b = after.gather(&order, longer, kept);
        assert_eq!(b.positions, fresh(&after).positions);
    }
}
