//! The eroded mass an open flume reports under `van_rijn_exner`: the sand collected whole
//! (Eq. 34) plus the mass the flow has worn off the bed as bed load, which under Exner's
//! balance a grain keeps in its region word while held and carries when let go. Under any
//! other erosion the wear is not conserved (a released grain starts whole), and the eroded
//! mass stays Eq. 34's.

mod common;

use flume_solver::budget::SedimentBudget;
use flume_solver::physics::sediment::pass::REGION_HELD;
use flume_solver::physics::sediment::pickup::{EXNER_WHOLE, units_word};
use flume_solver::physics::sediment::suspension::Region;
use flume_solver::{Backend, Case, Simulation};

const SAND: u32 = 2;
const WATER: u32 = 1;

fn collector(erosion: &str) -> Case {
    let set = [format!("phases.1.sediment.erosion={erosion}")];
    Case::from_path_with(&common::case_path("tests/cases/collector_2d.yaml"), &set)
        .expect("case parses")
}

fn flume_of(sim: &Simulation) -> flume_solver::FlumeObservation {
    sim.observe()
        .expect("observes")
        .flume
        .expect("an open flume reports")
}

/// Words set on the collector's particles before any step: eight sand grains held and worn a
/// quarter each, one let go that carries an eighth settled on it beyond its mass (-1/8), and a
/// water particle whose word has half a grain's units (as a stale word would). The report
/// counts the sand's: 2 - 1/8 grains; under `van_rijn_integrated`, none.
#[test]
fn the_eroded_mass_counts_the_sands_wear_and_no_other_particles() {
    for (erosion, grains) in [("van_rijn_exner", 1.875), ("van_rijn_integrated", 0.0)] {
        let c = collector(erosion);
        let mut sim = Simulation::new(Backend::cpu(1), &c).expect("case builds");
        let p = sim.read_particles().expect("reads");
        let quarter = EXNER_WHOLE as i32 / 4;
        let mut words = vec![0u32; p.len()];
        let sand: Vec<usize> = (0..p.len()).filter(|&i| p.phase(i) == SAND).collect();
        for &i in &sand[..8] {
            words[i] = Region::Unyielded as u32 | REGION_HELD | units_word(quarter);
        }
        words[sand[8]] = Region::BedLoad as u32 | units_word(-quarter / 2);
        let water = (0..p.len()).find(|&i| p.phase(i) == WATER).expect("water");
        words[water] = Region::Water as u32 | units_word(2 * quarter);
        sim.set_regions(&words);
        let f = flume_of(&sim);
        assert_eq!(f.eroded_particles, 0, "{erosion}");
        assert!(
            (f.worn_particles - grains).abs() < 1e-9,
            "{erosion}: {} grains worn",
            f.worn_particles
        );
        let m_s = sim.derived().phases[SAND as usize].mass;
        assert!(
            (f.eroded_kg_per_m - grains * m_s).abs() < 1e-12,
            "{erosion}: {} kg/m",
            f.eroded_kg_per_m
        );
    }
}

/// The collector's flow under `van_rijn_exner` to 0.5 s, with each grain of the cloud over the
/// pit set at the start to carry a quarter of a grain's wear (as one the bed let go would),
/// observed after every step from 0.1 to 0.3 s, while the cloud falls into the pit, and every
/// 0.05 s otherwise. The wear the report counts is the sediment budget's, which finds the sand
/// by id and phase: a grain collected in a chunk's last step still holds its word until the
/// next rheology pass, and counted as worn as well as collected it would be counted twice. The
/// eroded mass never falls while the cloud's grains are collected whole, each taking its wear
/// off the books as it goes.
#[test]
fn under_exner_the_eroded_mass_is_the_sand_gone_from_the_bed_and_never_falls() {
    let c = collector("van_rijn_exner");
    let mut sim = Simulation::new(Backend::cpu(2), &c).expect("case builds");
    let start = sim.read_particles().expect("reads");
    let cloud_y_min = c.fluid_blocks[1].min_m[1] as f32 - 1e-6;
    let mut words = vec![0u32; start.len()];
    let mut cloud = 0;
    for (i, w) in words.iter_mut().enumerate() {
        if start.phase(i) == SAND && start.positions[i][1] > cloud_y_min {
            *w = Region::Suspended as u32 | units_word(EXNER_WHOLE as i32 / 4);
            cloud += 1;
        }
    }
    sim.set_regions(&words);
    let mut budget = SedimentBudget::new(&c, &start).expect("sand in a flume");
    let m_s = sim.derived().phases[SAND as usize].mass;
    let mut last = flume_of(&sim);
    assert!((last.eroded_kg_per_m - 0.25 * f64::from(cloud) * m_s).abs() < 1e-12);
    let (mut checked_at_collection, mut samples) = (0, 0);
    while sim.time_s() < 0.5 {
        let t = sim.time_s();
        let next = if (0.1..0.3).contains(&t) {
            t + sim.last_dt_s()
        } else {
            0.05 * ((t / 0.05 + 1e-9).floor() + 1.0)
        };
        sim.advance_to(next).expect("runs");
        let f = flume_of(&sim);
        let now = sim.read_particles().expect("reads");
        let regions = sim.regions().expect("regions");
        let row = budget.update(sim.time_s(), &now, &regions, f.excluded_sediment);
        let at = sim.time_s();
        assert!(
            (f.worn_particles - row.worn).abs() < 1e-9,
            "at {at} s, {} collected: {} worn reported, {} in the sand",
            f.eroded_particles,
            f.worn_particles,
            row.worn
        );
        let books = (f.eroded_particles as f64 + row.worn) * m_s;
        assert!((f.eroded_kg_per_m - books).abs() < 1e-12, "at {at} s");
        assert!(
            f.eroded_kg_per_m >= last.eroded_kg_per_m - 1e-6 * m_s,
            "the eroded mass fell from {} to {} kg/m at {at} s",
            last.eroded_kg_per_m,
            f.eroded_kg_per_m
        );
        checked_at_collection += usize::from(f.eroded_particles > last.eroded_particles);
        samples += 1;
        last = f;
    }
    eprintln!(
        "{samples} observations, {checked_at_collection} right after a step that collected; {} grains collected ({cloud} in the cloud), {:.4} grains worn at the end",
        last.eroded_particles, last.worn_particles
    );
    assert!(
        last.eroded_particles > cloud as u64 / 2,
        "{} of the cloud's {cloud} grains collected: the test checks little",
        last.eroded_particles
    );
}
