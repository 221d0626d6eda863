//! `flume-twin bench`: throughput (particle-steps/s) and real-time factor on this machine.
//!
//! Each measurement warms up, estimates the cost of a step, then times whole steps for about
//! `--steps-seconds` of wall time, on each backend side by side (the native CPU backend and the
//! wgpu adapter). Nothing here asserts on speed: the figures are for a log.

use crate::adapters::table::{Table, sci, sig};
use crate::cli::BenchArgs;
use anyhow::{Context, Result, bail};
use flume_solver::StageTime;
use flume_solver::{Backend, Case, GpuContext, Simulation};
use std::sync::Arc;
use std::time::Instant;

/// DualSPHysics 5.4 on CaseDambreakVal2D, CPU, 2 OpenMP threads, particle-steps/s.
const DSPH_VERLET: f64 = 1.77e6;
const DSPH_SYMPLECTIC: f64 = 0.95e6;

/// Steps in the shortest stretch timed: a stretch of a few steps measures the submission and
/// readback around it more than the steps themselves.
const MIN_STRETCH_STEPS: f64 = 8.0;

/// Spacing of the synthetic cases, m: the tank grows with the particle count, not the resolution.
const BENCH_DP_M: f64 = 0.01;

/// One timed stretch of a run.
struct Measurement {
    particles: usize,
    fluid: usize,
    steps: u64,
    wall_s: f64,
    /// Simulated time covered by the timed stretch, from `start_s`.
    sim_s: f64,
    start_s: f64,
    /// The backend, as it names itself.
    backend: String,
    /// Seconds per stage over the timed stretch; empty where the backend cannot time them.
    stages: Vec<StageTime>,
    /// Share of the force pass's lane-pairs that added to a sum read, counted after it.
    lanes: Option<f64>,
}

impl Measurement {
    fn steps_per_s(&self) -> f64 {
        self.steps as f64 / self.wall_s
    }
    fn particle_steps_per_s(&self) -> f64 {
        self.particles as f64 * self.steps_per_s()
    }
}

pub fn run(args: &BenchArgs) -> Result<()> {
    if !(args.steps_seconds.is_finite() && args.steps_seconds > 0.0) {
        bail!(
            "--steps-seconds must be a positive number of seconds, got {}",
            args.steps_seconds
        );
    }
    if args.frames {
        return super::bench_frames::run(&args.flume, args.steps_seconds);
    }
    if args.levels {
        if args.until.is_nan() || args.until < 20.0 {
            bail!(
                "--until: {} s is too short to measure a drift; use at least 20",
                args.until
            );
        }
        if let Some(dp) = args.dp.iter().find(|dp| !(dp.is_finite() && **dp > 0.0)) {
            bail!("--dp: {dp} is not a positive length in metres");
        }
        return super::bench_levels::run(&args.flume, &args.set, &level_runs(args));
    }
    if let Some(n) = args.ladder.iter().find(|n| **n < 100) {
        bail!("--ladder: {n} particles is too few for a dam break; use at least 100");
    }
    // Load the cases first so a wrong path fails before minutes of timing.
    let reference = Case::from_path(&args.case)
        .context("cannot load the reference case (run from the repository root or pass --case)")?;
    if !(args.from.is_finite() && args.from >= 0.0) {
        bail!("--from: {} s is not a flume time", args.from);
    }
    let flume = Case::from_path_with(&args.flume, &args.set)
        .context("cannot load the flume case (run from the repository root or pass --flume)")?;
    let backends = backends()?;
    for b in &backends {
        println!("backend: {}", b.describe());
    }
    println!(
        "each figure times whole steps for about {} s of wall time, after a warm-up",
        args.steps_seconds
    );
    let tallies = [
        time_ladder(args, &reference, &backends),
        time_reference(args, &reference, &backends),
        time_flume(args, &flume, &backends),
    ];
    let (failed, timed) = tallies
        .iter()
        .fold((0, 0), |(f, t), (df, dt)| (f + df, t + dt));
    if failed > 0 {
        bail!("{failed} of {timed} measurements failed (see above)");
    }
    Ok(())
}

