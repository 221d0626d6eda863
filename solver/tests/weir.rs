//! The levels at CI size (dp = 1 cm, generalised walls): the ULBRA flume in clear water, the
//! weir alone over a still pool, the flume's held sand under the flow, and the gauges over
//! still water.
//!
//! The ULBRA flume in clear water (the sand bed made a fixed wall block) is run at a constant
//! 2 and 4 m3/h to a steady state and held against the 1-D reference of
//! `flume_solver::hydraulics` on the geometry as generated. The water's viscosity is the flow's
//! eddy viscosity, kappa u* h / 6 from the reference's depth and friction, given to
//! Monaghan's term (`numerics.viscosity.eddy_m2_per_s`), not the case's alpha = 0.02 (ten times
//! more). The flow over the bed is two to four particles deep.
//!
//! What is checked, over t = 31-40 s against 21-30 s (the flume fills in about 15 s):
//! - the levels at P1, P2 and P3 within 3 mm of the reference, the goal. Measured:
//!   -2.2 / -2.3 / -2.6 mm at 2 m3/h, -1.0 / -1.0 / -1.1 mm at 4. With alpha = 0.02, P1 stands
//!   +10.9 mm (the artificial viscosity's slope); with the reference's expanded pit in place of
//!   the current carried over it, P3 is -5.0 mm; with the case's DBC walls, +9.7 mm;
//! - each level's drift under 1 mm between the two windows (measured under 0.4 mm);
//! - the discharge over the weir within 2 % of the inflow: the flume has stopped storing;
//! - no water through a wall (the leak of an inlet buffer counted in the walls' pressure).
//!
//! What is left in them: the crest. The end wall's three particle layers make a crest 3 cm long
//! at dp = 1 cm, which the reference rates 2.5 mm over a thin plate; the model's crest passes
//! its discharge at a thin plate's head at this dp (the still pool below), and at 23.3 mm, 1.8
//! mm under the short crest's 25.1, once resolved (a 3 cm crest at dp = 5 and 3.75 mm; README,
//! levels section). Not checked: the pool between the bed's end and the weir, where the
//! gauge stands in the current that crosses the pit.

mod common;

use common::case_path;
use flume_solver::bed_contact::{COLUMNS, bed_contact};
use flume_solver::hydraulics::{Channel, Weir, fixed_bed_overrides};
use flume_solver::{Backend, Case, Simulation};

const WATER: u32 = 1;

/// The clear-water flume at CI size with a constant inflow of `m3_per_h`, and the reference on
/// the sand bed's geometry as generated (the fixed bed's block is that geometry). The water's
/// viscosity is the flow's eddy viscosity at that discharge, from the reference's own depth
/// and friction (`Channel::eddy_viscosity_m2_per_s`: 3.95e-5 m2/s at 2 m3/h, 7.45e-5 at 4).
fn clear_water_ci(m3_per_h: f64) -> (Case, Channel) {
    let path = case_path("../launch_configs/ulbra_flume.yaml");
    let q = m3_per_h / 3600.0;
    let mut set = vec![
        "numerics.dp_m=0.01".to_string(),
        format!("open_flume.inflow_m3_per_s={q}"),
        "open_flume.reservoir_particles=3000".to_string(),
        "numerics.boundary={method: generalised}".to_string(),
    ];
    let sand = Case::from_path_with(&path, &set).expect("the CI flume");
    let channel = Channel::as_generated(&sand).expect("a flume");
    let width = sand.open_flume.as_ref().expect("flume").width_m;
    let nu_t = channel.eddy_viscosity_m2_per_s(q, width);
    set.push(format!(
        "numerics.viscosity={{method: multiphase, eddy_m2_per_s: {nu_t}}}"
    ));
    set.extend(fixed_bed_overrides(&sand).expect("a sand bed to fix"));
    (
        Case::from_path_with(&path, &set).expect("the clear-water flume"),
        channel,
    )
}

#[test]
fn clear_water_flume_holds_the_weirs_level_and_passes_its_inflow_at_2_m3_per_h() {
    check_clear_water(2.0);
}

/// Twice the discharge: a head of about 4 cm over the crest, where the rating moves towards a
/// broad crest's (H / L about 1.3) and the flow is three to four particles deep.
#[test]
fn clear_water_flume_holds_the_weirs_level_and_passes_its_inflow_at_4_m3_per_h() {
    check_clear_water(4.0);
}

