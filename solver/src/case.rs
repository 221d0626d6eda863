//! Turns a validated `Case` into particles on the dp lattice and the derived physical constants.
//!
//! Like DualSPHysics' GenCase, every particle sits on the lattice of integer multiples of dp:
//! wall particles on the tank's faces and `layers - 1` rows outside them, fluid at the lattice
//! points inside each block (`min < x <= max`) that no wall or earlier block already holds.

use crate::config::{Case, SoundSpeed};
use std::collections::HashSet;

/// Phase index 0 on the GPU is the wall; case phase k is GPU phase k + 1.
pub const WALL_PHASE: u32 = 0;

/// GPU phase index of parked particles in an open flume: the one after the case's phases.
pub fn parked_phase(case: &Case) -> u32 {
    case.phases.len() as u32 + 1
}

/// Where parked particles wait in an open flume: a lattice of spots dp apart above the flume,
/// one per particle id, clear of the splash room above the walls by 4h, so that no parked
/// particle comes within a kernel support of the flow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parking {
    pub x0: f64,
    pub y0: f64,
    pub cols: u32,
    pub dp: f64,
}

impl Parking {
    pub fn new(case: &Case, h: f64) -> Parking {
        let dp = case.numerics.dp_m;
        let (lo, hi) = (&case.domain.min_m, &case.domain.max_m);
        let height = hi[1] - lo[1];
        Parking {
            x0: lo[0] + 0.5 * dp,
            y0: hi[1] + SPLASH_ROOM * height + 4.0 * h,
            cols: ((hi[0] - lo[0]) / dp).floor().max(1.0) as u32,
            dp,
        }
    }

    /// The spot of particle `id`, m.
    pub fn spot(&self, id: u32) -> [f32; 2] {
        [
            (self.x0 + f64::from(id % self.cols) * self.dp) as f32,
            (self.y0 + f64::from(id / self.cols) * self.dp) as f32,
        ]
    }

    /// Top of the spots of `n` particles, m.
    pub fn top(&self, n: u64) -> f64 {
        self.y0 + (n / u64::from(self.cols) + 1) as f64 * self.dp
    }
}

/// Room kept above a tank for splashes, as a fraction of its height (the neighbour grid covers
/// it; particles above the grid still live in its top row).
pub const SPLASH_ROOM: f64 = 0.25;

/// Particle state on the CPU, in the GPU's layout (see `gpu::params`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Particles {
    /// x, y, z (z = 0 in 2-D) and, in w, the phase index as f32 bits.
    pub positions: Vec<[f32; 4]>,
    /// Velocity x, y, z and, in w, the density in kg/m3.
    pub vel_rho: Vec<[f32; 4]>,
    /// Stable identity of each particle (its index at generation).
    pub ids: Vec<u32>,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.positions.len()
    }
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
    pub fn phase(&self, i: usize) -> u32 {
        self.positions[i][3].to_bits()
    }
}

/// One phase as the solver sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseProps {
    pub rho0: f64,
    /// Mass per particle, kg (per metre of width in 2-D): rho0 dp^dim.
    pub mass: f64,
    pub viscosity_pa_s: f64,
    pub mobile: bool,
}

/// The physical constants every stage needs, derived once from the case.
#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    pub h: f64,
    pub c0: f64,
    /// Height of the fluid used for c0 with `coefsound`, m.
    pub fluid_height: f64,
    /// Index 0 is the wall.
    pub phases: Vec<PhaseProps>,
}

fn lattice_bounds(case: &Case) -> (Vec<i64>, Vec<i64>) {
    let dp = case.numerics.dp_m;
    let lo = case
        .domain
        .min_m
        .iter()
        .map(|v| (v / dp).round() as i64)
        .collect();
    let hi = case
        .domain
        .max_m
        .iter()
        .map(|v| (v / dp).round() as i64)
        .collect();
    (lo, hi)
}

