//! The sediment stages' checks against their CPU oracles in `flume_solver::physics::sediment`,
//! for any backend (`gpu_vs_reference.rs` on lavapipe, `cpu_vs_reference.rs`): the rheology
//! pass, the release of held sand and the multiphase forces, on a sand bed in motion, and the
//! sediment cases they run on. Tolerances as in [`super::stages`].

use super::stages::{assert_close, assert_step_close, case};
use flume_solver::physics::sediment::pass::REGION_HELD;
use flume_solver::physics::{integrate, interaction};
use flume_solver::{Backend, Case};

/// A sediment case started from its perturbed lattice (random velocities up to 0.3 m/s: strain
/// rates of tens per second, bed shear stresses on both sides of the Shields threshold, yielded
/// and un-yielded sediment) with the lower three quarters of the bed at rest, so that the
/// first rheology pass holds them and the release stage has held sand under moving sand to
/// decide on. `prepare` may then change the particles before the simulation takes them.
pub fn sediment_in_motion(
    backend: &Backend,
    c: &Case,
    seed: u64,
    prepare: impl FnOnce(&mut flume_solver::Particles),
) -> (
    flume_solver::Simulation,
    flume_solver::Particles,
    flume_solver::physics::Params,
) {
    let lattice = flume_solver::Simulation::new(backend.clone(), c).expect("builds");
    let mut particles = super::perturbed(&lattice, 0.3, seed);
    let at_rest_below = 0.75 * c.fluid_blocks[0].max_m[1] as f32;
    for i in 0..particles.len() {
        if particles.phase(i) == 2 && particles.positions[i][1] < at_rest_below {
            particles.vel_rho[i][..3].fill(0.0);
        }
    }
    prepare(&mut particles);
    let sim = flume_solver::Simulation::from_particles(backend.clone(), c, particles.clone())
        .expect("builds");
    let params = super::reference_params(&sim);
    (sim, particles, params)
}

/// A sand bed in motion ([`sediment_in_motion`], with `prepare`) before and after two steps of
/// different lengths on `backend`, with the oracle's parameters and sediment model.
pub struct TwoSteps {
    pub particles: flume_solver::Particles,
    pub params: flume_solver::physics::Params,
    pub model: flume_solver::physics::sediment::pass::SedimentModel,
    pub after: flume_solver::Particles,
    pub dt: f32,
    pub dt2: f32,
}

pub fn two_steps_of_sand_in_motion(
    backend: &Backend,
    c: &Case,
    seed: u64,
    prepare: impl FnOnce(&mut flume_solver::Particles),
) -> TwoSteps {
    let (mut sim, particles, params) = sediment_in_motion(backend, c, seed, prepare);
    let model = super::reference_sediment(&sim);
    let (dt, dt2) = (2.0e-5f32, 1.5e-5f32);
    sim.advance_to(f64::from(dt)).expect("step 1");
    sim.advance_to(f64::from(dt) + f64::from(dt2))
        .expect("step 2");
    assert_eq!(sim.steps(), 2);
    let after = sim.read_particles().expect("readback");
    TwoSteps {
        particles,
        params,
        model,
        after,
        dt,
        dt2,
    }
}

