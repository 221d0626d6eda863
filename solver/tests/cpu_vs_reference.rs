//! Each stage of the CPU backend against its oracle in `flume_solver::physics`: the checks the
//! wgpu stages pass on lavapipe (`common/stages.rs`), with the same tolerances.

mod common;

use common::parked;
use common::sand_stages;
use common::stages::{self, case};
use flume_solver::Backend;

const CPU: Backend = Backend::cpu(2);

#[test]
fn cell_list_matches_a_counting_sort_exactly() {
    stages::check_cell_list(&CPU);
}

#[test]
fn forces_match_the_interaction_2d() {
    stages::check_forces(&CPU, case("tests/cases/hydrostatic_2d.yaml"), "2-D", 7);
}

#[test]
fn forces_match_the_interaction_3d() {
    stages::check_forces(&CPU, case("tests/cases/hydrostatic_3d.yaml"), "3-D", 8);
}

#[test]
fn forces_with_molteni_diffusion_match_the_interaction() {
    stages::check_forces(&CPU, stages::molteni_case(), "Molteni-Colagrossi", 19);
}

#[test]
fn generalised_wall_densities_match_the_interaction() {
    stages::check_generalised_wall_forces(&CPU);
}

#[test]
fn steps_under_generalised_walls_match_the_oracle() {
    stages::check_symplectic_step_generalised(&CPU);
    stages::check_verlet_steps_generalised(&CPU);
}

#[test]
fn laminar_forces_match_the_interaction() {
    stages::check_laminar_forces(&CPU);
}

#[test]
fn one_symplectic_step_matches_the_oracle() {
    stages::check_symplectic_step(&CPU);
}

#[test]
fn two_verlet_steps_match_the_oracle() {
    stages::check_verlet_steps(&CPU);
}

#[test]
fn probes_and_extremes_match_the_oracle() {
    stages::check_probes(&CPU);
}

#[test]
fn probe_phase_fullness_matches_the_oracle() {
    stages::check_phase_fullness(&CPU);
}

#[test]
fn two_verlet_steps_with_held_sand_match_the_oracle() {
    sand_stages::check_verlet_steps_with_held_sand(&CPU);
}

#[test]
fn two_verlet_steps_with_the_held_bed_as_a_wall_match_the_oracle() {
    common::held_bed::check_verlet_steps_with_held_bed_walls(&CPU);
}

#[test]
fn rheology_matches_the_oracle_drucker_prager_shields() {
    sand_stages::check_rheology(&CPU, case("tests/cases/sediment_bed_2d.yaml"), 21);
}

#[test]
fn rheology_lets_a_lone_grain_on_the_bed_move_as_the_oracle_does() {
    common::lone_grain::check_lone_grain(&CPU, 21);
}

#[test]
fn rheology_matches_the_oracle_shields_only() {
    sand_stages::check_rheology(&CPU, sand_stages::shields_only_case(), 22);
}

#[test]
fn rheology_matches_the_oracle_with_the_waters_eddy_viscosity() {
    sand_stages::check_rheology(&CPU, sand_stages::eddy_viscosity_case(), 24);
}

#[test]
fn rheology_wears_the_held_bed_as_the_oracle_does() {
    sand_stages::check_worn_away_pickup(&CPU, 26);
}

#[test]
fn rheology_wears_the_held_bed_net_of_what_settles_as_the_oracle_does() {
    sand_stages::check_exner_pickup(&CPU, 26);
}

#[test]
fn grains_worn_whole_and_loose_ones_carry_their_wear_as_the_oracle_does() {
    sand_stages::check_exner_release(&CPU, 27);
}

#[test]
fn grains_the_stress_releases_carry_their_wear_as_the_oracle_does() {
    sand_stages::check_release_carries_wear(&CPU, 28);
}

#[test]
fn parked_particles_sort_after_every_cell_and_take_no_part() {
    parked::check_parked_take_no_part(&CPU);
}

#[test]
fn inlet_scan_matches_a_scan_of_the_whole_state() {
    parked::check_inlet_scan(&CPU);
}

/// The force pass writes its sides and stress sides into buffers kept from the passes before:
/// after steps of a sand bed in motion, the forces of the state reached are those a fresh
/// simulation of that state (with the same region words) gives, to the bit. A pass that
/// rewrote only some slots would leave the others with the last step's sides (a fill of only
/// the slots never written before fails it, tried); a slot no pass writes is the oracle
/// tests' to find, as it is the same in both.
#[test]
fn forces_after_steps_are_those_of_a_fresh_start() {
    let c = case("tests/cases/sediment_bed_2d.yaml");
    let (mut sim, _, _) = sand_stages::sediment_in_motion(&CPU, &c, 29, |_| {});
    for t in [2.0e-5, 3.5e-5, 4.5e-5] {
        sim.advance_to(t).expect("a step");
    }
    assert_eq!(sim.steps(), 3);
    let state = sim.read_particles().expect("readback");
    let regions = sim.regions().expect("regions");
    assert!(
        regions.iter().any(|&w| w & 256 != 0),
        "some sand held, so the stress sides are in use"
    );
    // Setting the words forgets each grain's last walk in both alike.
    sim.set_regions(&regions);
    let mut fresh = flume_solver::Simulation::from_particles(CPU, &c, state).expect("builds");
    fresh.set_regions(&regions);
    let (stepped, dt_stepped) = sim.compute_forces().expect("forces");
    let (started, dt_started) = fresh.compute_forces().expect("forces");
    let bits =
        |f: &[[f32; 4]]| -> Vec<[u32; 4]> { f.iter().map(|v| v.map(f32::to_bits)).collect() };
    assert!(bits(&stepped) == bits(&started), "forces differ");
    assert_eq!(dt_stepped.to_bits(), dt_started.to_bits());
}
