//! Tier 2: each GPU stage against its CPU oracle in `flume_solver::physics`, on lavapipe in CI.
//! The checks are shared with the CPU backend (`common/stages.rs`).

mod common;

use common::parked;
use common::sand_stages;
use common::stages::{self, case};

/// Runs a shared stage check on the GPU, one GPU test at a time.
fn on_gpu(check: impl FnOnce(&flume_solver::Backend)) {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    check(&flume_solver::Backend::from(gpu));
}

#[test]
fn grid_stages_match_a_cpu_counting_sort_exactly() {
    on_gpu(stages::check_cell_list);
}

#[test]
fn the_interaction_stage_matches_the_cpu_2d() {
    on_gpu(|b| stages::check_forces(b, case("tests/cases/hydrostatic_2d.yaml"), "2-D", 7));
}

#[test]
fn the_interaction_stage_matches_the_cpu_3d() {
    on_gpu(|b| stages::check_forces(b, case("tests/cases/hydrostatic_3d.yaml"), "3-D", 8));
}

#[test]
fn the_interaction_stage_with_molteni_diffusion_matches_the_cpu() {
    on_gpu(|b| stages::check_forces(b, stages::molteni_case(), "Molteni-Colagrossi", 19));
}

#[test]
fn the_interaction_stage_with_generalised_walls_matches_the_cpu() {
    on_gpu(stages::check_generalised_wall_forces);
}

#[test]
fn steps_under_generalised_walls_match_the_cpu_steps() {
    on_gpu(|b| {
        stages::check_symplectic_step_generalised(b);
        stages::check_verlet_steps_generalised(b);
    });
}

#[test]
fn the_interaction_stage_with_laminar_viscosity_matches_the_cpu() {
    on_gpu(stages::check_laminar_forces);
}

#[test]
fn one_symplectic_step_matches_the_cpu_step() {
    on_gpu(stages::check_symplectic_step);
}

#[test]
fn probe_interpolate_and_observe_reduce_match_the_cpu() {
    on_gpu(stages::check_probes);
}

#[test]
fn two_verlet_steps_match_the_cpu_steps() {
    on_gpu(stages::check_verlet_steps);
}

#[test]
fn probe_interpolate_phase_fullness_matches_the_cpu() {
    on_gpu(stages::check_phase_fullness);
}

#[test]
fn two_verlet_steps_with_held_sand_match_the_cpu_steps() {
    on_gpu(sand_stages::check_verlet_steps_with_held_sand);
}

#[test]
fn two_verlet_steps_with_the_held_bed_as_a_wall_match_the_cpu_steps() {
    on_gpu(common::held_bed::check_verlet_steps_with_held_bed_walls);
}

#[test]
fn two_symplectic_steps_with_the_held_bed_as_a_wall_match_the_cpu_backend() {
    on_gpu(common::held_bed::check_symplectic_steps_with_held_bed_walls);
}

#[test]
fn rheology_matches_the_cpu_drucker_prager_shields() {
    on_gpu(|b| sand_stages::check_rheology(b, case("tests/cases/sediment_bed_2d.yaml"), 21));
}

#[test]
fn rheology_matches_the_cpu_shields_only() {
    on_gpu(|b| sand_stages::check_rheology(b, sand_stages::shields_only_case(), 22));
}

#[test]
fn rheology_matches_the_cpu_with_the_waters_eddy_viscosity() {
    on_gpu(|b| sand_stages::check_rheology(b, sand_stages::eddy_viscosity_case(), 24));
}

#[test]
fn rheology_matches_the_cpu_with_shields_reading_the_waters_own_speed() {
    on_gpu(|b| {
        let changed =
            sand_stages::regions_the_shields_speed_changes(b, &sand_stages::water_speed_case(), 25);
        assert!(changed > 0, "no region depends on the Shields speed here");
        sand_stages::check_rheology(b, sand_stages::water_speed_case(), 25);
    });
}

#[test]
fn rheology_wears_the_held_bed_as_the_cpu_does() {
    on_gpu(|b| sand_stages::check_worn_away_pickup(b, 26));
}

#[test]
fn rheology_wears_the_held_bed_net_of_what_settles_as_the_cpu_does() {
    on_gpu(|b| sand_stages::check_exner_pickup(b, 26));
}

#[test]
fn grains_worn_whole_and_loose_ones_carry_their_wear_as_the_cpu_does() {
    on_gpu(|b| sand_stages::check_exner_release(b, 27));
}

#[test]
fn grains_the_stress_releases_carry_their_wear_as_the_cpu_does() {
    on_gpu(|b| sand_stages::check_release_carries_wear(b, 28));
}

#[test]
fn parked_particles_sort_after_every_cell_and_take_no_part() {
    on_gpu(parked::check_parked_take_no_part);
}

#[test]
fn inlet_scan_matches_a_scan_of_the_whole_state() {
    on_gpu(parked::check_inlet_scan);
}

#[test]
fn rheology_lets_a_lone_grain_on_the_bed_move_as_the_cpu_does() {
    on_gpu(|b| common::lone_grain::check_lone_grain(b, 21));
}
