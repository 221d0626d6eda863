//! The rheology pass by hand: the bed's normal, the Shields chain, the regions and the wear.

use super::*;

use crate::physics::Phase;
use crate::physics::sediment::pickup::{EXNER_WHOLE, PICKUP_WHOLE, units_word};

/// The case's sand (d50 0.4 mm, 2710 kg/m3, phi 32 deg) in the Shields-only mode, at
/// dp = 1 cm with h = 1.7 dp: phases wall, water, sand.
fn flume_case() -> (Params, SedimentModel) {
    let dp = 0.01;
    let phase = |rho0: f32, mobile: bool| Phase {
        rho0,
        mass: rho0 * dp * dp,
        mu: 1e-3,
        mobile,
        generalised_wall: false,
    };
    let params = Params {
        dim: 2,
        h: 1.7 * dp,
        c0: 10.0,
        gravity: [0.0, -9.81, 0.0],
        hydrostatic_diffusion: true,
        delta: 0.1,
        viscosity: Viscosity::Multiphase {
            alpha: 0.0,
            sps_length2: 0.0,
        },
        clamp_negative_pressure: false,
        generalised_walls: true,
        cfl: 0.2,
        phases: vec![
            phase(1000.0, false),
            phase(1000.0, true),
            phase(2710.0, true),
        ],
    };
    let model = SedimentModel {
        material: crate::physics::sediment::flume_sand(),
        sediment_phase: 2,
        water_phase: 1,
        shields_only: true,
        water_speed: false,
        rests_beside_solid: false,
        mu_max: 50.0,
        pickup_per_s: 0.0,
        pickup_integrated: false,
        exner_step_per_stage: 0.0,
        dp_m: 0.01,
    };
    (params, model)
}

/// The Shields chain of the particle at the origin, the top of a flat bed of 13 x 5
/// particles at rest whose columns `x < 0` are of `left_phase`, under `water` (positions,
/// moving at 0.5 m/s along +x).
fn chain_on_flat_bed(left_phase: u32, water: &[[f32; 2]]) -> ShieldsChain {
    chain_of_grain(flume_case().1, left_phase, water, 0.0)
}

/// [`chain_on_flat_bed`] with `model`, the grain at the origin moving at `grain_u` along +x.
fn chain_of_grain(
    model: SedimentModel,
    left_phase: u32,
    water: &[[f32; 2]],
    grain_u: f32,
) -> ShieldsChain {
    let params = flume_case().0;
    let pass = Rheology::new(&params, &model);
    let dp = 0.01;
    let at = |x: f32, y: f32, phase: u32| [x, y, 0.0, f32::from_bits(phase)];
    let mut pos: Vec<[f32; 4]> = Vec::new();
    let mut vel: Vec<[f32; 4]> = Vec::new();
    for row in 0..5 {
        for col in -6..=6 {
            let phase = if col < 0 { left_phase } else { 2 };
            let u = if row == 0 && col == 0 { grain_u } else { 0.0 };
            pos.push(at(col as f32 * dp, -(row as f32) * dp, phase));
            vel.push([u, 0.0, 0.0, params.phases[phase as usize].rho0]);
        }
    }
    for w in water {
        pos.push(at(w[0], w[1], 1));
        vel.push([0.5, 0.0, 0.0, 1000.0]);
    }
    let i = pos.iter().position(|p| p[0] == 0.0 && p[1] == 0.0);
    let i = i.expect("the bed's top at the origin");
    let mut s = pass.start(&pos[i], &vel[i]);
    for j in 0..pos.len() {
        pass.add_pair((&pos[i], &vel[i]), (&pos[j], &vel[j]), &mut s);
    }
    pass.shields_chain(&s)
}