/// One round of `check_rheology`: the GPU's rheology, release and force passes from the holds
/// `held` against the CPU's. Returns the holds after it, how many held particles it released
/// and the count of each region (walls, 1-5).
pub fn check_rheology_round(
    sim: &mut flume_solver::Simulation,
    params: &flume_solver::physics::Params,
    model: &flume_solver::physics::sediment::pass::SedimentModel,
    particles: &flume_solver::Particles,
    held: &[bool],
) -> (Vec<bool>, usize, [usize; 6]) {
    use flume_solver::physics::sediment::{hold, pass, stress};
    let (pos, vel) = (&particles.positions, &particles.vel_rho);
    let (gpu_forces, gpu_dt) = sim.compute_forces().expect("forces");
    let gpu_regions = sim.regions().expect("regions");
    let mut rheology = pass::rheology_pass(params, model, pos, vel, held);
    let held_in_rheology: Vec<bool> = rheology.iter().map(|r| r.held).collect();
    hold::release_pass(params, model, pos, vel, &mut rheology);
    let released = (0..rheology.len())
        .filter(|&i| held_in_rheology[i] && !rheology[i].held)
        .count();
    let cpu_regions: Vec<u32> = rheology
        .iter()
        .map(|r| r.region | if r.held { 256 } else { 0 })
        .collect();
    // A comparison at a threshold (Shields, Drucker-Prager, c_v, the surface mass) may go
    // either way under f32 rounding of sums taken in different orders; none did here.
    let differ: Vec<usize> = (0..cpu_regions.len())
        .filter(|&i| cpu_regions[i] != gpu_regions[i])
        .collect();
    assert!(
        differ.is_empty(),
        "{} regions differ, first: particle {} gpu {} cpu {}",
        differ.len(),
        differ[0],
        gpu_regions[differ[0]],
        cpu_regions[differ[0]]
    );
    let mut count = [0usize; 6];
    for r in &cpu_regions {
        count[(*r & 255) as usize] += 1;
    }
    let mut cpu = interaction::interact(params, pos, vel);
    let stress = stress::stress_divergence(params, pos, vel, &rheology);
    for (f, s) in cpu.forces.iter_mut().zip(&stress) {
        for k in 0..3 {
            f[k] += s[k];
        }
    }
    // The Shields-only mode's held sand is fixed where it stands (these cases' walls are
    // DBC): the backends sum only its density rate, give it no acceleration and let it not
    // bound the step (`interaction::Side::fixed`).
    for ((f, dt), r) in cpu.forces.iter_mut().zip(&mut cpu.dt_limit).zip(&rheology) {
        if r.held && model.shields_only {
            f[..3].fill(0.0);
            *dt = f32::INFINITY;
        }
    }
    let dim = params.dim as usize;
    assert_close(
        "multiphase acceleration",
        &gpu_forces,
        &cpu.forces,
        dim,
        1e-4,
    );
    let drho: Vec<[f32; 4]> = gpu_forces.iter().map(|f| [f[3], 0.0, 0.0, 0.0]).collect();
    let drho_cpu: Vec<[f32; 4]> = cpu.forces.iter().map(|f| [f[3], 0.0, 0.0, 0.0]).collect();
    assert_close("multiphase density rate", &drho, &drho_cpu, 1, 1e-4);
    let h = params.h;
    let cpu_dt = cpu
        .dt_limit
        .iter()
        .zip(&rheology)
        .zip(vel)
        .map(|((&dt, r), v)| {
            if r.mu > 0.0 {
                dt.min(0.125 * h * h * v[3] / r.mu)
            } else {
                dt
            }
        })
        .fold(f32::INFINITY, f32::min);
    assert!(
        ((gpu_dt - cpu_dt) / cpu_dt).abs() < 1e-4,
        "stable step: gpu {gpu_dt} cpu {cpu_dt}"
    );
    (rheology.iter().map(|r| r.held).collect(), released, count)
}

/// The rheology pass, the release of held sediment and the multiphase force pass against
/// `sediment::pass` and `sediment::hold`: regions word for word, accelerations (pressure plus
/// stress divergence) and density rates within 1e-4 of the largest, and the stable step with
/// each particle's viscous limit. Two passes, the second starting from the holds of the first
/// as a step starts from the last one's.
pub fn check_rheology(backend: &Backend, c: Case, seed: u64) {
    let (mut sim, particles, params) = sediment_in_motion(backend, &c, seed, |_| {});
    let model = super::reference_sediment(&sim);
    let mut held = vec![false; particles.len()];
    let (mut released, mut count) = (0, [0usize; 6]);
    for round in 1..=2 {
        let (held_after, freed, regions) =
            check_rheology_round(&mut sim, &params, &model, &particles, &held);
        eprintln!(
            "{} round {round}: regions (walls, 1-5) {regions:?} agree",
            c.name
        );
        (held, count) = (held_after, regions);
        released += freed;
    }
    // Every sediment region this test exists for occurs; Drucker-Prager both releases held
    // sediment and keeps some held.
    let wanted: &[usize] = if model.shields_only {
        &[1, 3]
    } else {
        &[1, 2, 3]
    };
    for &r in wanted {
        assert!(count[r] > 0, "no particle in region {r}: {count:?}");
    }
    eprintln!("{released} held particles released by their neighbours' stress");
    if model.shields_only {
        assert_eq!(released, 0, "the Shields-only mode released held sediment");
    } else {
        assert!(released > 0, "no held particle was released");
    }
}

