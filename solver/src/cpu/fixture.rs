//! A small 2-D flume section for the CPU backend's own tests: a wall row, a sand bed and
//! water above it, on a jittered lattice with velocities and densities that vary from
//! particle to particle, so that every branch of the pair formulas (walls, scaled walls,
//! same-phase diffusion, approaching and receding pairs, the bed's nearest water) is taken.

use super::grid::Grid;
use crate::contract::SimParams;
use crate::physics::sediment::pass::SedimentModel;
use crate::physics::sediment::{SedimentParams, flume_sand};
use crate::physics::{Params, Phase, Viscosity};
use bytemuck::Zeroable;

pub const WALL: u32 = 0;
pub const WATER: u32 = 1;
pub const SAND: u32 = 2;

const DP: f32 = 0.01;

pub struct Fixture {
    pub params: Params,
    pub sediment: SedimentModel,
    /// Sorted into `grid`'s cells.
    pub pos: Vec<[f32; 4]>,
    pub vel: Vec<[f32; 4]>,
    pub grid: Grid,
}

/// A deterministic stream in [-1, 1).
fn jitter(seed: &mut u64) -> f32 {
    *seed = seed
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*seed >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
}

fn params(viscosity: Viscosity) -> Params {
    let phase = |rho0: f32, mu: f32, mobile: bool| Phase {
        rho0,
        mass: rho0 * DP * DP,
        mu,
        mobile,
        generalised_wall: false,
    };
    Params {
        dim: 2,
        h: 1.7 * DP,
        c0: 8.0,
        gravity: [0.0, -9.81, 0.0],
        hydrostatic_diffusion: true,
        delta: 0.1,
        viscosity,
        clamp_negative_pressure: false,
        generalised_walls: false,
        cfl: 0.2,
        phases: vec![
            phase(1000.0, 0.0, false),
            phase(1000.0, 1e-3, true),
            phase(2710.0, 1e-3, true),
        ],
    }
}

fn sediment() -> SedimentModel {
    SedimentModel {
        material: SedimentParams {
            phi_rad: 0.6,
            ..flume_sand()
        },
        sediment_phase: SAND as usize,
        water_phase: WATER as usize,
        shields_only: false,
        water_speed: false,
        rests_beside_solid: true,
        mu_max: 50.0,
        pickup_per_s: 0.0,
        pickup_integrated: false,
        exner_step_per_stage: 0.0,
        dp_m: 0.01,
    }
}

/// 24 x 12 particles: one wall row, four of sand, the rest water; cells of h (two divisions
/// of 2h, as the flume at this resolution has).
pub fn fixture(viscosity: Viscosity) -> Fixture {
    let params = params(viscosity);
    let (nx, ny) = (24usize, 12usize);
    let mut seed = 7u64;
    let mut pos = Vec::new();
    let mut vel = Vec::new();
    for iy in 0..ny {
        for ix in 0..nx {
            let phase = match iy {
                0 => WALL,
                1..=4 => SAND,
                _ => WATER,
            };
            let mobile = phase != WALL;
            let shake = if mobile { 0.2 * DP } else { 0.0 };
            let x = (ix as f32 + 0.5) * DP + shake * jitter(&mut seed);
            let y = (iy as f32 + 0.5) * DP + shake * jitter(&mut seed);
            pos.push([x, y, 0.0, f32::from_bits(phase)]);
            let rho0 = params.phases[phase as usize].rho0;
            let speed = if mobile { 0.3 } else { 0.0 };
            vel.push([
                speed * jitter(&mut seed),
                speed * jitter(&mut seed),
                0.0,
                rho0 * (1.0 + 0.01 * jitter(&mut seed)),
            ]);
        }
    }
    let divisions = 2;
    let cell = 2.0 * params.h / divisions as f32;
    let mut sim = SimParams::zeroed();
    let dims = [
        (nx as f32 * DP / cell).ceil() as u32 + 1,
        (ny as f32 * DP / cell).ceil() as u32 + 1,
    ];
    sim.grid_dims = [dims[0], dims[1], 1, 0];
    sim.grid_origin = [0.0, 0.0, 0.0, 1.0 / cell];
    sim.n_cells = dims[0] * dims[1];
    let mut grid = Grid::new(&sim, divisions);
    let ids: Vec<u32> = (0..pos.len() as u32).collect();
    let order = grid.sort(&pos, &ids, None, pos.len());
    let pos = super::grid::gather(&pos, &order);
    let vel = super::grid::gather(&vel, &order);
    Fixture {
        params,
        sediment: sediment(),
        pos,
        vel,
        grid,
    }
}
