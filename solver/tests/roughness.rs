//! The mechanism of the paper's Figure 10 (Zubeldia et al. 2018, Section 3.2): a rougher bed
//! (larger ks/d50) gives a larger friction velocity for the same near-bed flow (Eqs. 19-21), a
//! larger Shields number, and so more sand carried further.
//!
//! The ULBRA flume at the paper's dp = 4 mm, shortened to a bed of 0.8 m (x = 0-0.9 m: the
//! sand from the orifice, as the paper's; the sill and the collector pit behind it, as in the
//! bundled case), from its dry start to 6 s: the
//! front crosses the dry bed in about 3 s, the sheet of grains it sets moving has come to rest by
//! 5 s (ks/d50 = 1 and 3; at 7 it still creeps). At dp = 1 cm the flow moves no grain further
//! than 3 cm, so the CI-size flume cannot show it. Three runs, ks/d50 = 1, 3 and 7, on the CPU
//! backend, side by side on one thread each: its results do not depend on the thread count
//! (`cases.rs`), and two threads run the CI flume only some 1.5 times faster than one (README,
//! speed), so three one-thread runs fill two cores better than three two-thread runs in turn
//! (374.7 s against 533.3 s in whole runs of the suite).
//!
//! Each run's sand is followed by id (`flume_solver::budget`): the grains that reached the
//! collector, the grains carried further than the budget's `FAR_M` (10 cm, its
//! `travelled_far`), and the sand that crossed a fixed section of the bed, averaged over a
//! section every 1 cm along it (the bed-load volume the flow carried past a section).
//!
//! Measured on the paper's bed (the test prints them), at 6 s, for ks/d50 = 1 / 3 / 7:
//! collected 6 / 15 / 26, over 10 cm 0 / 132 / 176, mean section crossing 16.5 / 26.9 / 35.6
//! grains. The figures that follow, and the margins, were measured with a fixed apron under the
//! inlet (the bed from x = 0.1 m), which the case carried until 2026-11-27: collected 9 / 13 /
//! 11, over 10 cm 33 / 108 / 132, crossing 19.1 / 25.0 / 29.2. The sheet's travel is
//! sensitive to the smallest perturbation, so the same three runs were repeated with their steps
//! shortened to land every 0.25 s and every 0.3 s (`simulate` of the same flume): collected
//! 8 / 13 / 11 and 9 / 15 / 14, over 10 cm 63 / 103 / 123 and 71 / 119 / 130. Over 10 cm and the
//! crossing rise with ks/d50 at every step in every run; the collected grains rise from 1 to 3
//! and from 1 to 7, but in all three runs 7 collected 1-2 fewer than 3, so that step is not
//! asserted. The margins asserted are set under the smallest rise seen in those three runs
//! (over 10 cm +10 a step, seen +11; crossing +2 a step, seen +4.2; collected +2 from 1 to 3,
//! seen +4, and +1 from 1 to 7, seen +2), not fitted to one run.
//!
//! Before the bed's slope came from the bed (it came from the water around a grain, and the
//! front's sheet zeroed its critical stress on the flat bed, `physics/sediment/pass.rs`), the
//! same runs collected 7 / 13 / 17, 9 / 12 / 18 and 7 / 15 / 17: the front's false pick-ups fed
//! the sheet at the rough end. With the sill's crest level with the sand's top row (before it
//! stood a row under it, see `docs/scour/README.md`) the collected grains were 2 / 2 / 5.

mod common;

use common::case_path;
use flume_solver::budget::{BudgetRow, SedimentBudget};
use flume_solver::config::{CollectorConfig, ProfileConfig, SillConfig};
use flume_solver::{Backend, Case, Particles, Simulation};
use std::collections::HashMap;

const BED_START_M: f64 = 0.0;
const BED_END_M: f64 = 0.9;
const END_S: f64 = 6.0;

