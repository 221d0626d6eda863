//! The checks of each stage against its CPU oracle in `flume_solver::physics`, for any backend:
//! the wgpu stages on lavapipe (`gpu_vs_reference.rs`) and the CPU backend
//! (`cpu_vs_reference.rs`) pass the same ones. Integer stages (the cell list) must agree
//! exactly; float stages within a stated tolerance, because a backend sums neighbours in cell
//! order and the oracle in index order (f32 rounding of sums whose terms cancel).

use flume_solver::physics::{integrate, interaction, probe};
use flume_solver::{Backend, Case};

pub fn case(name: &str) -> Case {
    Case::from_path(&super::case_path(name)).expect("test case parses")
}

pub fn max_abs(v: &[[f32; 4]], k: usize) -> f32 {
    v.iter().map(|f| f[k].abs()).fold(0.0, f32::max)
}

/// Asserts each component agrees within `rel` of that component's largest magnitude.
pub fn assert_close(what: &str, gpu: &[[f32; 4]], cpu: &[[f32; 4]], components: usize, rel: f32) {
    assert_eq!(gpu.len(), cpu.len());
    for k in 0..components {
        let scale = max_abs(cpu, k).max(1e-30);
        for (i, (g, c)) in gpu.iter().zip(cpu).enumerate() {
            let err = (g[k] - c[k]).abs() / scale;
            assert!(
                err <= rel,
                "{what}: particle {i} component {k}: backend {} oracle {} (error {err:.2e} of max {scale:.3e}, allowed {rel:.0e})",
                g[k],
                c[k]
            );
        }
    }
}

/// The cell list: cell starts and particles in (cell, id) order, as a CPU counting sort gives.
pub fn check_cell_list(backend: &Backend) {
    // The second case is a wide, sparse 2-D tank: over 262,144 cells, so the prefix sum
    // takes three levels.
    let mut sparse = case("tests/cases/hydrostatic_2d.yaml");
    sparse.domain.max_m = vec![12.0, 12.0];
    let cases = [
        case("tests/cases/hydrostatic_2d.yaml"),
        case("tests/cases/hydrostatic_3d.yaml"),
        sparse,
    ];
    for (c, seed) in cases.iter().zip(1..) {
        let (sim, particles, _) = super::perturbed_sim(backend.clone(), c, 0.0, seed);
        let p = sim.params();
        let (starts, sorted_ids) = sim.cell_list().expect("cell list");
        // CPU: the same f32 cell formula, then a stable counting sort by (cell, id).
        let dims = [
            p.grid_dims[0] as i64,
            p.grid_dims[1] as i64,
            p.grid_dims[2] as i64,
        ];
        let cell_of = |x: &[f32; 4]| -> usize {
            let mut c = [0i64; 3];
            for k in 0..3 {
                let v = ((x[k] - p.grid_origin[k]) * p.grid_origin[3]).floor() as i64;
                c[k] = v.clamp(0, dims[k] - 1);
            }
            ((c[2] * dims[1] + c[1]) * dims[0] + c[0]) as usize
        };
        let n_cells = p.n_cells as usize;
        let mut counts = vec![0u32; n_cells + 1];
        for x in &particles.positions {
            counts[cell_of(x)] += 1;
        }
        let mut expect_starts = vec![0u32; n_cells + 1];
        for c in 0..n_cells {
            expect_starts[c + 1] = expect_starts[c] + counts[c];
        }
        assert!(n_cells > 0);
        assert_eq!(starts, expect_starts, "cell starts");
        let mut expect_ids: Vec<u32> = (0..particles.len() as u32).collect();
        expect_ids.sort_by_key(|&i| (cell_of(&particles.positions[i as usize]), i));
        assert_eq!(sorted_ids, expect_ids, "particles in (cell, id) order");
        eprintln!(
            "{}: {} particles, {} cells: exact",
            c.name,
            particles.len(),
            n_cells
        );
    }
}

