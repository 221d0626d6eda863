//! The CPU backend's awake set (`cpu/forces.rs`, `cpu/multiphase.rs`): walls, and held grains
//! far from anything moving or deep under the water, skip their neighbour loops. It must give
//! the full computation's bits, so each case runs twice, with the awake set and without, while
//! water reaches walls and held sand that were dry: every particle's position, velocity and
//! density, and every region word, must agree to the bit. A sleeper that water reached
//! unnoticed (a wall still at rest density, a grain still held away from the surface) would
//! differ from the step it was reached. With the awake set, an open flume's parked particles
//! stored last also keep their slots from one sort to the next, uncopied (`cpu/step.rs`): a
//! particle the inlet took from among them, or one newly parked, that the sort left where it
//! was would differ too.

mod common;

use common::case_path;
use flume_solver::{Backend, Case, Simulation, StageTime};

/// The run's state as bits: positions, velocities and densities, then region words.
fn bits(sim: &Simulation) -> Vec<u32> {
    let p = sim.read_particles().expect("readback");
    let regions = sim.regions().expect("regions");
    let values = p.positions.iter().chain(&p.vel_rho).flatten();
    values.map(|v| v.to_bits()).chain(regions).collect()
}

/// Share of the particles of `stage` that slept over the passes between two readings.
fn asleep_share(before: &[StageTime], after: &[StageTime], stage: &str) -> f64 {
    let pick = |s: &[StageTime]| {
        let s = s.iter().find(|s| s.stage == stage).expect("the stage");
        (s.particles, s.asleep)
    };
    let ((p0, a0), (p1, a1)) = (pick(before), pick(after));
    (a1 - a0) as f64 / (p1 - p0).max(1) as f64
}

/// Each neighbour pass that ran between `before` and `after` spent time in its walk, and no
/// more than the whole stage took (`bench` prints the walk's share of each).
fn assert_walk_within_stage(before: &[StageTime], after: &[StageTime], t: f64) {
    for (b, a) in before.iter().zip(after) {
        let (stage, walk) = (a.seconds - b.seconds, a.walk_seconds - b.walk_seconds);
        let walked = a.particles > b.particles;
        assert!(
            !walked || (walk > 0.0 && walk <= stage),
            "{} to t = {t} s: walk {walk} s of a stage of {stage} s",
            a.stage
        );
    }
}

/// Runs `case` to each of `times` with the awake set and without; the bits must agree at each.
/// Returns the share of rheology and force passes that slept over the first and the last
/// stretch.
fn assert_same_as_full(case: &Case, times: &[f64]) -> [(f64, f64); 2] {
    let awake = Backend::cpu(2);
    let full = Backend::Cpu {
        threads: 2,
        awake_set: false,
    };
    let mut a = Simulation::new(awake, case).expect("builds");
    let mut f = Simulation::new(full, case).expect("builds");
    let mut shares = Vec::new();
    for &t in times {
        let before = a.stage_times();
        a.advance_to(t).expect("runs with the awake set");
        f.advance_to(t).expect("runs in full");
        assert_eq!(a.steps(), f.steps(), "{}: steps to t = {t} s", case.name);
        assert!(
            bits(&a) == bits(&f),
            "{}: the awake set differs from the full computation by t = {t} s",
            case.name
        );
        let after = a.stage_times();
        assert_walk_within_stage(&before, &after, t);
        let share = |stage| asleep_share(&before, &after, stage);
        shares.push((share("rheology"), share("forces")));
        eprintln!(
            "{} to t = {t} s: asleep in rheology {:.3}, in forces {:.3}",
            case.name,
            share("rheology"),
            share("forces")
        );
    }
    [shares[0], shares[shares.len() - 1]]
}

fn ulbra(overrides: &[&str]) -> Case {
    let mut set = vec![
        "numerics.dp_m=0.01".to_string(),
        "open_flume.reservoir_particles=2500".to_string(),
    ];
    set.extend(overrides.iter().map(|s| s.to_string()));
    Case::from_path_with(&case_path("../launch_configs/ulbra_flume.yaml"), &set)
        .expect("the CI flume")
}

/// The CI flume with the twin's numerics (`scripts/run.sh`), its bed worn by `erosion`, and
/// `more` overrides.
fn twin(erosion: &str, more: &[&str]) -> Case {
    let erosion = format!("phases.1.sediment.erosion={erosion}");
    let mut set = vec![
        "numerics.boundary={method: generalised}",
        "numerics.viscosity={method: multiphase, eddy_m2_per_s: 3.95e-5}",
        &erosion,
        "phases.1.sediment.shields_speed=water",
        "phases.1.sediment.comes_to_rest=beside_a_solid",
    ];
    set.extend(more);
    ulbra(&set)
}

