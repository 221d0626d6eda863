//! Tier 3: whole cases at CI size, checked against physics and invariants, on the wgpu backend
//! (lavapipe in CI) and on the CPU backend, and the two backends against each other.

mod common;

use common::tank::{assert_in_tank, assert_mass_conserved, interpolate, read_front};
use flume_solver::Particles;
use flume_solver::{Backend, Case, Simulation};

const CPU: Backend = Backend::cpu(2);

/// Runs `check` on the CPU backend, then on the GPU when there is one (one GPU test at a
/// time): what it returns from each, CPU first.
fn on_both<T>(check: impl Fn(Backend) -> T) -> (T, Option<T>) {
    let cpu = check(CPU);
    let _l = common::gpu_lock();
    (cpu, common::gpu().map(|g| check(Backend::from(g))))
}

fn case(name: &str) -> Case {
    Case::from_path(&common::case_path(name)).expect("case parses")
}

/// After settling, the pressure at probes away from the walls follows rho g (H - z) within 2 %,
/// H being the free surface the gauge measures (itself within dp / 2 of the filled height).
/// 2 % is the bound; the residual is the slow sloshing mode left after the start,
/// about 1 % here, which alpha = 0.02 damps only slowly. Returns the probe pressures, Pa.
fn check_hydrostatic(backend: Backend, name: &str, times_s: &[f64]) -> Vec<f64> {
    let c = case(name);
    let d = c.dim();
    let rho_g = c.phases[0].rho0_kg_per_m3 * c.gravity_magnitude();
    let filled = c.fluid_blocks[0].max_m[d - 1] + 0.5 * c.numerics.dp_m;
    let mut sim = Simulation::new(backend, &c).expect("case builds");
    let mut pressures = Vec::new();
    for &t in times_s {
        sim.advance_to(t).expect("runs");
        let obs = sim.observe().expect("observes");
        let level = obs.gauges[0].level_m.expect("gauge in water");
        assert!(
            (level - filled).abs() <= 0.5 * c.numerics.dp_m,
            "{name} t={t}: free surface {level:.5} m, filled to {filled:.5} m"
        );
        for (probe, cfg) in obs.probes.iter().zip(&c.observations.pressure_probes) {
            let z = cfg.position_m[d - 1];
            let expected = rho_g * (level - z);
            let p = probe.pressure_pa.expect("probe in water");
            pressures.push(p);
            let err = p / expected - 1.0;
            eprintln!(
                "{} {name} t={t:.2} z={z:.3}: p = {p:.1} Pa, rho g (H - z) = {expected:.1} Pa ({:+.2} %)",
                sim.backend_name(),
                err * 100.0
            );
            assert!(
                err.abs() <= 0.02,
                "{name} t={t} probe {}: {:+.2} %",
                cfg.name,
                err * 100.0
            );
        }
    }
    pressures
}

