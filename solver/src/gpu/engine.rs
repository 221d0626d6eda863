//! The wgpu backend: the state in storage buffers, steps recorded into submissions of compute
//! passes (`pipeline.rs`), read back only at chunk ends.

use super::GpuContext;
use super::buffers::{cast_vec, read_buffers, storage_init, uniform_init};
use super::inlet::InletScanner;
use super::state::{GpuBuffers, StateBuffers};
use crate::contract::{Extremes, SimParams, StepState};
use crate::engine::{Engine, InletScan, PipelineShape, RawState, StageTime, by_id};
use crate::error::SolverError;
use crate::gpu::pipeline::{Bindings, SphPipeline};
use crate::particles::Particles;
use crate::physics::sediment::pass::{NO_FLUX, NO_TARGET};
use std::sync::Arc;

pub struct GpuEngine {
    gpu: Arc<GpuContext>,
    pipeline: SphPipeline,
    buffers: GpuBuffers,
    bindings: Bindings,
    /// The open flume's inlet stage, built on the first call.
    inlet: Option<InletScanner>,
    n: u64,
    n_probes: u64,
    n_cells: u64,
}

impl GpuEngine {
    pub fn new(
        gpu: Arc<GpuContext>,
        params: &SimParams,
        particles: &Particles,
        probe_points: &[[f32; 4]],
        shape: PipelineShape,
    ) -> Result<GpuEngine, SolverError> {
        GpuBuffers::check_limits(&gpu, particles.len() as u64, u64::from(params.n_cells))?;
        let a = StateBuffers {
            positions: storage_init(&gpu, "a.positions", &particles.positions),
            vel_rho: storage_init(&gpu, "a.vel_rho", &particles.vel_rho),
            ids: storage_init(&gpu, "a.ids", &particles.ids),
            vel_rho_prev: storage_init(&gpu, "a.vel_rho_prev", &particles.vel_rho),
        };
        let buffers = GpuBuffers::new(
            &gpu,
            uniform_init(&gpu, "params", params),
            a,
            params.n_cells,
            params.n_probes,
        );
        gpu.queue
            .write_buffer(&buffers.probe_points, 0, bytemuck::cast_slice(probe_points));
        // No particle has passed any bed load on, to any other, before the first pass.
        let no_flux = vec![NO_FLUX; 2 * particles.len()];
        let fluxes_at = particles.len() as u64 * 4;
        gpu.queue
            .write_buffer(&buffers.regions, fluxes_at, bytemuck::cast_slice(&no_flux));
        let no_target = vec![NO_TARGET; 2 * particles.len()];
        gpu.queue.write_buffer(
            &buffers.regions,
            3 * fluxes_at,
            bytemuck::cast_slice(&no_target),
        );
        let pipeline = SphPipeline::new(
            &gpu,
            shape.dim,
            shape.divisions,
            shape.verlet,
            shape.multiphase,
            shape.hold,
        );
        let n = particles.len() as u32;
        let bindings = pipeline.bind(&gpu, &buffers, n, params.n_cells, params.n_probes);
        Ok(GpuEngine {
            gpu,
            pipeline,
            buffers,
            bindings,
            inlet: None,
            n: u64::from(n),
            n_probes: u64::from(params.n_probes),
            n_cells: u64::from(params.n_cells),
        })
    }

    fn copy(&self, pairs: &[(&wgpu::Buffer, &wgpu::Buffer)]) {
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        for (src, dst) in pairs {
            encoder.copy_buffer_to_buffer(src, 0, dst, 0, src.size());
        }
        self.gpu.queue.submit([encoder.finish()]);
    }

    fn copy_state(&self, from: &StateBuffers, to: &StateBuffers, holds: [&wgpu::Buffer; 2]) {
        self.copy(&[
            (&from.positions, &to.positions),
            (&from.vel_rho, &to.vel_rho),
            (&from.ids, &to.ids),
            (&from.vel_rho_prev, &to.vel_rho_prev),
            // Which sediment is held is state too: the next rheology pass starts from it.
            (holds[0], holds[1]),
        ]);
    }

    /// Records `record` into one compute pass and submits it.
    fn submit(&self, record: impl FnOnce(&mut wgpu::ComputePass<'_>)) {
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            record(&mut pass);
        }
        self.gpu.queue.submit([encoder.finish()]);
    }

    fn write_state(&self, state: &StepState) {
        self.gpu
            .queue
            .write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(state));
    }
}

impl Engine for GpuEngine {
    fn name(&self) -> String {
        format!("wgpu on {}", self.gpu.adapter)
    }

    fn write_params(&mut self, params: &SimParams) {
        self.gpu
            .queue
            .write_buffer(&self.buffers.params, 0, bytemuck::bytes_of(params));
    }

    fn save(&mut self) {
        let b = &self.buffers;
        self.copy_state(&b.a, &b.snapshot, [&b.regions, &b.regions_snapshot]);
    }

