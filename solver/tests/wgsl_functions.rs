//! The WGSL functions that the stages share, against the Rust functions of `physics` that the
//! CPU backend and the oracle call, input by input on the adapter (lavapipe in CI): the kernel,
//! the equation of state, the time step (each particle's stable step and the step rule), the
//! Shields solve (critical Shields parameter, friction velocity,
//! slope factors), the HBP, Vand and Drucker-Prager laws, the pick-up (its draw, its rate and
//! the choice), and the choice of a sediment particle's region and its viscosity. A stage test compares whole passes on one particle
//! set; here each function meets a grid of inputs that reaches its branches and its edges
//! (the Shields jump at Re* = 500, the sub-layer, the suspension threshold), so a function
//! changed on one side only fails here even where no particle of a stage test goes.
//!
//! Each probe (`common/probe.rs`) composes the shared modules the function needs, binds the case's uniform block
//! as the stages do, and writes one `vec4<f32>` per input. Both sides compute in f32; they
//! agree within 2e-6 relatively (measured on lavapipe: at most 5e-7, a few ulp of `log`, `exp`
//! and `pow`), and exactly for regions; the equation of state and the Drucker-Prager yield
//! stress also allow the 2.5 ulp that Vulkan lets a division be off (an H100's driver uses
//! it); where a value falls to zero (the kernel at its support's edge) or loses its digits to a
//! cancellation (the slope factors) the test says how much more it allows.

mod common;
#[path = "wgsl_functions/pickup.rs"]
mod pickup;

use common::gpu_lock;
use common::probe::{Input, VULKAN_DIVISION, probe, same};
use flume_solver::Region;
use flume_solver::physics::eos;
use flume_solver::physics::eos::pressure;
use flume_solver::physics::kernel::Wendland;
use flume_solver::physics::sediment::drucker_prager::{
    alpha, kappa_c, skeleton_pressure, yield_stress,
};
use flume_solver::physics::sediment::rheology::hbp_viscosity;
use flume_solver::physics::sediment::shields::{
    critical_shields, friction_velocity, slope_factors,
};
use flume_solver::physics::sediment::suspension::{
    RegionInputs, apparent_viscosity, sediment_region, vand_viscosity,
};
use flume_solver::physics::timestep::{NextStep, next_step, particle_viscous_bound, stable_step};

/// What the Tait pressure `B ((rho / rho0)^7 - 1)` may differ by over `densities`, Pa, where the
/// adapter divides as loosely as Vulkan allows: the seventh power makes the quotient's relative
/// error seven times larger (on an H100, 3.9e-7 B was seen at rho / rho0 = 0.985; this allows
/// 4.1e-6 B for densities up to 1.1 rho0).
fn tait_division_slack(b: f32, rho0: f32, densities: &[Input]) -> f32 {
    let x_max = densities.iter().map(|i| i[0][0] / rho0).fold(0.0, f32::max);
    7.0 * VULKAN_DIVISION * b * x_max.powi(7)
}

/// `n` values from `lo` to `hi`, evenly spaced in their logarithm.
fn log_grid(lo: f32, hi: f32, n: usize) -> Vec<f32> {
    (0..n)
        .map(|k| lo * (hi / lo).powf(k as f32 / (n - 1) as f32))
        .collect()
}

fn one(x: f32) -> Input {
    [[x, 0.0, 0.0, 0.0], [0.0; 4]]
}

#[test]
fn kernel_and_equation_of_state() {
    let _lock = gpu_lock();
    let Some(p) = probe() else { return };
    let h = p.params.h;
    let kernel = Wendland::new(h, p.params.dim);
    let radii: Vec<Input> = (0..=110).map(|k| one(k as f32 * 0.02 * h)).collect();
    // Both fall to zero at 2h: a millionth of their value at r = 0 absolutely.
    p.agree_within(
        "kernel",
        "vec4<f32>(kernel_w(a.x), 0.0, 0.0, 0.0)",
        &radii,
        1,
        1e-6 * kernel.w(0.0),
        |i| [kernel.w(i[0][0]), 0.0, 0.0, 0.0],
    );
    p.agree_within(
        "kernel gradient",
        "vec4<f32>(kernel_grad_factor(a.x), 0.0, 0.0, 0.0)",
        &radii,
        1,
        1e-6 * kernel.grad_factor(0.0).abs(),
        |i| [kernel.grad_factor(i[0][0]), 0.0, 0.0, 0.0],
    );
    for (phase, ph) in p.params.phases.iter().enumerate() {
        let b = eos::tait_b(p.params.c0, ph.rho0);
        let densities: Vec<Input> = (0..=40)
            .map(|k| one(ph.rho0 * (0.9 + 0.005 * k as f32)))
            .collect();
        p.agree_within(
            &format!("Tait pressure of phase {phase}"),
            &format!("vec4<f32>(tait_pressure(a.x, {phase}u), 0.0, 0.0, 0.0)"),
            &densities,
            1,
            tait_division_slack(b, ph.rho0, &densities),
            |i| [pressure(i[0][0], ph.rho0, b), 0.0, 0.0, 0.0],
        );
    }
}