/// Both backends pass, and their probe pressures agree within 0.5 % of each other (a quarter
/// of the bound against the analytic profile: the two differ by f32 rounding that the
/// sloshing mode carries, not by a model).
fn check_hydrostatic_on_both(name: &str, times_s: &[f64]) {
    let (cpu, gpu) = on_both(|b| check_hydrostatic(b, name, times_s));
    let largest = cpu
        .iter()
        .zip(gpu.iter().flatten())
        .map(|(c, g)| (c / g - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!("{name}: probe pressures of the two backends differ by up to {largest:.2e}");
    for (c, g) in cpu.iter().zip(gpu.iter().flatten()) {
        assert!(
            (c / g - 1.0).abs() <= 0.005,
            "{name}: CPU backend {c:.1} Pa, wgpu {g:.1} Pa"
        );
    }
}

#[test]
fn hydrostatic_tank_2d_pressure_follows_depth() {
    check_hydrostatic_on_both("tests/cases/hydrostatic_2d.yaml", &[0.3, 0.35, 0.4]);
}

#[test]
fn hydrostatic_tank_3d_pressure_follows_depth() {
    check_hydrostatic_on_both("tests/cases/hydrostatic_3d.yaml", &[0.2, 0.25]);
}

/// Phases are data: a dense phase under water keeps the two-layer hydrostatic profile, within
/// the same 2 % as one phase (the interface lies halfway between the two blocks' lattices).
#[test]
fn two_phases_at_rest_keep_the_layered_hydrostatic_pressure() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let c = case("tests/cases/two_layer_2d.yaml");
    let g = c.gravity_magnitude();
    let (rho_w, rho_s) = (c.phases[0].rho0_kg_per_m3, c.phases[1].rho0_kg_per_m3);
    let interface = c.fluid_blocks[0].max_m[1] + 0.5 * c.numerics.dp_m;
    let mut sim = Simulation::new(gpu, &c).expect("case builds");
    for t in [0.3, 0.35] {
        sim.advance_to(t).expect("runs");
        let obs = sim.observe().expect("observes");
        assert!(
            obs.max_speed_m_per_s < 0.05,
            "t={t}: the layers are moving at {} m/s",
            obs.max_speed_m_per_s
        );
        let level = obs.gauges[0].level_m.expect("gauge in water");
        // The profile finds the same surface and the top of the dense layer, within dp / 2.
        assert_eq!(obs.profile.len(), 4);
        let half_dp = 0.5 * c.numerics.dp_m;
        for col in &obs.profile {
            let surface = col.surface_m.expect("wet column");
            let dense_top = col.layer_tops_m[1].expect("dense layer present");
            let water_top = col.layer_tops_m[0].expect("water present");
            eprintln!(
                "two layers t={t:.2} x={:.3}: surface {surface:.4} m, dense top {dense_top:.4} m",
                col.x_m
            );
            assert!(
                (surface - level).abs() <= half_dp,
                "x={}: surface {surface} vs gauge {level}",
                col.x_m
            );
            assert!(
                (water_top - surface).abs() <= half_dp,
                "x={}: water top {water_top}",
                col.x_m
            );
            assert!(
                (dense_top - interface).abs() <= half_dp,
                "x={}: dense top {dense_top} vs {interface}",
                col.x_m
            );
        }
        for (probe, cfg) in obs.probes.iter().zip(&c.observations.pressure_probes) {
            let z = cfg.position_m[1];
            let expected = if z < interface {
                rho_w * g * (level - interface) + rho_s * g * (interface - z)
            } else {
                rho_w * g * (level - z)
            };
            let p = probe.pressure_pa.expect("probe in fluid");
            let err = p / expected - 1.0;
            eprintln!(
                "two layers t={t:.2} z={z:.3}: p = {p:.1} Pa, expected {expected:.1} Pa ({:+.2} %)",
                err * 100.0
            );
            assert!(
                err.abs() <= 0.02,
                "t={t} probe {}: {:+.2} %",
                cfg.name,
                err * 100.0
            );
        }
    }
}

/// Dam break of a column twice as high as wide against Martin & Moyce (1952), n^2 = 2.
/// The experiment's time origin is uncertain by the removal of the gate, and the simulated
/// front leads their data by about 0.1 in T at the start (Z/a 1.35 against 1.25 at T = 0.85),
/// as in most published SPH and VOF comparisons. So the test fits one time shift dT in
/// [0, 0.3] (0.3 is 16 ms for their 2.25 in column), states it, and then requires every
/// measured point with T <= 2.5 of both column sizes within 5 % of the simulated front.
/// Without the shift the errors are printed too. Both backends pass, and their fronts agree
/// within 2 % of Z/a at every output (see `check_dambreak_on_both`).
#[test]
fn dambreak_front_follows_martin_moyce() {
    check_dambreak_on_both(flume_solver::config::Integrator::Symplectic);
}

/// The same with DualSPHysics' default Verlet integrator.
#[test]
fn dambreak_front_follows_martin_moyce_with_verlet() {
    check_dambreak_on_both(flume_solver::config::Integrator::Verlet {
        euler_every_steps: 40,
    });
}

/// The front on both backends. They sum the same pair terms in the same order with different
/// rounding (WGSL's kernel and fused operations against Rust's), and a breaking front
/// amplifies rounding; 2 % of Z/a is two fifths of the bound against the experiment.
fn check_dambreak_on_both(integrator: flume_solver::config::Integrator) {
    let (cpu, gpu) = on_both(|b| check_dambreak_front(b, integrator));
    let largest = cpu
        .iter()
        .zip(gpu.iter().flatten())
        .map(|((_, c), (_, g))| (c - g).abs())
        .fold(0.0, f64::max);
    eprintln!("{integrator:?}: fronts of the two backends differ by up to {largest:.4} Z/a");
    for ((t, c), (_, g)) in cpu.iter().zip(gpu.iter().flatten()) {
        assert!(
            (c - g).abs() <= 0.02,
            "{integrator:?} T = {t:.2}: front Z/a {c:.3} on the CPU backend, {g:.3} on wgpu"
        );
    }
}

/// Checks the front against Martin & Moyce and returns it, (T, Z/a).
fn check_dambreak_front(
    backend: Backend,
    integrator: flume_solver::config::Integrator,
) -> Vec<(f64, f64)> {
    let mut c = case("../launch_configs/dambreak_water.yaml");
    c.numerics.integrator = integrator;
    // The coarsest resolution that passes: a / dp = 25.
    c.numerics.dp_m = 0.004;
    let a = c.fluid_blocks[0].max_m[0] - c.fluid_blocks[0].min_m[0];
    let scale = (2.0 * c.gravity_magnitude() / a).sqrt();
    let mut sim = Simulation::new(backend, &c).expect("case builds");
    let front = |sim: &Simulation| sim.observe().expect("observes").front_m.expect("fluid");
    let mut curve = vec![(0.0, front(&sim) / a)];
    let steps = 52;
    for k in 1..=steps {
        let t_dimless = 2.6 * k as f64 / steps as f64;
        sim.advance_to(t_dimless / scale).expect("runs");
        curve.push((t_dimless, front(&sim) / a));
    }
    let mut data = read_front("dambreak_front_position/martin_moyce1952_n2_2_a1.125in.csv");
    data.extend(read_front(
        "dambreak_front_position/martin_moyce1952_n2_2_a2.25in.csv",
    ));
    data.retain(|(t, _)| *t <= 2.5);
    assert!(data.len() >= 6);
    let worst = |shift: f64| -> f64 {
        data.iter()
            .map(|(t, z)| (interpolate(&curve, t - shift) / z - 1.0).abs())
            .fold(0.0, f64::max)
    };
    let (shift, err) = (0..=30)
        .map(|k| 0.01 * k as f64)
        .map(|s| (s, worst(s)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("shifts");
    for (t, z) in &data {
        eprintln!(
            "{} {integrator:?}: T = {t:.3}: Martin & Moyce Z/a = {z:.3}; SPH {:.3} ({:+.1} %), with dT = {shift:.2}: {:.3} ({:+.1} %)",
            sim.backend_name(),
            interpolate(&curve, *t),
            (interpolate(&curve, *t) / z - 1.0) * 100.0,
            interpolate(&curve, t - shift),
            (interpolate(&curve, t - shift) / z - 1.0) * 100.0,
        );
    }
    assert!(
        err <= 0.05,
        "worst front error {:.1} % even with the best time shift {shift}",
        err * 100.0
    );
    let p = sim.read_particles().expect("readback");
    assert_in_tank(&c, &p);
    assert_mass_conserved(&sim, &p);
    curve
}

/// The same case run twice on the same adapter gives the same bits: neighbour order is fixed
/// by the (cell, id) sort and every reduction is a min or max.
#[test]
fn dambreak_is_bit_identical_run_to_run_and_loses_nothing() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let gpu = Backend::from(gpu);
    assert_same_bits(&[gpu.clone(), gpu]);
}

/// The CPU backend too, and on one thread as on two: each particle's sums are taken by one
/// thread in sorted order, whatever the number of threads.
#[test]
fn dambreak_on_the_cpu_is_bit_identical_run_to_run_and_on_any_thread_count() {
    assert_same_bits(&[CPU, CPU, Backend::cpu(1)]);
}

/// Runs the dam break at dp = 5 mm to 0.04 s on each backend: every run gives the same bits,
/// loses nothing and moved.
fn assert_same_bits(backends: &[Backend]) {
    let mut c = case("../launch_configs/dambreak_water.yaml");
    c.numerics.dp_m = 0.005;
    let run = |backend: &Backend| {
        let mut sim = Simulation::new(backend.clone(), &c).expect("case builds");
        sim.advance_to(0.04).expect("runs");
        let p = sim.read_particles().expect("readback");
        assert_mass_conserved(&sim, &p);
        assert_in_tank(&c, &p);
        (p, sim.steps())
    };
    let bits = |p: &Particles| -> Vec<u32> {
        p.positions
            .iter()
            .chain(&p.vel_rho)
            .flat_map(|v| v.map(f32::to_bits))
            .collect()
    };
    let (first, steps) = run(&backends[0]);
    for (k, backend) in backends.iter().enumerate().skip(1) {
        let (again, steps_again) = run(backend);
        assert_eq!(steps, steps_again, "run {k} on {backend:?}");
        assert!(
            bits(&first) == bits(&again),
            "run {k} on {backend:?} differs"
        );
    }
    assert_ne!(
        bits(&first),
        bits(&flume_solver::generate(&c, &flume_solver::derive(&c))),
        "nothing moved"
    );
}

#[test]
fn a_case_larger_than_the_adapter_allows_fails_before_allocating() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let mut c = case("tests/cases/hydrostatic_3d.yaml");
    // Enough particles to pass the per-binding limit of this adapter, whatever it is.
    let limit = gpu
        .limits
        .max_storage_buffer_binding_size
        .min(gpu.limits.max_buffer_size) as f64;
    let volume = c.fluid_blocks[0].max_m.iter().product::<f64>();
    c.numerics.dp_m = (volume / (2.0 * limit / 16.0)).cbrt();
    let err = match Simulation::new(gpu, &c) {
        Ok(_) => panic!(
            "a case of {} particles was accepted",
            flume_solver::generate::count(&c)
        ),
        Err(e) => e.to_string(),
    };
    eprintln!("{err}");
    assert!(
        err.contains("MiB") && (err.contains("per storage buffer") || err.contains("32-bit")),
        "unclear error: {err}"
    );
}

#[test]
fn an_unknown_adapter_name_lists_the_available_ones() {
    let Some(_gpu) = common::gpu() else { return };
    let _l = common::gpu_lock();
    let err = match flume_solver::GpuContext::with_adapter(Some("no-such-adapter-xyz")) {
        Ok(_) => panic!("matched a nonexistent adapter"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("FLUME_TWIN_ADAPTER") && err.contains("available:"),
        "{err}"
    );
}

/// An absurd CFL number makes the dam break blow up; the solver must notice on the GPU, roll
/// back to the chunk's start, halve the CFL number until the chunk passes, say so, and go on
/// with a state that is whole (finite, in the tank, every particle present).
#[test]
fn a_blow_up_is_caught_rolled_back_and_retried_with_a_smaller_cfl() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let mut c = case("../launch_configs/dambreak_water.yaml");
    c.numerics.dp_m = 0.005;
    let mut sim = Simulation::new(gpu, &c).expect("case builds");
    sim.advance_to(0.01).expect("runs at the case's CFL");
    assert!(sim.recoveries().is_empty());
    sim.set_cfl(5.0).expect("accepted for the test");
    sim.advance_to(0.03).expect("recovers");
    let rec = sim.recoveries().to_vec();
    assert!(!rec.is_empty(), "CFL 5 did not blow up");
    for r in &rec {
        eprintln!("recovered: {r:?}");
        assert_eq!(r.restored_to_s, 0.01);
        assert!(!r.health.is_ok());
        assert!(r.failed_at_s >= 0.01 && r.failed_at_s <= 0.03);
    }
    assert_eq!(
        sim.cfl(),
        5.0 * 0.5f64.powi(rec.len() as i32),
        "halved once per recovery"
    );
    assert_eq!(sim.time_s(), 0.03);
    let obs = sim.observe().expect("observes");
    assert_eq!(obs.recoveries as usize, rec.len());
    assert!(
        obs.max_density_error < 0.05,
        "density error {}",
        obs.max_density_error
    );
    let p = sim.read_particles().expect("readback");
    assert_in_tank(&c, &p);
    assert_mass_conserved(&sim, &p);
    // After enough calm chunks the CFL number doubles back towards the one asked for.
    let lowered = sim.cfl();
    let n = flume_solver::simulation::CFL_RESTORE_AFTER_CHUNKS;
    for k in 1..=n {
        sim.advance_to(0.03 + f64::from(k) * 2e-5)
            .expect("calm chunk");
    }
    assert_eq!(sim.recoveries().len(), rec.len(), "a calm chunk blew up");
    assert_eq!(
        sim.cfl(),
        2.0 * lowered,
        "not restored after {n} calm chunks"
    );
    assert!(
        sim.set_cfl(-1.0).is_err() && sim.set_cfl(f64::NAN).is_err() && sim.set_cfl(50.0).is_err()
    );
}

/// The dam-break case at spacing `dp_m` with the sound speed set to `c0_m_per_s`.
fn dambreak_with_c0(c0_m_per_s: f64, dp_m: f64) -> Case {
    let mut c = case("../launch_configs/dambreak_water.yaml");
    c.numerics.dp_m = dp_m;
    c.numerics.sound_speed = flume_solver::config::SoundSpeed {
        c0_m_per_s: Some(c0_m_per_s),
        coefsound: None,
    };
    c
}

/// A sound speed so low that the fluid at rest is already outside the weakly compressible
/// range is refused when the simulation is built, with the c0 that would do.
#[test]
fn a_sound_speed_too_low_for_the_column_is_refused_up_front() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let c = dambreak_with_c0(0.2, 0.0025);
    let err = match Simulation::new(gpu, &c) {
        Ok(_) => panic!("accepted c0 = 0.2 m/s for a 0.2 m column"),
        Err(e) => e.to_string(),
    };
    eprintln!("{err}");
    assert!(
        err.contains("too low") && err.contains("use c0 above"),
        "{err}"
    );
}