/// Mean of each gauge's level over the seconds `from..=to`, m.
fn mean_levels(sim: &mut Simulation, from: u32, to: u32) -> Vec<f64> {
    let mut sums = Vec::new();
    for t in from..=to {
        sim.advance_to(f64::from(t)).expect("runs");
        let obs = sim.observe().expect("observes");
        sums.resize(obs.gauges.len(), 0.0);
        for (sum, g) in sums.iter_mut().zip(&obs.gauges) {
            *sum += g.level_m.expect("a gauge dry after the flume filled");
        }
    }
    sums.iter().map(|s| s / f64::from(to - from + 1)).collect()
}

fn check_clear_water(m3_per_h: f64) {
    let (case, channel) = clear_water_ci(m3_per_h);
    let flume = case.open_flume.as_ref().expect("flume");
    let (q, width) = (flume.inflow_m3_per_s, flume.width_m);
    let reference = channel.steady(q, width);
    let mut sim = Simulation::new(Backend::cpu(0), &case).expect("builds");
    sim.advance_to(20.0).expect("fills");
    let before = mean_levels(&mut sim, 21, 30);
    let books = |sim: &Simulation| {
        let f = sim.flume().expect("flume");
        (
            f.parked_particles,
            f.injected_particles,
            f.excluded_particles,
        )
    };
    let start = books(&sim);
    let steady = mean_levels(&mut sim, 31, 40);
    let end = books(&sim);
    for (g, gauge) in case.observations.gauges.iter().enumerate() {
        let want = reference.level_m(gauge.position_m[0]);
        let (level, drift) = (steady[g], steady[g] - before[g]);
        eprintln!(
            "{m3_per_h} m3/h, {}: {level:.4} m against the reference's {want:.4} m, \
             {:+.1} mm in 10 s",
            gauge.name,
            1e3 * drift
        );
        assert!(
            (level - want).abs() < 0.003,
            "{m3_per_h} m3/h: {} at {level:.4} m, the reference gives {want:.4} m",
            gauge.name
        );
        assert!(
            drift.abs() < 0.001,
            "{m3_per_h} m3/h: {} moved {drift:.4} m from 21-30 s to 31-40 s",
            gauge.name
        );
    }
    // Particles parked at the outlet over the 10 s, the inlet's drawn back from the parked.
    let over_weir = (end.0 + end.1) as f64 - (start.0 + start.1) as f64 - (end.2 - start.2) as f64;
    let dp = case.numerics.dp_m;
    let outflow = over_weir * dp * dp * width / 10.0;
    assert!(
        (outflow / q - 1.0).abs() < 0.02,
        "over the weir {outflow:.3e} m3/s against {q:.3e} m3/s in"
    );
    let particles = sim.read_particles().expect("readback");
    let floor = -0.025;
    let through = (0..particles.len())
        .filter(|&i| particles.phase(i) == WATER && particles.positions[i][1] < floor)
        .count();
    assert_eq!(through, 0, "water below the floor's wall layers");
}

