//! The recovery's roll-back ([`Simulation::save`], [`Simulation::roll_back`]): a stretch of a
//! run, rolled back and run again, gives the bits it gave the first time. A comparison of the
//! awake set with the full computation cannot see a roll-back that forgets something both
//! forget; this one can.

use super::Simulation;
use crate::{Backend, BoundaryConditions, Case};

/// The run's state as bits: positions, velocities and densities, then region words.
fn bits(sim: &Simulation) -> Vec<u32> {
    let p = sim.read_particles().expect("readback");
    let regions = sim.regions().expect("regions");
    let values = p.positions.iter().chain(&p.vel_rho).flatten();
    values.map(|v| v.to_bits()).chain(regions).collect()
}

/// Particles in the open flume's reservoir.
fn parked(sim: &Simulation) -> usize {
    let phase = sim.parked_phase().expect("an open flume");
    let p = sim.read_particles().expect("readback");
    p.positions
        .iter()
        .filter(|x| x[3].to_bits() == phase)
        .count()
}

/// The CI flume as the twin runs it (`scripts/run.sh`), on the CPU backend with its awake set.
fn twin() -> Case {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../launch_configs/ulbra_flume.yaml"
    );
    let set = [
        "numerics.dp_m=0.01",
        "open_flume.reservoir_particles=2500",
        "numerics.boundary={method: generalised}",
        "numerics.viscosity={method: multiphase, eddy_m2_per_s: 3.95e-5}",
        "phases.1.sediment.erosion=van_rijn_exner",
        "phases.1.sediment.shields_speed=water",
        "phases.1.sediment.comes_to_rest=beside_a_solid",
    ];
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    Case::from_path_with(std::path::Path::new(path), &set).expect("the CI flume")
}

/// The twin's flume, filled to 7 s with its inlet then shut, so that only the weir parks
/// particles: run to 7.3 s, rolled back to 7 s and run again, it takes the same steps to the
/// same bits. Between the two, the awake set's engine keeps the parked particles stored last
/// in place from one sort to the next, from the slot where their run began (`cpu/step.rs`);
/// after the first run that slot lies lower than in the saved state, which has more particles
/// in the flow. A roll-back that kept it would leave particles of the flow out of the sort;
/// one that kept the engine's memory by id, or the host's clock or inlet, would differ too.
#[test]
fn a_run_rolled_back_and_run_again_gives_the_same_bits() {
    let mut sim = Simulation::new(Backend::cpu(2), &twin()).expect("builds");
    sim.advance_to(7.0).expect("runs");
    let shut = BoundaryConditions {
        inflow_m3_per_s: 0.0,
    };
    sim.set_boundary_conditions(shut).expect("the inlet shuts");
    let (saved, parked_before) = (sim.save(), parked(&sim));
    sim.advance_to(7.3).expect("runs");
    let (first, steps) = (bits(&sim), sim.steps());
    // Not vacuous: the weir parked particles in the stretch.
    assert!(
        parked(&sim) > parked_before,
        "{parked_before} parked at 7 s"
    );
    sim.roll_back(&saved);
    assert!(bits(&sim) != first, "rolled back");
    sim.advance_to(7.3).expect("runs again");
    assert_eq!(sim.steps(), steps, "steps to 7.3 s");
    assert!(bits(&sim) == first, "the run again differs");
}
