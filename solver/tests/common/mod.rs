//! Shared test helpers: the GPU (lavapipe in CI), serialised, and small case builders.

#![allow(dead_code)]

pub mod held_bed;
pub mod lone_grain;
pub mod parked;
pub mod probe;
pub mod sand_stages;
pub mod stages;
pub mod tank;

use flume_solver::{Backend, GpuContext, Particles};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

/// GPU tests run one at a time; runs on the CPU backend take no lock. Measured on CI's kind of
/// machine (two cores): a run on lavapipe keeps one core busy (user time equals wall time,
/// whatever `LP_NUM_THREADS` says), and a run of the CI flume on the CPU backend's two threads
/// about 1.2 cores; two such CPU runs side by side took 100 s against 165 s one after the
/// other. Lavapipe tests on an adapter each and with no lock were faster too (the splash tests
/// 68 s against 87 s, `gpu_vs_reference.rs` 20 s against 34-44 s), measured once on a machine
/// whose speed wandered by half; they keep to one at a time until a whole run settles it.
pub fn gpu_lock() -> MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// [`gpu_lock`] where `backend` is a GPU; nothing for the CPU backend.
pub fn lock_for(backend: &Backend) -> Option<MutexGuard<'static, ()>> {
    matches!(backend, Backend::Gpu(_)).then(gpu_lock)
}

/// This process's resident size in bytes, where Linux tells it (`/proc/self/statm`, in pages of
/// 4 KiB on x86-64), to hold a run's memory to a bound.
pub fn resident_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096)
}

/// The backend `simulate` chooses (`Backend::choose`): `FLUME_TWIN_ADAPTER`, else a hardware
/// GPU, else the CPU backend, which runs a flume some five times faster than lavapipe on the
/// same cores. The physics of whole cases runs on it; the wgpu stages are held to their CPU
/// oracles on lavapipe (`gpu_vs_reference.rs`), and both backends to each other on whole cases
/// (`cases.rs`, `whole_session.rs`, `weir.rs`).
pub fn chosen() -> Backend {
    Backend::choose().expect("FLUME_TWIN_ADAPTER names an adapter this machine has")
}

/// The adapter, or None outside CI when this machine has none (then the test says so and
/// passes); under CI=true a missing adapter fails the test, since CI has lavapipe.
pub fn gpu() -> Option<Arc<GpuContext>> {
    static GPU: OnceLock<Option<Arc<GpuContext>>> = OnceLock::new();
    GPU.get_or_init(|| match GpuContext::new() {
        Ok(g) => {
            eprintln!("adapter: {}", g.adapter);
            Some(Arc::new(g))
        }
        Err(e) => {
            if std::env::var("CI").as_deref() == Ok("true") {
                panic!("CI=true but no GPU adapter: {e}");
            }
            eprintln!("skipping GPU test: {e}");
            None
        }
    })
    .clone()
}

/// The particle phase of a case's sand: its second fluid phase (0 is the walls; every sediment
/// case here lists water first).
pub const SAND: u32 = 2;

/// Sand particles more than dp / 2 from where they started, or no longer sand (collected).
pub fn mobilised(start: &Particles, now: &Particles, dp: f32) -> usize {
    (0..now.len())
        .filter(|&i| start.phase(i) == SAND)
        .filter(|&i| {
            let (a, b) = (start.positions[i], now.positions[i]);
            now.phase(i) != SAND || (a[0] - b[0]).hypot(a[1] - b[1]) > 0.5 * dp
        })
        .count()
}

/// The ULBRA flume at CI size: dp = 1 cm (the bed 5 particles deep, the inlet 2 high), a
/// reservoir of 2,500 parked particles.
pub fn ulbra_ci() -> flume_solver::Case {
    let mut c = flume_solver::Case::from_path(&case_path("../launch_configs/ulbra_flume.yaml"))
        .expect("case parses");
    c.numerics.dp_m = 0.01;
    if let Some(f) = c.open_flume.as_mut() {
        f.reservoir_particles = 2500;
    }
    c
}

pub fn case_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(name)
}

pub fn validation_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/validation")
        .join(name)
}