/// The force stage on a perturbed state of case `c` (seeded by `seed`).
pub fn check_forces(backend: &Backend, c: Case, name: &str, seed: u64) {
    let (mut sim, particles, params) = super::perturbed_sim(backend.clone(), &c, 0.3, seed);
    let (gpu_forces, gpu_dt) = sim.compute_forces().expect("forces");
    let cpu = interaction::interact(&params, &particles.positions, &particles.vel_rho);
    // Pairwise pressure terms reach ~1e3 m/s2 and cancel to ~g: 1e-4 of the largest value
    // leaves room for the different summation order and nothing for a missing term.
    assert_close(
        &format!("{name} acceleration"),
        &gpu_forces,
        &cpu.forces,
        c.dim(),
        1e-4,
    );
    let drho: Vec<[f32; 4]> = gpu_forces.iter().map(|f| [f[3], 0.0, 0.0, 0.0]).collect();
    let drho_cpu: Vec<[f32; 4]> = cpu.forces.iter().map(|f| [f[3], 0.0, 0.0, 0.0]).collect();
    assert_close(&format!("{name} density rate"), &drho, &drho_cpu, 1, 1e-4);
    let cpu_dt = cpu.dt_limit.iter().copied().fold(f32::INFINITY, f32::min);
    assert!(
        ((gpu_dt - cpu_dt) / cpu_dt).abs() < 1e-4,
        "stable step: backend {gpu_dt} oracle {cpu_dt}"
    );
    eprintln!(
        "{name}: forces of {} particles agree; stable step {gpu_dt:.3e} s",
        particles.len()
    );
}

/// The force stage under the generalised wall condition: the fluid's forces as before, and each
/// wall's entry the density of the fluid's pressure around it (the oracle's Shepard sums). The
/// perturbed state's fluid moves at up to 0.3 m/s, so its densities and hence the walls' differ
/// from particle to particle; a wall whose density did not come from its own fluid neighbours,
/// or a rate left in its place, is off by far more than the tolerance.
pub fn check_generalised_wall_forces(backend: &Backend) {
    let mut c = case("tests/cases/hydrostatic_2d.yaml");
    c.numerics.boundary = flume_solver::config::BoundaryMethod::Generalised;
    let (mut sim, particles, params) = super::perturbed_sim(backend.clone(), &c, 0.3, 23);
    let (forces, _) = sim.compute_forces().expect("forces");
    let cpu = interaction::interact(&params, &particles.positions, &particles.vel_rho);
    let (mut wet, mut dry) = (0, 0);
    for (i, (f, o)) in forces.iter().zip(&cpu.forces).enumerate() {
        if particles.is_wall(i) {
            // Densities of ~1000 kg/m3 from sums of up to ~20 terms in another order.
            assert!(
                (f[3] - o[3]).abs() < 2e-3,
                "wall {i}: backend {} oracle {}",
                f[3],
                o[3]
            );
            if o[3] > 1000.0 { wet += 1 } else { dry += 1 }
        }
    }
    assert!(
        wet > 50 && dry > 50,
        "walls under water {wet}, dry or above it {dry}"
    );
    let fluid = |v: &[[f32; 4]]| -> Vec<[f32; 4]> {
        v.iter()
            .enumerate()
            .filter(|(i, _)| !particles.is_wall(*i))
            .map(|(_, f)| *f)
            .collect()
    };
    assert_close(
        "fluid forces",
        &fluid(&forces),
        &fluid(&cpu.forces),
        4,
        1e-4,
    );
}

/// The force stage with Morris laminar viscosity.
pub fn check_laminar_forces(backend: &Backend) {
    let mut c = case("tests/cases/hydrostatic_2d.yaml");
    c.numerics.viscosity = flume_solver::config::Viscosity::Laminar;
    c.phases[0].viscosity_pa_s = 0.5;
    let (mut sim, particles, params) = super::perturbed_sim(backend.clone(), &c, 0.3, 9);
    let (gpu_forces, _) = sim.compute_forces().expect("forces");
    let cpu = interaction::interact(&params, &particles.positions, &particles.vel_rho);
    assert_close("laminar acceleration", &gpu_forces, &cpu.forces, 2, 1e-4);
}

/// One symplectic step (predictor, forces at the half step, corrector).
pub fn check_symplectic_step(backend: &Backend) {
    symplectic_step(backend, case("tests/cases/hydrostatic_2d.yaml"));
}

/// The same under the generalised wall condition: the walls store the densities their force
/// passes give (predictor and corrector), not an integrated rate.
pub fn check_symplectic_step_generalised(backend: &Backend) {
    let mut c = case("tests/cases/hydrostatic_2d.yaml");
    c.numerics.boundary = flume_solver::config::BoundaryMethod::Generalised;
    symplectic_step(backend, c);
}

