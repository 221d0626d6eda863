//! One step of the CPU backend, in the order of `SphPipeline::record_step`: sort, (rheology,
//! release and) forces at n, the time step, then the Verlet update, or the symplectic
//! predictor, (rheology, release and) forces at n + 1/2 and corrector. The particle formulas
//! are `physics::integrate`'s; `store.rs` ends each particle's step, and `dt_update` mirrors
//! `dt_update.wgsl`.

use super::forces::{Extra, force_pass, lane_use, min_dt, wakes};
use super::grid::{Flagged, Grid};
use super::multiphase::{Holds, RheologyPass, rheology_pass};
use super::store::{Event, Store, tally};
use super::{CpuEngine, STAGE_FORCES, STAGE_INTEGRATE, STAGE_RHEOLOGY, STAGE_SORT, State};
use crate::contract::{SimParams, StepState};
use crate::health::Health;
use crate::physics::integrate::{Particle, bed_wall, correct, predict, verlet_step};
use crate::physics::interaction::{PairModel, Side};
use crate::physics::sediment::pass::{Draws, ParticleRheology};
use crate::physics::sediment::stress::{StressDivergence, StressSide};
use crate::physics::timestep::{NextStep, next_step};
use rayon::prelude::*;
use std::time::Instant;

/// Particles per block handed to a thread in the passes over each particle.
const BLOCK: usize = 64;

/// The force pass's sides of each active particle, kept from one pass to the next: filling
/// memory a pass has just used spares the allocator's zeroing of fresh memory.
#[derive(Default)]
pub(super) struct SideBuffers {
    sides: Vec<Side>,
    imposed: Vec<bool>,
    stress: Vec<StressSide>,
    mu: Vec<f32>,
}

/// What a force pass leaves the integrator, for each active particle (sorted order).
#[derive(Default)]
pub(super) struct ForcePass {
    pub forces: Vec<[f32; 4]>,
    /// The stable step each particle allows.
    pub dt_limit: Vec<f32>,
    /// Whether its rheology pass held the particle; empty without the multiphase model.
    held: Vec<bool>,
}

impl ForcePass {
    /// Whether active particle `i` is held.
    fn held(&self, i: usize) -> bool {
        self.held.get(i).is_some_and(|&h| h)
    }
}

impl SideBuffers {
    /// Fills the buffers with the sides of the first `active` particles at `pos`, `vel` (sorted
    /// order) as the force pass's pairs see them: with the holds and stresses of their
    /// `rheology`, if the model has one. The stress sides go in the same parallel region as
    /// the pair sides: a region costs a step more than its work at CI size (README, speed).
    /// Each block writes its slots in place: an `unzip` joins the threads' pieces on one
    /// thread. Runs on the engine's pool.
    fn fill(
        &mut self,
        (params, physics): (&SimParams, &crate::physics::Params),
        (model, div): (&PairModel, &StressDivergence),
        (active, pos, vel): (usize, &[[f32; 4]], &[[f32; 4]]),
        rheology: Option<&[ParticleRheology]>,
    ) {
        let store = Store::new(params, physics);
        let bed_walls = params.held_bed_is_wall();
        let shields_only = params.sediment.shields_only != 0;
        let side_of = |i: usize| {
            let imposed = store.velocity_imposed(&pos[i]);
            let side = model.side(&pos[i], &vel[i]);
            // The Shields-only mode's held bed stands as a wall does (`physics::boundary`), or
            // is fixed where it stands.
            let held = rheology.is_some_and(|r| r[i].held);
            let side = Side {
                imposed,
                mobile: side.mobile && !(bed_walls && held),
                fixed: side.mobile && held && !bed_walls && shields_only,
                ..side
            };
            (side, imposed)
        };
        let SideBuffers {
            sides,
            imposed,
            stress,
            mu,
        } = self;
        sides.resize(active, Side::default());
        imposed.resize(active, false);
        stress.resize(
            if rheology.is_some() { active } else { 0 },
            StressSide::default(),
        );
        mu.resize(stress.len(), 0.0);
        let pair_sides = |b: usize, sides: &mut [Side], imposed: &mut [bool]| {
            for (k, i) in (b * BLOCK..).take(sides.len()).enumerate() {
                (sides[k], imposed[k]) = side_of(i);
            }
        };
        let own = sides
            .par_chunks_mut(BLOCK)
            .zip(imposed.par_chunks_mut(BLOCK));
        match rheology {
            None => own
                .enumerate()
                .for_each(|(b, (sides, imposed))| pair_sides(b, sides, imposed)),
            Some(r) => {
                let theirs = stress.par_chunks_mut(BLOCK).zip(mu.par_chunks_mut(BLOCK));
                let blocks = own.zip(theirs).enumerate();
                blocks.for_each(|(b, ((sides, imposed), (stress, mu)))| {
                    pair_sides(b, sides, imposed);
                    for (k, i) in (b * BLOCK..).take(stress.len()).enumerate() {
                        stress[k] = div.side(&pos[i], vel[i][3], &r[i].stress);
                        mu[k] = r[i].mu;
                    }
                });
            }
        }
    }
}