/// A case that no time step can save (a sound speed far below the flow's speed) fails with
/// the blow-up error after the retries, instead of returning garbage.
#[test]
fn an_unrecoverable_blow_up_is_an_error_that_says_so() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let c = dambreak_with_c0(4.0, 0.01);
    let mut sim = Simulation::new(gpu, &c).expect("case builds");
    let err = sim.advance_to(0.3).expect_err("cannot survive");
    let text = err.to_string();
    eprintln!("{text}");
    assert!(
        matches!(err, flume_solver::SolverError::BlowUp { .. }),
        "{text}"
    );
    assert!(text.contains("blew up"), "{text}");
    assert_eq!(
        sim.recoveries().len(),
        flume_solver::simulation::MAX_RECOVERIES_PER_CHUNK as usize
    );
}

/// A domain whose neighbour grid would need more cells than 32-bit indices hold is refused
/// before anything is generated or allocated (the product used to wrap in u32).
#[test]
fn a_grid_too_large_for_32_bit_cell_indices_is_refused() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let mut c = case("tests/cases/hydrostatic_2d.yaml");
    c.domain.max_m = vec![2000.0, 2000.0];
    let err = match Simulation::new(gpu, &c) {
        Ok(_) => panic!("a grid of billions of cells was accepted"),
        Err(e) => e,
    };
    assert!(
        matches!(err, flume_solver::SolverError::TooManyCells(n) if n > u64::from(u32::MAX)),
        "{err}"
    );
    assert!(err.to_string().contains("coarser dp"), "{err}");
}