#[test]
fn a_grain_carried_at_the_waters_speed_feels_the_flow_only_by_the_waters_own_speed() {
    // Water 1 cm over the bed's top grain at 0.5 m/s, the grain carried along at 0.5 m/s.
    // Relative to the grain the water stands still: no shear. By the water's own speed, the
    // log law of Eqs. 19-21 with z = 0.01 m, ks = 3 d50 = 1.2 mm, nu = 1e-6 m2/s: rough
    // first, z0 = 0.033 ks = 3.96e-5 m, u* = 0.41 * 0.5 / ln(0.01 / 3.96e-5) = 0.03706 m/s;
    // ks u* / nu = 44.5 is transitional, z0 = 0.11 nu / u* + 0.033 ks = 4.253e-5 m after two
    // rounds, u* = 0.205 / ln(235.1) = 0.037546 m/s, tau_b = rho_w u*^2 = 1.4097 Pa.
    let dp = 0.01;
    let water = [[0.0, dp]];
    let relative = chain_of_grain(flume_case().1, 2, &water, 0.5);
    assert!(relative.at_surface, "{relative:?}");
    assert_eq!(relative.speed_m_per_s, 0.0, "{relative:?}");
    assert_eq!(relative.tau_b_pa, 0.0, "{relative:?}");
    let model = SedimentModel {
        water_speed: true,
        ..flume_case().1
    };
    let own = chain_of_grain(model.clone(), 2, &water, 0.5);
    assert_eq!(own.speed_m_per_s, 0.5, "{own:?}");
    assert!((own.z_m - dp).abs() < 1e-6, "{own:?}");
    assert!((own.tau_b_pa - 1.4097).abs() < 2e-3, "{own:?}");
    assert!(own.tau_b_pa > own.tau_bcr_pa, "{own:?}");
    // A grain at rest feels the same either way.
    let at_rest = chain_of_grain(model, 2, &water, 0.0);
    assert_eq!(at_rest, own, "the grain at rest");
    assert_eq!(chain_of_grain(flume_case().1, 2, &water, 0.0), own);
}

/// The chain's critical stress is a flat bed's for its friction velocity (slope factor 1).
fn assert_flat_critical_stress(chain: &ShieldsChain) {
    let m = crate::physics::sediment::flume_sand();
    let theta = critical_shields(chain.u_star_m_per_s * m.d50_m / m.nu_w);
    let flat = critical_bed_shear_stress(theta, m.rho_s, m.rho_w, 9.81, m.d50_m);
    assert!(
        (chain.tau_bcr_pa - flat).abs() < 1e-4 * flat,
        "{} Pa against the flat bed's {flat} Pa",
        chain.tau_bcr_pa
    );
}

#[test]
fn a_flat_bed_under_water_on_one_side_is_flat() {
    // The tip of a sheet one particle thick: water over the bed only downstream of the
    // grain. Its slope is the bed's (flat), not the water's: a normal taken from the
    // water leans 45 deg downstream, past the friction angle, and gives tau_bcr = 0.
    let dp = 0.01;
    let sheet = [[dp, dp], [2.0 * dp, dp], [3.0 * dp, dp]];
    let chain = chain_on_flat_bed(2, &sheet);
    assert!(chain.at_surface && chain.u_star_m_per_s > 0.0, "{chain:?}");
    assert_flat_critical_stress(&chain);
}

#[test]
fn a_wall_level_with_the_bed_is_bed() {
    // The sand's first column beside the apron: the wall upstream at the same level is as
    // solid as sand. Counting sand alone, the normal would lean 20-odd deg upstream.
    let dp = 0.01;
    let water = [[-dp, dp], [0.0, dp], [dp, dp]];
    let chain = chain_on_flat_bed(0, &water);
    assert_flat_critical_stress(&chain);
}

/// A flat bed of 13 x 5 held sand particles (x from -6 dp to 6 dp, its top at y = 0) under a
/// row of water dp over it flowing at 0.5 m/s along +x, worn by van Rijn's pick-up
/// (`van_rijn_exner` with `exner`, else `van_rijn_integrated`): positions, velocities, and
/// the region words of a bed held with `worn` of each particle worn off.
fn worn_bed(exner: bool, worn: i32) -> (SedimentModel, Vec<[f32; 4]>, Vec<[f32; 4]>, Words) {
    let model = flume_case().1.worn_by_van_rijn(exner);
    let at = |col: i32, y: f32, phase: u32| [col as f32 * 0.01, y, 0.0, f32::from_bits(phase)];
    let (mut pos, mut vel, mut words) = (Vec::new(), Vec::new(), Vec::new());
    for row in 0..5 {
        for col in -6..=6 {
            pos.push(at(col, -(row as f32) * 0.01, 2));
            vel.push([0.0, 0.0, 0.0, 2710.0]);
            words.push(Region::Unyielded as u32 | REGION_HELD | units_word(worn));
        }
    }
    for col in -6..=6 {
        pos.push(at(col, 0.01, 1));
        vel.push([0.5, 0.0, 0.0, 1000.0]);
        words.push(Region::Water as u32);
    }
    (model, pos, vel, words)
}