/// Two Verlet steps of a sand bed in motion against the CPU: the forces with the rheology and
/// release passes, then `integrate::verlet` with the holds of `integrate::hold_at_rest`; the
/// second step starts from the first one's holds and from its `vel_rho_prev`, so a grain held
/// for the first step and released in the second is checked too (when there is one).
pub fn check_verlet_steps_with_held_sand(backend: &Backend) {
    use flume_solver::physics::sediment::{hold, pass, stress};
    let c = case("tests/cases/sediment_bed_2d.yaml");
    let TwoSteps {
        particles,
        params,
        model,
        after,
        dt,
        dt2,
    } = two_steps_of_sand_in_motion(backend, &c, 23, |_| {});

    let n = particles.len();
    let forces = |pos: &[[f32; 4]], vel: &[[f32; 4]], held_before: &[bool]| {
        let mut r = pass::rheology_pass(&params, &model, pos, vel, held_before);
        hold::release_pass(&params, &model, pos, vel, &mut r);
        let mut f = interaction::interact(&params, pos, vel).forces;
        for (f, s) in f
            .iter_mut()
            .zip(stress::stress_divergence(&params, pos, vel, &r))
        {
            for k in 0..3 {
                f[k] += s[k];
            }
        }
        (f, r.iter().map(|r| r.held).collect::<Vec<bool>>())
    };
    let (pos0, vel0) = (&particles.positions, &particles.vel_rho);
    let clamp = params.clamp_negative_pressure;
    let (f0, held1) = forces(pos0, vel0, &vec![false; n]);
    let mut s1 = integrate::verlet(&params.phases, dt, 0.0, true, pos0, vel0, vel0, &f0);
    integrate::hold_at_rest(&params.phases, clamp, pos0, vel0, &held1, &mut s1);
    let (f1, held2) = forces(&s1.0, &s1.1, &held1);
    let mut s2 = integrate::verlet(&params.phases, dt2, dt, false, &s1.0, &s1.1, &s1.2, &f1);
    integrate::hold_at_rest(&params.phases, clamp, &s1.0, &s1.1, &held2, &mut s2);
    let count = |h: &[bool]| h.iter().filter(|&&h| h).count();
    let released = (0..n).filter(|&i| held1[i] && !held2[i]).count();
    eprintln!(
        "held {} then {}; {released} released in the second step",
        count(&held1),
        count(&held2)
    );
    assert!(count(&held1) > 0 && count(&held2) > 0, "nothing held");
    assert_step_close(&after, &s2.0, &s2.1, &[&f0, &f1], dt, 2.0);
    // Sand held in both steps is exactly where it started, at rest.
    for i in (0..n).filter(|&i| held1[i] && held2[i]) {
        assert_eq!(after.positions[i], pos0[i], "held particle {i} moved");
        assert_eq!(
            after.vel_rho[i][..3],
            [0.0; 3],
            "held particle {i} has a velocity"
        );
    }
}

/// [`shields_only_case`] with the Shields test reading the nearest water particle's own
/// velocity (`config::ShieldsSpeed::Water`).
pub fn water_speed_case() -> Case {
    let mut c = shields_only_case();
    if let Some(s) = c.phases[1].sediment.as_mut() {
        s.shields_speed = flume_solver::config::ShieldsSpeed::Water;
    }
    c
}

/// How many particles of [`sediment_in_motion`] of `c` the oracle's rheology pass puts in
/// another region when the Shields test reads the water's own velocity instead of its
/// velocity relative to the grain: a comparison that can tell the two apart needs some.
pub fn regions_the_shields_speed_changes(backend: &Backend, c: &Case, seed: u64) -> usize {
    use flume_solver::physics::sediment::pass::{SedimentModel, rheology_pass};
    let (sim, particles, params) = sediment_in_motion(backend, c, seed, |_| {});
    let model = super::reference_sediment(&sim);
    let regions = |m: &SedimentModel| -> Vec<u32> {
        let held = vec![false; particles.len()];
        let pass = rheology_pass(&params, m, &particles.positions, &particles.vel_rho, &held);
        pass.iter().map(|r| r.region).collect()
    };
    let relative = regions(&SedimentModel {
        water_speed: false,
        ..model.clone()
    });
    let own = regions(&model);
    own.iter().zip(&relative).filter(|(a, b)| a != b).count()
}

/// [`shields_only_case`] with the water's sub-particle-scale eddy viscosity (C_s = 0.12), which
/// outweighs its own viscosity forty-fold in the perturbed flow.
pub fn eddy_viscosity_case() -> Case {
    let mut c = shields_only_case();
    c.numerics.viscosity = flume_solver::config::Viscosity::Multiphase {
        alpha: 0.05,
        smagorinsky_cs: 0.12,
        eddy_m2_per_s: 0.0,
    };
    c
}

