//! One SPH step as a fixed sequence of compute dispatches (start here).
//!
//! `SphPipeline` holds the compiled stages and no particle state; `GpuBuffers` holds the
//! state; `Bindings` ties the two together once, at setup. A step never reads back.
//!
//! An open flume's parked particles sort after every cell (`grid_count.wgsl`): the scan leaves
//! the count of active particles in `cell_starts[n_cells]`, `active_dispatch` turns it into
//! workgroup counts, and every pass after the sort is dispatched indirectly over the active
//! particles only; `parked_copy` carries the parked ones over into the next state.

use crate::gpu::GpuContext;
use crate::gpu::stage::{AsBinding, Stage, groups};
use crate::gpu::stages::{self, PREFIX_SUM_BLOCK};
use crate::gpu::state::{GpuBuffers, StateTextures};

/// Workgroup sizes `active_dispatch` counts the active particles in: the neighbour passes'
/// and the per-particle passes' (the integrators, `parked_copy`, `observe_reduce`).
const SMALL_GROUP: u32 = 64;
const LARGE_GROUP: u32 = 128;
/// Byte offsets of the three (x, y, z) workgroup counts `active_dispatch` writes into
/// `GpuBuffers::dispatch`: the active particles in small and large groups, the parked ones in
/// large groups.
const ACTIVE_SMALL: u64 = 0;
const ACTIVE_LARGE: u64 = 12;
const PARKED_LARGE: u64 = 24;
pub const DISPATCH_BYTES: u64 = 36;

/// Cells per kernel support 2h along each axis (see `shaders/common/neighbours.wgsl`): 1 or 2.
/// Smaller cells mean fewer candidates outside the support but a four (2-D) or eight (3-D)
/// times larger cell list; they pay off once a cell of 2h holds more than about ten
/// particles. Measured on lavapipe: the DualSPHysics case (2-D, h = 1.41 dp, 8 per cell)
/// 9.4e5 with cells of 2h against 7.0e5 with cells of h; the dam break (2-D, h = 1.70 dp,
/// 11.5 per cell) 3.9e5 against 4.6e5; the 3-D dam break (h = 2.08 dp, 72 per cell) 1.03e5
/// against 1.37e5 particle-steps/s.
pub fn cell_divisions(dim: u32, h_over_dp: f64) -> u32 {
    if (2.0 * h_over_dp).powi(dim as i32) > 10.0 {
        2
    } else {
        1
    }
}

pub struct SphPipeline {
    grid_clear: Stage,
    grid_count: Stage,
    prefix_sum: Stage,
    grid_scatter: Stage,
    cell_sort: Stage,
    active_dispatch: Stage,
    reorder: Stage,
    parked_copy: Stage,
    forces_predict: Stage,
    forces_correct: Stage,
    rheology_predict: Stage,
    rheology_correct: Stage,
    release_predict: Stage,
    release_correct: Stage,
    /// Viscous stress from the rheology pass before each force pass.
    multiphase: bool,
    /// Held sediment released by Drucker-Prager after each rheology pass.
    hold: bool,
    dt_update: Stage,
    symplectic_predictor: Stage,
    symplectic_corrector: Stage,
    verlet_update: Stage,
    /// Verlet (one force pass a step) rather than symplectic (two).
    verlet: bool,
    probe_interpolate: Stage,
    observe_reduce: Stage,
}

