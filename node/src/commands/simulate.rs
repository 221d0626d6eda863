//! `flume-twin simulate`: an offline run of a case, interval by interval.

use crate::adapters::files::inflow::InflowSeries;
use crate::adapters::files::{
    bed_plot, budget_plot, outputs::OutputFiles, series_plot::SeriesPlots,
};
use crate::adapters::progress;
use crate::adapters::table::{Table, sci, sig};
use crate::cli::SimulateArgs;
use anyhow::{Context, Result, bail};
use flume_solver::{
    Backend, BoundaryConditions, Case, InflowSchedule, Observations, ProfileColumn, Simulation,
    SolverError,
};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Whether an output at `t_s`, the one after `before_s`, is the first at or past a quarter of
/// a run to `end_s`: the bed plot's panels, as the paper's Figs. 13-16 show the Louvain bed at
/// 0.25, 0.5, 0.75 and 1 s. 1e-9 keeps an output on a quarter from missing it by round-off.
fn passes_a_quarter(before_s: f64, t_s: f64, end_s: f64) -> bool {
    let quarter = |t: f64| (4.0 * t / end_s + 1e-9).floor();
    quarter(t_s) > quarter(before_s)
}

pub fn run(args: &SimulateArgs) -> Result<()> {
    // The case is checked before the GPU is opened, so a bad file fails fast and on any machine.
    let case = Case::from_path_with(&args.case, &args.set).context("the case file was refused")?;
    flume_solver::check_inflow(&case).context("the case file was refused")?;
    let (end_s, inflow) = end_and_inflow(args, &case)?;
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&case.name));
    let snapshot_every = (!args.no_snapshots).then_some(args.snapshot_every);

    let backend = Backend::choose().context("cannot open a backend")?;
    let mut sim = Simulation::new(backend, &case).context("cannot set up the simulation")?;
    println!("adapter: {}", sim.backend_name());
    print_case(&args.case, &case, &sim);
    if let Some(series) = &inflow {
        set_inflow(&mut sim, series, 0.0)?;
    }

    let mut recorder =
        OutputFiles::create(&out_dir, &case, sim.initial_particles(), snapshot_every)?;
    let interval_s = case.time.output_interval_s;
    // The last interval is shortened to land on end_s; 1e-9 keeps round-off from adding one.
    let intervals = ((end_s / interval_s) - 1e-9).ceil().max(1.0) as u64;
    println!(
        "run: to t = {end_s} s, output every {interval_s} s ({intervals} intervals) -> {} ({})",
        out_dir.display(),
        match snapshot_every {
            None => "no snapshots".to_string(),
            Some(1) => "a snapshot every interval".to_string(),
            Some(n) => format!("a snapshot every {n} intervals"),
        }
    );

    let bar = progress::bar(end_s);
    bar.set_message(format!("t = 0/{end_s} s"));
    let started = Instant::now();
    let mut last = recorder.record(&sim, 0)?;
    let mut plots = SeriesPlots::predicted_only();
    plots.observe(&last);
    let initial_profile = last.profile.clone();
    let mut bed_profiles = Vec::new();
    for k in 1..=intervals {
        let target_s = (k as f64 * interval_s).min(end_s);
        if let Err(err) = advance(&mut sim, inflow.as_ref(), target_s) {
            bar.abandon();
            save_failed_state(&err, &recorder, &sim);
            return Err(err.context(format!(
                "the simulation stopped; outputs up to t = {} s are in {}",
                last.time_s,
                out_dir.display()
            )));
        }
        let before_s = last.time_s;
        last = recorder.record(&sim, k)?;
        plots.observe(&last);
        if passes_a_quarter(before_s, last.time_s, end_s) {
            bed_profiles.push((last.time_s, last.profile.clone()));
        }
        let wall = started.elapsed().as_secs_f64();
        progress::set_time(&bar, sim.time_s());
        bar.set_message(format!(
            "t = {:.4}/{end_s} s, {:.0} steps/s",
            sim.time_s(),
            sim.steps() as f64 / wall
        ));
    }
    bar.finish_and_clear();
    let wall_s = started.elapsed().as_secs_f64();
    if recorder.has_bed_profile() {
        draw_bed(&out_dir, &case.name, &initial_profile, &bed_profiles)?;
    }
    draw_series(&out_dir, &case.name, &plots, &recorder)?;
    print_summary(&sim, &last, wall_s);
    Ok(())
}

