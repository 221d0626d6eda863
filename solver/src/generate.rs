//! Turns a validated `Case` into particles on the dp lattice.
//!
//! Like DualSPHysics' GenCase, every particle sits on the lattice of integer multiples of dp:
//! wall particles on the tank's faces and `layers - 1` rows outside them, fluid at the lattice
//! points inside each block (`min < x <= max`) that no wall or earlier block already holds.

use crate::config::{Case, OpenFlume};
use crate::derived::{Derived, tait_b};
use crate::particles::{Parking, Particles, WALL_PHASE, parked_phase};
use std::collections::HashSet;

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

/// Lattice bounds of the case's wall blocks and of the open flume's sill: the sill is a block
/// from the floor to the sediment bed's top, less its top row (`SillConfig`).
fn wall_blocks(case: &Case) -> Vec<(Vec<i64>, Vec<i64>)> {
    let mut blocks: Vec<_> = case
        .walls
        .blocks
        .iter()
        .map(|b| block_bounds(case, &b.min_m, &b.max_m))
        .collect();
    let sill = case.open_flume.as_ref().and_then(|f| f.sill.as_ref());
    if let (Some(s), Some(top)) = (sill, case.bed_top_m()) {
        let floor = case.domain.min_m[1];
        let (lo, mut hi) = block_bounds(case, &[s.x_min_m, floor], &[s.x_max_m, top]);
        hi[1] -= 1;
        blocks.push((lo, hi));
    }
    blocks
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
    for (blo, bhi) in wall_blocks(case) {
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
        park_reservoir(case, derived, f.reservoir_particles, rho0, &mut out);
    }
    out
}

/// Appends the open flume's `count` parked particles, each at its own spot above the flume at
/// the water's rest density `rho0`.
fn park_reservoir(case: &Case, derived: &Derived, count: u32, rho0: f64, out: &mut Particles) {
    let parking = Parking::new(case, derived.h);
    let parked = parked_phase(case);
    for _ in 0..count {
        let id = out.positions.len() as u32;
        let [x, y] = parking.spot(id);
        out.ids.push(id);
        out.positions.push([x, y, 0.0, f32::from_bits(parked)]);
        out.vel_rho.push([0.0, 0.0, 0.0, rho0 as f32]);
    }
}

/// Lattice points of the inlet buffer at the start: `layers` columns next to the upstream
/// wall, over the opening's height (block semantics: `y_min < y <= y_min + height`).
fn inlet_points(case: &Case, f: &OpenFlume) -> Vec<Vec<i64>> {
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
    let fluid = case
        .fluid_blocks
        .iter()
        .map(|b| block_bounds(case, &b.min_m, &b.max_m));
    for (blo, bhi) in wall_blocks(case).into_iter().chain(fluid) {
        let clo: Vec<i64> = blo.iter().zip(&inner_lo).map(|(a, b)| *a.max(b)).collect();
        let chi: Vec<i64> = bhi.iter().zip(&inner_hi).map(|(a, b)| *a.min(b)).collect();
        n += boxes(&clo, &chi);
    }
    if let Some(f) = &case.open_flume {
        n += inlet_points(case, f).len() as u64 + u64::from(f.reservoir_particles);
    }
    n
}