fn symplectic_step(backend: &Backend, c: Case) {
    let (mut sim, particles, params) = super::perturbed_sim(backend.clone(), &c, 0.3, 11);
    // A target below the stable step: the GPU takes exactly one step of that length.
    let dt = 2.0e-5f32;
    sim.advance_to(f64::from(dt)).expect("one step");
    assert_eq!(sim.steps(), 1);
    let after = sim.read_particles().expect("readback");

    let f_n = interaction::interact(&params, &particles.positions, &particles.vel_rho);
    let (pos_h, vel_h) = integrate::predictor(
        &params.phases,
        dt,
        &particles.positions,
        &particles.vel_rho,
        &f_n.forces,
    );
    let f_h = interaction::interact(&params, &pos_h, &vel_h);
    let (pos_1, vel_1) = integrate::corrector(
        &params.phases,
        dt,
        &particles.positions,
        &particles.vel_rho,
        &vel_h,
        &f_h.forces,
    );
    assert_step_close(&after, &pos_1, &vel_1, &[&f_n.forces, &f_h.forces], dt, 1.0);
}

/// Compares a GPU state after `steps` steps of `dt` with the CPU's. Displacements are ~1e-5 m on
/// positions ~0.1 m, so positions agree only to their own rounding (a few ulp) plus what the
/// force passes' tolerance (1e-4 of the largest rate, ~1e4 m/s2 in these perturbed states)
/// moves a particle over the steps; velocities and densities within that tolerance times dt.
pub fn assert_step_close(
    after: &flume_solver::Particles,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    passes: &[&Vec<[f32; 4]>],
    dt: f32,
    steps: f32,
) {
    let rel = 1e-4 * passes.len() as f32;
    let a_max = passes
        .iter()
        .flat_map(|f| [max_abs(f, 0), max_abs(f, 1)])
        .fold(0.0f32, f32::max);
    let drho_max = passes.iter().map(|f| max_abs(f, 3)).fold(0.0f32, f32::max);
    let t = steps * dt;
    for (i, (g, c)) in after.positions.iter().zip(pos).enumerate() {
        for k in 0..2 {
            let allowed = 4.0 * f32::EPSILON * c[k].abs() + rel * a_max * t * t;
            let err = (g[k] - c[k]).abs();
            assert!(
                err <= allowed,
                "position of particle {i}[{k}]: backend {} oracle {} (allowed {allowed:.2e})",
                g[k],
                c[k]
            );
        }
    }
    for (i, (g, c)) in after.vel_rho.iter().zip(vel_rho).enumerate() {
        for k in 0..4 {
            let rate = if k == 3 { drho_max } else { a_max };
            let allowed = 4.0 * f32::EPSILON * c[k].abs() + rel * rate * t;
            let err = (g[k] - c[k]).abs();
            assert!(
                err <= allowed,
                "velocity/density of particle {i}[{k}]: backend {} oracle {} (allowed {allowed:.2e})",
                g[k],
                c[k]
            );
        }
    }
}

