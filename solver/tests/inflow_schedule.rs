//! A schedule of discharges drives the open flume's inlet: each applied at its own time on the
//! way, one the inlet refuses leaving the one before in force, the limit the node is told the
//! same one the solver applies. The inlet places what the discharge calls for, or counts the
//! spots it found taken.

mod common;

use flume_solver::particles::{WALL_PHASE, parked_phase};
use flume_solver::{
    Backend, BoundaryConditions, InflowSchedule, Simulation, derive, generate,
    inflow_limit_m3_per_s,
};

fn bits(sim: &Simulation) -> Vec<[u32; 4]> {
    let p = sim.read_particles().expect("reads");
    p.positions.iter().map(|x| x.map(f32::to_bits)).collect()
}

fn set(sim: &mut Simulation, q: f64) {
    sim.set_boundary_conditions(BoundaryConditions { inflow_m3_per_s: q })
        .expect("a discharge the inlet carries");
}

#[test]
fn a_schedule_applies_each_discharge_at_its_time_and_a_refused_one_changes_nothing() {
    let c = common::ulbra_ci();
    let backend = Backend::cpu(0);
    let limit = inflow_limit_m3_per_s(&c).expect("an open flume");
    let (q1, q2) = (1.0 / 3600.0, 3.0 / 3600.0);
    let schedule = InflowSchedule::new(vec![(0.02, q1), (0.04, 2.0 * limit), (0.06, q2)]);
    let mut through = Simulation::new(backend.clone(), &c).expect("case builds");
    let refused = through.advance_through(0.08, &schedule).expect("runs");
    assert_eq!(refused.len(), 1, "{refused:?}");
    assert_eq!(refused[0].time_s, 0.04);
    assert_eq!(refused[0].inflow_m3_per_s, 2.0 * limit);
    assert_eq!(through.time_s(), 0.08);
    let f = through.flume().expect("an open flume");
    assert_eq!(f.inflow_m3_per_s, q2, "the last discharge is in force");

    // The same run stopped at each change by hand, the refused one included: the same bits.
    let mut by_hand = Simulation::new(backend, &c).expect("case builds");
    by_hand.advance_to(0.02).expect("runs");
    set(&mut by_hand, q1);
    by_hand.advance_to(0.04).expect("runs");
    by_hand.advance_to(0.06).expect("runs");
    set(&mut by_hand, q2);
    by_hand.advance_to(0.08).expect("runs");
    assert_eq!(by_hand.steps(), through.steps());
    assert!(bits(&by_hand) == bits(&through), "the runs differ");

    // The limit the node gates with is the solver's own, to the last bit.
    set(&mut by_hand, limit);
    let above = limit * (1.0 + f64::EPSILON);
    let bc = BoundaryConditions {
        inflow_m3_per_s: above,
    };
    assert!(
        by_hand.set_boundary_conditions(bc).is_err(),
        "{above} taken"
    );
}

/// Runs the CI flume to `end_s`, if `obstacle` with wall particles dp / 2 apart along the
/// inlet's lower row, over the whole buffer; returns (placed, blocked, the observation's share).
fn inlet_books(obstacle: bool, end_s: f64) -> (u64, u64, f64) {
    let c = common::ulbra_ci();
    let mut particles = generate(&c, &derive(&c));
    if obstacle {
        let dp = c.numerics.dp_m as f32;
        let f = c.open_flume.as_ref().expect("an open flume");
        let row = ((f.inlet.y_min_m / c.numerics.dp_m).floor() + 1.0) as f32 * dp;
        // A submission moves the buffer by up to its depth less one column, so a new column
        // enters anywhere from x_min + dp to the buffer's face (4 dp): a wall every dp / 2
        // takes the lower spot of each.
        let x0 = c.domain.min_m[0] as f32;
        let walls = (2..=2 * f.inlet.layers).map(|k| x0 + 0.5 * dp * k as f32);
        let parked = parked_phase(&c);
        let spare: Vec<usize> = (0..particles.len())
            .filter(|&i| particles.phase(i) == parked)
            .collect();
        assert!(
            spare.len() > 2 * f.inlet.layers as usize,
            "parked particles to spare"
        );
        for (i, x) in spare.into_iter().zip(walls) {
            particles.positions[i] = [x, row, 0.0, f32::from_bits(WALL_PHASE)];
            particles.vel_rho[i] = [0.0, 0.0, 0.0, c.phases[0].rho0_kg_per_m3 as f32];
        }
    }
    let mut sim = Simulation::from_particles(Backend::cpu(0), &c, particles).expect("case builds");
    sim.advance_to(end_s).expect("runs");
    let f = sim.flume().expect("an open flume");
    let share = sim
        .observe()
        .expect("observes")
        .flume
        .expect("flume")
        .blocked_share();
    (f.injected_particles, f.blocked_particles, share)
}

#[test]
fn the_inlet_places_what_the_discharge_calls_for_or_counts_the_spot_taken() {
    let c = common::ulbra_ci();
    let f = c.open_flume.as_ref().expect("an open flume");
    let dp = c.numerics.dp_m;
    let end_s = 0.5;
    // 2 m3/h through 2 rows of 1 cm over 8.6 cm of width: 64.6 particles a second, in
    // columns of 2.
    let due = f.inflow_m3_per_s * end_s / (dp * dp * f.width_m);
    let (placed, blocked, share) = inlet_books(false, end_s);
    assert_eq!(blocked, 0, "nothing sits in the inlet's way");
    assert_eq!(share, 0.0);
    assert!(
        (placed as f64 - due).abs() <= 2.0,
        "{placed} placed, {due:.1} due"
    );
    // Walls along the lower row take one spot of every column: half the inflow is counted
    // blocked, none placed on top of a wall.
    let (placed, blocked, share) = inlet_books(true, end_s);
    assert!(
        ((placed + blocked) as f64 - due).abs() <= 2.0,
        "{placed} placed and {blocked} blocked, {due:.1} due"
    );
    assert_eq!(placed, blocked, "one spot of each column of two");
    assert_eq!(share, 0.5);
}
