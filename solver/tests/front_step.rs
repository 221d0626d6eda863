//! The front over the dry held bed moves with the flow, not with the time step.
//!
//! The ULBRA flume at CI size (dp = 1 cm) under generalised walls, with a sand the flow cannot
//! move (d50 = 4 cm, ks kept: a critical stress of about 30 Pa), so that only the water's own
//! update is tested: the thin sheet that runs ahead of the flow over the dry bed. The front is
//! the furthest profile column where the water stands 4 mm over the sand (as
//! `scripts/water_front.py` reads it), at t = 2 and 4.5 s, at CFL 0.2 and 0.05. The step may
//! move it by a tenth of the way it has run.
//!
//! Measured (CPU backend, two threads): 0.740 / 0.740 m at 2 s and 1.380 / 1.320 m at 4.5 s
//! under generalised walls. Under the dynamic boundary (DBC) of the case file this test reads
//! 0.640 / 1.040 m and 1.190 / 1.780 m: half to three fifths of the way run. One-thread runs
//! give 0.65 m at 2 s at CFL 0.2 and 0.1 and 1.03-1.04 m at 0.05 and 0.025: over DBC walls the
//! sheet has two speeds, and the step picks one. The step enters where the inlet's buffer
//! slides between DBC walls a dp under and over it (docs/scour/README.md, "The front's step is
//! the dynamic boundary's"). The front reaches the bed's end at 6.5-7.5 s (dp = 4 and 16 mm); the test stops at 4.5 s,
//! past the bed's middle, where the DBC's gap is already 0.6 m (CFL 0.05 costs four times the
//! steps).

mod common;

use common::{case_path, mobilised};
use flume_solver::{Backend, Case, Simulation};

/// The depth of water over the sand that counts as the front's, m.
const FRONT_DEPTH_M: f64 = 0.004;
/// When the front is read, s: a third of the way along the bed, and past its middle.
const TIMES_S: [f64; 2] = [2.0, 4.5];

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

/// The front at each of [`TIMES_S`], m, and the grains that left the bed by the last: none may,
/// or the bed was not held.
fn fronts(cfl: f64) -> (Vec<f64>, usize) {
    let case = held_bed_ci(cfl);
    let mut sim = Simulation::new(Backend::cpu(0), &case).expect("builds");
    let start = sim.read_particles().expect("reads");
    let mut fronts = Vec::new();
    for t in TIMES_S {
        sim.advance_to(t).expect("runs");
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
        fronts.push(front);
    }
    let now = sim.read_particles().expect("reads");
    (fronts, mobilised(&start, &now, 0.01))
}

#[test]
fn the_front_over_a_held_bed_does_not_move_with_the_step() {
    let (coarse, moved_coarse) = fronts(0.2);
    let (fine, moved_fine) = fronts(0.05);
    eprintln!(
        "front at {TIMES_S:?} s: {coarse:.3?} m at CFL 0.2, {fine:.3?} m at CFL 0.05; sand moved {moved_coarse} / {moved_fine}"
    );
    assert_eq!(
        (moved_coarse, moved_fine),
        (0, 0),
        "the bed was to be held: the front is then the water's alone"
    );
    // An inlet that stopped would pass the comparison with two dry beds.
    assert!(
        coarse[0] > 0.3 && coarse[1] > coarse[0] + 0.3,
        "the front at {coarse:.3?} m: the water did not run over the bed"
    );
    for ((t, c), f) in TIMES_S.iter().zip(&coarse).zip(&fine) {
        assert!(
            (c - f).abs() <= 0.1 * c,
            "the front at t = {t} s stands at {c:.3} m at CFL 0.2 and {f:.3} m at CFL 0.05"
        );
    }
}