/// Iterates the lattice points of the box `lo..=hi` (lattice indices).
fn for_each_point(lo: &[i64], hi: &[i64], mut f: impl FnMut(&[i64])) {
    let d = lo.len();
    let mut p = lo.to_vec();
    if lo.iter().zip(hi).any(|(a, b)| a > b) {
        return;
    }
    loop {
        f(&p);
        let mut k = 0;
        loop {
            p[k] += 1;
            if p[k] <= hi[k] {
                break;
            }
            p[k] = lo[k];
            k += 1;
            if k == d {
                return;
            }
        }
    }
}

fn is_wall(case: &Case, p: &[i64], lo: &[i64], hi: &[i64]) -> bool {
    let d = p.len();
    let layers = i64::from(case.walls.layers);
    let vert = d - 1;
    let mut outside_or_on = false;
    for k in 0..d {
        let top_open = k == vert && !case.walls.closed_top;
        if p[k] < lo[k] - (layers - 1) || (!top_open && p[k] > hi[k] + (layers - 1)) {
            return false;
        }
        if p[k] <= lo[k] || (!top_open && p[k] >= hi[k]) {
            outside_or_on = true;
        }
    }
    // An open flume's downstream wall stops at the weir; the floor under it stays.
    if let Some(f) = &case.open_flume
        && p[0] >= hi[0]
        && p[vert] > lo[vert]
        && p[vert] as f64 * case.numerics.dp_m > f.outlet_weir_m + 1e-9
    {
        return false;
    }
    outside_or_on
}

fn wall_box(case: &Case, lo: &[i64], hi: &[i64]) -> (Vec<i64>, Vec<i64>) {
    let layers = i64::from(case.walls.layers);
    let d = lo.len();
    let wlo = lo.iter().map(|v| v - (layers - 1)).collect();
    let whi = (0..d)
        .map(|k| {
            if k == d - 1 && !case.walls.closed_top {
                hi[k]
            } else {
                hi[k] + layers - 1
            }
        })
        .collect();
    (wlo, whi)
}

fn block_bounds(case: &Case, min: &[f64], max: &[f64]) -> (Vec<i64>, Vec<i64>) {
    let dp = case.numerics.dp_m;
    let lo = min
        .iter()
        .map(|v| (v / dp + 1e-6).floor() as i64 + 1)
        .collect();
    let hi = max.iter().map(|v| (v / dp + 1e-6).floor() as i64).collect();
    (lo, hi)
}

/// Generates the particles of a case: walls, wall blocks, then fluid blocks in file order
/// (and, in an open flume, the inlet buffer and the parked reservoir).
pub fn generate(case: &Case, derived: &Derived) -> Particles {
    let dp = case.numerics.dp_m;
    let d = case.dim();
    let (lo, hi) = lattice_bounds(case);
    let mut out = Particles::default();
    let mut taken: HashSet<Vec<i64>> = HashSet::new();
    let gravity = case.gravity_magnitude();
    let push = |p: &[i64], phase: u32, rho: f64, out: &mut Particles| {
        let mut pos = [0.0f32; 4];
        for k in 0..d {
            pos[k] = (p[k] as f64 * dp) as f32;
        }
        pos[3] = f32::from_bits(phase);
        out.ids.push(out.positions.len() as u32);
        out.positions.push(pos);
        out.vel_rho.push([0.0, 0.0, 0.0, rho as f32]);
    };
    let (wlo, whi) = wall_box(case, &lo, &hi);
    let wall = derived.phases[WALL_PHASE as usize];
    let wall_b = tait_b(derived.c0, wall.rho0);
    let reach = f64::from(case.walls.layers) * dp + 1e-9;
    // Walls under fluid start at the hydrostatic density of what lies above them, so that the
    // fluid does not first sink into walls at rest density.
    let push_wall = |p: &[i64], out: &mut Particles| {
        let x: Vec<f64> = p.iter().map(|v| *v as f64 * dp).collect();
        let pressure = hydrostatic_pressure(case, &x, reach, gravity);
        push(
            p,
            WALL_PHASE,
            tait_density(wall.rho0, wall_b, pressure),
            out,
        );
    };
    for_each_point(&wlo, &whi, |p| {
        if is_wall(case, p, &lo, &hi) {
            taken.insert(p.to_vec());
            push_wall(p, &mut out);
        }
    });
    for block in &case.walls.blocks {
        let (blo, bhi) = block_bounds(case, &block.min_m, &block.max_m);
        for_each_point(&blo, &bhi, |p| {
            if taken.insert(p.to_vec()) {
                push_wall(p, &mut out);
            }
        });
    }
    for block in &case.fluid_blocks {
        let Some(k) = case.phase_index(&block.phase) else {
            continue;
        };
        let phase = k as u32 + 1;
        let props = derived.phases[phase as usize];
        let b = tait_b(derived.c0, props.rho0);
        let (blo, bhi) = block_bounds(case, &block.min_m, &block.max_m);
        for_each_point(&blo, &bhi, |p| {
            if taken.insert(p.to_vec()) {
                // Hydrostatic start so that the column does not first bounce.
                let x: Vec<f64> = p.iter().map(|v| *v as f64 * dp).collect();
                let pressure = hydrostatic_pressure(case, &x, 0.0, gravity);
                push(p, phase, tait_density(props.rho0, b, pressure), &mut out);
            }
        });
    }
    if let Some(f) = &case.open_flume {
        let water = 1 + case.sediment_phases().map_or(0, |(_, w)| w) as u32;
        let rho0 = derived.phases[water as usize].rho0;
        for p in inlet_points(case, f) {
            if taken.insert(p.clone()) {
                push(&p, water, rho0, &mut out);
            }
        }
        let parking = Parking::new(case, derived.h);
        let parked = parked_phase(case);
        for _ in 0..f.reservoir_particles {
            let id = out.positions.len() as u32;
            let [x, y] = parking.spot(id);
            out.ids.push(id);
            out.positions.push([x, y, 0.0, f32::from_bits(parked)]);
            out.vel_rho.push([0.0, 0.0, 0.0, rho0 as f32]);
        }
    }
    out
}