/// A target time that is not a finite number is refused, and the simulation stays usable.
#[test]
fn a_non_finite_target_time_is_refused() {
    let _l = common::gpu_lock();
    let Some(gpu) = common::gpu() else { return };
    let c = dambreak_with_c0(28.0, 0.01);
    let mut sim = Simulation::new(gpu, &c).expect("case builds");
    for t in [f64::NAN, f64::INFINITY] {
        let err = sim.advance_to(t).expect_err("refused");
        assert!(err.to_string().contains("finite"), "{err}");
    }
    sim.advance_to(0.001).expect("still runs");
    assert_eq!(sim.time_s(), 0.001);
    assert!(matches!(
        sim.advance_to(0.0005),
        Err(flume_solver::SolverError::TimeGoesBack { .. })
    ));
}

/// A sand bed under still water for 2 s: the bed surface of each profile column (the top of
/// the sand layer) stays within dp / 2 of where it started, the bound. A bed that creeps
/// moves as a whole, so no sand particle may move by more than dp either, walls included (before
/// walls were scaled to the fluid they touch, sand rose 2.3 cm up the side walls in these 2 s).
/// Measured on 2026-12-02, on both backends alike: no sand particle moved by more than 0.03 dp
/// in 2 s (this comment said up to 0.8 dp when the test was written). It runs on the backend
/// `simulate` chooses (the CPU backend in CI, 10 s against lavapipe's 280 s).
#[test]
fn a_sand_bed_under_still_water_does_not_creep() {
    let backend = common::chosen();
    let _l = common::lock_for(&backend);
    let c = case("tests/cases/sediment_bed_2d.yaml");
    let half_dp = 0.5 * c.numerics.dp_m;
    let mut sim = Simulation::new(backend, &c).expect("case builds");
    let start = sim.observe().expect("observes");
    let initial = sim.initial_particles().clone();
    let sand = 2u32;
    let two_h = 2.0 * sim.derived().h as f32;
    let (x_min, x_max) = (c.domain.min_m[0] as f32, c.domain.max_m[0] as f32);
    for t in [0.5, 1.0, 1.5, 2.0] {
        sim.advance_to(t).expect("runs");
        let obs = sim.observe().expect("observes");
        let now = sim.read_particles().expect("reads");
        let regions = sim.regions().expect("regions");
        let mut count = [0usize; 6];
        // Largest displacement (m, particle) in the interior and within 2h of a side wall.
        let mut interior = (0.0f32, 0usize);
        let mut by_wall = (0.0f32, 0usize);
        for i in 0..now.len() {
            if now.phase(i) != sand {
                continue;
            }
            count[(regions[i] & 255) as usize] += 1;
            let d = (0..2)
                .map(|k| (now.positions[i][k] - initial.positions[i][k]).powi(2))
                .sum::<f32>()
                .sqrt();
            let x0 = initial.positions[i][0];
            let slot = if x0 < x_min + two_h || x0 > x_max - two_h {
                &mut by_wall
            } else {
                &mut interior
            };
            if d > slot.0 {
                *slot = (d, i);
            }
        }
        eprintln!(
            "bed t={t:.1}: steps {}, max speed {:.2e} m/s, sand regions 1-5 {:?}",
            obs.steps,
            obs.max_speed_m_per_s,
            &count[1..]
        );
        for (name, (d, i)) in [("interior", interior), ("by a wall", by_wall)] {
            eprintln!(
                "  largest sand displacement {name}: {d:.2e} m, from {:?} to {:?}",
                &initial.positions[i][..2],
                &now.positions[i][..2]
            );
        }
        for (d, i) in [interior, by_wall] {
            assert!(
                f64::from(d) < 2.0 * half_dp,
                "t={t}: sand particle {i} moved {d} m"
            );
        }
        for (col, col0) in obs.profile.iter().zip(&start.profile) {
            let top = col.layer_tops_m[1].expect("sand under the column");
            let top0 = col0.layer_tops_m[1].expect("sand under the column");
            let bed = col.bed.expect("a sediment case reports Zb, Zs, Zw");
            eprintln!(
                "  x={:.3}: bed {top:.4} m (start {top0:.4} m), Zb {:?} Zs {:?} Zw {:?}",
                col.x_m, bed.zb_m, bed.zs_m, bed.zw_m
            );
            // Nothing moves: the immobile grains reach the top of the sand.
            let (zb, zs) = (bed.zb_m.expect("Zb"), bed.zs_m.expect("Zs"));
            assert!((zb - zs).abs() < half_dp, "x={}: Zb {zb} Zs {zs}", col.x_m);
            assert_eq!(Some(top), bed.zs_m);
            assert_eq!(col.surface_m, bed.zw_m);
            assert!(
                (top - top0).abs() < half_dp,
                "t={t} x={}: the bed surface moved from {top0} to {top} m",
                col.x_m
            );
        }
        assert_mass_conserved(&sim, &now);
    }
}
