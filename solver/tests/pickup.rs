//! The pick-up under the front, at the size the twin runs live: the CI-size ULBRA flume
//! (dp = 1 cm) with the twin's generalised walls and eddy viscosity, from its dry start to 4 s,
//! when the front has crossed the bed, under van Rijn's (1984) pick-up rate taken two ways
//! (`physics::sediment::pickup`).
//!
//! As a chance each step (`van_rijn_pickup`), a grain the front's sheet passes over is lifted
//! whole, one in ten or so: measured, 20 grains set moving by 4 s, whose holes and perched
//! grains, a dp deep under a flow 3 dp deep, held the levels 6-10 mm high (README, levels
//! section). Worn away (`van_rijn_integrated`), the same rate takes a share of each grain's
//! mass, and no grain has lost all of it by the time the front has passed: none set moving by
//! 4 s (6 by 8 s, at the inlet's jet and the bed's end, in a `simulate` run), while 215 of the
//! 1,100 held grains have lost some, a fifth of one at most, 17.05 grains' mass in all: the
//! mass the chance lifted whole, spread thin.

mod common;

use common::case_path;
use flume_solver::budget::SedimentBudget;
use flume_solver::physics::sediment::pickup::{PICKUP_SHIFT, PICKUP_WHOLE};
use flume_solver::{Backend, Case, ParticleRegion, Simulation};

const END_S: f64 = 4.0;

/// The twin's CI flume with pick-up `erosion`: the grains set moving by [`END_S`] and the
/// share of its mass each held grain has lost, in [`PICKUP_WHOLE`]ths.
fn front_over_the_bed(erosion: &str) -> (u64, Vec<u32>) {
    let set = [
        "numerics.dp_m=0.01".to_string(),
        "open_flume.reservoir_particles=2500".to_string(),
        "numerics.boundary={method: generalised}".to_string(),
        "numerics.viscosity={method: multiphase, eddy_m2_per_s: 3.95e-5}".to_string(),
        format!("phases.1.sediment.erosion={erosion}"),
    ];
    let path = case_path("../launch_configs/ulbra_flume.yaml");
    let case = Case::from_path_with(&path, &set).expect("the CI flume");
    let mut sim = Simulation::new(Backend::cpu(0), &case).expect("builds");
    let initial = sim.read_particles().expect("reads");
    let mut books = SedimentBudget::new(&case, &initial).expect("sand");
    let mut mobilised = 0;
    for k in 1..=(END_S * 10.0).round() as u32 {
        let t = 0.1 * f64::from(k);
        sim.advance_to(t).expect("runs");
        let now = sim.read_particles().expect("reads");
        let regions = sim.regions().expect("regions");
        let excluded = sim.flume().map_or(0, |f| f.excluded_sediment);
        mobilised = books.update(t, &now, &regions, excluded).mobilised;
    }
    let regions = sim.regions().expect("regions");
    let worn = regions
        .iter()
        .filter(|&&w| ParticleRegion::from_word(w).held)
        .map(|w| w >> PICKUP_SHIFT)
        .collect();
    (mobilised, worn)
}

#[test]
fn the_front_wears_the_bed_where_a_chance_lifted_whole_grains() {
    let (by_chance, worn_by_chance) = front_over_the_bed("van_rijn_pickup");
    let (worn_away, worn) = front_over_the_bed("van_rijn_integrated");
    let touched: Vec<f64> = worn
        .iter()
        .filter(|&&u| u > 0)
        .map(|&u| f64::from(u) / f64::from(PICKUP_WHOLE))
        .collect();
    let most = touched.iter().copied().fold(0.0, f64::max);
    let total: f64 = touched.iter().sum();
    eprintln!(
        "by 4 s: set moving {by_chance} by chance, {worn_away} worn away; worn: {} of {} held \
         grains, {total:.2} grains' mass in all, {most:.3} of one at most",
        touched.len(),
        worn.len()
    );
    assert!(by_chance >= 10, "the chance set {by_chance} grains moving");
    assert!(worn_away <= 2, "{worn_away} grains worn away by 4 s");
    // The chance keeps no account of what it wore; worn away, the front wore most of the
    // wetted surface, a fraction of a grain each.
    assert!(worn_by_chance.iter().all(|&u| u == 0));
    assert!(touched.len() >= 100, "{} grains worn", touched.len());
    assert!(most < 1.0, "{most}");
    // The same rate either way: the mass worn off is what the chance lifts whole, within the
    // chance's scatter (20 grains, so +/- 9 at 2 sigma) and the two runs' different beds;
    // a share of a step mis-scaled by a power of two fails it.
    let lifted = by_chance as f64;
    assert!(
        total > 0.5 * lifted && total < 2.0 * lifted,
        "{total:.2} grains' mass worn against {by_chance} lifted"
    );
}
