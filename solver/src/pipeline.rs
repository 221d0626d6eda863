//! One SPH step as a fixed sequence of compute dispatches (start here).
//!
//! `SphPipeline` holds the compiled stages and no particle state; `GpuBuffers` holds the
//! state; `Bindings` ties the two together once, at setup. A step never reads back.

use crate::gpu::buffers::{particle_texture, storage};
use crate::gpu::params::{ScanInfo, StepState};
use crate::gpu::stage::{Stage, groups};
use crate::gpu::{GpuContext, GpuError};
use crate::stages::{self, PREFIX_SUM_BLOCK};

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
    reorder: Stage,
    forces_predict: Stage,
    forces_correct: Stage,
    rheology_predict: Stage,
    rheology_correct: Stage,
    release_predict: Stage,
    release_correct: Stage,
    /// Viscous stress from the rheology pass before each force pass.
    multiphase: bool,
    /// Held sediment released by Drucker-Prager after each rheology pass.
    yield_release: bool,
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
        yield_release: bool,
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
            reorder: Stage::new(
                d,
                &stages::REORDER,
                &[("WITH_PREVIOUS", f64::from(u8::from(verlet)))],
            ),
            forces_predict: Stage::new(
                d,
                &stages::FORCES_WCSPH,
                &[stencil[0], stencil[1], ("REDUCE_DT", 1.0)],
            ),
            forces_correct: Stage::new(
                d,
                &stages::FORCES_WCSPH,
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
                &stages::YIELD_RELEASE,
                &[stencil[0], stencil[1], ("BEFORE_DT", 1.0)],
            ),
            release_correct: Stage::new(
                d,
                &stages::YIELD_RELEASE,
                &[stencil[0], stencil[1], ("BEFORE_DT", 0.0)],
            ),
            multiphase,
            yield_release,
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

/// Rows of the particle textures are 2^TEXEL_ROW_SHIFT texels wide; mirrors the WGSL constant
/// of the same name in `shaders/common/particle_texture.wgsl` (checked by `shaders_validate`).
pub const TEXEL_ROW_SHIFT: u32 = 11;

/// Particle state and scratch, all resident on the GPU. `a` is the state between steps,
/// `b` its copy in cell order at the start of a step, `c` the half-step state; `b` and `c`
/// are textures because neighbour loops read them (see `particle_texture.wgsl`).
pub struct GpuBuffers {
    pub params: wgpu::Buffer,
    pub a: StateBuffers,
    pub b: StateTextures,
    pub b_ids: wgpu::Buffer,
    pub b_vel_rho_prev: wgpu::Buffer,
    /// A copy of `a` taken at the start of each chunk, restored after a blow-up.
    pub snapshot: StateBuffers,
    pub c: StateTextures,
    /// The rheology pass's viscous stress, (xx, xy, xz, yy) and (yz, zz, mu, region word), in cell
    /// order, and region words (region | REGION_HELD) by particle id.
    pub stress_a: wgpu::TextureView,
    pub stress_b: wgpu::TextureView,
    pub regions: wgpu::Buffer,
    /// A copy of `regions` taken with `snapshot`: which sediment is held is state too.
    pub regions_snapshot: wgpu::Buffer,
    pub forces: wgpu::Buffer,
    pub cell_of: wgpu::Buffer,
    pub cell_starts: wgpu::Buffer,
    pub cell_cursor: wgpu::Buffer,
    pub sorted_index: wgpu::Buffer,
    /// Per scan level: its uniform and the block sums it writes.
    pub scan_levels: Vec<(wgpu::Buffer, wgpu::Buffer, u32)>,
    pub state: wgpu::Buffer,
    pub probe_points: wgpu::Buffer,
    pub probe_sums: wgpu::Buffer,
    pub extremes: wgpu::Buffer,
}

pub struct StateBuffers {
    pub positions: wgpu::Buffer,
    pub vel_rho: wgpu::Buffer,
    pub ids: wgpu::Buffer,
    /// Velocity and density of the step before (the Verlet integrator's second sequence).
    pub vel_rho_prev: wgpu::Buffer,
}

pub struct StateTextures {
    pub positions: wgpu::TextureView,
    pub vel_rho: wgpu::TextureView,
}

impl StateTextures {
    fn new(gpu: &GpuContext, label: &str, n: u64) -> StateTextures {
        StateTextures {
            positions: particle_texture(gpu, &format!("{label}.positions"), n, TEXEL_ROW_SHIFT),
            vel_rho: particle_texture(gpu, &format!("{label}.vel_rho"), n, TEXEL_ROW_SHIFT),
        }
    }
}

/// Bytes of one vec4<f32> particle attribute (positions, velocity-density, forces).
pub const VEC4_BYTES: u64 = 16;