/// The bundled ULBRA case at its own dp (4 mm), its bed 0.8 m long.
fn short_flume(ks_over_d50: f64) -> Case {
    let mut c = Case::from_path(&case_path("../launch_configs/ulbra_flume.yaml")).expect("parses");
    assert_eq!(c.numerics.dp_m, 0.004, "the paper's dp");
    let pit_end = BED_END_M + 0.2;
    c.domain.max_m[0] = pit_end;
    c.fluid_blocks[0].max_m[0] = BED_END_M;
    let flume = c.open_flume.as_mut().expect("an open flume");
    flume.sill = Some(SillConfig {
        x_min_m: BED_END_M,
        x_max_m: BED_END_M + 0.03,
    });
    flume.collector = CollectorConfig {
        x_min_m: BED_END_M + 0.02,
        x_max_m: pit_end,
        y_max_m: 0.05,
    };
    flume.reservoir_particles = 6000;
    c.observations.gauges.truncate(1);
    c.observations.profile = Some(ProfileConfig {
        x_min_m: 0.05,
        x_max_m: BED_END_M - 0.05,
        columns: 9,
        y_m: 0.0,
    });
    let (sand, _) = c.sediment_phases().expect("sand in water");
    c.phases[sand]
        .sediment
        .as_mut()
        .expect("a sediment")
        .ks_over_d50 = ks_over_d50;
    c
}

/// Sand grains' x by id.
fn sand_x(p: &Particles, sand_phase: u32) -> HashMap<u32, f64> {
    (0..p.len())
        .filter(|&i| p.phase(i) == sand_phase)
        .map(|i| (p.ids[i], f64::from(p.positions[i][0])))
        .collect()
}

/// Sand that crossed each section of the bed 1 cm apart (its ends excluded) downstream (a
/// grain no longer sand has left the bed over its end), averaged over the sections.
fn mean_section_crossing(start: &HashMap<u32, f64>, end: &HashMap<u32, f64>) -> f64 {
    let n = ((BED_END_M - BED_START_M) / 0.01).round() as u32;
    let sections: Vec<f64> = (1..n).map(|k| BED_START_M + 0.01 * f64::from(k)).collect();
    let crossed: usize = sections
        .iter()
        .map(|&s| {
            start
                .iter()
                .filter(|&(id, &x0)| x0 < s && end.get(id).is_none_or(|&x1| x1 >= s))
                .count()
        })
        .sum();
    crossed as f64 / sections.len() as f64
}

struct Run {
    ks_over_d50: f64,
    row: BudgetRow,
    crossing: f64,
}

fn run(ks_over_d50: f64) -> Run {
    let case = short_flume(ks_over_d50);
    let sand_phase = case.sediment_phases().expect("sand").0 as u32 + 1;
    let mut sim = Simulation::new(Backend::cpu(1), &case).expect("builds");
    let initial = sim.read_particles().expect("reads");
    let mut books = SedimentBudget::new(&case, &initial).expect("a flume with sand");
    sim.advance_to(END_S).expect("runs");
    let now = sim.read_particles().expect("reads");
    let regions = sim.regions().expect("regions");
    let excluded = sim.flume().map_or(0, |f| f.excluded_sediment);
    let row = books.update(END_S, &now, &regions, excluded);
    let crossing = mean_section_crossing(&sand_x(&initial, sand_phase), &sand_x(&now, sand_phase));
    Run {
        ks_over_d50,
        row,
        crossing,
    }
}

#[test]
fn a_rougher_bed_carries_more_sand_further_and_into_the_collector_at_the_papers_dp() {
    let runs: Vec<Run> = std::thread::scope(|s| {
        let handles = [1.0, 3.0, 7.0].map(|k| s.spawn(move || run(k)));
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    for r in &runs {
        println!(
            "ks/d50 {}: mobilised {}, over 10 cm {}, mean section crossing {:.1}, \
             collected {}, furthest {:.3} m",
            r.ks_over_d50,
            r.row.mobilised,
            r.row.travelled_far,
            r.crossing,
            r.row.collected,
            r.row.furthest_m
        );
    }
    for pair in runs.windows(2) {
        let (smooth, rough) = (&pair[0], &pair[1]);
        let says = format!(
            "ks/d50 {} against {}: collected {} / {}, over 10 cm {} / {}, crossing {:.1} / {:.1}",
            smooth.ks_over_d50,
            rough.ks_over_d50,
            smooth.row.collected,
            rough.row.collected,
            smooth.row.travelled_far,
            rough.row.travelled_far,
            smooth.crossing,
            rough.crossing
        );
        assert!(rough.crossing >= smooth.crossing + 2.0, "{says}");
        assert!(
            rough.row.travelled_far >= smooth.row.travelled_far + 10,
            "{says}"
        );
    }
    let collected: Vec<u64> = runs.iter().map(|r| r.row.collected).collect();
    assert!(
        collected[1] >= collected[0] + 2 && collected[2] > collected[0],
        "ks/d50 1 / 3 / 7 collect {collected:?} grains: the rougher beds not more than the smoothest"
    );
}
