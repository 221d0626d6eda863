//! A splash is one particle's fate, not the end of a run (`flume_solver::health`): in an open
//! flume a particle whose density leaves rho0 +/- 30 % is excluded (parked, recycled through the
//! inlet, counted); a real blow-up still rolls back, and one that recurs at the same simulated
//! time with a smaller step is reported as not a time-step problem, naming its particles.

mod common;

use flume_solver::particles::parked_phase;
use flume_solver::{Case, Health, Simulation, SolverError};
use flume_solver::{derive, generate};

const WATER: u32 = 1;

/// The ULBRA flume at CI size with no inflow: nothing moves but what a test sets moving.
fn ulbra_ci_still() -> Case {
    let mut c = common::ulbra_ci();
    if let Some(f) = c.open_flume.as_mut() {
        f.inflow_m3_per_s = 0.0;
    }
    c
}

/// A simulation of `case` whose parked particle of the lowest id is turned into a water drop
/// at `at`, moving at `velocity`; and the drop's id.
fn with_drop(case: &Case, at: [f32; 2], velocity: [f32; 2]) -> Option<(Simulation, u32)> {
    let gpu = common::gpu()?;
    let mut p = generate(case, &derive(case));
    let parked = parked_phase(case);
    let id = (0..p.len())
        .find(|&i| p.phase(i) == parked)
        .expect("a parked particle");
    p.positions[id] = [at[0], at[1], 0.0, f32::from_bits(WATER)];
    p.vel_rho[id] = [velocity[0], velocity[1], 0.0, 1000.0];
    let sim = Simulation::from_particles(gpu, case, p).expect("builds");
    Some((sim, id as u32))
}

/// One drop falling at 5 m/s (Mach 0.5 with c0 = 10 m/s) onto the floor of the empty collector
/// pit, alone: it compresses past 30 % against the wall and is excluded; the run goes on with
/// no blow-up, the drop is parked again, and the count and mass are whole. On the code before
/// this rule the same drop stopped the run ("a density left the weakly compressible range" at
/// every CFL).
#[test]
fn a_lone_drop_hitting_a_wall_is_excluded_and_the_run_goes_on() {
    let _l = common::gpu_lock();
    let c = ulbra_ci_still();
    let Some((mut sim, id)) = with_drop(&c, [2.35, 0.06], [0.0, -5.0]) else {
        return;
    };
    let parked_at_start = sim.flume().expect("flume").parked_particles;
    sim.advance_to(0.1).expect("a splash does not stop the run");
    let obs = sim.observe().expect("observes");
    let f = obs.flume.expect("flume");
    let now = sim.read_particles().expect("reads");
    eprintln!("after the splash: {f:?}, recoveries {}", obs.recoveries);
    assert_eq!(obs.recoveries, 0, "the splash was taken for a blow-up");
    assert_eq!(f.excluded_particles, 1, "the drop alone is excluded");
    assert_eq!(f.excluded_sediment, 0);
    assert_eq!(
        now.phase(id as usize),
        parked_phase(&c),
        "the drop is parked again"
    );
    assert_eq!(f.parked_particles, parked_at_start + 1);
    assert_eq!(f.eroded_particles, 0, "an excluded drop is not eroded sand");
    assert_eq!(now.len(), sim.initial_particles().len());
}

/// The same drop falling at 1.2 m/s, as the splash into the pit that stopped the twin at
/// t = 2.65 s: it compresses about 12 % and bounces; nothing is excluded and nothing blows up.
#[test]
fn a_drop_at_the_speed_of_the_pit_splash_is_neither_excluded_nor_fatal() {
    let _l = common::gpu_lock();
    let c = ulbra_ci_still();
    let Some((mut sim, id)) = with_drop(&c, [2.35, 0.04], [0.0, -1.2]) else {
        return;
    };
    sim.advance_to(0.1).expect("runs");
    let obs = sim.observe().expect("observes");
    let f = obs.flume.expect("flume");
    let now = sim.read_particles().expect("reads");
    eprintln!(
        "drop {id}: {:?} {:?}, max density error {:.3}",
        now.positions[id as usize], now.vel_rho[id as usize], obs.max_density_error
    );
    assert_eq!(obs.recoveries, 0);
    assert_eq!(f.excluded_particles, 0);
    assert_eq!(now.phase(id as usize), WATER);
    assert!(
        now.positions[id as usize][1] > 0.0,
        "the drop went through the pit's floor"
    );
}

/// A real blow-up (CFL 5, 25 times the case's, on a flowing flume) is not passed off as
/// splashes: it is caught, rolled back and retried, and the flags say why.
#[test]
fn an_unstable_step_in_a_flume_is_still_a_blow_up() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let c =
        Case::from_path(&common::case_path("tests/cases/collector_2d.yaml")).expect("case parses");
    let mut sim = Simulation::new(gpu, &c).expect("case builds");
    sim.advance_to(0.02).expect("runs");
    sim.set_cfl(5.0).expect("accepted for the test");
    let result = sim.advance_to(0.1);
    eprintln!("result {result:?}, recoveries {:?}", sim.recoveries());
    let first = sim.recoveries().first().expect("CFL 5 was not caught");
    let caught = Health::NON_FINITE | Health::MANY_EXCLUDED | Health::DT_COLLAPSE;
    assert!(
        first.health.0 & caught != 0,
        "caught for {}, not for the state going bad",
        first.health
    );
    assert!(first.cfl < 5.0);
}

/// A particle whose velocity is NaN fails the first step at every CFL: after the retries the
/// solver says it is not a time-step problem, and names the particle, its phase and where it
/// was.
#[test]
fn a_failure_at_the_same_time_at_a_smaller_step_is_reported_as_not_a_time_step_problem() {
    let _l = common::gpu_lock();
    let c = ulbra_ci_still();
    let Some((mut sim, id)) = with_drop(&c, [1.5, 0.2], [f32::NAN, 0.0]) else {
        return;
    };
    let err = sim.advance_to(0.05).expect_err("a NaN particle cannot run");
    let text = err.to_string();
    eprintln!("{text}");
    let SolverError::BlowUp {
        health,
        culprits,
        recurring_cfl,
        ..
    } = err
    else {
        panic!("not a blow-up: {text}")
    };
    assert!(health.0 & Health::NON_FINITE != 0, "{health}");
    let retries = flume_solver::simulation::MAX_RECOVERIES_PER_CHUNK;
    assert_eq!(sim.recoveries().len(), retries as usize);
    assert!(
        recurring_cfl.is_some_and(|cfl| (cfl - 0.2 * 0.5f64.powi(retries as i32)).abs() < 1e-6),
        "not reported as recurring down to the last CFL: {recurring_cfl:?}"
    );
    assert_eq!(culprits[0].id, id, "the NaN particle is named first");
    assert_eq!(culprits[0].phase, "water");
    assert!(text.contains("not a time-step problem"), "{text}");
    assert!(text.contains(&format!("id {id} (water)")), "{text}");
}