impl SphPipeline {
    pub fn new(
        gpu: &GpuContext,
        dim: u32,
        divisions: u32,
        verlet: bool,
        multiphase: bool,
        hold: bool,
    ) -> SphPipeline {
        let d = &gpu.device;
        let width = f64::from(2 * divisions + 1);
        let rows = if dim == 2 { width } else { width * width };
        let stencil = [
            ("STENCIL_ROWS", rows),
            ("CELL_DIVISIONS", f64::from(divisions)),
        ];
        SphPipeline {
            grid_clear: Stage::new(d, &stages::GRID_CLEAR, &[]),
            grid_count: Stage::new(d, &stages::GRID_COUNT, &[]),
            prefix_sum: Stage::new(d, &stages::PREFIX_SUM, &[]),
            grid_scatter: Stage::new(d, &stages::GRID_SCATTER, &[]),
            cell_sort: Stage::new(d, &stages::CELL_SORT, &[]),
            active_dispatch: Stage::new(
                d,
                &stages::ACTIVE_DISPATCH,
                &[
                    ("SMALL_GROUP", f64::from(SMALL_GROUP)),
                    ("LARGE_GROUP", f64::from(LARGE_GROUP)),
                ],
            ),
            parked_copy: Stage::new(d, &stages::PARKED_COPY, &[]),
            reorder: Stage::new(
                d,
                &stages::REORDER,
                &[("WITH_PREVIOUS", f64::from(u8::from(verlet)))],
            ),
            forces_predict: Stage::new(
                d,
                &stages::INTERACTION,
                &[stencil[0], stencil[1], ("REDUCE_DT", 1.0)],
            ),
            forces_correct: Stage::new(
                d,
                &stages::INTERACTION,
                &[stencil[0], stencil[1], ("REDUCE_DT", 0.0)],
            ),
            rheology_predict: Stage::new(
                d,
                &stages::RHEOLOGY,
                &[stencil[0], stencil[1], ("BEFORE_DT", 1.0)],
            ),
            rheology_correct: Stage::new(
                d,
                &stages::RHEOLOGY,
                &[stencil[0], stencil[1], ("BEFORE_DT", 0.0)],
            ),
            release_predict: Stage::new(
                d,
                &stages::HOLD,
                &[stencil[0], stencil[1], ("BEFORE_DT", 1.0)],
            ),
            release_correct: Stage::new(
                d,
                &stages::HOLD,
                &[stencil[0], stencil[1], ("BEFORE_DT", 0.0)],
            ),
            multiphase,
            hold,
            dt_update: Stage::new(d, &stages::DT_UPDATE, &[]),
            symplectic_predictor: Stage::new(d, &stages::SYMPLECTIC_PREDICTOR, &[]),
            symplectic_corrector: Stage::new(d, &stages::SYMPLECTIC_CORRECTOR, &[]),
            verlet_update: Stage::new(d, &stages::VERLET_UPDATE, &[]),
            verlet,
            probe_interpolate: Stage::new(d, &stages::PROBE_INTERPOLATE, &stencil),
            observe_reduce: Stage::new(d, &stages::OBSERVE_REDUCE, &[]),
        }
    }
}

pub struct Bindings {
    grid_clear: wgpu::BindGroup,
    grid_count: wgpu::BindGroup,
    scan: Vec<(wgpu::BindGroup, u32)>,
    grid_scatter: wgpu::BindGroup,
    cell_sort: wgpu::BindGroup,
    active_dispatch: wgpu::BindGroup,
    reorder: wgpu::BindGroup,
    parked_copy: wgpu::BindGroup,
    forces_predict: wgpu::BindGroup,
    forces_correct: wgpu::BindGroup,
    rheology_predict: wgpu::BindGroup,
    rheology_correct: wgpu::BindGroup,
    release_predict: wgpu::BindGroup,
    release_correct: wgpu::BindGroup,
    dt_update: wgpu::BindGroup,
    symplectic_predictor: wgpu::BindGroup,
    symplectic_corrector: wgpu::BindGroup,
    verlet_update: wgpu::BindGroup,
    probe_interpolate: wgpu::BindGroup,
    observe_reduce: wgpu::BindGroup,
    /// Where `active_dispatch` writes the indirect dispatch arguments.
    dispatch: wgpu::Buffer,
    n_particles: u32,
    n_cells: u32,
    n_probes: u32,
}

impl SphPipeline {
    pub fn bind(
        &self,
        gpu: &GpuContext,
        g: &GpuBuffers,
        n_particles: u32,
        n_cells: u32,
        n_probes: u32,
    ) -> Bindings {
        let d = &gpu.device;
        let mut scan = Vec::new();
        let mut data = &g.cell_starts;
        for (info, sums, len) in &g.scan_levels {
            scan.push((self.prefix_sum.bind(d, &[info, data, sums]), *len));
            data = sums;
        }
        let [grid_scatter, parked_copy, reorder] = self.bind_sort_copies(d, g);
        let [symplectic_predictor, symplectic_corrector, verlet_update] = self.bind_updates(d, g);
        let (predict, correct) = (pass_buffers(g, &g.b), pass_buffers(g, &g.c));
        Bindings {
            grid_clear: self
                .grid_clear
                .bind(d, &[&g.params, &g.cell_starts, &g.cell_cursor]),
            grid_count: self
                .grid_count
                .bind(d, &[&g.params, &g.a.positions, &g.cell_of, &g.cell_starts]),
            scan,
            grid_scatter,
            cell_sort: self
                .cell_sort
                .bind(d, &[&g.params, &g.cell_starts, &g.a.ids, &g.sorted_index]),
            active_dispatch: self
                .active_dispatch
                .bind(d, &[&g.params, &g.cell_starts, &g.dispatch]),
            parked_copy,
            reorder,
            forces_predict: self.forces_predict.bind(d, &predict),
            forces_correct: self.forces_correct.bind(d, &correct),
            rheology_predict: self.rheology_predict.bind(d, &rheology_buffers(g, &g.b)),
            release_predict: self.release_predict.bind(d, &rheology_buffers(g, &g.b)),
            rheology_correct: self.rheology_correct.bind(d, &rheology_buffers(g, &g.c)),
            release_correct: self.release_correct.bind(d, &rheology_buffers(g, &g.c)),
            dt_update: self.dt_update.bind(d, &[&g.params, &g.state]),
            symplectic_predictor,
            symplectic_corrector,
            verlet_update,
            probe_interpolate: self.probe_interpolate.bind(
                d,
                &[
                    &g.params,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.cell_starts,
                    &g.probe_points,
                    &g.probe_sums,
                    &g.b_ids,
                    &g.regions,
                ],
            ),
            observe_reduce: self.observe_reduce.bind(
                d,
                &[
                    &g.params,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.extremes,
                    &g.cell_starts,
                ],
            ),
            dispatch: g.dispatch.clone(),
            n_particles,
            n_cells,
            n_probes,
        }
    }