/// Failed and attempted measurements of one section of the benchmark.
type Tally = (usize, usize);

/// The synthetic dam breaks of `--ladder` on each backend, as one table.
fn time_ladder(args: &BenchArgs, reference: &Case, backends: &[Backend]) -> Tally {
    println!();
    println!(
        "synthetic 2-D dam breaks: a water column filling 1/4 of the tank, dp = {BENCH_DP_M} m, \
         the numerics of {}",
        reference.name
    );
    let mut table = throughput_table();
    let mut errors = Vec::new();
    for &n in &args.ladder {
        for b in backends {
            let result = dam_break_case(n).and_then(|case| measure(b, &case, args.steps_seconds));
            match result {
                Ok(m) => throughput_row(&mut table, &m),
                Err(e) => {
                    table.row([format!("~{n}"), "failed".to_string()]);
                    errors.push(format!("~{n} particles: {e:#}"));
                }
            }
        }
    }
    print!("{table}");
    for e in &errors {
        println!("error: {e}");
    }
    (errors.len(), args.ladder.len() * backends.len())
}

/// The DualSPHysics case on each backend, against DualSPHysics' own figure.
fn time_reference(args: &BenchArgs, reference: &Case, backends: &[Backend]) -> Tally {
    println!();
    println!("case {} ({})", reference.name, args.case.display());
    let mut measured = Vec::new();
    for b in backends {
        match measure(b, reference, args.steps_seconds) {
            Ok(m) => measured.push(m),
            Err(e) => println!("error: {e:#}"),
        }
    }
    print_reference(&measured, reference);
    (backends.len() - measured.len(), backends.len())
}

/// The open flume from `--from` on each backend, the CPU backend also in full.
fn time_flume(args: &BenchArgs, flume: &Case, backends: &[Backend]) -> Tally {
    println!();
    let start = if args.from > 0.0 {
        format!("from t = {} s", args.from)
    } else {
        "from the dry start".to_string()
    };
    println!(
        "open flume {} ({}), dp = {} m, {start} with the inlet running;\n\
         particle-steps count the particles in the flow (not the parked ones); the CPU \
         backend also without its awake set",
        flume.name,
        args.flume.display(),
        flume.numerics.dp_m
    );
    let all = with_full_cpu(backends);
    let mut failed = 0;
    for b in &all {
        match measure_from(b, flume, args.from, args.steps_seconds) {
            Ok(m) => {
                let mut table = throughput_table();
                throughput_row(&mut table, &m);
                print!("{table}");
                println!(
                    "real-time factor: {} simulated s per wall s (t = {:.4} .. {:.4} s)",
                    sig(m.sim_s / m.wall_s),
                    m.start_s,
                    m.start_s + m.sim_s
                );
                print_stages(&m);
            }
            Err(e) => {
                failed += 1;
                println!("error: {e:#}");
            }
        }
    }
    (failed, all.len())
}

/// The backends to time: the CPU backend, and the wgpu adapter when there is one, unless
/// `FLUME_TWIN_ADAPTER` names one of them.
fn backends() -> Result<Vec<Backend>> {
    let wanted = std::env::var(flume_solver::ADAPTER_ENV).unwrap_or_default();
    if wanted.eq_ignore_ascii_case(flume_solver::CPU_BACKEND) {
        return Ok(vec![Backend::cpu(0)]);
    }
    if !wanted.is_empty() {
        let gpu = GpuContext::new().context("cannot open the adapter FLUME_TWIN_ADAPTER names")?;
        return Ok(vec![Backend::from(Arc::new(gpu))]);
    }
    let mut out = vec![Backend::cpu(0)];
    match GpuContext::new() {
        Ok(gpu) => out.push(Backend::from(Arc::new(gpu))),
        Err(e) => println!("no wgpu adapter: {e}"),
    }
    Ok(out)
}