/// The sediment bed in the Shields-only mode, with artificial viscosity on top of the stress
/// and without tension, as the flume case runs (the perturbed densities, 1 % either side of
/// rest, give negative pressures).
pub fn shields_only_case() -> Case {
    let mut c = case("tests/cases/sediment_bed_2d.yaml");
    if let Some(s) = c.phases[1].sediment.as_mut() {
        s.criterion = flume_solver::config::YieldCriterion::ShieldsOnly;
        s.hbp_m_s = 0.0;
        s.hbp_n = 1.0;
    }
    c.numerics.viscosity = flume_solver::config::Viscosity::Multiphase {
        alpha: 0.05,
        smagorinsky_cs: 0.0,
        eddy_m2_per_s: 0.0,
    };
    c.numerics.clamp_negative_pressure = true;
    c
}

/// [`water_speed_case`] with the pick-up worn away (`Erosion::VanRijnIntegrated`), as the
/// twin runs: a held grain under a shear past Shields' threshold loses a share of its mass each
/// step, kept in its region word.
pub fn worn_away_case() -> Case {
    let mut c = water_speed_case();
    if let Some(s) = c.phases[1].sediment.as_mut() {
        s.erosion = flume_solver::config::Erosion::VanRijnIntegrated;
    }
    c
}

/// [`worn_away_case`] worn net of what settles from upstream (`Erosion::VanRijnExner`).
pub fn exner_case() -> Case {
    let mut c = worn_away_case();
    if let Some(s) = c.phases[1].sediment.as_mut() {
        s.erosion = flume_solver::config::Erosion::VanRijnExner;
    }
    c
}

/// What [`check_wear`] saw: grains that began to wear, wore on, and whose wear the bed load
/// from upstream cut by two units or more (more than the comparison's tolerance).
pub struct Wear {
    pub started: usize,
    pub carried: usize,
    pub supplied: usize,
    /// Grains worn whole, let go carrying all but a unit of their wear (`van_rijn_exner`).
    pub spent: usize,
    /// Grain-steps of grains not held before that carried wear off the bed.
    pub carried_loose: usize,
}

