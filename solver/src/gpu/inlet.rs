//! The open flume's inlet on the GPU (`inlet_scan.wgsl`): which spots are occupied and which
//! parked slots to fill, read back in a few bytes per spot instead of the whole state.

use super::GpuContext;
use super::buffers::{cast_vec, read_buffers, storage, uniform_init};
use super::stage::Stage;
use super::state::GpuBuffers;
use crate::contract::InletQuery;
use crate::engine::InletScan;
use crate::error::SolverError;
use bytemuck::Zeroable;

pub struct InletScanner {
    stage: Stage,
    room: Option<Room>,
}

/// The scan's buffers, for up to `capacity` spots.
struct Room {
    capacity: usize,
    query: wgpu::Buffer,
    spots: wgpu::Buffer,
    occupied: wgpu::Buffer,
    picks: wgpu::Buffer,
    parked_bits: wgpu::Buffer,
    bind: wgpu::BindGroup,
}

/// Spots the buffers first hold room for: a few inlet columns of a few particles each.
const FIRST_CAPACITY: usize = 64;

impl Room {
    fn new(gpu: &GpuContext, stage: &Stage, g: &GpuBuffers, n: u64, capacity: usize) -> Room {
        let query = uniform_init(gpu, "inlet query", &InletQuery::zeroed());
        let spots = storage(gpu, "inlet spots", capacity as u64 * 8);
        let occupied = storage(gpu, "inlet occupied", capacity as u64 * 4);
        let picks = storage(gpu, "inlet picks", (capacity as u64 + 1) * 4);
        let parked_bits = storage(gpu, "parked ids", n.div_ceil(32) * 4);
        let slot_of = storage(gpu, "parked slots by id", n * 4);
        let bind = stage.bind(
            &gpu.device,
            &[
                &g.params,
                &query,
                &g.a.positions,
                &g.a.ids,
                &spots,
                &occupied,
                &parked_bits,
                &slot_of,
                &picks,
            ],
        );
        Room {
            capacity,
            query,
            spots,
            occupied,
            picks,
            parked_bits,
            bind,
        }
    }
}

impl InletScanner {
    pub fn new(gpu: &GpuContext) -> InletScanner {
        InletScanner {
            stage: Stage::new(&gpu.device, &crate::gpu::stages::INLET_SCAN, &[]),
            room: None,
        }
    }

    /// `Engine::inlet_scan` on the state in `g`, of `n` particles.
    pub fn scan(
        &mut self,
        gpu: &GpuContext,
        g: &GpuBuffers,
        n: u32,
        spots: &[[f32; 2]],
        radius: f32,
    ) -> Result<InletScan, SolverError> {
        let k = spots.len();
        if k == 0 {
            return Ok(InletScan {
                occupied: Vec::new(),
                parked_slots: Vec::new(),
            });
        }
        if self.room.as_ref().is_some_and(|r| r.capacity < k) {
            self.room = None;
        }
        let room = self.room.get_or_insert_with(|| {
            Room::new(gpu, &self.stage, g, u64::from(n), k.max(FIRST_CAPACITY))
        });
        let query = InletQuery {
            n_spots: k as u32,
            radius2: radius * radius,
            pad: [0; 2],
        };
        gpu.queue
            .write_buffer(&room.query, 0, bytemuck::bytes_of(&query));
        gpu.queue
            .write_buffer(&room.spots, 0, bytemuck::cast_slice(spots));
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&room.occupied, 0, None);
        encoder.clear_buffer(&room.parked_bits, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.stage.record_items(&mut pass, 0, &room.bind, n);
            self.stage.record(&mut pass, 1, &room.bind, 1);
        }
        gpu.queue.submit([encoder.finish()]);
        let raw = read_buffers(
            gpu,
            &[
                (&room.picks, (k as u64 + 1) * 4),
                (&room.occupied, k as u64 * 4),
            ],
        )?;
        let picks: Vec<u32> = cast_vec(&raw[0]);
        let occupied: Vec<u32> = cast_vec(&raw[1]);
        let count = (picks[0] as usize).min(k);
        Ok(InletScan {
            occupied: occupied.iter().map(|&o| o != 0).collect(),
            parked_slots: picks[1..=count].iter().map(|&s| s as usize).collect(),
        })
    }
}