/// Region words, one a particle.
type Words = Vec<u32>;

/// The top row's column `col` in [`worn_bed`]'s order.
fn top(col: i32) -> usize {
    (col + 6) as usize
}

/// One pass of a second over [`worn_bed`] (the step's share then its whole second's), from
/// the words, and the loads passed on and where, before: what each particle gives.
fn wear_for_a_second(
    model: &SedimentModel,
    (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
    (words, passed): (&[u32], &Passed),
) -> Vec<ParticleRheology> {
    let params = flume_case().0;
    let draws = Some(Draws { step: 1, dt_s: 1.0 });
    let before = (words, passed.0.as_slice(), passed.1.as_slice());
    rheology_pass_exner(&params, model, (pos, vel), before, draws)
}

/// The loads particles passed on in a pass, and the particles they passed them to.
type Passed = (Vec<f32>, Vec<u32>);

/// What the particles of a pass passed on, and to which.
fn passed(out: &[ParticleRheology]) -> Passed {
    out.iter().map(|r| (r.flux, r.target)).unzip()
}

#[test]
fn a_bed_under_a_flow_the_same_all_along_it_wears_only_where_nothing_comes_from_upstream() {
    let (model, pos, vel, words) = worn_bed(true, 0);
    let none = (vec![NO_FLUX; pos.len()], vec![NO_TARGET; pos.len()]);
    let whole = EXNER_WHOLE as f32;
    // By hand: z = dp, 0.5 m/s give u* = 0.037546 m/s and tau_b = 1.4097 Pa (the test above);
    // Re* = 0.037546 x 4e-4 / 1e-6 = 15.018, Eq. 17 theta_cr = 0.010595 ln 15.018 + 0.110476 /
    // 15.018 + 0.0027197 = 0.038781, tau_bcr = 0.038781 x 1710 x 9.81 x 4e-4 = 0.26022 Pa on
    // the flat bed, T = 4.4174; the rate 5.432e-3 T^1.5 = 0.05043 per second (pickup.rs), the
    // step 3 d50 D*^0.6 T^0.9 / dp = 0.48456 T^0.9 = 1.845 particles (D* = 10.2396), so the
    // bed load the flow can carry is 0.09305 particles per second.
    let chain_t = 1.4097 / 0.26022 - 1.0_f64;
    let (rate, capacity) = (0.05043, 0.09305);
    assert!((5.432e-3 * chain_t.powf(1.5) - rate).abs() < 1e-5);
    assert!((rate * 0.48456 * chain_t.powf(0.9) - capacity).abs() < 1e-4);
    // Passed nothing yet, each top particle passes on what is picked up of it, not what the
    // flow could carry: its pick-up, all of which it loses. None knew which of its neighbours
    // were held at the surface, so none names one downstream; from the next pass they do.
    let first = wear_for_a_second(&model, (&pos, &vel), (&words, &none));
    let e = first[top(0)].flux;
    assert!(
        (f64::from(e) / rate - 1.0).abs() < 0.05,
        "{e} against {rate}"
    );
    assert!((first[top(0)].pickup as f32 - e * whole).abs() <= 1.0);
    assert!(first.iter().all(|r| r.target == NO_TARGET));
    let first = wear_for_a_second(&model, (&pos, &vel), (&words, &passed(&first)));
    assert!((first[top(0)].pickup as f32 - e * whole).abs() <= 1.0);
    // The bed's end faces are surface too; its middle's buried particles are not.
    for row in 1..5 {
        for col in -3..=3 {
            let k = top(col) + 13 * row;
            assert_eq!(
                (first[k].flux, first[k].target),
                (NO_FLUX, NO_TARGET),
                "buried {k}"
            );
        }
    }
    for (k, water) in first.iter().enumerate().skip(65) {
        assert_eq!(water.flux, NO_FLUX, "water particle {k}");
    }
    // Each top particle passes its load to the next downstream (ids are indices here). On the
    // bed's last column, whose corner faces the flow over the end, nothing holds a grain
    // (tau_bcr = 0): it leaves whole, worn of nothing, and in the pass it leaves in still takes
    // load, so the one before names it (what that passes settles on the moving grain).
    for col in -6..6 {
        assert_eq!(first[top(col)].target, top(col + 1) as u32, "column {col}");
    }
    let last = &first[top(6)];
    assert!(
        !last.held && last.flux == 0.0 && last.pickup == 0 && last.target == NO_TARGET,
        "{last:?}"
    );
    // Passed its upstream neighbour's pick-up, a top particle of the bed's middle passes on
    // what the flow can carry, and loses that less what it was passed.
    let second = wear_for_a_second(&model, (&pos, &vel), (&words, &passed(&first)));
    let q = second[top(0)].flux;
    assert!(
        (f64::from(q) / capacity - 1.0).abs() < 0.05,
        "{q} against {capacity}"
    );
    assert!((second[top(0)].pickup as f32 - (q - e) * whole).abs() <= 1.0);
    // Passed that, it loses nothing to a unit in 2^22. The bed's first column, passed nothing
    // and under a weaker shear at the bed's end, loses what it passes on.
    let fluxes = passed(&second);
    let third = wear_for_a_second(&model, (&pos, &vel), (&words, &fluxes));
    for col in -1..=2 {
        let r = &third[top(col)];
        assert!(r.held && r.pickup.abs() <= 2, "column {col}: {r:?}");
    }
    let first_col = &third[top(-6)];
    let own = first_col.flux * whole;
    assert!(
        (first_col.pickup as f32 - own).abs() <= 1.0,
        "{first_col:?}"
    );
    // Worn by the pick-up alone, the middle loses as much as the first particle.
    let (gross, pos, vel, words) = worn_bed(false, 0);
    let alone = wear_for_a_second(&gross, (&pos, &vel), (&words, &none));
    let picked = f64::from(alone[top(0)].pickup) / f64::from(PICKUP_WHOLE);
    assert!((picked / rate - 1.0).abs() < 0.05, "{picked}");
    // Starved again (column -1 made to pass none on), column 0 loses its pick-up and no more,
    // though its grains' step is longer than the particle, and passes on only that.
    let mut starved = fluxes.clone();
    starved.0[top(-1)] = 0.0;
    let (model, pos, vel, words) = worn_bed(true, 0);
    let fourth = wear_for_a_second(&model, (&pos, &vel), (&words, &starved));
    let r = &fourth[top(0)];
    let lost = f64::from(r.pickup) / f64::from(EXNER_WHOLE);
    assert!(
        (lost - picked).abs() < 5e-7,
        "{r:?}: {lost} against {picked}"
    );
    assert!((f64::from(r.flux) / picked - 1.0).abs() < 1e-4, "{r:?}");
}

/// Each particle gains what it is passed less what it passes on: `units` after the pass
/// against those before, within the draw's rounding.
fn assert_balanced(r: &ParticleRheology, before: i32, passed: f32) {
    let want = before as f32 + (r.flux - passed) * EXNER_WHOLE as f32;
    assert!((r.pickup as f32 - want).abs() <= 2.0, "{r:?}: {want}");
}

#[test]
fn bed_load_from_upstream_fills_what_was_worn_then_builds_the_bed() {
    let whole = EXNER_WHOLE as i32;
    let half = whole / 2;
    let (model, pos, vel, words) = worn_bed(true, half);
    let none = (vec![NO_FLUX; pos.len()], vec![NO_TARGET; pos.len()]);
    let first = wear_for_a_second(&model, (&pos, &vel), (&words, &none));
    let first = wear_for_a_second(&model, (&pos, &vel), (&words, &passed(&first)));
    let mut fluxes = passed(&first);
    // Column -1 passes on ten times its pick-up, more than the flow carries: column 0 keeps
    // what it cannot pass on.
    let e = fluxes.0[top(0)];
    fluxes.0[top(-1)] = 10.0 * e;
    // Column 1 passes its load to column 3, past column 2: column 2 is passed nothing and
    // column 3 both loads, each counted once.
    fluxes.1[top(1)] = top(3) as u32;
    let second = wear_for_a_second(&model, (&pos, &vel), (&words, &fluxes));
    assert!(
        second[top(0)].pickup < half - whole / 4,
        "{:?}",
        second[top(0)]
    );
    assert_balanced(&second[top(0)], half, 10.0 * e);
    assert_balanced(&second[top(2)], half, 0.0);
    assert_balanced(&second[top(3)], half, 2.0 * e);
    // Passed more than was worn off it, a particle builds the bed up: more than whole, held.
    let (model, pos, vel, words) = worn_bed(true, 100);
    let second = wear_for_a_second(&model, (&pos, &vel), (&words, &fluxes));
    assert!(second[top(0)].held && second[top(0)].pickup < -whole / 4);
    assert_balanced(&second[top(0)], 100, 10.0 * e);
    // Built up a whole particle more, all but a thousand units, it keeps those and passes the
    // rest on.
    let (model, pos, vel, words) = worn_bed(true, 1000 - whole);
    let second = wear_for_a_second(&model, (&pos, &vel), (&words, &fluxes));
    assert!(second[top(0)].pickup <= 1 - whole, "{:?}", second[top(0)]);
    assert_balanced(&second[top(0)], 1000 - whole, 10.0 * e);
}

/// A wet front: [`worn_bed`] with water over its columns -6 to -1 only. Column 2 is the last
/// the water's kernel reaches (3.2 dp from the water over column -1, against a support of
/// 3.4 dp); column 3 and on are dry.
#[test]
fn bed_load_carried_to_a_wet_front_settles_on_the_dry_bed_ahead() {
    let (model, mut pos, mut vel, mut words) = worn_bed(true, 0);
    for v in [&mut pos, &mut vel] {
        v.truncate(65 + 6);
    }
    words.truncate(65 + 6);
    let none = (vec![NO_FLUX; pos.len()], vec![NO_TARGET; pos.len()]);
    let first = wear_for_a_second(&model, (&pos, &vel), (&words, &none));
    // The dry top is held and offers to take bed load: a flux of its own, none to pass on.
    // Its end face and its underside, whose normals lean 45 deg or more from straight up, do
    // not; nor does the corner between them.
    for col in 3..=5 {
        let r = &first[top(col)];
        assert!(
            r.held && r.flux == 0.0 && r.pickup == 0,
            "column {col}: {r:?}"
        );
    }
    let faces = (0..5)
        .map(|row| top(6) + 13 * row)
        .chain((3..6).map(|col| top(col) + 13 * 4));
    for k in faces {
        assert_eq!(first[k].flux, NO_FLUX, "particle {k}");
    }
    let mut fluxes = passed(&wear_for_a_second(
        &model,
        (&pos, &vel),
        (&words, &passed(&first)),
    ));
    assert_eq!(
        fluxes.1[top(2)],
        top(3) as u32,
        "the last wet column names the dry one"
    );
    // What column 2 passes on settles on column 3, which passes none on.
    let load = 0.05;
    fluxes.0[top(2)] = load;
    let third = wear_for_a_second(&model, (&pos, &vel), (&words, &fluxes));
    let dry = &third[top(3)];
    assert!(
        dry.held && dry.flux == 0.0 && dry.target == NO_TARGET,
        "{dry:?}"
    );
    assert_balanced(dry, 0, load);
    assert_eq!(third[top(4)].pickup, 0, "passed nothing");
}

/// Worn whole under Exner's balance, a particle leaves the bed keeping all but a unit of its
/// wear: its mass went downstream as bed load, so the moving grain carries none of its own.
/// Not held, it wears no more and keeps its units, where worn by the pick-up alone a released
/// grain starts whole.
#[test]
fn a_grain_worn_whole_carries_its_wear_off_the_bed() {
    use crate::physics::sediment::pickup::EXNER_SPENT;
    let whole = EXNER_WHOLE as i32;
    let (model, pos, vel, words) = worn_bed(true, whole - 10);
    let none = (vec![NO_FLUX; pos.len()], vec![NO_TARGET; pos.len()]);
    let first = wear_for_a_second(&model, (&pos, &vel), (&words, &none));
    // It passes on the load of the pass it leaves in: what was left of it, 9 units over the
    // second, though the flow could pick up 0.05 of a particle (nothing came from upstream).
    let r = &first[top(0)];
    assert!(!r.held && r.pickup == EXNER_SPENT, "{r:?}");
    assert_eq!(r.flux, 9.0 / EXNER_WHOLE as f32, "{r:?}");
    let words: Words = first.iter().map(ParticleRheology::word).collect();
    let second = wear_for_a_second(&model, (&pos, &vel), (&words, &passed(&first)));
    let r = &second[top(0)];
    assert!(!r.held && r.pickup == EXNER_SPENT, "{r:?}");
    // A grain the bed does not hold, a third worn, keeps that and wears no more; what is
    // passed to it settles on it.
    let (model, pos, vel, mut loose) = worn_bed(true, 0);
    loose[top(0)] = Region::BedLoad as u32 | units_word(whole / 3);
    let mut fluxes = (vec![NO_FLUX; pos.len()], vec![NO_TARGET; pos.len()]);
    let third = wear_for_a_second(&model, (&pos, &vel), (&loose, &fluxes));
    assert_eq!(third[top(0)].pickup, whole / 3, "{:?}", third[top(0)]);
    fluxes.0[top(-1)] = 0.05;
    fluxes.1[top(-1)] = top(0) as u32;
    let fourth = wear_for_a_second(&model, (&pos, &vel), (&loose, &fluxes));
    let settled = (whole / 3) as f32 - 0.05 * whole as f32;
    let r = &fourth[top(0)];
    assert!(
        !r.held && (r.pickup as f32 - settled).abs() <= 1.0,
        "{r:?}: {settled}"
    );
    // By the pick-up alone it would start whole.
    let (gross, pos, vel, mut words) = worn_bed(false, 0);
    words[top(0)] = Region::BedLoad as u32 | units_word(1000);
    let alone = wear_for_a_second(&gross, (&pos, &vel), (&words, &none));
    assert_eq!(alone[top(0)].pickup, 0);
}

/// A grain at rest come down on a flat bed of 13 x 5 held particles (its top at y = 0),
/// in the Drucker-Prager mode, with `beside` (positions and phases) at its level, held again
/// only beside a solid or `anywhere`: whether the pass holds it.
fn grain_on_the_bed_is_held(beside: &[([f32; 2], u32)], anywhere: bool) -> bool {
    let (params, model) = flume_case();
    let model = SedimentModel {
        shields_only: false,
        rests_beside_solid: !anywhere,
        ..model
    };
    let at = |x: f32, y: f32, phase: u32| [x, y, 0.0, f32::from_bits(phase)];
    let rest = |phase: u32| [0.0, 0.0, 0.0, params.phases[phase as usize].rho0];
    let (mut pos, mut vel, mut held) = (Vec::new(), Vec::new(), Vec::new());
    for row in 0..5 {
        for col in -6..=6 {
            pos.push(at(col as f32 * 0.01, -(row as f32) * 0.01, 2));
            vel.push(rest(2));
            held.push(true);
        }
    }
    for &([x, y], phase) in [([0.0, 0.01], 2)].iter().chain(beside) {
        pos.push(at(x, y, phase));
        vel.push(rest(phase));
        held.push(false);
    }
    let grain = 65;
    let out = rheology_pass(&params, &model, &pos, &vel, &held);
    // The bed stays held whatever lies on it.
    assert!(out[..grain].iter().all(|r| r.held));
    out[grain].held
}

#[test]
fn a_grain_alone_on_the_bed_is_not_held_and_one_in_a_row_is() {
    assert!(!grain_on_the_bed_is_held(&[], false));
    // As the paper's model holds it, anywhere.
    assert!(grain_on_the_bed_is_held(&[], true));
    // A grain a row higher, or over the next column's gap, is not at its level.
    assert!(!grain_on_the_bed_is_held(&[([0.0, 0.02], 2)], false));
    assert!(!grain_on_the_bed_is_held(&[([0.015, 0.02], 2)], false));
    assert!(grain_on_the_bed_is_held(&[([0.01, 0.01], 2)], false));
    assert!(grain_on_the_bed_is_held(&[([-0.012, 0.013], 2)], false));
    // A wall beside it holds it as a grain would.
    assert!(grain_on_the_bed_is_held(&[([0.01, 0.01], 0)], false));
}

/// In 3-D the velocity gradient counts the third axis (Eq. 13: `V_j (u_j - u_i)_a (grad_i
/// W)_b`, with `grad_i W = x_ij F(r)`): a water neighbour straight below in z, moving along x
/// and z, gives `grad[0][2]` and `grad[2][2]` and nothing else. A pair that stopped at two
/// dimensions gives zero for both.
#[test]
fn the_velocity_gradient_counts_the_third_axis_in_3d() {
    let (mut params, model) = flume_case();
    params.dim = 3;
    params.gravity = [0.0, 0.0, -9.81];
    let pass = Rheology::new(&params, &model);
    let water = f32::from_bits(1);
    let (x_i, v_i) = ([0.0, 0.0, 0.0, water], [0.0, 0.0, 0.0, 1000.0]);
    let (x_j, v_j) = ([0.0, 0.0, -0.01, water], [0.3, 0.0, 0.2, 1000.0]);
    let mut s = pass.start(&x_i, &v_i);
    pass.add_pair((&x_i, &v_i), (&x_j, &v_j), &mut s);
    let f = crate::physics::kernel::grad_factor(0.01, params.h, 3);
    let vol = pass.volume(&x_j, &v_j);
    let close = |got: f32, want: f32| (got - want).abs() <= 1e-6 * want.abs();
    assert!(close(s.grad[0][2], vol * 0.3 * 0.01 * f), "{:?}", s.grad);
    assert!(close(s.grad[2][2], vol * 0.2 * 0.01 * f), "{:?}", s.grad);
    for (a, b) in [(0, 0), (0, 1), (1, 0), (1, 1), (1, 2), (2, 0), (2, 1)] {
        assert_eq!(s.grad[a][b], 0.0, "grad[{a}][{b}] of {:?}", s.grad);
    }
}

/// In 3-D the stress divergence counts the third axis: `m_j (tau_i / rho_i^2 + tau_j /
/// rho_j^2)_ab (grad_i W)_b` with `grad_i W = x_ij F(r)`, for a water neighbour straight below
/// in z whose stress has xz and zz parts, gives x and z accelerations and no y. A term that
/// stopped at two dimensions gives zero for both.
#[test]
fn the_stress_divergence_counts_the_third_axis_in_3d() {
    use crate::physics::sediment::stress::StressDivergence;
    let (mut params, _) = flume_case();
    params.dim = 3;
    params.gravity = [0.0, 0.0, -9.81];
    let (dp, rho, water) = (0.01, 1000.0, f32::from_bits(1));
    let div = StressDivergence::new(&params);
    let mut tau_j = [[0.0_f32; 3]; 3];
    (tau_j[0][2], tau_j[2][0], tau_j[2][2]) = (2.0, 2.0, 3.0);
    let i = div.side(&[0.0, 0.0, 0.0, water], rho, &[[0.0; 3]; 3]);
    let j = div.side(&[0.0, 0.0, -dp, water], rho, &tau_j);
    let mut acc = [0.0_f32; 3];
    div.add_pair(&i, &j, &mut acc);
    let mass = params.phases[1].mass;
    let per_stress = mass / (rho * rho) * dp * crate::physics::kernel::grad_factor(dp, params.h, 3);
    let close = |got: f32, want: f32| (got - want).abs() <= 1e-5 * want.abs();
    assert!(close(acc[0], 2.0 * per_stress), "{acc:?}");
    assert!(close(acc[2], 3.0 * per_stress), "{acc:?}");
    assert_eq!(acc[1], 0.0);
}
