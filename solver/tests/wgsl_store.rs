//! The end of a step, `store_rule` of `shaders/common/store_rule.wgsl`, against the CPU
//! backend's `Store::apply`, input by input on the adapter (lavapipe in CI): what each
//! particle becomes (kept, parked over the weir, parked as eroded sand, excluded for its
//! density), its new position and velocity-density, and the health flags it raises, for
//! water, sand and walls at every place the open flume treats apart (the bed, past the weir,
//! the collector, the inlet buffer, a bottom outlet's duct), held or not, at densities at
//! rest, under it, past the exclusion bound and infinite.
//!
//! The two sides share no code: a store rule changed on one side only fails here. Where their
//! contracts differ the inputs keep to both: the CPU backend's integrator gives a wall its
//! position, velocity and floor on density before the store (`integrate.rs`), the WGSL's store
//! does it, so walls are given at rest with a density at or above rest.

mod common;

use common::gpu_lock;
use common::probe::{Input, Probe, probe_of, same};
use flume_solver::contract::SimParams;
use flume_solver::gpu::shader;
use flume_solver::physics::Params;
use flume_solver::{Case, Store};

/// The step of every probe, s.
const DT: f32 = 0.01;

/// The WGSL side: `a` = (x, y, new density, phase bits), `b` = (u, v, old density, held +
/// 2 id); the old velocity is half the new, the free new position x + DT v. `DT` is defined
/// before it from the Rust constant.
const STORE_PROBE: &str = "
fn store_probe(a: vec4<f32>, b: vec4<f32>) -> Stored {
    let p = vec4<f32>(a.x, a.y, 0.0, a.w);
    let code = u32(b.w);
    let v = vec3<f32>(b.x, b.y, 0.0);
    let vr = vec4<f32>(0.5 * v, b.z);
    return store_rule(code / 2u, p, vr, p.xyz + DT * v, v, a.z, (code & 1u) != 0u, DT);
}
";

/// The fates of `store_rule.wgsl`.
const KEPT: f32 = 0.0;
const PARKED: f32 = 1.0;
const ERODED: f32 = 2.0;
const EXCLUDED: f32 = 3.0;

/// The Rust side of one input: position, velocity-density, and (fate, flags, 0, 0).
fn rust_store(store: &Store, input: &Input) -> [[f32; 4]; 3] {
    let [a, b] = *input;
    let code = b[3] as u32;
    let (id, held) = (code / 2, code & 1 != 0);
    let p = [a[0], a[1], 0.0, a[3]];
    let v = [b[0], b[1], 0.0];
    let vr = [0.5 * v[0], 0.5 * v[1], 0.0, b[2]];
    let x = [p[0] + DT * v[0], p[1] + DT * v[1], p[2] + DT * v[2], p[3]];
    let ((pos, vel_rho), event) = store.apply(id, &p, &vr, held, DT, (x, [v[0], v[1], 0.0, a[2]]));
    let fate = match (event.excluded.is_some(), event.parked, event.eroded) {
        (true, _, _) => EXCLUDED,
        (false, true, true) => ERODED,
        (false, true, false) => PARKED,
        _ => KEPT,
    };
    [pos, vel_rho, [fate, event.flags as f32, 0.0, 0.0]]
}

/// The places of the flume that the store treats apart: on the bed, past the weir, in the
/// collector, in the inlet buffer, and in the duct when there is one, each well clear of its
/// edges.
fn places(probe: &Probe) -> Vec<[f32; 2]> {
    let f = &probe.uniform.flume;
    let mut at = vec![
        [1.0, 0.08],
        [f.outlet_x + 0.05, 0.06],
        [
            0.5 * (f.collector_x_min + f.collector_x_max),
            0.5 * f.collector_y_max,
        ],
        [
            f.inlet_x_face - 0.004,
            0.5 * (f.inlet_y_min + f.inlet_y_max),
        ],
    ];
    if f.duct_y_max > f.duct_y_min {
        at.push([f.duct_x_min + 0.05, 0.5 * (f.duct_y_min + f.duct_y_max)]);
    }
    at
}

