//! One step of the CPU backend, in the order of `SphPipeline::record_step`: sort, forces at n,
//! the time step, then the Verlet update, or the symplectic predictor, forces at n + 1/2 and
//! corrector. The particle formulas are `physics::integrate`'s; `store` is the CPU side of
//! `store_state.wgsl` for a closed tank, and `dt_update` mirrors `dt_update.wgsl`.

use super::forces::{force_pass, min_dt};
use super::grid::Grid;
use super::{CpuEngine, State};
use crate::gpu::params::{SimParams, StepState};
use crate::health::Health;
use crate::physics::integrate::{Particle, correct, predict, verlet_step};
use crate::physics::interaction::{PairModel, Side, phase_index};
use crate::physics::{Params, Phase};
use rayon::prelude::*;
use std::time::Instant;

impl CpuEngine {
    /// Forces and stable steps of particles in sorted order, their cells from `grid`.
    pub(super) fn force_pass(
        &self,
        grid: &Grid,
        positions: &[[f32; 4]],
        vel_rho: &[[f32; 4]],
    ) -> (Vec<[f32; 4]>, Vec<f32>) {
        let model = PairModel::new(&self.model);
        let sides: Vec<Side> = self.pool.install(|| {
            positions
                .par_iter()
                .zip(vel_rho)
                .map(|(p, v)| model.side(p, v))
                .collect()
        });
        let n = positions.len();
        let (mut forces, mut dt_limit) = (vec![[0.0; 4]; n], vec![0.0; n]);
        force_pass(&self.pool, &model, grid, &sides, &mut forces, &mut dt_limit);
        (forces, dt_limit)
    }

    /// One step; false once the chunk has no more to do (its time reached, or a health flag
    /// raised), as the GPU's idle steps past the end of a chunk.
    pub(super) fn step(&mut self, st: &mut StepState) -> bool {
        let start = Instant::now();
        let mut grid = self.grid();
        let b = self.a.gather(&grid.sort(&self.a.positions, &self.a.ids));
        self.timed(0, start);
        let start = Instant::now();
        let mut forces = Vec::new();
        if st.t_rel < st.t_target && st.status == 0 {
            let dt_limit;
            (forces, dt_limit) = self.force_pass(&grid, &b.positions, &b.vel_rho);
            let stable = f32::from_bits(st.dt_min_bits).min(min_dt(&dt_limit));
            st.dt_min_bits = stable.to_bits();
        }
        self.timed(1, start);
        dt_update(&self.params, st);
        if st.dt == 0.0 {
            return false;
        }
        if self.shape.verlet {
            let start = Instant::now();
            self.verlet(st, b, &forces);
            self.timed(2, start);
        } else {
            self.symplectic(st, &grid, b, &forces);
        }
        st.status == 0
    }

    fn verlet(&mut self, st: &mut StepState, b: State, forces: &[[f32; 4]]) {
        // dt_update has counted this step already.
        let euler = (st.step_base + st.steps - 1).is_multiple_of(self.params.euler_every.max(1));
        let (dt, dt_prev) = (st.dt, st.dt_prev);
        let store = Store::new(&self.params, &self.model);
        let phases = &self.model.phases;
        let mut next = State {
            positions: vec![[0.0; 4]; b.ids.len()],
            vel_rho: vec![[0.0; 4]; b.ids.len()],
            ids: Vec::new(),
            vel_rho_prev: Vec::new(),
        };
        let flags = self.pool.install(|| {
            (next.positions.par_iter_mut(), next.vel_rho.par_iter_mut())
                .into_par_iter()
                .enumerate()
                .map(|(i, (x_out, v_out))| {
                    let (x, v) = (&b.positions[i], &b.vel_rho[i]);
                    let phase = &phases[phase_index(x)];
                    let moved = verlet_step(
                        phase,
                        dt,
                        dt_prev,
                        euler,
                        x,
                        v,
                        &b.vel_rho_prev[i],
                        &forces[i],
                    );
                    let flags;
                    ((*x_out, *v_out), flags) = store.apply(phase, moved);
                    flags
                })
                .reduce(|| 0, |a, b| a | b)
        });
        st.status |= flags;
        next.ids = b.ids;
        next.vel_rho_prev = b.vel_rho;
        self.a = next;
    }