#[test]
fn the_shields_solve() {
    let _lock = gpu_lock();
    let Some(p) = probe() else { return };
    let mut re: Vec<f32> = log_grid(1e-3, 1e4, 60);
    re.extend([0.0, -1.0, 499.99, 500.0, 500.01]);
    let re: Vec<Input> = re.into_iter().map(one).collect();
    p.agree(
        "critical Shields parameter",
        "vec4<f32>(critical_shields(a.x), 0.0, 0.0, 0.0)",
        &re,
        1,
        |i| [critical_shields(i[0][0]), 0.0, 0.0, 0.0],
    );

    // Speeds from still to a dam-break front, heights from inside the roughness to a flume's
    // depth, ks from a smooth bed to gravel: every regime and the sub-layer.
    let nu = 1.0e-6;
    let mut cases = Vec::new();
    for u in std::iter::once(0.0).chain(log_grid(1e-4, 3.0, 14)) {
        for z in log_grid(1e-5, 0.05, 12) {
            for ks in [1e-5, 1.2e-3, 1e-2] {
                cases.push([[u, z, ks, nu], [0.0; 4]]);
            }
        }
    }
    p.agree(
        "friction velocity",
        "vec4<f32>(friction_velocity(a.x, a.y, a.z, a.w), 0.0, 0.0, 0.0)",
        &cases,
        1,
        |i| {
            let [u, z, ks, nu] = i[0];
            [friction_velocity(u, z, ks, nu).u_star, 0.0, 0.0, 0.0]
        },
    );

    // The bed's normal tilted up and down the flow and across it (a 2-D case: across is
    // ignored), and past the horizontal (the roof of a hole, which holds no grain), flows
    // either way.
    let phi = p.model.material.phi_rad;
    let mut slopes = Vec::new();
    for tilt in [-2.5f32, -0.5, -0.2, 0.0, 0.1, 0.3, 0.52, 0.8, 1.6, 2.2] {
        for ux in [-0.4f32, 0.0, 0.25] {
            slopes.push([[tilt.sin(), tilt.cos(), 0.0, 0.0], [ux, 0.05, 0.0, phi]]);
        }
    }
    // Vulkan lets atan2 be off by 4096 ulp, and sin(phi - beta) loses the rest of the digits
    // where the bed stands near its repose angle (k_beta = 0.08 there, 3e-6 apart): the
    // factors, of order one, agree to 1e-5 absolutely.
    let dim = p.params.dim;
    p.agree_within(
        "slope factors",
        "vec4<f32>(slope_factors(a.xyz, b.xyz, b.w), 0.0, 0.0, 0.0)",
        &slopes,
        1,
        1e-5,
        |i| {
            let n = [i[0][0], i[0][1], i[0][2]];
            let u = [i[1][0], i[1][1], i[1][2]];
            [slope_factors(n, u, dim, i[1][3]), 0.0, 0.0, 0.0]
        },
    );
}