/// Lattice points of the inlet buffer at the start: `layers` columns next to the upstream
/// wall, over the opening's height (block semantics: `y_min < y <= y_min + height`).
fn inlet_points(case: &Case, f: &crate::config::OpenFlume) -> Vec<Vec<i64>> {
    let (lo, _) = lattice_bounds(case);
    let dp = case.numerics.dp_m;
    let (ylo, yhi) = block_bounds(
        case,
        &[f.inlet.y_min_m],
        &[f.inlet.y_min_m + f.inlet.height_m],
    );
    let mut points = Vec::new();
    for i in 1..=i64::from(f.inlet.layers) {
        for j in ylo[0]..=yhi[0] {
            if (j as f64) * dp > case.domain.min_m[1] {
                points.push(vec![lo[0] + i, j]);
            }
        }
    }
    points
}

/// Pressure at `x` of the fluid blocks above it at rest, Pa: each block whose horizontal
/// extent (widened by `reach`) holds `x` adds rho0 g times the part of its height above `x`.
/// Blocks are taken as layers that do not overlap (a sediment bed under water, say). Below
/// the lowest block (wall particles) the lowest block's gradient carries on, so that the
/// walls' pressure keeps rising with depth as DBC needs to hold the fluid up.
fn hydrostatic_pressure(case: &Case, x: &[f64], reach: f64, gravity: f64) -> f64 {
    let d = x.len();
    let z = x[d - 1];
    let mut pressure = 0.0;
    let mut lowest: Option<(f64, f64)> = None;
    for b in case
        .fluid_blocks
        .iter()
        .filter(|b| (0..d - 1).all(|k| x[k] >= b.min_m[k] - reach && x[k] <= b.max_m[k] + reach))
    {
        let rho0 = case
            .phase_index(&b.phase)
            .map_or(0.0, |k| case.phases[k].rho0_kg_per_m3);
        let bottom = b.min_m[d - 1];
        pressure += rho0 * gravity * (b.max_m[d - 1] - z.max(bottom)).max(0.0);
        if lowest.is_none_or(|(low, _)| bottom < low) {
            lowest = Some((bottom, rho0));
        }
    }
    match lowest {
        Some((bottom, rho0)) if z < bottom => pressure + rho0 * gravity * (bottom - z),
        _ => pressure,
    }
}

