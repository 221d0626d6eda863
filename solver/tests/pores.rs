//! The dry bed's pores (`phases.*.sediment.pores`): a still pool over a dry bed
//! (`tests/cases/pores_2d.yaml`) soaks into it at Green & Ampt's rate, column by column, until
//! the bed is full, and the water it takes is parked, not lost.

mod common;

use flume_solver::{Backend, Case, Particles, Simulation};

const DP: f64 = 0.01;
/// The case's bed: porosity, K (m/s), psi_f (m), depth (m), and the pool over it (m).
const POROSITY: f64 = 0.4;
const K: f64 = 1.0e-3;
const SUCTION: f64 = 0.2;
const BED: f64 = 0.05;
const POOL: f64 = 0.05;
/// Columns of the bed downstream of the inlet's buffer, which covers its first 3 cm.
const N: usize = 25;

fn case() -> Case {
    Case::from_path(&common::case_path("tests/cases/pores_2d.yaml")).expect("case parses")
}

/// Green-Ampt's depth taken up in `t` under ponding `head` deep, by the fixed-point iteration
/// of Chow, Maidment & Mays (1988, Example 4.4.1), F = K t + S ln(1 + F / S): another
/// algorithm than the solver's bisection.
fn green_ampt(t: f64, head: f64) -> f64 {
    let s = (SUCTION + head) * POROSITY;
    let mut f = K * t;
    for _ in 0..200 {
        f = K * t + s * (1.0 + f / s).ln();
    }
    f
}

fn flume_of(sim: &Simulation) -> flume_solver::FlumeObservation {
    sim.observe()
        .expect("observes")
        .flume
        .expect("an open flume reports")
}

fn count(p: &Particles, phase: u32) -> usize {
    (0..p.len()).filter(|&i| p.phase(i) == phase).count()
}

/// Per column, the depth taken up and the particles parked, after `t` s on `backend`; and the
/// simulation.
fn soak(backend: Backend, t: f64) -> (Vec<(f64, u32)>, Simulation) {
    let mut sim = Simulation::new(backend, &case()).expect("case builds");
    sim.advance_to(t).expect("runs");
    let columns = sim.pores().expect("the case's bed has pores").columns();
    (columns, sim)
}

#[test]
fn a_still_pool_soaks_into_the_dry_bed_at_green_ampts_rate_until_it_is_full() {
    let c = case();
    let water = 1;
    let parked = flume_solver::particles::parked_phase(&c);
    let mut sim = Simulation::new(Backend::cpu(2), &c).expect("case builds");
    let start = sim.read_particles().expect("reads");
    sim.advance_to(0.5).expect("runs");
    let columns = sim.pores().expect("pores").columns();
    assert_eq!(columns.len(), N, "one column a dp wide");
    // The pool drains into the pores: the head lies between none and the pool's start, read
    // from the top particles' centres, which the settling pool moves by a fraction of a dp.
    let (low, high) = (green_ampt(0.5, 0.0), green_ampt(0.5, POOL + 0.5 * DP));
    eprintln!("F(0.5 s) between {low:.5} and {high:.5} m; columns {columns:?}");
    for (i, &(taken, parked_here)) in columns.iter().enumerate() {
        assert!(
            taken > 0.97 * low && taken < 1.01 * high,
            "column {i} took {taken} m"
        );
        assert_eq!(parked_here, 1, "column {i}: F / dp = {:.2}", taken / DP);
    }
    // Nothing else leaves the closed pool (the weir stands over it): the water the pores
    // took is gone from the flow, and parked.
    let now = sim.read_particles().expect("reads");
    let f = flume_of(&sim);
    assert_eq!(f.soaked_particles, N as u64);
    assert_eq!(
        count(&start, water) - count(&now, water),
        N,
        "the water taken is gone"
    );
    assert_eq!(count(&now, parked) - count(&start, parked), N, "and parked");
    assert_eq!(f.parked_particles as usize, count(&now, parked));

    // The bed holds its porosity's share of its depth, 2 cm, and no more: Green-Ampt would
    // have put 2.5 cm in by 4 s even with no head left.
    assert!(green_ampt(4.0, 0.0) > POROSITY * BED * 1.2);
    sim.advance_to(4.0).expect("runs");
    let columns = sim.pores().expect("pores").columns();
    for (i, &(taken, parked_here)) in columns.iter().enumerate() {
        assert!(
            (taken - POROSITY * BED).abs() < 1e-12,
            "column {i} took {taken} m"
        );
        assert_eq!(parked_here, 2, "column {i}");
    }
    assert_eq!(flume_of(&sim).soaked_particles, 2 * N as u64);
}

/// The host reads the state and parks through the backend's own calls: the wgpu backend
/// (lavapipe in CI) takes the same water from the same columns.
#[test]
fn the_gpu_backend_soaks_the_bed_as_the_cpu_backend_does() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let (cpu, _) = soak(Backend::cpu(2), 0.5);
    let (gpu, sim) = soak(Backend::from(gpu), 0.5);
    for (i, (c, g)) in cpu.iter().zip(&gpu).enumerate() {
        assert_eq!(c.1, g.1, "column {i}: parked on CPU and GPU");
        assert!(
            (c.0 - g.0).abs() < 0.01 * c.0,
            "column {i}: {c:?} against {g:?}"
        );
    }
    let f = flume_of(&sim);
    assert_eq!(f.soaked_particles, N as u64);
}

/// A blow-up sends the state back to where the call began, and the pores go back with it:
/// what they count parked is what the state holds parked, retries and all. (At CFL 5 the
/// retries at 0.625 and 0.31 run several submissions, parking water, before one holds.)
#[test]
fn a_recovered_blow_up_takes_the_pores_back_with_the_state() {
    let c = case();
    let parked = flume_solver::particles::parked_phase(&c);
    let mut sim = Simulation::new(Backend::cpu(2), &c).expect("case builds");
    let start = sim.read_particles().expect("reads");
    // Each column parks its second particle at F = 1.5 cm, about 1.1 s in.
    sim.advance_to(1.0).expect("runs");
    sim.set_cfl(5.0).expect("accepted for the test");
    sim.advance_to(1.6).expect("recovers");
    eprintln!("recoveries: {:?}", sim.recoveries());
    assert!(!sim.recoveries().is_empty(), "CFL 5 did not blow up");
    let in_pores: u32 = sim
        .pores()
        .expect("pores")
        .columns()
        .iter()
        .map(|c| c.1)
        .sum();
    let now = sim.read_particles().expect("reads");
    let f = flume_of(&sim);
    assert_eq!(u64::from(in_pores), f.soaked_particles);
    assert_eq!(
        count(&now, parked) - count(&start, parked),
        in_pores as usize,
        "parked in the state"
    );
}