/// The CPU oracle's parameters for a simulation, from its case file and what the case implies
/// (`derive`, in f64), never from the uniform the backends run on: a field packed wrongly
/// into the uniform then shows as a disagreement with the oracle instead of being copied
/// into it.
pub fn reference_params(sim: &flume_solver::Simulation) -> flume_solver::physics::Params {
    use flume_solver::config::{DensityDiffusion, Viscosity as CaseViscosity};
    use flume_solver::physics::{Params, Phase, Viscosity};
    let case = sim.case();
    let derived = sim.derived();
    let mut gravity = [0.0f32; 3];
    for (g, v) in gravity.iter_mut().zip(&case.gravity_m_per_s2) {
        *g = *v as f32;
    }
    let (delta, hydrostatic_diffusion) = match case.numerics.density_diffusion {
        DensityDiffusion::None => (0.0, false),
        DensityDiffusion::MolteniColagrossi2009 { delta } => (delta as f32, false),
        DensityDiffusion::Fourtakas2019 { delta } => (delta as f32, true),
    };
    Params {
        dim: case.dimension,
        h: derived.h as f32,
        c0: derived.c0 as f32,
        gravity,
        delta,
        hydrostatic_diffusion,
        clamp_negative_pressure: case.numerics.clamp_negative_pressure,
        generalised_walls: case.numerics.boundary
            == flume_solver::config::BoundaryMethod::Generalised,
        viscosity: match case.numerics.viscosity {
            CaseViscosity::Artificial { alpha } => Viscosity::Artificial {
                alpha: alpha as f32,
            },
            CaseViscosity::Laminar => Viscosity::Laminar,
            CaseViscosity::Multiphase {
                alpha,
                smagorinsky_cs,
                eddy_m2_per_s,
            } => Viscosity::Multiphase {
                alpha: (alpha
                    + flume_solver::monaghan_alpha(
                        eddy_m2_per_s,
                        derived.h,
                        derived.c0,
                        case.dim(),
                    )) as f32,
                sps_length2: (smagorinsky_cs * case.numerics.dp_m).powi(2) as f32,
            },
        },
        cfl: case.numerics.cfl as f32,
        phases: derived
            .phases
            .iter()
            .map(|ph| Phase {
                rho0: ph.rho0 as f32,
                mass: ph.mass as f32,
                mu: ph.viscosity_pa_s as f32,
                mobile: ph.mobile,
                generalised_wall: !ph.mobile
                    && case.numerics.boundary == flume_solver::config::BoundaryMethod::Generalised,
            })
            .collect(),
    }
}