/// The rheology pass with its pick-up draws over 200 steps of case `c`, its perturbed speeds
/// scaled by `calm`, (of 20, 15 and 25 us in turn): after each step but the first, every particle's region word (region, hold and the
/// mass worn off it) against `pass::rheology_pass_exner` from the state and words the step
/// started from, drawn at the step's run count with the previous step's length (the first
/// step's draw has no length before it, so it wears nothing), and from the bed load the
/// oracle's pass of the step before passed on. Grains must begin to wear as the churning
/// water's shear passes their threshold, the worn mass carry over from step to step, and the
/// shares be rounded both down and up.
pub fn check_wear(backend: &Backend, c: &Case, seed: u64, (calm, worn): (f32, bool)) -> Wear {
    const STEPS: usize = 200;
    use flume_solver::physics::sediment::pass::{Draws, NO_FLUX, NO_TARGET, rheology_pass_exner};
    use flume_solver::physics::sediment::pickup::{EXNER_SPENT, PICKUP_SHIFT, word_units};
    let (mut sim, _, params) = sediment_in_motion(backend, c, seed, |p| {
        p.vel_rho
            .iter_mut()
            .for_each(|v| v[..3].iter_mut().for_each(|u| *u *= calm))
    });
    let model = super::reference_sediment(&sim);
    assert!(model.pickup_integrated, "the case does not wear the bed");
    let dts: Vec<f32> = (0..STEPS)
        .map(|k| [2.0e-5f32, 1.5e-5, 2.5e-5][k % 3])
        .collect();
    let mut t = 0.0f64;
    let mut before = (sim.read_particles().expect("readback"), Vec::new());
    let n = before.0.len();
    let mut fluxes = (vec![NO_FLUX; n], vec![NO_TARGET; n]);
    let mut wear = Wear {
        started: 0,
        carried: 0,
        supplied: 0,
        spent: 0,
        carried_loose: 0,
    };
    let (mut grew_by, mut off_by_one) = (Vec::new(), 0);
    for (k, &dt) in dts.iter().enumerate() {
        t += f64::from(dt);
        sim.advance_to(t).expect("steps");
        let words = sim.regions().expect("regions");
        let (p, w) = &before;
        let draws = Draws {
            step: k as u32,
            dt_s: if k > 0 { dts[k - 1] } else { 0.0 },
        };
        let w = if k > 0 { w.clone() } else { words.clone() };
        let state = (p.positions.as_slice(), p.vel_rho.as_slice());
        let passed = (w.as_slice(), fluxes.0.as_slice(), fluxes.1.as_slice());
        let oracle = rheology_pass_exner(&params, &model, state, passed, Some(draws));
        // The same pass with nothing passed on from upstream.
        let unsupplied = vec![NO_TARGET; n];
        let passed = (w.as_slice(), fluxes.0.as_slice(), unsupplied.as_slice());
        let alone = rheology_pass_exner(&params, &model, state, passed, Some(draws));
        fluxes = oracle.iter().map(|r| (r.flux, r.target)).unzip();
        if k > 0 {
            for (i, r) in oracle.iter().enumerate() {
                let (got, want) = (words[i], r.word());
                // The region and the hold to the bit; the worn units within one, where the
                // share's fraction, its rate summed in another order (or its step an ulp
                // apart), falls on the other side of the draw.
                let exner = model.exner();
                let (units, want_units) = (word_units(got, exner), word_units(want, exner));
                let region_and_hold = (1 << PICKUP_SHIFT) - 1;
                assert!(
                    got & region_and_hold == want & region_and_hold
                        && units.abs_diff(want_units) <= 1,
                    "step {}: particle {i} word {got:#x}, the oracle's {want:#x}",
                    k + 1
                );
                off_by_one += usize::from(units != want_units);
                let was = word_units(w[i], exner);
                if want_units > 0 && was == 0 {
                    wear.started += 1;
                }
                if want_units > was && was > 0 {
                    wear.carried += 1;
                }
                if want_units > was {
                    grew_by.push(want_units - was);
                }
                if (alone[i].pickup).saturating_sub(r.pickup) >= 2 {
                    wear.supplied += 1;
                }
                let held_before = w[i] & REGION_HELD != 0;
                if held_before && !r.held && r.pickup == EXNER_SPENT {
                    wear.spent += 1;
                }
                if exner && !held_before && want_units != 0 {
                    wear.carried_loose += 1;
                }
            }
        }
        // The first pass has held the bed: wear it before the next reads it.
        let words = if worn && k == 0 {
            let words = worn_words(&words);
            sim.set_regions(&words);
            words
        } else {
            words
        };
        before = (sim.read_particles().expect("readback"), words);
    }
    let share_rounded_both_ways = grew_by.iter().min() != grew_by.iter().max();
    eprintln!(
        "{} grains began to wear, {} wore on from the step before, {} were passed bed load, {} were worn whole, {} loose grain-steps carried wear; shares {:?} to {:?} units; {off_by_one} a unit off",
        wear.started,
        wear.carried,
        wear.supplied,
        wear.spent,
        wear.carried_loose,
        grew_by.iter().min(),
        grew_by.iter().max()
    );
    // A draw at another step or id than the oracle's rounds a share otherwise with the chance
    // 2 f (1 - f) of its fraction f (202 of 382 with the oracle's draw one step late).
    assert!(
        off_by_one * 50 <= grew_by.len(),
        "{off_by_one} of {} shares rounded otherwise",
        grew_by.len()
    );
    assert!(
        wear.started > 0 && wear.carried > 0,
        "nothing wore, or nothing carried over"
    );
    assert!(share_rounded_both_ways, "every share was rounded alike");
    wear
}

/// [`check_wear`] of [`worn_away_case`].
pub fn check_worn_away_pickup(backend: &Backend, seed: u64) {
    check_wear(backend, &worn_away_case(), seed, (1.0, false));
}

/// The region words `words` with the bed worn (`van_rijn_exner`'s units): every other held
/// grain within 64 units of whole, so that under the churning water (a unit or two a step) some
/// are worn whole, the rest as they were; a third of the grains the bed does not hold carry a
/// quarter grain's wear, which they must keep.
fn worn_words(words: &[u32]) -> Vec<u32> {
    use flume_solver::physics::sediment::pickup::{EXNER_SPENT, EXNER_WHOLE, units_word};
    use flume_solver::physics::sediment::suspension::Region;
    let loose = [Region::Yielded, Region::BedLoad, Region::Suspended].map(|r| r as u32);
    let keep = (1u32 << flume_solver::physics::sediment::pickup::PICKUP_SHIFT) - 1;
    let mut out = words.to_vec();
    for (id, w) in out.iter_mut().enumerate() {
        let id = id as i32;
        if *w & REGION_HELD != 0 && id % 2 == 0 {
            *w = (*w & keep) | units_word(EXNER_SPENT - id % 64);
        } else if loose.contains(&(*w & 255)) && id % 3 == 0 {
            *w = (*w & keep) | units_word(EXNER_WHOLE as i32 / 4);
        }
    }
    out
}