/// The CI flume as the twin runs it (generalised walls, the held bed a wall, van Rijn's
/// pick-up worn net of what settles, `van_rijn_exner`): the front crosses 2 m of dry bed in its
/// first 4 s, waking walls and held sand as it goes, and carries the load it picks up to the
/// dry bed's top ahead of it, whose grains slept until the water came near; by 6 s it has gone
/// over the end wall into the pit. To 10 s the water covers the bed, and the held grains deep
/// under it sleep by their last walk (`cpu/multiphase/deep.rs`).
#[test]
fn the_twins_flume_with_its_awake_set_is_the_full_computation() {
    let case = twin("van_rijn_exner", &[]);
    let [first, last] = assert_same_as_full(&case, &[0.5, 1.5, 2.5, 3.5, 6.0, 10.0]);
    // Not vacuous: walls and grains slept, and the front woke some (fewer slept at the end).
    // To 0.5 s the dry bed ahead of the front sleeps: 0.964 of the rheology's particles. With
    // no grain sleeping dry (the engine forgetting which grains its last pass found dry, so
    // that each walks every pass) only the walls do, 0.500 (tried); the bound lies between.
    assert!(first.0 > 0.9 && first.1 > 0.3, "{first:?}");
    assert!(
        last.0 < first.0 && last.1 < first.1,
        "{first:?} then {last:?}"
    );
}

/// The same flume at CFL 2.5 from 8 s, where the water over the filled bed moves ten times
/// further each step: a held grain may sleep while the walls and held grains in its reach take
/// new densities from water beyond it, which its bed-top record (Exner's balance) reads
/// through their volumes. Without the walls and held grains off their rest density counted as
/// stirring, a grain at the bed's end beside the pit took load it no longer offered to take,
/// by 8.45 s.
#[test]
fn the_twins_flume_at_a_large_step_is_the_full_computation() {
    let case = twin("van_rijn_exner", &[]);
    let full = Backend::Cpu {
        threads: 2,
        awake_set: false,
    };
    let mut runs = [Backend::cpu(2), full].map(|b| Simulation::new(b, &case).expect("builds"));
    for sim in &mut runs {
        sim.advance_to(8.0).expect("runs");
        sim.set_cfl(2.5).expect("accepted for the test");
    }
    for t in (1..=20).map(|k| 8.0 + 0.05 * f64::from(k)) {
        for sim in &mut runs {
            sim.advance_to(t).expect("runs");
        }
        let [a, f] = &runs;
        assert_eq!(a.steps(), f.steps(), "steps to t = {t} s");
        assert!(bits(a) == bits(f), "t = {t} s: the awake set differs");
    }
    // Not vacuous: the large steps held (no recovery took the CFL back down).
    assert!(runs[0].recoveries().is_empty());
}

/// The same under the symplectic scheme, whose corrector's passes read the predictor's holds
/// and the half step's velocities, with the pick-up worn away alone (`van_rijn_integrated`).
#[test]
fn the_twins_flume_under_the_symplectic_scheme_is_the_full_computation() {
    let case = twin(
        "van_rijn_integrated",
        &["numerics.integrator={method: symplectic}"],
    );
    let [first, _] = assert_same_as_full(&case, &[0.5, 2.0]);
    assert!(first.0 > 0.2 && first.1 > 0.3, "{first:?}");
}

/// The paper's numerics on the same flume (dynamic boundaries, the held sand a mobile phase
/// held fixed at rest): walls sleep in the force pass, those under the held bed too, and held
/// grains in the rheology pass.
#[test]
fn the_papers_flume_with_its_awake_set_is_the_full_computation() {
    let case = ulbra(&[]);
    let [first, last] = assert_same_as_full(&case, &[0.5, 2.0]);
    // Without the walls under the bed, 0.11 of the force pass slept.
    assert!(first.0 > 0.2 && first.1 > 0.3, "{first:?}");
    assert!(last.0 < first.0, "{first:?} then {last:?}");
}

/// Louvain's dam break over sand (Drucker-Prager with Shields, the release of held sand by its
/// neighbours' stress): the release reads the rheology of sleeping grains.
#[test]
fn the_louvain_dam_break_with_its_awake_set_is_the_full_computation() {
    let mut case =
        Case::from_path(&case_path("../launch_configs/louvain_dambreak.yaml")).expect("parses");
    case.numerics.dp_m = 0.01;
    let [first, _] = assert_same_as_full(&case, &[0.05, 0.3]);
    assert!(first.0 > 0.05, "{first:?}");
}