/// The sediment model the case file describes, for the CPU oracle: read from the case and
/// `derive()` like [`reference_params`], never from the uniform the backends run on, so a
/// field packed wrongly into the uniform fails the stage tests.
pub fn reference_sediment(
    sim: &flume_solver::Simulation,
) -> flume_solver::physics::sediment::pass::SedimentModel {
    use flume_solver::config::YieldCriterion;
    use flume_solver::physics::sediment::SedimentParams;
    let case = sim.case();
    let derived = sim.derived();
    let (k_sed, k_water) = case.sediment_phases().expect("a case with sediment");
    let (sed, water) = (&case.phases[k_sed], &case.phases[k_water]);
    let cfg = sed.sediment.as_ref().expect("the sediment phase's model");
    // MODEL.md: without a cap, mu_max = 0.125 h rho_s c0.
    let mu_max = cfg
        .max_viscosity_pa_s
        .unwrap_or(0.125 * derived.h * sed.rho0_kg_per_m3 * derived.c0);
    flume_solver::physics::sediment::pass::SedimentModel {
        material: SedimentParams {
            rho_s: sed.rho0_kg_per_m3 as f32,
            d50_m: cfg.d50_m as f32,
            phi_rad: cfg.friction_angle_deg.to_radians() as f32,
            cohesion_pa: cfg.cohesion_pa as f32,
            hbp_m: cfg.hbp_m_s as f32,
            hbp_n: cfg.hbp_n as f32,
            mu_s_pa_s: sed.viscosity_pa_s as f32,
            ks_over_d50: cfg.ks_over_d50 as f32,
            surface_mass_fraction: cfg.surface_mass_fraction as f32,
            rho_w: water.rho0_kg_per_m3 as f32,
            nu_w: (water.viscosity_pa_s / water.rho0_kg_per_m3) as f32,
            mu_w: water.viscosity_pa_s as f32,
        },
        // Phase 0 is the walls: the case's phases count from 1.
        sediment_phase: k_sed + 1,
        water_phase: k_water + 1,
        shields_only: cfg.criterion == YieldCriterion::ShieldsOnly,
        water_speed: cfg.shields_speed == flume_solver::config::ShieldsSpeed::Water,
        rests_beside_solid: cfg.comes_to_rest == flume_solver::config::ComesToRest::BesideASolid,
        mu_max: mu_max as f32,
        pickup_per_s: match cfg.erosion {
            flume_solver::config::Erosion::Threshold => 0.0,
            flume_solver::config::Erosion::VanRijnPickup
            | flume_solver::config::Erosion::VanRijnIntegrated
            | flume_solver::config::Erosion::VanRijnExner => {
                flume_solver::physics::sediment::pickup::pickup_per_s(
                    cfg.d50_m,
                    sed.rho0_kg_per_m3,
                    water.rho0_kg_per_m3,
                    water.viscosity_pa_s / water.rho0_kg_per_m3,
                    case.gravity_magnitude(),
                    case.numerics.dp_m,
                ) as f32
            }
        },
        pickup_integrated: matches!(
            cfg.erosion,
            flume_solver::config::Erosion::VanRijnIntegrated
                | flume_solver::config::Erosion::VanRijnExner
        ),
        // van Rijn (1984a): a saltation length of 3 d50 D*^0.6 T^0.9, over dp.
        exner_step_per_stage: if cfg.erosion == flume_solver::config::Erosion::VanRijnExner {
            let nu = water.viscosity_pa_s / water.rho0_kg_per_m3;
            let submerged =
                (sed.rho0_kg_per_m3 / water.rho0_kg_per_m3 - 1.0) * case.gravity_magnitude();
            let d_star = cfg.d50_m * (submerged / (nu * nu)).cbrt();
            (3.0 * cfg.d50_m * d_star.powf(0.6) / case.numerics.dp_m) as f32
        } else {
            0.0
        },
        dp_m: case.numerics.dp_m as f32,
    }
}

/// A deterministic pseudo-random stream in [-1, 1) (64-bit LCG), for perturbing states.
pub struct Jitter(pub u64);

impl Jitter {
    pub fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }
}

/// The case's lattice with every fluid particle displaced by up to 0.2 dp, given a velocity of
/// up to `speed` and a density off rho0 by up to 1 %: no symmetry left to hide a wrong sign.
pub fn perturbed(sim: &flume_solver::Simulation, speed: f32, seed: u64) -> flume_solver::Particles {
    let mut p = sim.initial_particles().clone();
    let dp = sim.case().numerics.dp_m as f32;
    let d = sim.case().dim();
    let mut j = Jitter(seed);
    for i in 0..p.len() {
        if p.phase(i) == flume_solver::particles::WALL_PHASE {
            p.vel_rho[i][3] *= 1.0 + 0.005 * (j.next() + 1.0);
            continue;
        }
        for k in 0..d {
            p.positions[i][k] += 0.2 * dp * j.next();
            p.vel_rho[i][k] = speed * j.next();
        }
        p.vel_rho[i][3] *= 1.0 + 0.01 * j.next();
    }
    p
}

/// A simulation of `case` started from its lattice perturbed as `perturbed` does, with that
/// state and the CPU oracle's parameters: the starting point of every stage-vs-oracle test.
pub fn perturbed_sim(
    backend: impl Into<Backend>,
    case: &flume_solver::Case,
    speed: f32,
    seed: u64,
) -> (
    flume_solver::Simulation,
    flume_solver::Particles,
    flume_solver::physics::Params,
) {
    let backend = backend.into();
    let lattice = flume_solver::Simulation::new(backend.clone(), case).expect("case builds");
    let particles = perturbed(&lattice, speed, seed);
    let sim = flume_solver::Simulation::from_particles(backend, case, particles.clone())
        .expect("perturbed state builds");
    let params = reference_params(&sim);
    (sim, particles, params)
}