impl GpuBuffers {
    /// Checks every large buffer against the adapter's limits before anything is allocated.
    pub fn check_limits(gpu: &GpuContext, n_particles: u64, n_cells: u64) -> Result<(), GpuError> {
        gpu.check_storage_size("positions", n_particles * VEC4_BYTES)?;
        gpu.check_storage_size("cell_starts", (n_cells + 1) * 4)?;
        let rows = n_particles.div_ceil(1 << TEXEL_ROW_SHIFT);
        let max_rows = u64::from(gpu.limits.max_texture_dimension_2d);
        if rows > max_rows {
            return Err(GpuError::TooLarge {
                buffer: "particle textures".to_string(),
                needed_mib: (n_particles * VEC4_BYTES) as f64 / 1048576.0,
                limit_mib: ((max_rows << TEXEL_ROW_SHIFT) * VEC4_BYTES) as f64 / 1048576.0,
                adapter: gpu.adapter.name.clone(),
            });
        }
        let max_groups = u64::from(gpu.limits.max_compute_workgroups_per_dimension);
        if n_particles.div_ceil(u64::from(stages::FORCES_WCSPH.workgroup)) > max_groups
            || (n_cells + 1).div_ceil(u64::from(stages::GRID_CLEAR.workgroup)) > max_groups
        {
            return Err(GpuError::TooLarge {
                buffer: "dispatch size".to_string(),
                needed_mib: (n_particles * VEC4_BYTES) as f64 / 1048576.0,
                limit_mib: (max_groups * 64 * VEC4_BYTES) as f64 / 1048576.0,
                adapter: gpu.adapter.name.clone(),
            });
        }
        Ok(())
    }

    pub fn new(
        gpu: &GpuContext,
        params: wgpu::Buffer,
        a: StateBuffers,
        n_cells: u32,
        n_probes: u32,
    ) -> GpuBuffers {
        let n = a.positions.size() / VEC4_BYTES;
        let b = StateTextures::new(gpu, "b", n);
        let mut scan_levels = Vec::new();
        let mut len = n_cells + 1;
        loop {
            let blocks = len.div_ceil(PREFIX_SUM_BLOCK);
            let info = crate::gpu::buffers::uniform_init(
                gpu,
                "scan info",
                &ScanInfo {
                    n: len,
                    pad: [0; 3],
                },
            );
            scan_levels.push((
                info,
                storage(gpu, "scan block sums", u64::from(blocks) * 4),
                len,
            ));
            if blocks == 1 {
                break;
            }
            len = blocks;
        }
        GpuBuffers {
            params,
            b,
            b_ids: storage(gpu, "b.ids", n * 4),
            b_vel_rho_prev: storage(gpu, "b.vel_rho_prev", n * VEC4_BYTES),
            snapshot: StateBuffers {
                positions: storage(gpu, "snapshot.positions", n * VEC4_BYTES),
                vel_rho: storage(gpu, "snapshot.vel_rho", n * VEC4_BYTES),
                ids: storage(gpu, "snapshot.ids", n * 4),
                vel_rho_prev: storage(gpu, "snapshot.vel_rho_prev", n * VEC4_BYTES),
            },
            c: StateTextures::new(gpu, "c", n),
            stress_a: particle_texture(gpu, "stress_a", n, TEXEL_ROW_SHIFT),
            stress_b: particle_texture(gpu, "stress_b", n, TEXEL_ROW_SHIFT),
            regions: storage(gpu, "regions", n * 4),
            regions_snapshot: storage(gpu, "regions snapshot", n * 4),
            forces: storage(gpu, "forces", n * VEC4_BYTES),
            cell_of: storage(gpu, "cell_of", n * 4),
            cell_starts: storage(gpu, "cell_starts", u64::from(n_cells + 1) * 4),
            cell_cursor: storage(gpu, "cell_cursor", u64::from(n_cells + 1) * 4),
            sorted_index: storage(gpu, "sorted_index", n * 4),
            scan_levels,
            state: storage(gpu, "step state", std::mem::size_of::<StepState>() as u64),
            probe_points: storage(gpu, "probe points", u64::from(n_probes.max(1)) * VEC4_BYTES),
            probe_sums: storage(gpu, "probe sums", u64::from(n_probes.max(1)) * VEC4_BYTES),
            extremes: storage(gpu, "extremes", 16),
            a,
        }
    }
}