fn print_reference(measured: &[Measurement], case: &Case) {
    let mut table = throughput_table();
    for m in measured {
        throughput_row(&mut table, m);
    }
    print!("{table}");
    println!("against DualSPHysics 5.4 on the CPU (2 OpenMP threads), same case:");
    for m in measured {
        let rate = m.particle_steps_per_s();
        println!(
            "  {}: Verlet ({}) ratio {:.3}, symplectic ({}) ratio {:.3}",
            m.backend,
            sci(DSPH_VERLET),
            rate / DSPH_VERLET,
            sci(DSPH_SYMPLECTIC),
            rate / DSPH_SYMPLECTIC
        );
    }
    println!(
        "  This run used the {:?} integrator: compare with the ratio of the same scheme (a\n  \
         Verlet step takes one force pass, a symplectic step two).",
        case.numerics.integrator
    );
    for m in measured {
        println!(
            "real-time factor on {}: {} simulated s per wall s (t = {:.4} .. {:.4} s of the {} s case)",
            m.backend,
            sig(m.sim_s / m.wall_s),
            m.start_s,
            m.start_s + m.sim_s,
            case.time.end_s
        );
        print_stages(m);
    }
}

/// Where the timed stretch's wall time went, stage by stage.
fn print_stages(m: &Measurement) {
    if m.stages.is_empty() {
        return;
    }
    let parts: Vec<String> = m
        .stages
        .iter()
        .map(|s| {
            let share = |seconds: f64| 100.0 * seconds / m.wall_s;
            if s.walk_seconds > 0.0 {
                format!(
                    "{} {:.1} % (walk {:.1} %)",
                    s.stage,
                    share(s.seconds),
                    share(s.walk_seconds)
                )
            } else {
                format!("{} {:.1} %", s.stage, share(s.seconds))
            }
        })
        .collect();
    println!("  stages on {}: {}", m.backend, parts.join(", "));
    let awake: Vec<String> = m
        .stages
        .iter()
        .filter(|s| s.particles > 0)
        .map(|s| {
            let share = 1.0 - s.asleep as f64 / s.particles as f64;
            format!("{} {:.1} %", s.stage, 100.0 * share)
        })
        .collect();
    if !awake.is_empty() {
        println!(
            "  awake (particles that walked their neighbours): {}",
            awake.join(", ")
        );
    }
    if let Some(share) = m.lanes {
        println!(
            "  lanes: {:.1} % of the force pass's lane-pairs add to a sum read",
            100.0 * share
        );
    }
}

fn throughput_table() -> Table {
    Table::new([
        "particles",
        "fluid",
        "steps",
        "wall s",
        "steps/s",
        "particle-steps/s",
        "backend",
    ])
}

/// One row of a throughput table.
fn throughput_row(table: &mut Table, m: &Measurement) {
    table.row([
        m.particles.to_string(),
        m.fluid.to_string(),
        m.steps.to_string(),
        format!("{:.2}", m.wall_s),
        sig(m.steps_per_s()),
        sci(m.particle_steps_per_s()),
        m.backend.clone(),
    ]);
}

/// A 2-D dam break with about `fluid` fluid particles: a column a wide and 2a high against the
/// left wall of a tank 3.2a long and 2.5a high (the column fills 1/4 of it), one wall layer, and
/// the numerics of DualSPHysics' CaseDambreakVal2D.
pub fn dam_break_case(fluid: u64) -> Result<Case> {
    // The block fills lattice points (0, a] x (0, 2a]: m columns of 2m points.
    let m = ((fluid as f64 / 2.0).sqrt().round() as u64).max(4);
    let dp = BENCH_DP_M;
    let a = m as f64 * dp;
    let length = (3.2 * m as f64).ceil() * dp;
    let height = (2.5 * m as f64).ceil() * dp;
    let column = 2.0 * a;
    let yaml = format!(
        "name: bench_{fluid}
dimension: 2
domain: {{ min_m: [0.0, 0.0], max_m: [{length}, {height}] }}
walls: {{ layers: 1 }}
phases:
  - {{ name: water, rho0_kg_per_m3: 1000.0, viscosity_pa_s: 1.0e-3 }}
fluid_blocks:
  - {{ phase: water, min_m: [0.0, 0.0], max_m: [{a}, {column}] }}
numerics:
  dp_m: {dp}
  coefh: 1.0
  cfl: 0.2
  sound_speed: {{ coefsound: 20.0 }}
  density_diffusion: {{ method: fourtakas2019, delta: 0.1 }}
  viscosity: {{ method: artificial, alpha: 0.02 }}
  integrator: {{ method: verlet, euler_every_steps: 40 }}
gravity_m_per_s2: [0.0, -9.81]
time: {{ end_s: 10.0, output_interval_s: 0.01 }}
"
    );
    Case::from_yaml(&yaml, "bench")
        .with_context(|| format!("the synthetic case for {fluid} particles is invalid"))
}