/// The density at which the Tait equation gives `pressure`.
fn tait_density(rho0: f64, b: f64, pressure: f64) -> f64 {
    rho0 * (1.0 + pressure / b).powf(1.0 / 7.0)
}

/// Number of particles `generate` would make, without making them (for limit checks).
pub fn count(case: &Case) -> u64 {
    let (lo, hi) = lattice_bounds(case);
    let (wlo, whi) = wall_box(case, &lo, &hi);
    let boxes = |a: &[i64], b: &[i64]| -> u64 {
        a.iter()
            .zip(b)
            .map(|(l, h)| (h - l + 1).max(0) as u64)
            .product()
    };
    let d = lo.len();
    // Walls: the wall box minus its interior (lattice points strictly inside the tank's faces).
    let inner_lo: Vec<i64> = lo.iter().map(|v| v + 1).collect();
    let inner_hi: Vec<i64> = (0..d)
        .map(|k| {
            if k == d - 1 && !case.walls.closed_top {
                hi[k]
            } else {
                hi[k] - 1
            }
        })
        .collect();
    let mut n = boxes(&wlo, &whi) - boxes(&inner_lo, &inner_hi);
    // Wall and fluid blocks: an upper bound when blocks overlap, exact otherwise; it only
    // guards limits.
    let blocks = case.walls.blocks.iter().map(|b| (&b.min_m, &b.max_m));
    for (min, max) in blocks.chain(case.fluid_blocks.iter().map(|b| (&b.min_m, &b.max_m))) {
        let (blo, bhi) = block_bounds(case, min, max);
        let clo: Vec<i64> = blo.iter().zip(&inner_lo).map(|(a, b)| *a.max(b)).collect();
        let chi: Vec<i64> = bhi.iter().zip(&inner_hi).map(|(a, b)| *a.min(b)).collect();
        n += boxes(&clo, &chi);
    }
    if let Some(f) = &case.open_flume {
        n += inlet_points(case, f).len() as u64 + u64::from(f.reservoir_particles);
    }
    n
}

/// The Tait constant B = c0^2 rho0 / 7 (Eq. 4, gamma = 7), in f64 for case setup.
pub fn tait_b(c0: f64, rho0: f64) -> f64 {
    c0 * c0 * rho0 / 7.0
}

/// h, c0 and the phase table of a case.
pub fn derive(case: &Case) -> Derived {
    let d = case.dim();
    let dp = case.numerics.dp_m;
    let vmin = case.domain.min_m[d - 1];
    let top = case
        .fluid_blocks
        .iter()
        .map(|b| b.max_m[d - 1])
        .fold(vmin, f64::max);
    let fluid_height = top - vmin;
    let c0 = match case.numerics.sound_speed {
        SoundSpeed {
            c0_m_per_s: Some(c),
            ..
        } => c,
        // A validated case gives exactly one of the two; a case built in code without either
        // gets MODEL.md's usual c0 = 10 u_max.
        SoundSpeed { coefsound, .. } => crate::physics::eos::c0_from_coefsound(
            coefsound.unwrap_or(10.0),
            case.gravity_magnitude(),
            fluid_height,
        ),
    };
    let vol = dp.powi(d as i32);
    let mut phases = vec![PhaseProps {
        rho0: case.phases[0].rho0_kg_per_m3,
        mass: case.phases[0].rho0_kg_per_m3 * vol,
        viscosity_pa_s: case.phases[0].viscosity_pa_s,
        mobile: false,
    }];
    phases.extend(case.phases.iter().map(|p| PhaseProps {
        rho0: p.rho0_kg_per_m3,
        mass: p.rho0_kg_per_m3 * vol,
        viscosity_pa_s: p.viscosity_pa_s,
        mobile: true,
    }));
    if case.open_flume.is_some() {
        // Parked particles are water waiting out of the flow.
        let water = 1 + case.sediment_phases().map_or(0, |(_, w)| w);
        phases.push(PhaseProps {
            mobile: false,
            ..phases[water]
        });
    }
    Derived {
        h: case.smoothing_length_m(),
        c0,
        fluid_height,
        phases,
    }
}
