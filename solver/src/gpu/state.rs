//! The GPU-resident particle state and the scratch buffers the stages of `pipeline.rs` share.

use super::GpuContext;
use super::GpuError;
use super::buffers::{indirect, particle_texture, storage};
use crate::contract::{ScanInfo, StepState};
use crate::gpu::stages::{self, PREFIX_SUM_BLOCK};

/// Rows of the particle textures are 2^TEXEL_ROW_SHIFT texels wide, as the WGSL constant of
/// the same name in `shaders/common/particle_texture.wgsl` (checked by `shaders_validate`).
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
    /// [`REGION_SLOTS`] runs of one word per particle id: the region words, then the bed load
    /// each held particle at the surface passed on (f32 bits, `van_rijn_exner`) in the steps
    /// of even and of odd run count, one read while the other is written, then the ids of the
    /// particles it passed them to, likewise.
    pub regions: wgpu::Buffer,
    /// A copy of `regions` taken with `snapshot`: which sediment is held is state too.
    pub regions_snapshot: wgpu::Buffer,
    pub forces: wgpu::Buffer,
    pub cell_of: wgpu::Buffer,
    pub cell_starts: wgpu::Buffer,
    pub cell_cursor: wgpu::Buffer,
    pub sorted_index: wgpu::Buffer,
    /// Indirect dispatch arguments from the active count (`pipeline::ACTIVE_SMALL` and after).
    pub dispatch: wgpu::Buffer,
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

/// Bytes of one `vec4<f32>` particle attribute (positions, velocity-density, forces).
pub const VEC4_BYTES: u64 = 16;

/// The runs of one word per particle in `GpuBuffers::regions`: words, two steps' fluxes and the
/// two steps' particles they went to.
pub const REGION_SLOTS: u64 = 5;

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
        if n_particles.div_ceil(u64::from(stages::INTERACTION.workgroup)) > max_groups
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
            let info = super::buffers::uniform_init(
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
            regions: storage(gpu, "regions", n * 4 * REGION_SLOTS),
            regions_snapshot: storage(gpu, "regions snapshot", n * 4 * REGION_SLOTS),
            forces: storage(gpu, "forces", n * VEC4_BYTES),
            cell_of: storage(gpu, "cell_of", n * 4),
            cell_starts: storage(gpu, "cell_starts", u64::from(n_cells + 1) * 4),
            cell_cursor: storage(gpu, "cell_cursor", u64::from(n_cells + 1) * 4),
            sorted_index: storage(gpu, "sorted_index", n * 4),
            dispatch: indirect(gpu, "active dispatch", crate::gpu::pipeline::DISPATCH_BYTES),
            scan_levels,
            state: storage(gpu, "step state", std::mem::size_of::<StepState>() as u64),
            probe_points: storage(gpu, "probe points", u64::from(n_probes.max(1)) * VEC4_BYTES),
            probe_sums: storage(gpu, "probe sums", u64::from(n_probes.max(1)) * VEC4_BYTES),
            extremes: storage(gpu, "extremes", 16),
            a,
        }
    }
}