/// The bed plot, a panel per quarter of the run, where any profile column held sediment.
fn draw_bed(
    out_dir: &Path,
    name: &str,
    initial: &[ProfileColumn],
    quarters: &[(f64, Vec<ProfileColumn>)],
) -> Result<()> {
    if !bed_plot::holds_sediment(quarters) {
        println!("bed plot: none, no profile column held sediment");
        return Ok(());
    }
    let path = out_dir.join("bed.png");
    bed_plot::draw(&path, name, initial, quarters)?;
    println!("bed plot: {}", path.display());
    Ok(())
}

/// The run's end (`--until`, or the case's) and the inflow series `--inflow` reads, refused
/// for a case with no open flume.
fn end_and_inflow(args: &SimulateArgs, case: &Case) -> Result<(f64, Option<InflowSeries>)> {
    let end_s = match args.until {
        Some(t) if !(t.is_finite() && t > 0.0) => {
            bail!("--until must be a positive time in s, got {t}")
        }
        Some(t) => t,
        None => case.time.end_s,
    };
    let inflow = match &args.inflow {
        None => None,
        Some(path) if case.open_flume.is_none() => bail!(
            "--inflow {}: the case {} has no open_flume to feed",
            path.display(),
            case.name
        ),
        Some(path) => Some(InflowSeries::from_path(path)?),
    };
    Ok((end_s, inflow))
}

/// With a blow-up, writes the broken state, which shows where it went wrong (losing it would
/// waste the run); its `culprit` field marks the particles the error names.
fn save_failed_state(err: &anyhow::Error, recorder: &OutputFiles, sim: &Simulation) {
    if let Some(SolverError::BlowUp { culprits, .. }) = err.downcast_ref::<SolverError>() {
        let ids: Vec<u32> = culprits.iter().map(|c| c.id).collect();
        if let Err(e) = recorder.snapshot_marked(sim, "particles_failed.vtk", &ids) {
            log::warn!("could not write the failed state: {e:#}");
        }
    }
}

/// Draws the gauges' and the eroded mass's series, and the sediment budget where it has more
/// than one row.
fn draw_series(
    out_dir: &Path,
    case_name: &str,
    plots: &SeriesPlots,
    recorder: &OutputFiles,
) -> Result<()> {
    for path in plots.draw(out_dir, case_name)? {
        println!("plot: {}", path.display());
    }
    if recorder.budget_rows().len() > 1 {
        let path = out_dir.join("sediment_budget.png");
        budget_plot::draw(&path, case_name, recorder.budget_rows())?;
        println!("plot: {}", path.display());
    }
    Ok(())
}

/// Advances to `target_s`, each change of the inflow series on the way applied at its own
/// time; a discharge the inlet refuses ends the run.
fn advance(
    sim: &mut Simulation,
    inflow: Option<&InflowSeries>,
    target_s: f64,
) -> Result<(), anyhow::Error> {
    let Some(series) = inflow else {
        sim.advance_to(target_s)?;
        return Ok(());
    };
    let mut changes: Vec<(f64, f64)> = series
        .changes_between(sim.time_s(), target_s)
        .into_iter()
        .map(|t| (t, series.discharge_at(t)))
        .collect();
    changes.push((target_s, series.discharge_at(target_s)));
    let refused = sim.advance_through(target_s, &InflowSchedule::new(changes))?;
    match refused.into_iter().next() {
        Some(r) => Err(anyhow::Error::new(r.error).context(format!(
            "the inflow series' discharge {} m3/s at t = {} s",
            r.inflow_m3_per_s, r.time_s
        ))),
        None => Ok(()),
    }
}

fn set_inflow(sim: &mut Simulation, series: &InflowSeries, t_s: f64) -> Result<()> {
    let q = series.discharge_at(t_s);
    sim.set_boundary_conditions(BoundaryConditions { inflow_m3_per_s: q })
        .with_context(|| format!("the inflow series' discharge {q} m3/s at t = {t_s} s"))
}

fn print_case(path: &Path, case: &Case, sim: &Simulation) {
    let derived = sim.derived();
    println!(
        "case: {} ({}-D) from {}",
        case.name,
        case.dimension,
        path.display()
    );
    println!(
        "particles: {} ({} fluid, {} wall)",
        sim.particle_count(),
        sim.fluid_count(),
        sim.particle_count() - sim.fluid_count()
    );
    println!(
        "h = {:.6} m, c0 = {:.3} m/s, dp = {} m",
        derived.h, derived.c0, case.numerics.dp_m
    );
}

