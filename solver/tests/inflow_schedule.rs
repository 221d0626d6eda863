//! A schedule of discharges drives the open flume's inlet: each applied at its own time on the
//! way, one the inlet refuses leaving the one before in force, the limit the node is told the
//! same one the solver applies.

mod common;

use flume_solver::{
    Backend, BoundaryConditions, InflowSchedule, Simulation, inflow_limit_m3_per_s,
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