/// `backends` with, after each CPU backend, the same computing every particle in full (the
/// awake set's reference).
fn with_full_cpu(backends: &[Backend]) -> Vec<Backend> {
    let mut out = Vec::new();
    for b in backends {
        out.push(b.clone());
        if let Backend::Cpu { threads, .. } = *b {
            out.push(Backend::Cpu {
                threads,
                awake_set: false,
            });
        }
    }
    out
}

/// Times `case` on `backend` for about `wall_target_s` after a warm-up.
fn measure(backend: &Backend, case: &Case, wall_target_s: f64) -> Result<Measurement> {
    measure_from(backend, case, 0.0, wall_target_s)
}

/// [`measure`] from flume time `from_s`.
fn measure_from(
    backend: &Backend,
    case: &Case,
    from_s: f64,
    wall_target_s: f64,
) -> Result<Measurement> {
    let name = &case.name;
    let mut sim =
        Simulation::new(backend.clone(), case).with_context(|| format!("cannot set up {name}"))?;
    sim.advance_to(from_s)
        .with_context(|| format!("{name}: failed before t = {from_s} s"))?;
    // The real step is never larger, so the warm-up is at least 4 steps.
    let dt_guess = sim.acoustic_dt_bound_s();
    sim.advance_to(from_s + 4.0 * dt_guess)
        .with_context(|| format!("{name}: warm-up failed"))?;

    let min_stretch_s = |sim: &Simulation| MIN_STRETCH_STEPS * sim.last_dt_s().max(dt_guess);

    // Estimate wall s per simulated s from ever longer stretches until one is long enough
    // to trust (a tenth of the target, or half a second on a slow adapter).
    let mut stretch_s = min_stretch_s(&sim);
    let wall_per_sim = loop {
        let t0 = sim.time_s();
        let started = Instant::now();
        sim.advance_to(t0 + stretch_s)
            .with_context(|| format!("{name}: warm-up failed"))?;
        let wall = started.elapsed().as_secs_f64();
        if wall >= (0.1 * wall_target_s).min(0.5) {
            break wall / stretch_s;
        }
        stretch_s *= 4.0;
    };

    // Advance in quarters of the estimate until the target wall time has passed: the step
    // shrinks as the column collapses, so one stretch of the estimate could overshoot.
    let start_s = sim.time_s();
    let steps0 = sim.steps();
    let stages0 = sim.stage_times();
    let started = Instant::now();
    while started.elapsed().as_secs_f64() < wall_target_s {
        let piece_s = (0.25 * wall_target_s / wall_per_sim).max(2.0 * min_stretch_s(&sim));
        let target = sim.time_s() + piece_s;
        sim.advance_to(target)
            .with_context(|| format!("{name}: failed at t = {:.4} s", sim.time_s()))?;
    }
    let wall_s = started.elapsed().as_secs_f64();
    // Parked particles of an open flume wait out of the flow and cost almost nothing.
    let parked = sim.flume().map_or(0, |f| f.parked_particles as usize);
    let stages = sim
        .stage_times()
        .into_iter()
        .zip(stages0)
        .map(|(now, before)| StageTime {
            stage: now.stage,
            seconds: now.seconds - before.seconds,
            walk_seconds: now.walk_seconds - before.walk_seconds,
            particles: now.particles - before.particles,
            asleep: now.asleep - before.asleep,
            lane_pairs: 0,
            useful_pairs: 0,
        })
        .collect();
    let lanes = count_lanes(&mut sim, 0.1 * wall_target_s)?;
    Ok(Measurement {
        particles: sim.particle_count() - parked,
        fluid: sim.fluid_count() - parked,
        steps: sim.steps() - steps0,
        wall_s,
        sim_s: sim.time_s() - start_s,
        start_s,
        backend: sim.backend_name(),
        stages,
        lanes,
    })
}