/// Water, sand and walls at every place, moving or at rest, held or not, at densities at
/// rest, 4 % under it, 20 % over it (past the exclusion bound) and infinite.
fn inputs(probe: &Probe) -> Vec<Input> {
    let (f, sediment) = (&probe.uniform.flume, probe.uniform.sediment.phase);
    let wall = (0..probe.params.phases.len() as u32)
        .find(|&k| !probe.params.phases[k as usize].mobile && k != f.parked_phase)
        .expect("a wall phase");
    let mut out = Vec::new();
    for [x, y] in places(probe) {
        for phase in [f.water_phase, sediment, wall] {
            let rho0 = probe.params.phases[phase as usize].rho0;
            let mobile = phase != wall;
            let speeds: &[[f32; 2]] = if mobile {
                &[[0.3, -0.1], [0.0, 0.0]]
            } else {
                &[[0.0, 0.0]]
            };
            let rhos: &[f32] = if mobile {
                &[rho0, 0.96 * rho0, 1.2 * rho0, f32::INFINITY]
            } else {
                &[rho0, 1.02 * rho0]
            };
            for &[u, v] in speeds {
                for &rho in rhos {
                    for held in [0.0, 1.0] {
                        let a = [x, y, rho, f32::from_bits(phase)];
                        out.push([a, [u, v, 1.01 * rho0, held + 2.0 * 123.0]]);
                    }
                }
            }
        }
    }
    out
}

/// Runs the probe over the case's inputs and asserts every output against the CPU's, and that
/// the inputs reach every fate in `fates`.
fn agree_on(probe: &Probe, fates: &[f32]) {
    let helpers = [
        shader::source("common/flume.wgsl"),
        shader::source("common/store_rule.wgsl"),
        &format!("const DT: f32 = {DT:?};"),
        STORE_PROBE,
    ]
    .concat();
    let inputs = inputs(probe);
    let gpu = [
        probe.run_with(&helpers, "store_probe(a, b).pos", &inputs),
        probe.run_with(&helpers, "store_probe(a, b).vel_rho", &inputs),
        probe.run_with(
            &helpers,
            "vec4<f32>(f32(store_probe(a, b).fate), f32(store_probe(a, b).flags), 0.0, 0.0)",
            &inputs,
        ),
    ];
    let store = Store::new(&probe.uniform, &probe.params);
    let mut reached = Vec::new();
    for (k, input) in inputs.iter().enumerate() {
        let want = rust_store(&store, input);
        for (what, (got, want)) in ["position", "velocity-density", "fate and flags"]
            .iter()
            .zip(gpu.iter().map(|g| g[k]).zip(want))
        {
            assert!(
                got.iter().zip(&want).all(|(g, w)| same(*g, *w, 0.0)),
                "{what} at {input:?}: WGSL {got:?} against Rust {want:?}"
            );
        }
        reached.push(want[2][0]);
    }
    for fate in fates {
        assert!(reached.contains(fate), "no input reaches fate {fate}");
    }
}

fn case(path: &str, dp_m: f64) -> Case {
    let mut case = Case::from_path(&common::case_path(path)).expect("case parses");
    case.numerics.dp_m = dp_m;
    case
}

#[test]
fn the_store_rule_on_the_ulbra_flume() {
    let _lock = gpu_lock();
    let mut flume = case("../launch_configs/ulbra_flume.yaml", 0.01);
    if let Some(f) = &mut flume.open_flume {
        f.reservoir_particles = 2500;
    }
    let Some(probe) = probe_of(&flume) else {
        return;
    };
    agree_on(&probe, &[KEPT, PARKED, ERODED, EXCLUDED]);
    // The inlet buffer's density under the generalised wall condition is its own.
    flume.numerics.boundary = flume_solver::config::BoundaryMethod::Generalised;
    let probe = probe_of(&flume).expect("the adapter opened once");
    agree_on(&probe, &[KEPT, PARKED, ERODED, EXCLUDED]);
}