    fn restore(&mut self) {
        let b = &self.buffers;
        self.copy_state(&b.snapshot, &b.a, [&b.regions_snapshot, &b.regions]);
    }

    fn run(&mut self, init: StepState, steps: u32) -> Result<StepState, SolverError> {
        self.write_state(&init);
        self.submit(|pass| {
            for _ in 0..steps {
                self.pipeline.record_step(pass, &self.bindings);
            }
        });
        let size = std::mem::size_of::<StepState>() as u64;
        let bytes = read_buffers(&self.gpu, &[(&self.buffers.state, size)])?;
        Ok(bytemuck::pod_read_unaligned(&bytes[0]))
    }

    fn read_state(&self) -> Result<RawState, SolverError> {
        let a = &self.buffers.a;
        let n = self.n;
        let raw = read_buffers(
            &self.gpu,
            &[
                (&a.positions, n * 16),
                (&a.vel_rho, n * 16),
                (&a.ids, n * 4),
            ],
        )?;
        Ok(RawState {
            positions: cast_vec(&raw[0]),
            vel_rho: cast_vec(&raw[1]),
            ids: cast_vec(&raw[2]),
        })
    }

    fn place(&mut self, slot: usize, position: [f32; 4], vel_rho: [f32; 4]) {
        let offset = slot as u64 * 16;
        let a = &self.buffers.a;
        let q = &self.gpu.queue;
        q.write_buffer(&a.positions, offset, bytemuck::bytes_of(&position));
        q.write_buffer(&a.vel_rho, offset, bytemuck::bytes_of(&vel_rho));
        q.write_buffer(&a.vel_rho_prev, offset, bytemuck::bytes_of(&vel_rho));
    }

    fn inlet_scan(&mut self, spots: &[[f32; 2]], radius: f32) -> Result<InletScan, SolverError> {
        let gpu = &self.gpu;
        let scanner = self.inlet.get_or_insert_with(|| InletScanner::new(gpu));
        scanner.scan(gpu, &self.buffers, self.n as u32, spots, radius)
    }

    fn regions(&self) -> Result<Vec<u32>, SolverError> {
        let raw = read_buffers(&self.gpu, &[(&self.buffers.regions, self.n * 4)])?;
        Ok(cast_vec(&raw[0]))
    }

    fn write_regions(&mut self, words: &[u32]) {
        let q = &self.gpu.queue;
        q.write_buffer(&self.buffers.regions, 0, bytemuck::cast_slice(words));
    }

    fn forces(&mut self) -> Result<(Vec<[f32; 4]>, f32), SolverError> {
        // A chunk that has not ended, so the force pass runs.
        self.write_state(&StepState::chunk(f32::MAX, (0.0, 0.0), (0, 0)));
        // The pass writes the active particles only: parked ones feel nothing.
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&self.buffers.forces, 0, None);
        self.gpu.queue.submit([encoder.finish()]);
        self.submit(|pass| self.pipeline.record_forces(pass, &self.bindings));
        let b = &self.buffers;
        let raw = read_buffers(
            &self.gpu,
            &[
                (&b.forces, self.n * 16),
                (&b.b_ids, self.n * 4),
                (&b.state, std::mem::size_of::<StepState>() as u64),
            ],
        )?;
        let forces: Vec<[f32; 4]> = cast_vec(&raw[0]);
        let ids: Vec<u32> = cast_vec(&raw[1]);
        let state: StepState = bytemuck::pod_read_unaligned(&raw[2]);
        Ok((by_id(&forces, &ids), f32::from_bits(state.dt_min_bits)))
    }

    fn cell_list(&self) -> Result<(Vec<u32>, Vec<u32>), SolverError> {
        self.submit(|pass| self.pipeline.record_sort(pass, &self.bindings));
        let b = &self.buffers;
        let raw = read_buffers(
            &self.gpu,
            &[
                (&b.cell_starts, (self.n_cells + 1) * 4),
                (&b.b_ids, self.n * 4),
            ],
        )?;
        Ok((cast_vec(&raw[0]), cast_vec(&raw[1])))
    }

    fn observe(&self) -> Result<(Vec<[f32; 4]>, Extremes), SolverError> {
        let reset = Extremes {
            front_key: 0,
            max_speed_bits: 0,
            max_rho_err_bits: 0,
            fluid_count: 0,
        };
        self.gpu
            .queue
            .write_buffer(&self.buffers.extremes, 0, bytemuck::bytes_of(&reset));
        self.submit(|pass| self.pipeline.record_observe(pass, &self.bindings));
        let raw = read_buffers(
            &self.gpu,
            &[
                (&self.buffers.probe_sums, self.n_probes * 16),
                (&self.buffers.extremes, 16),
            ],
        )?;
        Ok((cast_vec(&raw[0]), bytemuck::pod_read_unaligned(&raw[1])))
    }

    fn stage_times(&self) -> Vec<StageTime> {
        Vec::new()
    }
}