/// After the timed stretch, the share of the force pass's evaluated lane-pairs that added to a
/// sum read, over about `wall_s` more; None where the backend has no lanes.
fn count_lanes(sim: &mut Simulation, wall_s: f64) -> Result<Option<f64>> {
    let pick = |sim: &Simulation| {
        let stages = sim.stage_times();
        let forces = stages.into_iter().find(|s| s.stage == "forces")?;
        Some((forces.lane_pairs, forces.useful_pairs))
    };
    let Some(before) = pick(sim) else {
        return Ok(None);
    };
    sim.count_lanes(true);
    let started = Instant::now();
    while started.elapsed().as_secs_f64() < wall_s {
        let t = sim.time_s() + 8.0 * sim.last_dt_s();
        sim.advance_to(t).context("counting the lanes")?;
    }
    sim.count_lanes(false);
    let after = pick(sim).unwrap_or(before);
    let evaluated = (after.0 - before.0) as f64;
    Ok((evaluated > 0.0).then(|| (after.1 - before.1) as f64 / evaluated))
}

/// The runs `bench --levels` asks for, one per `--dp`: the sand bed's pit full unless
/// `--empty-pit`.
fn level_runs(args: &BenchArgs) -> Vec<super::bench_levels::LevelRun> {
    (args.dp.iter())
        .map(|&dp_m| super::bench_levels::LevelRun {
            dp_m,
            m3_per_h: args.m3_per_h,
            until_s: args.until,
            fixed_bed: args.fixed_bed,
            filled_pit: !args.empty_pit,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
    use clap::Parser;
    use flume_solver::{derive, generate};
    use std::path::Path;

    /// The pit each run starts with, as the command line parses.
    fn pits(extra: &[&str]) -> Vec<(bool, bool)> {
        let mut argv = vec!["flume-twin", "bench", "--levels", "--dp", "0.01,0.005"];
        argv.extend_from_slice(extra);
        match Cli::parse_from(argv).command {
            Command::Bench(a) => (level_runs(&a).iter())
                .map(|r| (r.filled_pit, r.fixed_bed))
                .collect(),
            _ => unreachable!("parsed a bench"),
        }
    }

    /// The benchmark's start is a full pit at every dp; `--empty-pit` is the case's start.
    #[test]
    fn level_runs_start_with_a_full_pit_unless_asked_empty() {
        assert_eq!(pits(&[]), [(true, false), (true, false)]);
        assert_eq!(pits(&["--empty-pit"]), [(false, false), (false, false)]);
        assert_eq!(pits(&["--fixed-bed"]), [(true, true), (true, true)]);
    }

    /// Fluid particles a case holds, counted on the CPU.
    fn fluid_of(case: &Case) -> usize {
        let particles = generate(case, &derive(case));
        (0..particles.len())
            .filter(|&i| !particles.is_wall(i))
            .count()
    }

    #[test]
    fn synthetic_cases_hold_about_the_asked_fluid_count() {
        for n in [4000u64, 16000, 64000] {
            let case = dam_break_case(n).unwrap();
            let fluid = fluid_of(&case) as f64;
            assert!(
                (fluid / n as f64 - 1.0).abs() < 0.02,
                "{n} asked, {fluid} made"
            );
        }
    }

    #[test]
    fn reference_case_file_parses() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../launch_configs/dsph_dambreak_val2d.yaml");
        let case = Case::from_path(&path).unwrap();
        assert_eq!(case.dimension, 2);
    }
}
