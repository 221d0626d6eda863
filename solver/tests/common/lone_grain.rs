//! A grain come to rest alone on the bed's top (`sediment_region`'s `lone`): the rheology pass
//! on any backend against the CPU oracle, under either `comes_to_rest`.

use super::sand_stages::{check_rheology_round, sediment_in_motion};
use super::stages::case;
use flume_solver::Backend;
use flume_solver::physics::sediment::suspension::Region;

/// The sand bed in motion ([`sediment_in_motion`]) with a grain at rest a spacing over the
/// bed's top near x = 0.1 m, in place of the water particle there, and every particle within
/// its kernel's support at rest: held as the paper's model holds it (`anywhere`), bed load
/// under `beside_a_solid`, having nothing beside it; the backend agreeing with the oracle both
/// ways (a backend that read the setting wrongly, or not at all, disagrees in one).
pub fn check_lone_grain(backend: &Backend, seed: u64) {
    use flume_solver::config::ComesToRest;
    for (rest, region, held) in [
        (ComesToRest::Anywhere, Region::Unyielded, true),
        (ComesToRest::BesideASolid, Region::BedLoad, false),
    ] {
        let r = lone_grain_rheology(backend, seed, rest);
        assert!(
            r.region == region as u32 && r.held == held,
            "the lone grain under {rest:?}: {r:?}"
        );
    }
}

/// [`check_lone_grain`]'s scene under `rest`: the oracle's rheology of the grain, after
/// checking the backend's regions against the oracle's.
fn lone_grain_rheology(
    backend: &Backend,
    seed: u64,
    rest: flume_solver::config::ComesToRest,
) -> flume_solver::physics::sediment::pass::ParticleRheology {
    use flume_solver::physics::sediment::pass::rheology_pass;
    let mut c = case("tests/cases/sediment_bed_2d.yaml");
    if let Some(s) = c.phases[1].sediment.as_mut() {
        s.comes_to_rest = rest;
    }
    let dp = c.numerics.dp_m as f32;
    let support = 2.0 * c.numerics.coefh as f32 * 2.0_f32.sqrt() * dp;
    let mut lone = usize::MAX;
    let (mut sim, particles, params) = sediment_in_motion(backend, &c, seed, |p| {
        lone = place_on_the_bed(p, dp, support);
    });
    let model = super::reference_sediment(&sim);
    let held = vec![false; particles.len()];
    check_rheology_round(&mut sim, &params, &model, &particles, &held);
    let (pos, vel) = (&particles.positions, &particles.vel_rho);
    rheology_pass(&params, &model, pos, vel, &held)[lone]
}

/// Turns the water particle nearest the point a spacing over the bed's top near x = 0.1 m
/// into a grain at rest there, and stops every particle within `support` of it: its index.
fn place_on_the_bed(p: &mut flume_solver::Particles, dp: f32, support: f32) -> usize {
    let sand = 2;
    let top = (0..p.len())
        .filter(|&i| p.phase(i) == sand && (p.positions[i][0] - 0.1).abs() < 0.5 * dp)
        .max_by(|&a, &b| p.positions[a][1].total_cmp(&p.positions[b][1]))
        .expect("sand under x = 0.1 m");
    let at = [p.positions[top][0], p.positions[top][1] + dp];
    let d2 = |x: &[f32; 4]| (x[0] - at[0]).powi(2) + (x[1] - at[1]).powi(2);
    let grain = (0..p.len())
        .filter(|&i| p.phase(i) == 1)
        .min_by(|&a, &b| d2(&p.positions[a]).total_cmp(&d2(&p.positions[b])))
        .expect("water over the bed");
    p.positions[grain] = [at[0], at[1], 0.0, f32::from_bits(sand)];
    p.vel_rho[grain] = [0.0, 0.0, 0.0, 2710.0];
    for (x, v) in p.positions.iter().zip(p.vel_rho.iter_mut()) {
        if d2(x) < support * support {
            v[..3].fill(0.0);
        }
    }
    grain
}