fn print_summary(sim: &Simulation, last: &Observations, wall_s: f64) {
    let steps = sim.steps() as f64;
    let particles = sim.particle_count() as f64;
    let mut t = Table::new(["quantity", "value"]);
    t.row([
        "simulated time".to_string(),
        format!("{:.6} s", sim.time_s()),
    ]);
    t.row([
        "wall time (with output)".to_string(),
        format!("{wall_s:.3} s"),
    ]);
    t.row(["steps".to_string(), sim.steps().to_string()]);
    t.row([
        "particle-steps/s".to_string(),
        sci(particles * steps / wall_s),
    ]);
    t.row(["steps/s".to_string(), sig(steps / wall_s)]);
    t.row([
        "real-time factor".to_string(),
        format!("{} (sim s per wall s)", sig(sim.time_s() / wall_s)),
    ]);
    for g in &last.gauges {
        let level = g.level_m.map_or("dry".to_string(), |v| format!("{v:.4} m"));
        t.row([format!("gauge {}", g.name), level]);
    }
    for p in &last.probes {
        let pressure = p
            .pressure_pa
            .map_or("dry".to_string(), |v| format!("{v:.1} Pa"));
        t.row([format!("probe {}", p.name), pressure]);
    }
    t.row([
        "front".to_string(),
        last.front_m
            .map_or_else(|| "no fluid".to_string(), |x| format!("{x:.4} m")),
    ]);
    t.row([
        "max density error".to_string(),
        format!("{:.3e}", last.max_density_error),
    ]);
    if let Some(f) = &last.flume {
        t.row([
            "particles excluded".to_string(),
            format!(
                "{} ({} sand; density out of range, recycled)",
                f.excluded_particles, f.excluded_sediment
            ),
        ]);
        t.row([
            "inlet spots blocked".to_string(),
            format!(
                "{} of {} ({:.2} % of the inflow not placed)",
                f.blocked_particles,
                f.blocked_particles + f.injected_particles,
                100.0 * f.blocked_share()
            ),
        ]);
        if f.soaked_particles > 0 {
            let share = if f.injected_particles > 0 {
                format!(
                    " ({:.1} % of those the inlet placed)",
                    100.0 * f.soaked_particles as f64 / f.injected_particles as f64
                )
            } else {
                String::new()
            };
            t.row([
                "water in the bed's pores".to_string(),
                format!("{} particles{share}", f.soaked_particles),
            ]);
        }
    }
    t.row([
        "blow-ups recovered".to_string(),
        format!("{} (CFL now {:.3})", last.recoveries, last.cfl),
    ]);
    println!();
    print!("{t}");
}

#[cfg(test)]
mod tests {
    use super::passes_a_quarter;

    /// The panels a run with outputs every `interval_s` to `end_s` gets.
    fn panels(interval_s: f64, end_s: f64) -> Vec<f64> {
        let n = ((end_s / interval_s) - 1e-9).ceil() as u64;
        let times: Vec<f64> = (0..=n)
            .map(|k| (k as f64 * interval_s).min(end_s))
            .collect();
        times
            .windows(2)
            .filter(|w| passes_a_quarter(w[0], w[1], end_s))
            .map(|w| w[1])
            .collect()
    }

    #[test]
    fn the_bed_plot_shows_the_first_output_at_each_quarter() {
        // Louvain: 0.05 s outputs to 1 s land on the quarters, however 0.05 k rounds.
        let louvain = panels(0.05, 1.0);
        assert_eq!(louvain.len(), 4, "{louvain:?}");
        for (t, q) in louvain.iter().zip([0.25, 0.5, 0.75, 1.0]) {
            assert!((t - q).abs() < 1e-12, "{louvain:?}");
        }
        // Outputs coarser than a quarter: one panel each, never two for one output.
        assert_eq!(panels(0.5, 1.0), vec![0.5, 1.0]);
        // Outputs between the quarters: the first past each, one panel for an output past two
        // (0.8 s passes 0.5 and 0.75), and the shortened last one.
        assert_eq!(panels(0.4, 1.0), vec![0.4, 0.8, 1.0]);
        assert_eq!(panels(0.05, 0.05), vec![0.05]);
    }
}