    /// The sort's copies between the states: the scatter into cells, the parked particles'
    /// copy and the reorder of `a` into `b`.
    fn bind_sort_copies(&self, d: &wgpu::Device, g: &GpuBuffers) -> [wgpu::BindGroup; 3] {
        [
            self.grid_scatter.bind(
                d,
                &[
                    &g.params,
                    &g.cell_of,
                    &g.cell_starts,
                    &g.cell_cursor,
                    &g.sorted_index,
                ],
            ),
            self.parked_copy.bind(
                d,
                &[
                    &g.params,
                    &g.state,
                    &g.cell_starts,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.b_ids,
                    &g.a.positions,
                    &g.a.vel_rho,
                    &g.a.ids,
                    &g.a.vel_rho_prev,
                    &g.regions,
                ],
            ),
            self.reorder.bind(
                d,
                &[
                    &g.params,
                    &g.sorted_index,
                    &g.a.positions,
                    &g.a.vel_rho,
                    &g.a.ids,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.b_ids,
                    &g.a.vel_rho_prev,
                    &g.b_vel_rho_prev,
                ],
            ),
        ]
    }

    /// The integrators' updates: the symplectic predictor and corrector, and Verlet's step.
    fn bind_updates(&self, d: &wgpu::Device, g: &GpuBuffers) -> [wgpu::BindGroup; 3] {
        [
            self.symplectic_predictor.bind(
                d,
                &[
                    &g.params,
                    &g.state,
                    &g.forces,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.c.positions,
                    &g.c.vel_rho,
                    &g.regions,
                    &g.b_ids,
                    &g.cell_starts,
                ],
            ),
            self.symplectic_corrector.bind(
                d,
                &[
                    &g.params,
                    &g.state,
                    &g.forces,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.b_ids,
                    &g.c.vel_rho,
                    &g.a.positions,
                    &g.a.vel_rho,
                    &g.a.ids,
                    &g.regions,
                    &g.cell_starts,
                ],
            ),
            self.verlet_update.bind(
                d,
                &[
                    &g.params,
                    &g.state,
                    &g.forces,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.b_ids,
                    &g.b_vel_rho_prev,
                    &g.a.positions,
                    &g.a.vel_rho,
                    &g.a.ids,
                    &g.a.vel_rho_prev,
                    &g.regions,
                    &g.cell_starts,
                ],
            ),
        ]
    }

    /// Neighbour search: counting sort of state `a` into cells (an open flume's parked
    /// particles after them all), copied in cell order into `b`; then the workgroup counts of
    /// the passes over the active particles.
    pub fn record_sort(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings) {
        let n = b.n_particles;
        let cells = b.n_cells + 1;
        self.grid_clear.record_items(pass, 0, &b.grid_clear, cells);
        self.grid_count.record_items(pass, 0, &b.grid_count, n);
        // Exclusive scan of the counts into cell starts, level by level, then added back down.
        for (bind, len) in &b.scan {
            self.prefix_sum
                .record(pass, 0, bind, groups(*len, PREFIX_SUM_BLOCK));
        }
        for (bind, len) in b.scan.iter().rev().skip(1) {
            self.prefix_sum
                .record(pass, 1, bind, groups(*len, PREFIX_SUM_BLOCK));
        }
        self.active_dispatch.record(pass, 0, &b.active_dispatch, 1);
        self.grid_scatter.record_items(pass, 0, &b.grid_scatter, n);
        // The parked particles' order after the cells is left to thread timing: nothing sums
        // over them, and the host picks them by id (`inlet_scan.wgsl`).
        self.cell_sort
            .record_items(pass, 0, &b.cell_sort, b.n_cells);
        self.reorder.record_items(pass, 0, &b.reorder, n);
    }