/// The churning water's speeds scaled for [`check_exner_pickup`]. At their full size every
/// grain that wears does so under a shear whose grains' step is longer than dp, so it loses its
/// whole pick-up whatever it is passed (`Rheology::pick_up`), and no grain's wear shows what
/// came from upstream; at 0.85 some steps are shorter. Chosen by trying 0.5, 0.7 and 0.85 (at
/// the first two hardly a grain wears).
const CALM: f32 = 0.85;

/// [`check_wear`] of [`exner_case`], the water calmer ([`CALM`]): the bed load from upstream
/// must cut some grain's wear by more than the comparison's unit, or a backend that ignored it
/// would pass.
pub fn check_exner_pickup(backend: &Backend, seed: u64) {
    let wear = check_wear(backend, &exner_case(), seed, (CALM, false));
    assert!(wear.supplied > 0, "no grain was passed bed load");
}

/// [`check_wear`] of [`exner_case`] on a bed worn nearly whole ([`worn_words`]): grains worn
/// whole must leave it carrying their wear, and grains it does not hold keep theirs, or a
/// backend that dropped either would pass. (That bed load passed to a loose grain settles on
/// it, the pass's unit tests show: here no grain is released beside one that passes it load.)
pub fn check_exner_release(backend: &Backend, seed: u64) {
    let wear = check_wear(backend, &exner_case(), seed, (CALM, true));
    assert!(wear.spent > 0, "no grain was worn whole");
    assert!(wear.carried_loose > 0, "no loose grain carried wear");
}

/// The release of held sand by its neighbours' stress (Drucker-Prager, `sediment_bed_2d`) worn
/// net of what settles (`van_rijn_exner`), against `sediment::pass` and `sediment::hold`: from
/// the grains at rest held, each with 1,000-1,006 units of wear, the pass's words to the bit,
/// units and all. A grain released carries its wear (`hold.wgsl`
/// keeps the bits above the hold), where one released by the pick-up alone starts whole; a
/// backend that dropped it would differ on every grain released.
pub fn check_release_carries_wear(backend: &Backend, seed: u64) {
    use flume_solver::physics::sediment::pass::{Draws, NO_FLUX, NO_TARGET, rheology_pass_exner};
    use flume_solver::physics::sediment::suspension::Region;
    use flume_solver::physics::sediment::{hold, pickup::units_word, pickup::word_units};
    let mut c = case("tests/cases/sediment_bed_2d.yaml");
    if let Some(s) = c.phases[1].sediment.as_mut() {
        s.erosion = flume_solver::config::Erosion::VanRijnExner;
    }
    let (mut sim, particles, params) = sediment_in_motion(backend, &c, seed, |_| {});
    let model = super::reference_sediment(&sim);
    let held = Region::Unyielded as u32 | REGION_HELD;
    let worn: Vec<u32> = (0..particles.len())
        .map(|id| {
            let at_rest = particles.vel_rho[id][..3].iter().all(|&u| u == 0.0);
            match particles.phase(id) == 2 && at_rest {
                true => held | units_word(1000 + (id % 7) as i32),
                false => 0,
            }
        })
        .collect();
    sim.set_regions(&worn);
    sim.compute_forces().expect("forces");
    let got = sim.regions().expect("regions");
    let n = worn.len();
    let state = (particles.positions.as_slice(), particles.vel_rho.as_slice());
    let none = (vec![NO_FLUX; n], vec![NO_TARGET; n]);
    // The force pass's rheology draws, over a step of none: no grain wears.
    let draws = Some(Draws { step: 0, dt_s: 0.0 });
    let before = (worn.as_slice(), none.0.as_slice(), none.1.as_slice());
    let mut want = rheology_pass_exner(&params, &model, state, before, draws);
    hold::release_pass(&params, &model, state.0, state.1, &mut want);
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(
            *g,
            w.word(),
            "particle {i}: {g:#x}, the oracle's {:#x}",
            w.word()
        );
    }
    let carried = (0..n)
        .filter(|&i| worn[i] & REGION_HELD != 0 && !want[i].held && word_units(got[i], true) > 0)
        .count();
    eprintln!("{carried} grains released carrying their wear");
    assert!(carried > 0, "no held grain was released");
}