/// Probe pressures and the whole-state extremes.
pub fn check_probes(backend: &Backend) {
    let c = case("tests/cases/hydrostatic_2d.yaml");
    let (sim, particles, params) = super::perturbed_sim(backend.clone(), &c, 0.3, 13);
    let obs = sim.observe().expect("observe");
    for (reading, cfg) in obs.probes.iter().zip(&c.observations.pressure_probes) {
        let x = &cfg.position_m;
        let sums = probe::probe(
            &params,
            [x[0] as f32, x[1] as f32, 0.0],
            &particles.positions,
            &particles.vel_rho,
        );
        let cpu = f64::from(sums.pressure().expect("probe in water"));
        let gpu = reading.pressure_pa.expect("probe in water");
        assert!(
            (gpu - cpu).abs() <= 1e-4 * cpu.abs().max(1.0),
            "{}: backend {gpu} oracle {cpu}",
            cfg.name
        );
    }
    let fluid: Vec<usize> = (0..particles.len())
        .filter(|&i| particles.phase(i) != 0)
        .collect();
    let front = fluid
        .iter()
        .map(|&i| particles.positions[i][0])
        .fold(f32::MIN, f32::max);
    let speed = fluid
        .iter()
        .map(|&i| {
            let v = particles.vel_rho[i];
            (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
        })
        .fold(0.0f32, f32::max);
    assert_eq!(obs.front_m, Some(f64::from(front)));
    assert!((obs.max_speed_m_per_s - f64::from(speed)).abs() <= 1e-6 * f64::from(speed));
    assert_eq!(obs.fluid_particles as usize, fluid.len());
}

/// Two Verlet steps, the first an Euler step (as every run's first is), the second a leapfrog
/// step from the previous velocity, against the CPU oracle; tolerances as for the symplectic
/// step (each step here takes one force pass, and there are two steps).
pub fn check_verlet_steps(backend: &Backend) {
    verlet_steps(backend, case("tests/cases/hydrostatic_2d.yaml"));
}

/// The same under the generalised wall condition.
pub fn check_verlet_steps_generalised(backend: &Backend) {
    let mut c = case("tests/cases/hydrostatic_2d.yaml");
    c.numerics.boundary = flume_solver::config::BoundaryMethod::Generalised;
    verlet_steps(backend, c);
}

fn verlet_steps(backend: &Backend, mut c: Case) {
    c.numerics.integrator = flume_solver::config::Integrator::Verlet {
        euler_every_steps: 40,
    };
    let (mut sim, particles, params) = super::perturbed_sim(backend.clone(), &c, 0.3, 17);
    let dt = 2.0e-5f32;
    sim.advance_to(f64::from(dt)).expect("step 1");
    // A second step of another length: the leapfrog spans both steps.
    let dt2 = 1.5e-5f32;
    sim.advance_to(f64::from(dt) + f64::from(dt2))
        .expect("step 2");
    assert_eq!(sim.steps(), 2);
    let after = sim.read_particles().expect("readback");

    let f0 = interaction::interact(&params, &particles.positions, &particles.vel_rho);
    let (p1, v1, prev1) = integrate::verlet(
        &params.phases,
        dt,
        0.0,
        true,
        &particles.positions,
        &particles.vel_rho,
        &particles.vel_rho,
        &f0.forces,
    );
    let f1 = interaction::interact(&params, &p1, &v1);
    let (p2, v2, _) =
        integrate::verlet(&params.phases, dt2, dt, false, &p1, &v1, &prev1, &f1.forces);
    assert_step_close(&after, &p2, &v2, &[&f0.forces, &f1.forces], dt, 2.0);
}

/// The per-phase fullness of the probe stage, through the profile it yields: on a perturbed
/// two-layer state, each column's free surface and layer tops from the GPU equal those the
/// CPU oracle's sums give on the same sample heights (the floor to dp / 2 above the tank top
/// plus 2h, as `observe::Column` samples), to within 1e-5 m of interpolation rounding.
pub fn check_phase_fullness(backend: &Backend) {
    let c = case("tests/cases/two_layer_2d.yaml");
    let (sim, particles, params) = super::perturbed_sim(backend.clone(), &c, 0.3, 23);
    let obs = sim.observe().expect("observe");
    let h = sim.derived().h;
    let step = 0.5 * c.numerics.dp_m;
    let top = c.domain.max_m[1] + 2.0 * h;
    let n = ((top - c.domain.min_m[1]) / step).ceil() as usize + 1;
    let heights: Vec<f64> = (0..n)
        .map(|k| c.domain.min_m[1] + k as f64 * step)
        .collect();
    assert!(!obs.profile.is_empty());
    for col in &obs.profile {
        let sums: Vec<probe::ProbeSums> = heights
            .iter()
            .map(|z| {
                probe::probe(
                    &params,
                    [col.x_m as f32, *z as f32, 0.0],
                    &particles.positions,
                    &particles.vel_rho,
                )
            })
            .collect();
        let level = |f: &dyn Fn(&probe::ProbeSums) -> f32| {
            let v: Vec<f32> = sums.iter().map(f).collect();
            probe::free_surface_level(&heights, &v, 0.5)
        };
        let close = |gpu: Option<f64>, cpu: Option<f64>, what: &str| match (gpu, cpu) {
            (Some(g), Some(c)) => assert!(
                (g - c).abs() < 1e-5,
                "x={} {what}: backend {g} oracle {c}",
                col.x_m
            ),
            (g, c) => assert_eq!(g, c, "x={} {what}", col.x_m),
        };
        close(col.surface_m, level(&|s| s.fullness), "surface");
        for (k, gpu_top) in col.layer_tops_m.iter().enumerate() {
            close(
                *gpu_top,
                level(&|s| s.phase_fullness[k + 1]),
                &format!("top of phase {}", k + 1),
            );
        }
    }
}

/// The 2-D tank with Molteni-Colagrossi density diffusion (no hydrostatic correction).
pub fn molteni_case() -> Case {
    let mut c = case("tests/cases/hydrostatic_2d.yaml");
    c.numerics.density_diffusion =
        flume_solver::config::DensityDiffusion::MolteniColagrossi2009 { delta: 0.1 };
    c
}