#[test]
fn the_sediment_laws() {
    let _lock = gpu_lock();
    let Some(p) = probe() else { return };
    let mat = &p.model.material;
    let mut strain = Vec::new();
    for ii_d in std::iter::once(0.0).chain(log_grid(1e-8, 1e4, 25)) {
        for tau_c in [0.0, 3.0, 250.0] {
            strain.push([[ii_d, tau_c, 0.0, 0.0], [0.0; 4]]);
        }
    }
    p.agree(
        "HBP viscosity",
        "vec4<f32>(hbp_viscosity(a.x, a.y), 0.0, 0.0, 0.0)",
        &strain,
        1,
        |i| {
            let mu = hbp_viscosity(i[0][0], i[0][1], mat.hbp_m, mat.hbp_n, mat.mu_s_pa_s);
            [mu, 0.0, 0.0, 0.0]
        },
    );
    let c_v: Vec<Input> = (0..=30).map(|k| one(k as f32 * 0.01)).collect();
    p.agree(
        "Vand viscosity",
        "vec4<f32>(vand_viscosity(a.x), 0.0, 0.0, 0.0)",
        &c_v,
        1,
        |i| [vand_viscosity(i[0][0], mat.mu_w), 0.0, 0.0, 0.0],
    );
    let sed = &p.params.phases[p.model.sediment_phase];
    let b = eos::tait_b(p.params.c0, sed.rho0);
    let densities: Vec<Input> = (0..=40)
        .map(|k| one(sed.rho0 * (0.95 + 0.0025 * k as f32)))
        .collect();
    p.agree_within(
        "Drucker-Prager yield stress",
        "vec4<f32>(drucker_prager_yield(a.x), 0.0, 0.0, 0.0)",
        &densities,
        1,
        alpha(mat.phi_rad)
            * skeleton_pressure(
                tait_division_slack(b, sed.rho0, &densities),
                mat.rho_s,
                mat.rho_w,
            ),
        |i| {
            let p_skel = skeleton_pressure(pressure(i[0][0], sed.rho0, b), mat.rho_s, mat.rho_w);
            let tau_y = yield_stress(
                alpha(mat.phi_rad),
                kappa_c(mat.phi_rad, mat.cohesion_pa),
                p_skel,
            );
            [tau_y, 0.0, 0.0, 0.0]
        },
    );
}

/// Every combination of mode, hold, pick-up, a solid beside or none, surface, Shields and
/// Drucker-Prager on either side of their thresholds, and concentrations either side of 0.3.
fn region_inputs() -> Vec<RegionInputs> {
    let mut all = Vec::new();
    for mode in 0..16 {
        for at_surface in [false, true] {
            for tau_b in [0.5, 1.0, 2.0] {
                for sqrt_j2 in [0.0, 5.0, 6.0] {
                    for c_v in [0.1, 0.3, 0.6] {
                        all.push(RegionInputs {
                            shields_only: mode & 1 != 0,
                            held_before: mode & 2 != 0,
                            at_surface,
                            tau_b,
                            tau_bcr: 1.0,
                            sqrt_j2,
                            tau_y: 5.0,
                            c_v,
                            picked_up: mode & 4 != 0,
                            lone: mode & 8 != 0,
                        });
                    }
                }
            }
        }
    }
    all
}

#[test]
fn the_region_and_its_viscosity() {
    let _lock = gpu_lock();
    let Some(p) = probe() else { return };
    let flag = |b: bool| if b { 1.0 } else { 0.0 };
    let inputs: Vec<RegionInputs> = region_inputs();
    let packed: Vec<Input> = inputs
        .iter()
        .map(|r| {
            let modes = flag(r.shields_only) + 2.0 * flag(r.held_before) + 8.0 * flag(r.lone);
            [
                [modes, flag(r.picked_up), flag(r.at_surface), r.tau_b],
                [r.tau_bcr, r.sqrt_j2, r.tau_y, r.c_v],
            ]
        })
        .collect();
    let helper = "fn region_probe(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    let m = u32(a.x);
    let r = RegionInputs((m & 1u) != 0u, (m & 2u) != 0u, a.z > 0.5, a.w, b.x, b.y, b.z, b.w,
        a.y > 0.5, (m & 8u) != 0u);
    return vec4<f32>(f32(sediment_region(r)), 0.0, 0.0, 0.0);
}
";
    let regions = p.run_with(helper, "region_probe(a, b)", &packed);
    for (r, got) in inputs.iter().zip(&regions) {
        assert_eq!(
            got[0] as u32,
            sediment_region(r) as u32,
            "the region of {r:?}"
        );
    }

    // Each region's viscosity at strain rates from rest to a dam-break front's.
    let mat = &p.model.material;
    let mut cases = Vec::new();
    for region in [
        Region::Unyielded,
        Region::Yielded,
        Region::BedLoad,
        Region::Suspended,
    ] {
        for ii_d in log_grid(1e-6, 1e4, 11) {
            cases.push([
                [region as u32 as f32, ii_d, 40.0, 2.5],
                [0.2, 0.0, 0.0, 0.0],
            ]);
        }
    }
    let mu_max = p.model.mu_max;
    p.agree(
        "region viscosity",
        "vec4<f32>(region_viscosity(u32(a.x), a.y, a.z, a.w, b.x), 0.0, 0.0, 0.0)",
        &cases,
        1,
        |i| {
            let region = match i[0][0] as u32 {
                1 => Region::Unyielded,
                2 => Region::Yielded,
                3 => Region::BedLoad,
                _ => Region::Suspended,
            };
            let [_, ii_d, tau_y, tau_bcr] = i[0];
            let mu = apparent_viscosity(region, ii_d, tau_y, tau_bcr, i[1][0], mat);
            [mu.min(mu_max), 0.0, 0.0, 0.0]
        },
    );
}

