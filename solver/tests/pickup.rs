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
//! mass the chance lifted whole, spread thin. Worn net of what settles from upstream
//! (`van_rijn_exner`), the bed's middle three fifths, over which the front runs alike, gain
//! 0.24 grains' mass where the pick-up alone wears 10.55 off them (measured): the load the
//! front carries settles on the dry bed ahead of it. The bed's first columns, passed nothing
//! from upstream, wear what the rest gains, 0.07 grains' mass more in all.

mod common;

use common::case_path;
use flume_solver::budget::SedimentBudget;
use flume_solver::{Backend, Case, ParticleRegion, Simulation};
use std::sync::OnceLock;

const END_S: f64 = 4.0;

/// The twin's CI flume with pick-up `erosion`: the grains set moving by [`END_S`] and, for
/// each held grain, where it lies along the flume (m) and the share of its mass it has lost,
/// in particles (negative where more settled on it than was worn off).
fn front_over_the_bed(erosion: &str) -> (u64, Vec<(f32, f64)>) {
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
    let now = sim.read_particles().expect("reads");
    let exner = erosion == "van_rijn_exner";
    let worn = regions
        .iter()
        .map(|&w| ParticleRegion::from_word(w))
        .zip(&now.positions)
        .filter(|(r, _)| r.held)
        .map(|(r, x)| (x[0], r.worn(exner)))
        .collect();
    (mobilised, worn)
}

/// [`front_over_the_bed`] worn away (`van_rijn_integrated`), run once for both tests.
fn worn_away() -> &'static (u64, Vec<(f32, f64)>) {
    static RUN: OnceLock<(u64, Vec<(f32, f64)>)> = OnceLock::new();
    RUN.get_or_init(|| front_over_the_bed("van_rijn_integrated"))
}

/// The grains' mass worn off the held grains of `worn` between `from_m` and `to_m` along the
/// flume, net of what settled on them, and how many held grains there have lost or gained.
fn worn_between(worn: &[(f32, f64)], from_m: f32, to_m: f32) -> (f64, usize) {
    let there = worn
        .iter()
        .filter(|(x, u)| *u != 0.0 && (from_m..to_m).contains(x));
    there.fold((0.0, 0), |(mass, n), (_, u)| (mass + u, n + 1))
}

#[test]
fn the_front_wears_the_bed_where_a_chance_lifted_whole_grains() {
    let (by_chance, worn_by_chance) = front_over_the_bed("van_rijn_pickup");
    let (worn_away, worn) = (worn_away().0, &worn_away().1);
    let touched: Vec<f64> = worn
        .iter()
        .filter(|(_, u)| *u > 0.0)
        .map(|&(_, u)| u)
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
    assert!(worn_by_chance.iter().all(|(_, u)| *u == 0.0));
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

/// The bed's middle three fifths, m: the sand lies from 0.1 to 2.2 m (`ulbra_flume.yaml`).
const MIDDLE_M: (f32, f32) = (0.52, 1.78);

/// Worn net of what settles from upstream (`van_rijn_exner`, Exner's balance), a grain under
/// the front's sheet is passed about what it passes on, as the front runs the same over the
/// whole middle of the bed: what is worn there is what the flow's change along it leaves, a
/// small part of what the pick-up alone wears off the same stretch. The first column, passed
/// nothing, still wears.
#[test]
fn the_front_wears_the_beds_middle_net_of_what_settles_from_upstream() {
    let gross = &worn_away().1;
    let (set_moving, net) = front_over_the_bed("van_rijn_exner");
    let (from, to) = MIDDLE_M;
    let (gross_mass, gross_n) = worn_between(gross, from, to);
    let (net_mass, net_n) = worn_between(&net, from, to);
    let (all_net, _) = worn_between(&net, 0.0, 3.0);
    eprintln!(
        "by 4 s over {from}-{to} m: the pick-up alone wore {gross_mass:.2} grains' mass off \
         {gross_n} grains, net of what settles {net_mass:.3} off {net_n}; {all_net:.3} in all, \
         {set_moving} set moving"
    );
    assert!(
        gross_mass > 5.0,
        "{gross_mass}: the front wore little even alone"
    );
    assert!(
        net_mass.abs() < 0.2 * gross_mass,
        "{net_mass:.3} grains' mass worn net against {gross_mass:.2} alone"
    );
    assert!(all_net > net_mass, "nothing worn outside the middle");
}