impl CpuEngine {
    /// Sorts the state into cells: the sorted copy and its grid.
    pub(super) fn sorted(&self) -> (Grid, State) {
        self.sorted_into(State::default(), self.a.positions.len())
    }

    /// [`CpuEngine::sorted`] into the buffers of `spare`, whose slots from `kept` on hold
    /// their particles already.
    fn sorted_into(&self, spare: State, kept: usize) -> (Grid, State) {
        let mut grid = self.grid();
        let (a, parked) = (&self.a, self.parked_phase());
        let order = grid.sort(&a.positions, &a.ids, parked, self.still);
        (grid, a.gather(&order, spare, kept))
    }

    /// The region word the last rheology pass left each mobile particle of the first
    /// `active` of `b` (sorted order); 0 for the others.
    fn words(&self, b: &State, active: usize) -> Vec<u32> {
        let words = b.positions[..active].iter().zip(&b.ids);
        words.map(|(x, &id)| self.word(x, id)).collect()
    }

    /// The region word of particle `id` at `x`: the last rheology pass's if its phase is
    /// mobile, else 0.
    fn word(&self, x: &[f32; 4], id: u32) -> u32 {
        let mobile = self.model.phases[x[3].to_bits() as usize].mobile;
        if mobile {
            self.by_id.regions[id as usize]
        } else {
            0
        }
    }