/// The weir alone against Rehbock's thin-plate rating (`Cd = 0.611 + 0.08 H / P`, Rehbock 1929):
/// a pool 1 m long, fed over its whole depth below the crest so that the flow reaches the weir
/// slow and even, as the rating assumes (`tests/cases/weir_pool_2d.yaml`: dp = 1 cm, generalised
/// walls, 2 m3/h, the head 2.3 dp). The level 10 cm (4 H) before the weir over t = 15-25 s, the
/// pool filled by about 12 s, within dp/10 of the crest plus Rehbock's head, as the gauges read
/// still water (the test above). Measured: -0.5 mm. Under DBC walls it stands +11 mm; an outlet
/// that cut the nappe, or a gauge or crest off by half a dp, would fail it.
///
/// The crest is the end wall's three particle layers, 3 cm long against the head's 2.3 cm. The
/// model passes its discharge at a thin plate's head, not the 2.5 mm higher one of a short
/// crest that `hydraulics::crest_coefficient` gives for 3 cm (and -0.2 mm at dp = 5 mm, its
/// crest 1.5 cm long, in a long pit behind a bed; see the README's levels section).
#[test]
fn the_weir_passes_its_discharge_at_rehbocks_head_over_a_still_pool() {
    let case = Case::from_path(&case_path("tests/cases/weir_pool_2d.yaml")).expect("the pool");
    let dp = case.numerics.dp_m;
    let flume = case.open_flume.as_ref().expect("an open flume");
    let q = flume.inflow_m3_per_s / flume.width_m;
    let mut sim = Simulation::new(Backend::cpu(0), &case).expect("builds");
    let weir = weir_as_generated(sim.initial_particles(), dp, case.walls.layers);
    let want = weir.crest_m + weir.sharp_head_m(q);
    let gauge = case
        .observations
        .gauges
        .iter()
        .position(|g| g.name == "weir")
        .expect("a gauge before the weir");
    sim.advance_to(15.0).expect("fills");
    let mut levels = Vec::new();
    for t in 16..=25 {
        sim.advance_to(f64::from(t)).expect("runs");
        let obs = sim.observe().expect("observes");
        levels.push(obs.gauges[gauge].level_m.expect("wet"));
    }
    let level = levels.iter().sum::<f64>() / levels.len() as f64;
    eprintln!(
        "the pool stands at {level:.4} m; the crest at {:.4} m, plus Rehbock's head {want:.4} m",
        weir.crest_m
    );
    assert!(
        (level - want).abs() < 0.1 * dp,
        "the pool stands at {level:.4} m where Rehbock's rating puts it at {want:.4} m"
    );
}

/// The end wall's crest and the floor in front of it as the generator placed them, each face
/// half a dp beyond its outermost particle, the crest as long as the wall's layers: the weir
/// of a pool whose water ends before it.
fn weir_as_generated(particles: &flume_solver::Particles, dp: f64, layers: u32) -> Weir {
    // The floor is read under the pool's last half metre, clear of the walls over the inlet.
    const POOL_FLOOR_M: f64 = 0.5;
    let walls = (0..particles.len()).filter(|&i| particles.is_wall(i));
    let water_end = (0..particles.len())
        .filter(|&i| particles.phase(i) == WATER)
        .map(|i| f64::from(particles.positions[i][0]))
        .fold(f64::MIN, f64::max);
    let (mut crest, mut face, mut floor) = (f64::MIN, f64::MAX, f64::MIN);
    for i in walls {
        let [x, y, ..] = particles.positions[i].map(f64::from);
        if x > water_end {
            crest = crest.max(y);
            face = face.min(x);
        } else if x > water_end - POOL_FLOOR_M {
            floor = floor.max(y);
        }
    }
    Weir {
        x_m: face - 0.5 * dp,
        crest_m: crest + 0.5 * dp,
        length_m: f64::from(layers) * dp,
        floor_m: floor + 0.5 * dp,
    }
}

/// The wgpu stages of the generalised walls and of the inlet buffer's density (forces,
/// integrators, the end of a step) against the CPU backend on the first 4 s of the same flume:
/// the jet over the apron, where a buffer at rest density drove water through the walls. The
/// level at P1 (wet from about 2 s) within a dp, and no water through a wall on either.
///
/// Neither run may keep memory step after step: the process grows by less than
/// `GROWTH_BOUND` from 1 s to 4 s of each. On Debian 12's Mesa 22.3, whose lavapipe keeps
/// memory with every rheology pass, the wgpu run grew by some 4 GB over those seconds (the
/// test peaked at 8.75 GB); on Mesa 25 the whole test peaked at 0.18 GB. Other tests of this
/// binary run beside it, but they build their cases before it reaches 1 s and hold them.
#[test]
fn the_cpu_and_wgpu_backends_agree_on_the_clear_water_flume() {
    const GROWTH_BOUND: u64 = 300 << 20;
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let (case, _) = clear_water_ci(2.0);
    let run = |backend: Backend| {
        let name = backend.describe();
        let mut sim = Simulation::new(backend, &case).expect("builds");
        let mut resident = Vec::new();
        let levels: Vec<Option<f64>> = (1..=4)
            .map(|t| {
                sim.advance_to(f64::from(t)).expect("runs");
                resident.push(common::resident_bytes());
                sim.observe().expect("observes").gauges[0].level_m
            })
            .collect();
        if let (Some(Some(first)), Some(Some(last))) = (resident.first(), resident.last()) {
            let grown = last.saturating_sub(*first);
            eprintln!("{name}: grew {} MB from 1 s to 4 s", grown >> 20);
            assert!(
                grown < GROWTH_BOUND,
                "{name}: the process grew {} MB from 1 s to 4 s of the flume (a software \
                 adapter on Mesa 22.3 does; scripts/setup.sh installs Mesa 25)",
                grown >> 20
            );
        }
        let particles = sim.read_particles().expect("readback");
        let through = (0..particles.len())
            .filter(|&i| particles.phase(i) == WATER && particles.positions[i][1] < -0.025)
            .count();
        (levels, through)
    };
    let (cpu, cpu_through) = run(Backend::cpu(0));
    let (wgpu, wgpu_through) = run(Backend::from(gpu));
    assert_eq!((cpu_through, wgpu_through), (0, 0), "water through a wall");
    assert!(cpu[3].is_some(), "P1 dry at 4 s");
    for (t, (a, b)) in cpu.iter().zip(&wgpu).enumerate() {
        let (a, b) = (a.unwrap_or(0.0), b.unwrap_or(0.0));
        assert!(
            (a - b).abs() <= case.numerics.dp_m,
            "t = {} s: P1 {a:.4} m on the CPU backend, {b:.4} m on wgpu",
            t + 1
        );
    }
}