#[test]
fn the_store_rule_at_a_bottom_outlet() {
    let _lock = gpu_lock();
    let Some(probe) = probe_of(&case("../launch_configs/falappi_flushing.yaml", 0.02)) else {
        return;
    };
    assert!(
        probe.uniform.flume.duct_y_max > probe.uniform.flume.duct_y_min,
        "the case has a duct"
    );
    agree_on(&probe, &[KEPT, PARKED, EXCLUDED]);
}

/// The CI-size flume's uniform block and physics, as the CPU backend stores with them.
fn ci_flume() -> (SimParams, Params) {
    let mut flume = case("../launch_configs/ulbra_flume.yaml", 0.01);
    if let Some(f) = &mut flume.open_flume {
        f.reservoir_particles = 2500;
    }
    let sim = flume_solver::Simulation::new(flume_solver::Backend::cpu(1), &flume).expect("runs");
    (*sim.params(), common::reference_params(&sim))
}

/// A grain that strays into the inlet's opening leaves with the inflow, held or not, in the
/// predictor's half step and in the store (the CPU side; `agree_on` holds the WGSL's store to
/// it). On the paper's bed, sand to the orifice, two grains the jet lifted came to rest held in
/// the opening at t = 50 s of the bundled session; the inlet places no particle over another,
/// and the CI flume lost 150 of its 950 stored particles in the next 10 s
/// (docs/scour/README.md).
#[test]
fn sand_in_the_inlet_buffer_leaves_with_the_inflow() {
    let (uniform, params) = ci_flume();
    let store = Store::new(&uniform, &params);
    let f = &uniform.flume;
    let sand = uniform.sediment.phase;
    let rho0 = params.phases[sand as usize].rho0;
    let y = 0.5 * (f.inlet_y_min + f.inlet_y_max);
    let at = [f.inlet_x_face - 0.004, y, 0.0, f32::from_bits(sand)];
    let rest = [0.0, 0.0, 0.0, rho0];
    assert!(
        store.velocity_imposed(&at),
        "its acceleration bounds the step"
    );
    for held in [false, true] {
        let ((pos, vel), event) = store.apply(7, &at, &rest, held, DT, (at, rest));
        assert!(!event.parked, "held {held}: {event:?}");
        assert_eq!(vel[..3], [f.inlet_u, 0.0, 0.0], "held {held}");
        assert_eq!(pos[0], at[0] + DT * f.inlet_u, "held {held}");
        let (half, vel) = store.half_step(&at, &rest, held, 0.5 * DT, (at, rest));
        assert_eq!(vel[..3], [f.inlet_u, 0.0, 0.0], "held {held}, half step");
        assert!(half[0] > at[0], "held {held}, half step");
    }
    // Out of the opening, a held grain stays where it is.
    let below = [at[0], f.inlet_y_min - 0.005, 0.0, at[3]];
    let ((pos, vel), _) = store.apply(7, &below, &rest, true, DT, (below, rest));
    assert_eq!((pos, vel[..3].to_vec()), (below, vec![0.0; 3]));
}

/// A held grain the store parks (here in the collector) says so: its mass leaves the kernels
/// of the grains around it, whose records of it must go (`cpu/multiphase/deep.rs`). A moving
/// grain parked there, or a held one kept, does not.
#[test]
fn a_held_grain_parked_says_so() {
    let (uniform, params) = ci_flume();
    let store = Store::new(&uniform, &params);
    let f = &uniform.flume;
    let sand = uniform.sediment.phase;
    let rest = [0.0, 0.0, 0.0, params.phases[sand as usize].rho0];
    let x = 0.5 * (f.collector_x_min + f.collector_x_max);
    let pit = [x, 0.5 * f.collector_y_max, 0.0, f32::from_bits(sand)];
    let bed = [1.0, 0.03, 0.0, pit[3]];
    let parked = |at: &[f32; 4], held| store.apply(7, at, &rest, held, DT, (*at, rest)).1;
    let (held, moving, kept) = (parked(&pit, true), parked(&pit, false), parked(&bed, true));
    assert!(held.parked && held.held_parked, "{held:?}");
    assert!(moving.parked && !moving.held_parked, "{moving:?}");
    assert!(!kept.parked && !kept.held_parked, "{kept:?}");
}
