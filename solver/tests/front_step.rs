//! The front over the dry held bed moves with the flow, not with the time step.
//!
//! The ULBRA flume at CI size (dp = 1 cm) under generalised walls, with a sand the flow cannot
//! move (d50 = 4 cm, ks kept: a critical stress of about 30 Pa), so that only the water's own
//! update is tested: the thin sheet that runs ahead of the flow over the dry bed. The front is
//! the furthest profile column where the water stands 4 mm over the sand (as
//! `scripts/water_front.py` reads it), at t = 2 s, at CFL 0.2 and 0.05.
//!
//! Measured (CPU backend): 0.740 / 0.740 m under generalised walls. Under the dynamic boundary
//! (DBC) of the case file this test reads 0.640 / 1.040 m; one-thread runs give 0.65 m at CFL
//! 0.2 and 0.1 and 1.03-1.04 m at 0.05 and 0.025: over DBC walls the sheet has two speeds, and
//! the step picks one. The step enters where the inlet's buffer slides between DBC walls a dp
//! under and over it (docs/scour/README.md, "The front's step is the dynamic boundary's"). The
//! bound, 5 cm, is five of the profile's columns; the DBC's gap is 40 cm.

mod common;

use common::case_path;
use flume_solver::{Backend, Case, Simulation};

const SAND: u32 = 2;

/// The depth of water over the sand that counts as the front's, m.
const FRONT_DEPTH_M: f64 = 0.004;

fn held_bed_ci(cfl: f64) -> Case {
    let set = [
        "numerics.dp_m=0.01".to_string(),
        "open_flume.reservoir_particles=2500".to_string(),
        "numerics.boundary={method: generalised}".to_string(),
        "phases.1.sediment.d50_m=0.04".to_string(),
        "phases.1.sediment.ks_over_d50=0.03".to_string(),
        "observations.profile={x_min_m: 0.05, x_max_m: 2.15, columns: 211}".to_string(),
        format!("numerics.cfl={cfl}"),
    ];
    Case::from_path_with(&case_path("../launch_configs/ulbra_flume.yaml"), &set)
        .expect("the CI flume over a held bed")
}

/// The front at `t_s`, m, and the grains that left the bed: none may, or the bed was not held.
fn front_at(cfl: f64, t_s: f64) -> (f64, usize) {
    let case = held_bed_ci(cfl);
    let mut sim = Simulation::new(Backend::cpu(0), &case).expect("builds");
    let start = sim.read_particles().expect("reads");
    sim.advance_to(t_s).expect("runs");
    let obs = sim.observe().expect("observes");
    let front = obs
        .profile
        .iter()
        .filter_map(|c| {
            let bed = c.bed.as_ref()?;
            let depth = bed.zw_m? - bed.zs_m?;
            (depth >= FRONT_DEPTH_M).then_some(c.x_m)
        })
        .fold(0.0, f64::max);
    let now = sim.read_particles().expect("reads");
    let moved = (0..now.len())
        .filter(|&i| start.phase(i) == SAND)
        .filter(|&i| {
            let (a, b) = (start.positions[i], now.positions[i]);
            now.phase(i) != SAND || (a[0] - b[0]).hypot(a[1] - b[1]) > 0.005
        })
        .count();
    (front, moved)
}

#[test]
fn the_front_over_a_held_bed_does_not_move_with_the_step() {
    let t = 2.0;
    let (coarse, moved_coarse) = front_at(0.2, t);
    let (fine, moved_fine) = front_at(0.05, t);
    eprintln!(
        "front at t = {t} s: {coarse:.3} m at CFL 0.2, {fine:.3} m at CFL 0.05; sand moved {moved_coarse} / {moved_fine}"
    );
    assert_eq!(
        (moved_coarse, moved_fine),
        (0, 0),
        "the bed was to be held: the front is then the water's alone"
    );
    assert!(
        coarse > 0.3,
        "the front at {coarse:.3} m by t = {t} s: the water did not run over the bed"
    );
    assert!(
        (coarse - fine).abs() <= 0.05,
        "the front at t = {t} s stands at {coarse:.3} m at CFL 0.2 and {fine:.3} m at CFL 0.05"
    );
}