    fn symplectic(&mut self, st: &mut StepState, grid: &Grid, b: State, forces: &[[f32; 4]]) {
        let start = Instant::now();
        let dt = st.dt;
        let store = Store::new(&self.params, &self.model);
        let phases = &self.model.phases;
        let half: Vec<Particle> = self.pool.install(|| {
            (0..b.ids.len())
                .into_par_iter()
                .map(|i| {
                    let phase = &phases[phase_index(&b.positions[i])];
                    let (x, mut v) = predict(phase, dt, &b.positions[i], &b.vel_rho[i], &forces[i]);
                    if phase.mobile && store.clamp {
                        v[3] = v[3].max(phase.rho0);
                    }
                    (x, v)
                })
                .collect()
        });
        let (x_half, v_half): (Vec<[f32; 4]>, Vec<[f32; 4]>) = half.into_iter().unzip();
        self.timed(2, start);
        let start = Instant::now();
        let (forces_half, _) = self.force_pass(grid, &x_half, &v_half);
        self.timed(1, start);
        let start = Instant::now();
        let phases = &self.model.phases;
        let (moved, flags): (Vec<Particle>, Vec<u32>) = self.pool.install(|| {
            (0..b.ids.len())
                .into_par_iter()
                .map(|i| {
                    let (x, v) = (&b.positions[i], &b.vel_rho[i]);
                    let phase = &phases[phase_index(x)];
                    store.apply(
                        phase,
                        correct(phase, dt, x, v, v_half[i][3], &forces_half[i]),
                    )
                })
                .unzip()
        });
        st.status |= flags.iter().fold(0, |a, f| a | f);
        let (positions, vel_rho) = moved.into_iter().unzip();
        self.a = State {
            positions,
            vel_rho,
            ids: b.ids,
            vel_rho_prev: b.vel_rho_prev,
        };
        self.timed(2, start);
    }
}

/// The end of a step for a closed tank (`store_state.wgsl`): without tension a free
/// particle's density never falls below rest; its new state raises the health flags.
struct Store {
    clamp: bool,
    rho_ratio_max: f32,
}

impl Store {
    fn new(params: &SimParams, model: &Params) -> Store {
        Store {
            clamp: model.clamp_negative_pressure,
            rho_ratio_max: params.rho_ratio_max,
        }
    }

    /// The particle as stored, and the health flags it raises (walls raise none).
    fn apply(&self, phase: &Phase, (x, mut v): Particle) -> (Particle, u32) {
        if !phase.mobile {
            return ((x, v), 0);
        }
        if self.clamp {
            v[3] = v[3].max(phase.rho0);
        }
        let s = x[0] * x[0]
            + x[1] * x[1]
            + x[2] * x[2]
            + v[0] * v[0]
            + v[1] * v[1]
            + v[2] * v[2]
            + v[3];
        // Infinities (and sums near them) exceed the bound of store_state.wgsl.
        let flags = if s.is_nan() || s.abs() > 3.0e38 {
            Health::NON_FINITE
        } else if (v[3] / phase.rho0 - 1.0).abs() > self.rho_ratio_max {
            Health::DENSITY_RUNAWAY
        } else {
            0
        };
        ((x, v), flags)
    }
}

/// The variable time step of `dt_update.wgsl`: dt = CFL min(dt_force, dt_sound, dt_visc),
/// landing exactly on the chunk's target time; zero once the chunk is over.
pub fn dt_update(params: &SimParams, st: &mut StepState) {
    let stable = f32::from_bits(st.dt_min_bits);
    st.dt_min_bits = f32::MAX.to_bits();
    let mut dt = params.cfl * stable.min(params.dt_visc);
    let remaining = st.t_target - st.t_rel;
    if st.status != 0 || remaining <= 0.0 {
        st.dt = 0.0;
        return;
    }
    // NaN is a collapse too.
    if dt.is_nan() || dt < params.dt_min {
        st.status |= Health::DT_COLLAPSE;
        st.dt = 0.0;
        return;
    }
    st.last_dt = dt;
    let mut t_next = st.t_rel + dt;
    if dt >= remaining {
        dt = remaining;
        t_next = st.t_target;
    } else if 2.0 * dt > remaining {
        // Two equal steps rather than a full one and a sliver.
        dt = 0.5 * remaining;
        t_next = st.t_rel + dt;
    }
    st.dt = dt;
    st.dt_prev = st.dt_taken;
    st.dt_taken = dt;
    st.t_rel = t_next;
    st.steps += 1;
}