/// Still water three particles deep at the flume's dp = 1 cm, in a tank 15 cm wide, on either
/// wall condition: after it settles, the gauge at the centre reads the level its particles fill
/// within a tenth of a dp. The level is worked out from the tank as generated: the generator
/// puts particles on the nodes of its lattice, so the walls' faces stand half a dp inside their
/// outermost particles and the water fills `N dp^2` between them. A gauge that lost the kernel
/// sums of so thin a layer, or counted from the particles' centres instead of their faces, would
/// read 5 mm off.
#[test]
fn a_still_tank_three_particles_deep_reads_its_true_level() {
    for boundary in ["dynamic", "generalised"] {
        let set = [
            "numerics.dp_m=0.01".to_string(),
            "fluid_blocks.0.max_m=[0.15, 0.03]".to_string(),
            format!("numerics.boundary={{method: {boundary}}}"),
        ];
        let case = Case::from_path_with(&case_path("tests/cases/hydrostatic_2d.yaml"), &set)
            .expect("the still tank");
        let mut sim = Simulation::new(Backend::cpu(0), &case).expect("builds");
        let filled = filled_level(sim.initial_particles(), case.numerics.dp_m);
        let mut levels = Vec::new();
        for k in 1..=10 {
            sim.advance_to(1.0 + 0.1 * f64::from(k)).expect("runs");
            levels.push(
                sim.observe().expect("observes").gauges[0]
                    .level_m
                    .expect("wet"),
            );
        }
        let level = levels.iter().sum::<f64>() / levels.len() as f64;
        eprintln!("{boundary}: the gauge reads {level:.5} m, the particles fill {filled:.5} m");
        assert!(
            (level - filled).abs() < 0.1 * case.numerics.dp_m,
            "{boundary} walls: the gauge reads {level:.5} m over water filling {filled:.5} m"
        );
    }
}

/// The level that the water of a rectangular tank fills, m: its area `N dp^2` over the width
/// between the side walls' faces, above the floor's face (each half a dp inside the wall
/// particles next to the water).
fn filled_level(particles: &flume_solver::Particles, dp: f64) -> f64 {
    let (mut left, mut right, mut floor) = (f64::MIN, f64::MAX, f64::MIN);
    let mut water = 0usize;
    let (mut x_min, mut x_max, mut y_min) = (f64::MAX, f64::MIN, f64::MAX);
    for i in 0..particles.len() {
        let [x, y, ..] = particles.positions[i].map(f64::from);
        if particles.phase(i) == WATER {
            water += 1;
            (x_min, x_max, y_min) = (x_min.min(x), x_max.max(x), y_min.min(y));
        }
    }
    for i in 0..particles.len() {
        let [x, y, ..] = particles.positions[i].map(f64::from);
        if particles.phase(i) != WATER {
            if y >= y_min && x < x_min {
                left = left.max(x);
            }
            if y >= y_min && x > x_max {
                right = right.min(x);
            }
            if x >= x_min && x <= x_max && y < y_min {
                floor = floor.max(y);
            }
        }
    }
    let width = right - left - dp;
    floor + 0.5 * dp + water as f64 * dp * dp / width
}