#[test]
fn the_time_step() {
    let _lock = gpu_lock();
    let Some(p) = probe() else { return };
    let (h, c0) = (p.params.h, p.params.c0);
    // Accelerations from none to a splash's, with and without the force bound, and the
    // pairs' largest approach speed term from none to past c0.
    let mut forces = Vec::new();
    for accel in std::iter::once(0.0).chain(log_grid(1e-3, 1e5, 9)) {
        for force_bound in [0.0, 1.0] {
            for visc_max in [0.0, 0.5, 30.0] {
                forces.push([[accel, force_bound, visc_max, 0.0], [0.0; 4]]);
            }
        }
    }
    p.agree(
        "stable step",
        &format!("vec4<f32>(stable_step({h:e}, {c0:e}, a.x, a.y > 0.5, a.z), 0.0, 0.0, 0.0)"),
        &forces,
        1,
        |i| {
            [
                stable_step(h, c0, i[0][0], i[0][1] > 0.5, i[0][2]),
                0.0,
                0.0,
                0.0,
            ]
        },
    );
    let viscous: Vec<Input> = [0.0, -1.0, 1e-3, 0.1, 57.0, 2000.0]
        .into_iter()
        .map(|mu| [[1000.0, mu, 0.0, 0.0], [0.0; 4]])
        .collect();
    p.agree(
        "viscous step",
        &format!("vec4<f32>(viscous_step({h:e}, a.x, a.y), 0.0, 0.0, 0.0)"),
        &viscous,
        1,
        |i| [particle_viscous_bound(h, i[0][0], i[0][1]), 0.0, 0.0, 0.0],
    );

    // From the chunk's start to past its end, stable steps that land in one, in two equal
    // halves, in many, that collapse, and a halted run. (Not NaN: the GPU's reduction by bits
    // never yields it, and WGSL leaves min with NaN undefined.)
    let (cfl, dt_min, t_target) = (0.2, 1e-7, 0.1);
    let mut steps = Vec::new();
    for t_rel in [0.0, 0.05, 0.0999, 0.1, 0.2] {
        for stable in [1e-8, 1e-4, 0.3, 0.4, 10.0] {
            for dt_visc in [f32::MAX, 2e-4] {
                for halted in [0.0, 1.0] {
                    steps.push([
                        [cfl, stable, dt_visc, dt_min],
                        [t_rel, t_target, halted, 0.0],
                    ]);
                }
            }
        }
    }
    let packed = "fn next_step_probe(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    let n = next_step(a.x, a.y, a.z, a.w, b.x, b.y, b.z > 0.5);
    return vec4<f32>(f32(n.kind), n.dt, n.t_next, n.cfl_dt);
}
";
    let kinds = p.run_with(packed, "next_step_probe(a, b)", &steps);
    for (i, got) in steps.iter().zip(&kinds) {
        let [cfl, stable, dt_visc, dt_min] = i[0];
        let [t_rel, t_target, halted, _] = i[1];
        let want = match next_step(cfl, stable, dt_visc, dt_min, t_rel, t_target, halted > 0.5) {
            NextStep::Stop => [0.0, 0.0, 0.0, 0.0],
            NextStep::Collapse => [1.0, 0.0, 0.0, 0.0],
            NextStep::Step { dt, t_next, cfl_dt } => [2.0, dt, t_next, cfl_dt],
        };
        let got = if got[0] < 2.0 {
            [got[0], 0.0, 0.0, 0.0]
        } else {
            *got
        };
        assert!(
            got.iter().zip(&want).all(|(g, w)| same(*g, *w, 0.0)),
            "next step at {i:?}: WGSL {got:?} against Rust {want:?}"
        );
    }
}