    /// Records `stage` over the active particles, in the workgroups `active_dispatch` counted.
    fn record_active(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        b: &Bindings,
        stage: &Stage,
        bind: &wgpu::BindGroup,
    ) {
        let offset = match stage.spec.workgroup {
            SMALL_GROUP => ACTIVE_SMALL,
            LARGE_GROUP => ACTIVE_LARGE,
            other => unreachable!(
                "{} has workgroups of {other}: active_dispatch counts in {SMALL_GROUP} and {LARGE_GROUP}",
                stage.spec.name
            ),
        };
        stage.record_indirect(pass, 0, bind, &b.dispatch, offset);
    }

    /// One step: sort, (rheology and) forces at n, dt, then either the symplectic predictor,
    /// (rheology and) forces at n + 1/2 and corrector, or the Verlet update (both as in
    /// DualSPHysics), each over the active particles; the parked ones are copied over as they are.
    pub fn record_step(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings) {
        self.record_sort(pass, b);
        self.record_rheology(pass, b, true);
        self.record_active(pass, b, &self.forces_predict, &b.forces_predict);
        self.dt_update.record_items(pass, 0, &b.dt_update, 1);
        // After dt_update: on an idle step it must leave the state alone, as the integrators do.
        self.parked_copy
            .record_indirect(pass, 0, &b.parked_copy, &b.dispatch, PARKED_LARGE);
        if self.verlet {
            self.record_active(pass, b, &self.verlet_update, &b.verlet_update);
        } else {
            self.record_active(pass, b, &self.symplectic_predictor, &b.symplectic_predictor);
            self.record_rheology(pass, b, false);
            self.record_active(pass, b, &self.forces_correct, &b.forces_correct);
            self.record_active(pass, b, &self.symplectic_corrector, &b.symplectic_corrector);
        }
    }

    /// The rheology pass and the release of held sediment, on the state at n (`predict`) or
    /// at n + 1/2, when the case has them.
    fn record_rheology(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings, predict: bool) {
        if !self.multiphase {
            return;
        }
        let (rheology, bind) = if predict {
            (&self.rheology_predict, &b.rheology_predict)
        } else {
            (&self.rheology_correct, &b.rheology_correct)
        };
        self.record_active(pass, b, rheology, bind);
        if self.hold {
            let (release, bind) = if predict {
                (&self.release_predict, &b.release_predict)
            } else {
                (&self.release_correct, &b.release_correct)
            };
            self.record_active(pass, b, release, bind);
        }
    }

    /// Forces at the current state only (no integration): for tests against the CPU oracle.
    pub fn record_forces(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings) {
        self.record_sort(pass, b);
        self.record_rheology(pass, b, true);
        self.record_active(pass, b, &self.forces_predict, &b.forces_predict);
    }

    /// Observation passes: probe sums on the sorted state and the maxima over its active
    /// particles.
    pub fn record_observe(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings) {
        self.record_sort(pass, b);
        self.probe_interpolate
            .record_items(pass, 0, &b.probe_interpolate, b.n_probes);
        self.record_active(pass, b, &self.observe_reduce, &b.observe_reduce);
    }
}

/// The force pass's buffers over the neighbours of state `s`: the parameters, `s`, the cells,
/// the forces, the step's state and the stress textures.
fn pass_buffers<'a>(g: &'a GpuBuffers, s: &'a StateTextures) -> [&'a dyn AsBinding; 8] {
    [
        &g.params,
        &s.positions,
        &s.vel_rho,
        &g.cell_starts,
        &g.forces,
        &g.state,
        &g.stress_a,
        &g.stress_b,
    ]
}

/// The rheology's and the release's buffers over the neighbours of state `s`, whose ids are
/// `b_ids` (the passes read the sorted states only).
fn rheology_buffers<'a>(g: &'a GpuBuffers, s: &'a StateTextures) -> [&'a dyn AsBinding; 9] {
    [
        &g.params,
        &s.positions,
        &s.vel_rho,
        &g.cell_starts,
        &g.state,
        &g.stress_a,
        &g.stress_b,
        &g.regions,
        &g.b_ids,
    ]
}
