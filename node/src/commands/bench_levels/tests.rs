//! The benchmark's books, windows and lists on made-up histories and a short CI flume.

use super::*;

/// Over 10 s the inlet placed 646 particles and the parked count rose by 3: one of the
/// three is a grain that reached the collector, one water excluded for its density, so
/// 646 + 3 - 2 = 647 left over the weir. A grain or an exclusion counted as outflow, or the
/// parked count's sign turned, gives another number.
#[test]
fn the_weir_passes_what_the_inlet_placed_less_what_the_flume_kept() {
    let first = Books {
        t: 50.0,
        parked: 2270,
        injected: 10_000,
        eroded: 4,
        excluded: 0,
        soaked: 7,
    };
    let last = Books {
        t: 60.0,
        parked: 2273,
        injected: 10_646,
        eroded: 5,
        excluded: 1,
        soaked: 7,
    };
    assert_eq!(last.since(&first), (646.0, 647.0));
    // The flume storing all it was given: nothing over the weir.
    let stored = Books {
        t: 60.0,
        parked: 2270 - 646,
        injected: 10_646,
        ..first
    };
    assert_eq!(stored.since(&first), (646.0, 0.0));
}

/// The bundled flume's case file, and a run of it at dp = 1 cm and 2 m3/h to `until_s`.
fn ci_flume(until_s: f64) -> (std::path::PathBuf, LevelRun) {
    let flume = Path::new(env!("CARGO_MANIFEST_DIR")).join("../launch_configs/ulbra_flume.yaml");
    let run = LevelRun {
        dp_m: 0.01,
        m3_per_h: 2.0,
        until_s,
        fixed_bed: false,
        filled_pit: false,
    };
    (flume, run)
}

/// An observation of the gauges' `levels` alone.
fn gauges_at(t: f64, levels: &[Option<f64>]) -> Observations {
    let gauges = levels
        .iter()
        .map(|&level_m| flume_solver::GaugeReading {
            name: "g".to_string(),
            level_m,
        })
        .collect();
    Observations {
        gauges,
        ..crate::test_support::observations_at(t)
    }
}

/// A run to 60 s observed every second: until 40 s the flume stores its inflow and P1
/// stands at 70 mm; after, the weir passes 66 particles a second (the inflow asked is 64.6:
/// 6.46e-3 m2/s over dp^2) and P1 rises 0.1 mm a second from 80 mm. The stretch starts at the
/// observation of 40 s and holds the 20 after it: its trend is 1 mm per 10 s and its weir
/// 66 / 64.6 of the inflow. Taking the 40 s observation in, or the books from another,
/// gives other figures.
#[test]
fn the_settled_stretch_starts_at_40_s() {
    let (flume, run) = ci_flume(60.0);
    let (case, _) = level_case(&flume, &[], &run).expect("the CI flume");
    let history: Vec<(Books, Observations)> = (1..=60u64)
        .map(|t| {
            let out = 66 * t.saturating_sub(40);
            let books = Books {
                t: t as f64,
                parked: 10_000 - 65 * t + out,
                injected: 65 * t,
                eroded: 0,
                excluded: 0,
                soaked: 0,
            };
            let level = if t > 40 {
                0.080 + 1e-4 * (t - 40) as f64
            } else {
                0.070
            };
            (books, gauges_at(t as f64, &[Some(level)]))
        })
        .collect();
    let s = settled(&case, &run, &[0], &history).expect("a stretch");
    assert_eq!((s.from_s, s.to_s, s.levels_m[0].len()), (40.0, 60.0, 20));
    let trend = s.trends()[0].expect("wet");
    assert!((trend - 1e-3).abs() < 1e-12, "{trend}");
    let asked = 2.0 / 3600.0 / 0.086;
    assert!(
        (s.over_weir - 66e-4 / asked).abs() < 1e-9,
        "{}",
        s.over_weir
    );
    let short = ci_flume(45.0).1;
    assert!(
        settled(&case, &short, &[0], &history).is_none(),
        "ends within a window"
    );
}

/// Of five particles of the CI flume (bed surface 0.055 m, the bed's end 2.23 m): sand in
/// the top row, a held grain on it, a grain moving in the pit, water over the bed and a
/// wall past the end. The two grains out of the bed, by x; a grain in the top row, or water
/// or a wall, listed, or the phase codes read as the case's indices, gives another list.
#[test]
fn the_sand_out_of_the_bed_is_listed_by_x() {
    let (flume, run) = ci_flume(30.0);
    let (case, channel) = level_case(&flume, &[], &run).expect("the CI flume");
    assert!((channel.bed_m - 0.055).abs() < 1e-9, "{}", channel.bed_m);
    let code = |phase: u32| f32::from_bits(phase);
    let (water, sand) = (code(1), code(2));
    let particles = Particles {
        positions: vec![
            [1.005, 0.050, 0.0, sand],
            [2.305, 0.030, 0.0, sand],
            [2.163, 0.061, 0.0, sand],
            [1.5, 0.065, 0.0, water],
            [2.505, 0.040, 0.0, code(flume_solver::particles::WALL_PHASE)],
        ],
        vel_rho: vec![[0.0; 4]; 5],
        ids: (0..5).collect(),
    };
    // Region 1 held, region 3 (bed load), water, a wall.
    let held = 1 | flume_solver::physics::sediment::pass::REGION_HELD;
    let regions = [held, 3, held, 5, 0];
    let loose = bed::loose_sand(&case, &channel, &particles, &regions);
    assert_eq!(loose, vec![(2.163, 0.061, true), (2.305, 0.030, false)]);
}

/// The reservoir is sized for the stored water unless `--set` sizes it; the resolution,
/// the discharge and the run's length are the benchmark's own.
#[test]
fn a_set_reservoir_is_kept() {
    let (flume, run) = ci_flume(30.0);
    let reservoir = |set: &[String]| {
        let (case, _) = level_case(&flume, set, &run).expect("the CI flume");
        assert_eq!(case.numerics.dp_m, 0.01);
        assert_eq!(case.time.end_s, 30.0);
        case.open_flume.expect("an open flume").reservoir_particles
    };
    // 0.3 m2 / (1 cm)^2.
    assert_eq!(reservoir(&[]), 3000);
    let set = ["open_flume.reservoir_particles=2500".to_string()];
    assert_eq!(reservoir(&set), 2500);
    let set = ["numerics.dp_m=0.02".to_string()];
    assert_eq!(reservoir(&set), 3000, "--dp is the benchmark's");
}

/// The full pit (the default; `--empty-pit` turns it off) reaches the run's case: the sand
/// bed's block stays, the pit's water is added, and the fixed bed, whose pit is always full,
/// keeps its own blocks.
#[test]
fn a_filled_pit_run_starts_with_water_in_the_pit() {
    let (flume, run) = ci_flume(60.0);
    let blocks = |filled_pit: bool, fixed_bed: bool| {
        let r = LevelRun {
            filled_pit,
            fixed_bed,
            ..run
        };
        let (case, _) = level_case(&flume, &[], &r).expect("the CI flume");
        let phases: Vec<String> = case.fluid_blocks.iter().map(|b| b.phase.clone()).collect();
        phases
    };
    assert_eq!(blocks(false, false), ["sand"]);
    assert_eq!(blocks(true, false), ["sand", "water"]);
    assert_eq!(blocks(true, true), blocks(false, true));
    assert_eq!(blocks(false, true), ["water"]);
}