/// The sand bed under generalised walls at 2 m3/h, with the flow's eddy viscosity and van
/// Rijn's pick-up, once the flume has settled (t = 40 and 50 s; it fills by about 15 s): the
/// held bed stands as a wall (`physics::boundary`), and in the columns from x = 0.3 to 2.1 m its
/// top particle carries the water above it, its Tait pressure as the water feels it
/// (`flume_solver::bed_contact`) within 25 % of the water's weight (the median column), with the
/// water standing on it: the 5th percentile of the water's heights at most 1.2 dp over the top
/// held particle in every column (the levels issue's goals). No water gets through the bed and
/// the floor. Measured: 1.01 of the weight at both times, the gap 0.66 and 0.73 dp (with the
/// contact force's first reach, dp / sqrt(2): 1.03, 0.49 and 0.73 dp). With the
/// paper's release (the top row mobilised at once) 0.96 and 0.89, the gap 1.10 and 1.17 dp.
/// As a dynamic boundary (before the held bed stood as a wall) the held sand carried 0.86 and
/// 0.82 of the weight as the water felt it but held the water 2 dp off; under DBC walls its
/// density ratchets up next to the flow, 4.3 times the weight at 40 s (this test with `dynamic`
/// walls fails). Without the held bed's contact force, water got into the bed and out through
/// the floor (5 particles by 60 s, `bench --levels`).
#[test]
fn the_held_sand_carries_the_water_above_it() {
    let path = case_path("../launch_configs/ulbra_flume.yaml");
    let set = [
        "numerics.dp_m=0.01".to_string(),
        "open_flume.reservoir_particles=3000".to_string(),
        "numerics.boundary={method: generalised}".to_string(),
        "numerics.viscosity={method: multiphase, eddy_m2_per_s: 3.95e-5}".to_string(),
        "phases.1.sediment.erosion=van_rijn_pickup".to_string(),
    ];
    let case = Case::from_path_with(&path, &set).expect("the CI flume");
    let mut sim = Simulation::new(Backend::cpu(0), &case).expect("builds");
    for t in [40.0, 50.0] {
        sim.advance_to(t).expect("runs");
        let particles = sim.read_particles().expect("readback");
        let regions = sim.regions().expect("regions");
        let contact = bed_contact(&case, sim.derived(), &particles, &regions).expect("sand");
        let wet = contact.columns.iter().filter(|c| c.wet.is_some()).count();
        assert_eq!(wet, COLUMNS, "dry columns at {t} s: {:?}", contact.columns);
        let felt = contact.felt_over_load().expect("held sand under water");
        eprintln!(
            "t = {t} s: the held sand's Tait pressure over its load {:.2}, as the water feels \
             it {felt:.2}; gap {:.2} dp",
            contact.median_tait_over_load().unwrap_or(f64::NAN),
            contact.largest_gap_dp().unwrap_or(f64::NAN)
        );
        assert!(
            (0.75..=1.25).contains(&felt),
            "t = {t} s: the held sand pushes on the water {felt:.2} times the weight it carries"
        );
        let floor = case.domain.min_m[1] - f64::from(case.walls.layers) * case.numerics.dp_m;
        let through = (0..particles.len())
            .filter(|&i| particles.phase(i) == WATER)
            .filter(|&i| f64::from(particles.positions[i][1]) < floor)
            .count();
        assert_eq!(through, 0, "t = {t} s: water through the bed and the floor");
        // The pick-up at work: some sand leaves the bed (the front's), and less than the
        // paper's release at once collects. Measured here: 5 grains by 40 s and 50 s with the
        // pick-up (9 with the contact force's first reach), 22 by 40 s with the paper's release
        // (the test then fails); Meyer-Peter &
        // Mueller give about none after the front. The bound of 15 is set between the two
        // measured counts, not from a reference. Fails if the draws never pick or always do.
        let collected = sim
            .observe()
            .expect("observes")
            .flume
            .expect("an open flume")
            .eroded_particles;
        eprintln!("t = {t} s: {collected} grains collected");
        assert!(
            (1..=15).contains(&collected),
            "t = {t} s: {collected} grains collected (1 to 15)"
        );
        let gap = contact.largest_gap_dp().expect("wet columns");
        assert!(
            gap <= 1.2,
            "t = {t} s: the water stands {gap:.2} dp over the held sand (at most 1.2 dp)"
        );
    }
}