    /// (Rheology and release, then) forces and stable steps of the active particles of `b`
    /// at positions `pos`, velocities `vel` (sorted order), cells from `grid`.
    pub(super) fn force_pass(
        &mut self,
        grid: &Grid,
        b: &State,
        (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
        draws: Option<Draws>,
    ) -> ForcePass {
        let active = grid.active() as usize;
        let start = Instant::now();
        let rheology = self.rheology(grid, b, (pos, vel), draws);
        self.timed(STAGE_RHEOLOGY, start);
        let start = Instant::now();
        let model = PairModel::new(&self.model);
        let div = StressDivergence::new(&self.model);
        let mut buffers = std::mem::take(&mut self.side_buffers);
        let rheology_out = rheology.as_ref().map(|r| r.out.as_slice());
        let (params, physics) = (&self.params, &self.model);
        let by_id = &mut self.by_id;
        // The stores by id are serial: they run while the other threads fill the sides.
        let ((), held) = self.pool.install(|| {
            rayon::join(
                || {
                    let sides = (&model, &div);
                    buffers.fill((params, physics), sides, (active, pos, vel), rheology_out);
                },
                || {
                    let pass = rheology.as_ref()?;
                    by_id.keep(pass, &b.ids, active);
                    // Read from the pass rather than from the words it stored by id: the
                    // same flags.
                    Some(pass.out.iter().map(|r| r.held).collect())
                },
            )
        });
        let multiphase = rheology.is_some();
        let SideBuffers {
            sides,
            imposed,
            stress,
            mu,
        } = &buffers;
        let waking = self
            .awake_set
            .then(|| Flagged::new(active, |k| wakes(&sides[k])));
        let extra = Extra {
            stress: multiphase.then_some((&div, stress.as_slice(), mu.as_slice())),
            imposed,
            waking: waking.as_ref(),
        };
        let (mut forces, mut dt_limit) = (vec![[0.0; 4]; active], vec![0.0; active]);
        let walk = Instant::now();
        let asleep = force_pass(
            &self.pool,
            &model,
            grid,
            sides,
            &extra,
            &mut forces,
            &mut dt_limit,
        );
        self.walk_seconds[STAGE_FORCES] += walk.elapsed().as_secs_f64();
        let lanes = self
            .count_lanes
            .then(|| lane_use(&self.pool, &model, grid, sides, &extra));
        self.count(STAGE_FORCES, active, asleep);
        self.timed(STAGE_FORCES, start);
        if let Some(lanes) = lanes {
            self.lanes.evaluated += lanes.evaluated;
            self.lanes.useful += lanes.useful;
        }
        self.side_buffers = buffers;
        ForcePass {
            forces,
            dt_limit,
            held: held.unwrap_or_default(),
        }
    }

    /// The rheology (and release) of the active particles of `b`, None without the
    /// multiphase model; what it leaves them is the caller's to keep by id
    /// ([`ById::keep`](super::by_id::ById::keep)).
    fn rheology(
        &mut self,
        grid: &Grid,
        b: &State,
        (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
        draws: Option<Draws>,
    ) -> Option<RheologyPass> {
        let active = grid.active() as usize;
        let model = self.sediment.as_ref()?;
        let words = self.words(b, active);
        let holds = Holds {
            words: &words,
            ids: &b.ids[..active],
            fluxes: &self.by_id.fluxes,
            draws,
            awake_set: self.awake_set,
            bed_tops: &self.by_id.bed_tops,
            records: &self.by_id.records,
            dry_before: &self.by_id.dry,
        };
        let release = self.shape.hold;
        let (params, pool) = (&self.model, &self.pool);
        let pass = rheology_pass(pool, params, model, grid, pos, vel, &holds, release);
        self.count(STAGE_RHEOLOGY, active, pass.asleep);
        self.walk_seconds[STAGE_RHEOLOGY] += pass.walk_s;
        Some(pass)
    }

    /// One step; false once the chunk has no more to do (its time reached, or a health flag
    /// raised), as the GPU's idle steps past the end of a chunk.
    pub(super) fn step(&mut self, st: &mut StepState) -> bool {
        let start = Instant::now();
        let spare = std::mem::take(&mut self.spare);
        let (grid, b) = self.sorted_into(spare, self.still);
        self.timed(STAGE_SORT, start);
        let mut pass = ForcePass::default();
        if st.t_rel < st.t_target && st.status == 0 {
            // The pass before the step's size is chosen draws the pick-ups, one draw a step.
            let draws = Draws {
                step: st.run_steps.wrapping_add(st.steps),
                dt_s: st.dt_taken,
            };
            pass = self.force_pass(&grid, &b, (&b.positions, &b.vel_rho), Some(draws));
            let stable = f32::from_bits(st.dt_min_bits).min(min_dt(&pass.dt_limit));
            st.dt_min_bits = stable.to_bits();
        }
        dt_update(&self.params, st);
        if st.dt == 0.0 {
            return false;
        }
        if self.shape.verlet {
            let start = Instant::now();
            self.verlet(st, &grid, b, &pass);
            self.timed(STAGE_INTEGRATE, start);
        } else {
            self.symplectic(st, &grid, b, &pass);
        }
        st.status == 0
    }

    fn verlet(&mut self, st: &mut StepState, grid: &Grid, b: State, pass: &ForcePass) {
        // dt_update has counted this step already.
        let euler = (st.step_base + st.steps - 1).is_multiple_of(self.params.euler_every.max(1));
        let (dt, dt_prev) = (st.dt, st.dt_prev);
        let store = Store::new(&self.params, &self.model);
        let bed_walls = self.bed_is_boundary();
        let buffers = std::mem::take(&mut self.a);
        let (next, held_parked) = Self::store_all(&self.pool, st, (buffers, self.still), |i| {
            let (x, v) = (&b.positions[i], &b.vel_rho[i]);
            let Some(f) = pass.forces.get(i) else {
                // Parked: out of the flow, kept as it is.
                return ((*x, *v), b.vel_rho_prev[i], Event::default());
            };
            let held = pass.held(i);
            let phase = store.phase(x);
            let moved = if bed_walls && held {
                bed_wall(phase, x, f)
            } else {
                verlet_step(phase, dt, dt_prev, euler, x, v, &b.vel_rho_prev[i], f)
            };
            let (out, event) = store.apply(b.ids[i], x, v, held, dt, moved);
            // Held sediment is at rest in both of the leapfrog's sequences.
            let prev = if held { [0.0, 0.0, 0.0, v[3]] } else { *v };
            (out, prev, event)
        });
        self.a_after(b, next, grid.active() as usize);
        self.forget_records(held_parked);
    }

    fn symplectic(&mut self, st: &mut StepState, grid: &Grid, b: State, pass: &ForcePass) {
        let start = Instant::now();
        let dt = st.dt;
        let store = Store::new(&self.params, &self.model);
        let bed_walls = self.bed_is_boundary();
        let half: Vec<Particle> = self.pool.install(|| {
            (0..b.ids.len())
                .into_par_iter()
                .map(|i| {
                    let (x, v) = (&b.positions[i], &b.vel_rho[i]);
                    let Some(f) = pass.forces.get(i) else {
                        return (*x, *v);
                    };
                    let held = pass.held(i);
                    let free = if bed_walls && held {
                        bed_wall(store.phase(x), x, f)
                    } else {
                        predict(store.phase(x), dt, x, v, f)
                    };
                    store.half_step(x, v, held, 0.5 * dt, free)
                })
                .collect()
        });
        let (x_half, v_half): (Vec<[f32; 4]>, Vec<[f32; 4]>) = half.into_iter().unzip();
        self.timed(STAGE_INTEGRATE, start);
        // The corrector's rheology pass sets the holds again.
        let half = self.force_pass(grid, &b, (&x_half, &v_half), None);
        let start = Instant::now();
        let store = Store::new(&self.params, &self.model);
        let bed_walls = self.bed_is_boundary();
        let buffers = std::mem::take(&mut self.a);
        let (next, held_parked) = Self::store_all(&self.pool, st, (buffers, self.still), |i| {
            let (x, v) = (&b.positions[i], &b.vel_rho[i]);
            let Some(f) = half.forces.get(i) else {
                return ((*x, *v), b.vel_rho_prev[i], Event::default());
            };
            let held = half.held(i);
            let moved = if bed_walls && held {
                bed_wall(store.phase(x), x, f)
            } else {
                correct(store.phase(x), dt, x, v, v_half[i][3], f)
            };
            let (out, event) = store.apply(b.ids[i], x, v, held, dt, moved);
            (out, b.vel_rho_prev[i], event)
        });
        self.a_after(b, next, grid.active() as usize);
        self.forget_records(held_parked);
        self.timed(STAGE_INTEGRATE, start);
    }

    /// Whether held sediment stands as a wall: the paper's Shields-only mode holds it as
    /// boundary particles, and under the generalised wall condition it takes the fluid's
    /// pressure as the walls do (`physics::boundary`). Drucker-Prager's held sand carries the
    /// bed's own stress and keeps its density by continuity.
    fn bed_is_boundary(&self) -> bool {
        self.params.held_bed_is_wall()
    }

    /// Stores each particle (`store_one(i)`: where it goes, its velocity of the step
    /// before and what storing it did), in parallel, straight into the state that follows
    /// (the buffers of the state before, whose sorted copy the step read), up to slot
    /// `still`: the parked ones after it are there already. The events, rare, are tallied in
    /// sorted order. The state's ids are left to the caller. Returns it, and whether a held
    /// grain was parked.
    fn store_all(
        pool: &rayon::ThreadPool,
        st: &mut StepState,
        (mut next, still): (State, usize),
        store_one: impl Fn(usize) -> (Particle, [f32; 4], Event) + Sync,
    ) -> (State, bool) {
        let still = still.min(next.positions.len());
        let events: Vec<Event> = pool.install(|| {
            let out = next.positions[..still].par_iter_mut();
            let out = out.zip(&mut next.vel_rho[..still]);
            out.zip(&mut next.vel_rho_prev[..still])
                .enumerate()
                .filter_map(|(i, ((x, v), prev))| {
                    let ((x_new, v_new), prev_new, event) = store_one(i);
                    (*x, *v, *prev) = (x_new, v_new, prev_new);
                    event.happened().then_some(event)
                })
                .collect()
        });
        tally(st, &events);
        (next, events.iter().any(|e| e.held_parked))
    }

    /// Makes `next` (with the ids of `b`, whose order it was stored in) the state, and keeps
    /// what is left of both as the next sort's buffers. The parked particles, from slot
    /// `active` of the sort on, are then alike in both: with the awake set, the next sort
    /// keeps them in place.
    fn a_after(&mut self, b: State, mut next: State, active: usize) {
        // The slots the sort kept held the same ids before and after it; those the newly
        // parked took did not.
        let moved = active..self.still.min(b.ids.len()).max(active);
        next.ids[moved.clone()].copy_from_slice(&b.ids[moved]);
        self.spare = State { ids: next.ids, ..b };
        self.a = State { ids: b.ids, ..next };
        // Without the awake set every particle is sorted and stored in full.
        self.still = if self.awake_set {
            active
        } else {
            self.a.positions.len()
        };
    }

    /// After a held grain was parked, no record bounds a kernel mass it was in
    /// (`multiphase::deep`).
    fn forget_records(&mut self, held_parked: bool) {
        if held_parked {
            self.by_id.forget_records();
        }
    }
}

/// The variable time step of `dt_update.wgsl` ([`next_step`]); the step is zero once the chunk
/// is over.
pub fn dt_update(params: &SimParams, st: &mut StepState) {
    let stable = f32::from_bits(st.dt_min_bits);
    st.dt_min_bits = f32::MAX.to_bits();
    let next = next_step(
        params.cfl,
        stable,
        params.dt_visc,
        params.dt_min,
        st.t_rel,
        st.t_target,
        st.status != 0,
    );
    match next {
        NextStep::Stop => st.dt = 0.0,
        NextStep::Collapse => {
            st.status |= Health::DT_COLLAPSE;
            st.dt = 0.0;
        }
        NextStep::Step { dt, t_next, cfl_dt } => {
            st.last_dt = cfl_dt;
            st.dt = dt;
            st.dt_prev = st.dt_taken;
            st.dt_taken = dt;
            st.t_rel = t_next;
            st.steps += 1;
        }
    }
}