pub struct Bindings {
    grid_clear: wgpu::BindGroup,
    grid_count: wgpu::BindGroup,
    scan: Vec<(wgpu::BindGroup, u32)>,
    grid_scatter: wgpu::BindGroup,
    cell_sort: wgpu::BindGroup,
    reorder: wgpu::BindGroup,
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
        Bindings {
            grid_clear: self
                .grid_clear
                .bind(d, &[&g.params, &g.cell_starts, &g.cell_cursor]),
            grid_count: self
                .grid_count
                .bind(d, &[&g.params, &g.a.positions, &g.cell_of, &g.cell_starts]),
            scan,
            grid_scatter: self.grid_scatter.bind(
                d,
                &[
                    &g.params,
                    &g.cell_of,
                    &g.cell_starts,
                    &g.cell_cursor,
                    &g.sorted_index,
                ],
            ),
            cell_sort: self
                .cell_sort
                .bind(d, &[&g.params, &g.cell_starts, &g.a.ids, &g.sorted_index]),
            reorder: self.reorder.bind(
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
            forces_predict: self.forces_predict.bind(
                d,
                &[
                    &g.params,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.cell_starts,
                    &g.forces,
                    &g.state,
                    &g.stress_a,
                    &g.stress_b,
                ],
            ),
            forces_correct: self.forces_correct.bind(
                d,
                &[
                    &g.params,
                    &g.c.positions,
                    &g.c.vel_rho,
                    &g.cell_starts,
                    &g.forces,
                    &g.state,
                    &g.stress_a,
                    &g.stress_b,
                ],
            ),
            rheology_predict: self.rheology_predict.bind(
                d,
                &[
                    &g.params,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.cell_starts,
                    &g.state,
                    &g.stress_a,
                    &g.stress_b,
                    &g.regions,
                    &g.b_ids,
                ],
            ),
            release_predict: self.release_predict.bind(
                d,
                &[
                    &g.params,
                    &g.b.positions,
                    &g.b.vel_rho,
                    &g.cell_starts,
                    &g.state,
                    &g.stress_a,
                    &g.stress_b,
                    &g.regions,
                    &g.b_ids,
                ],
            ),
            rheology_correct: self.rheology_correct.bind(
                d,
                &[
                    &g.params,
                    &g.c.positions,
                    &g.c.vel_rho,
                    &g.cell_starts,
                    &g.state,
                    &g.stress_a,
                    &g.stress_b,
                    &g.regions,
                    &g.b_ids,
                ],
            ),
            release_correct: self.release_correct.bind(
                d,
                &[
                    &g.params,
                    &g.c.positions,
                    &g.c.vel_rho,
                    &g.cell_starts,
                    &g.state,
                    &g.stress_a,
                    &g.stress_b,
                    &g.regions,
                    &g.b_ids,
                ],
            ),
            dt_update: self.dt_update.bind(d, &[&g.params, &g.state]),
            symplectic_predictor: self.symplectic_predictor.bind(
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
                ],
            ),
            symplectic_corrector: self.symplectic_corrector.bind(
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
                ],
            ),
            verlet_update: self.verlet_update.bind(
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
                ],
            ),
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
            observe_reduce: self
                .observe_reduce
                .bind(d, &[&g.params, &g.a.positions, &g.a.vel_rho, &g.extremes]),
            n_particles,
            n_cells,
            n_probes,
        }
    }

    /// Neighbour search: counting sort of state `a` into cells, copied in cell order into `b`.
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
        self.grid_scatter.record_items(pass, 0, &b.grid_scatter, n);
        self.cell_sort
            .record_items(pass, 0, &b.cell_sort, b.n_cells);
        self.reorder.record_items(pass, 0, &b.reorder, n);
    }

    /// One step: sort, (rheology and) forces at n, dt, then either the symplectic predictor,
    /// (rheology and) forces at n + 1/2 and corrector, or the Verlet update (both as in
    /// DualSPHysics).
    pub fn record_step(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings) {
        let n = b.n_particles;
        self.record_sort(pass, b);
        self.record_rheology(pass, b, true);
        self.forces_predict
            .record_items(pass, 0, &b.forces_predict, n);
        self.dt_update.record_items(pass, 0, &b.dt_update, 1);
        if self.verlet {
            self.verlet_update
                .record_items(pass, 0, &b.verlet_update, n);
        } else {
            self.symplectic_predictor
                .record_items(pass, 0, &b.symplectic_predictor, n);
            self.record_rheology(pass, b, false);
            self.forces_correct
                .record_items(pass, 0, &b.forces_correct, n);
            self.symplectic_corrector
                .record_items(pass, 0, &b.symplectic_corrector, n);
        }
    }

    /// The rheology pass and the release of held sediment, on the state at n (`predict`) or
    /// at n + 1/2, when the case has them.
    fn record_rheology(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings, predict: bool) {
        let n = b.n_particles;
        if !self.multiphase {
            return;
        }
        let (rheology, bind) = if predict {
            (&self.rheology_predict, &b.rheology_predict)
        } else {
            (&self.rheology_correct, &b.rheology_correct)
        };
        rheology.record_items(pass, 0, bind, n);
        if self.yield_release {
            let (release, bind) = if predict {
                (&self.release_predict, &b.release_predict)
            } else {
                (&self.release_correct, &b.release_correct)
            };
            release.record_items(pass, 0, bind, n);
        }
    }

    /// Forces at the current state only (no integration): for tests against the CPU oracle.
    pub fn record_forces(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings) {
        self.record_sort(pass, b);
        self.record_rheology(pass, b, true);
        self.forces_predict
            .record_items(pass, 0, &b.forces_predict, b.n_particles);
    }

    /// Observation passes: probe sums on the sorted state and the whole-state maxima.
    pub fn record_observe(&self, pass: &mut wgpu::ComputePass<'_>, b: &Bindings) {
        self.record_sort(pass, b);
        self.probe_interpolate
            .record_items(pass, 0, &b.probe_interpolate, b.n_probes);
        self.observe_reduce
            .record_items(pass, 0, &b.observe_reduce, b.n_particles);
    }
}
