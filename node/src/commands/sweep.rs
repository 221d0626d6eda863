//! `flume-twin sweep`: one case run once per value of one field, each to the same time, and
//! the eroded sediment mass each run ends with (the paper's Figure 10: eroded mass against
//! ks/d50 in the ULBRA flume), with each run's files as `simulate` writes them.

use crate::adapters::files::outputs::OutputFiles;
use crate::adapters::files::{budget_plot, csv::field, sweep_plot};
use crate::adapters::progress;
use crate::adapters::table::{Table, sig};
use crate::cli::SweepArgs;
use anyhow::{Context, Result, bail};
use flume_solver::FlumeObservation;
use flume_solver::budget::BudgetRow;
use flume_solver::{Backend, Case, Simulation};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

const USAGE: &str = "expected KEY=V1,V2,..., e.g. phases.1.sediment.ks_over_d50=1,2,3";

/// The field a sweep varies and its values, as given (a value is YAML, as for --set).
#[derive(Debug, PartialEq)]
struct Ladder {
    key: String,
    values: Vec<String>,
}

impl Ladder {
    fn parse(spec: &str) -> Result<Ladder> {
        let Some((key, list)) = spec.split_once('=') else {
            bail!("--set-values {spec:?} has no '=': {USAGE}");
        };
        let key = key.trim();
        if key.is_empty() {
            bail!("--set-values {spec:?} names no field: {USAGE}");
        }
        if list.trim().is_empty() {
            bail!("--set-values {spec:?} lists no values: {USAGE}");
        }
        let values: Vec<String> = list.split(',').map(|v| v.trim().to_string()).collect();
        if values.iter().any(String::is_empty) {
            bail!("--set-values {spec:?} has an empty value in its list: {USAGE}");
        }
        // Rows are told apart by their value alone.
        for (k, v) in values.iter().enumerate() {
            if values[..k].contains(v) {
                bail!("--set-values {spec:?} lists {v} twice");
            }
        }
        Ok(Ladder {
            key: key.to_string(),
            values,
        })
    }
}

/// What one run of the ladder ended with.
struct Row {
    value: String,
    /// The last output time the run completed, s.
    time_s: f64,
    /// Wall time of the run, its set-up included, s.
    wall_s: f64,
    steps: u64,
    recoveries: u32,
    /// The flume's figures at the end, or why the run failed.
    outcome: Result<FlumeObservation, String>,
    /// The sediment budget at the last output the run wrote (none without a sediment).
    budget: Option<BudgetRow>,
}

impl Row {
    fn status(&self) -> &str {
        self.outcome.as_ref().err().map_or("ok", String::as_str)
    }
}

pub fn run(args: &SweepArgs) -> Result<()> {
    let ladder = Ladder::parse(&args.set_values)?;
    // Every case is checked before a backend is opened: a bad value fails at once, on any
    // machine, and not hours into the sweep.
    let cases = build_cases(args, &ladder)?;
    let ends: Vec<f64> = cases
        .iter()
        .map(|c| args.until.unwrap_or(c.time.end_s))
        .collect();
    let name = cases[0].name.clone();
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{name}_sweep")));

    // The backend `simulate` chooses (`FLUME_TWIN_ADAPTER`, else a hardware GPU, else the CPU),
    // so a sweep's runs are the runs `simulate` gives, at its speed.
    let backend = Backend::choose().context("cannot open a backend")?;
    println!("adapter: {}", backend.describe());
    std::fs::create_dir_all(&out_dir)
        .with_context(|| format!("cannot create {}", out_dir.display()))?;
    println!(
        "sweep: {} at {} runs of {} from {}, to {} -> {}",
        ladder.key,
        ladder.values.len(),
        name,
        args.case.display(),
        time_label(&ends),
        out_dir.display()
    );
    let rows = run_ladder(&backend, &ladder, &cases, &ends, &out_dir)?;
    print_table(&ladder.key, &rows);
    let chart = out_dir.join("sweep.png");
    let bars: Vec<(String, Option<f64>)> = rows
        .iter()
        .map(|r| {
            (
                r.value.clone(),
                r.outcome.as_ref().ok().map(|f| f.eroded_kg_per_m),
            )
        })
        .collect();
    let title = format!("{name}: eroded mass at {}", time_label(&ends));
    sweep_plot::draw(&chart, &title, &ladder.key, &bars)?;
    println!("table: {}", out_dir.join("sweep.csv").display());
    println!("chart: {}", chart.display());
    let failed: Vec<&str> = rows
        .iter()
        .filter(|r| r.outcome.is_err())
        .map(|r| r.value.as_str())
        .collect();
    if !failed.is_empty() {
        bail!(
            "{} of {} runs failed ({}={}); the others' results are in {}",
            failed.len(),
            rows.len(),
            ladder.key,
            failed.join(","),
            out_dir.display()
        );
    }
    Ok(())
}

/// The case at each value of the ladder, with the --set overrides under it.
fn build_cases(args: &SweepArgs, ladder: &Ladder) -> Result<Vec<Case>> {
    if let Some(o) = args.set.iter().find(|o| {
        o.split_once('=')
            .is_some_and(|(k, _)| k.trim() == ladder.key)
    }) {
        bail!(
            "--set {o} and --set-values both set {}: give its values in --set-values only",
            ladder.key
        );
    }
    ladder
        .values
        .iter()
        .map(|value| {
            let mut overrides = args.set.clone();
            overrides.push(format!("{}={value}", ladder.key));
            let case = Case::from_path_with(&args.case, &overrides)
                .with_context(|| format!("--set-values: {}={value} was refused", ladder.key))?;
            if case.open_flume.is_none() {
                bail!(
                    "sweep needs an open flume: it reports the eroded mass ({} with {}={value} has \
                     no open_flume)",
                    args.case.display(),
                    ladder.key
                );
            }
            Ok(case)
        })
        .collect()
}

/// Runs every case in turn; a run that fails is a row with its error, and the next one runs.
fn run_ladder(
    backend: &Backend,
    ladder: &Ladder,
    cases: &[Case],
    ends: &[f64],
    out_dir: &Path,
) -> Result<Vec<Row>> {
    let csv = out_dir.join("sweep.csv");
    let mut rows = Vec::new();
    for (k, ((value, case), &end_s)) in ladder.values.iter().zip(cases).zip(ends).enumerate() {
        let label = format!("{}={value}", ladder.key);
        let run_dir = out_dir.join(run_dir_name(k, value));
        let row = run_one(backend, case, end_s, value, &label, &run_dir);
        let outcome = match &row.outcome {
            Ok(f) => format!("eroded {} kg/m", sig(f.eroded_kg_per_m)),
            Err(e) => format!("FAILED: {e}"),
        };
        println!(
            "run {}/{} {label}: t = {} s, {:.1} s wall, {outcome}",
            k + 1,
            cases.len(),
            sig(row.time_s),
            row.wall_s
        );
        rows.push(row);
        // Rewritten after every run, so a sweep stopped part-way keeps the runs it finished.
        write_csv(&csv, &ladder.key, &rows)?;
    }
    Ok(rows)
}

/// A run's folder: its place in the ladder and its value, with any character a file name
/// should not hold as '_' (a value is YAML, and may be a list or a map).
fn run_dir_name(k: usize, value: &str) -> String {
    let safe: String = value
        .chars()
        .take(40)
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{:02}_{safe}", k + 1)
}

fn run_one(
    backend: &Backend,
    case: &Case,
    end_s: f64,
    value: &str,
    label: &str,
    run_dir: &Path,
) -> Row {
    let started = Instant::now();
    let mut row = Row {
        value: value.to_string(),
        time_s: 0.0,
        wall_s: 0.0,
        steps: 0,
        recoveries: 0,
        outcome: Err(String::new()),
        budget: None,
    };
    row.outcome =
        run_case(backend, case, end_s, label, run_dir, &mut row).map_err(|e| format!("{e:#}"));
    row.wall_s = started.elapsed().as_secs_f64();
    row
}

/// Runs `case` to `end_s` interval by interval, writing its files to `run_dir` as `simulate`
/// does (no snapshots) and keeping in `row` how far it got and its sediment budget, and reads
/// the flume's figures at the end.
fn run_case(
    backend: &Backend,
    case: &Case,
    end_s: f64,
    label: &str,
    run_dir: &Path,
    row: &mut Row,
) -> Result<FlumeObservation> {
    let mut sim = Simulation::new(backend.clone(), case).context("cannot set up the simulation")?;
    let mut files = OutputFiles::create(run_dir, case, sim.initial_particles(), None)?;
    let mut last = files.record(&sim, 0)?;
    let interval_s = case.time.output_interval_s;
    // The last interval is shortened to land on end_s; 1e-9 keeps round-off from adding one.
    let intervals = ((end_s / interval_s) - 1e-9).ceil().max(1.0) as u64;
    let bar = progress::bar(end_s);
    let started = Instant::now();
    for k in 1..=intervals {
        let target_s = (k as f64 * interval_s).min(end_s);
        let advanced = sim.advance_to(target_s);
        row.steps = sim.steps();
        row.recoveries = sim.recoveries().len() as u32;
        if let Err(e) = advanced {
            bar.finish_and_clear();
            return Err(e.into());
        }
        last = files.record(&sim, k)?;
        row.budget = files.budget_rows().last().cloned();
        row.time_s = target_s;
        progress::set_time(&bar, target_s);
        bar.set_message(format!(
            "{label}: t = {target_s:.4}/{end_s} s, {:.0} s wall",
            started.elapsed().as_secs_f64()
        ));
    }
    bar.finish_and_clear();
    if files.budget_rows().len() > 1 {
        budget_plot::draw(
            &run_dir.join("sediment_budget.png"),
            label,
            files.budget_rows(),
        )?;
    }
    row.recoveries = last.recoveries;
    last.flume.context("the open flume reported no eroded mass")
}

/// "t = 18 s", or the range when the runs stop at different times (a sweep of time.end_s).
fn time_label(ends: &[f64]) -> String {
    let lo = ends.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ends.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lo == hi {
        format!("t = {lo} s")
    } else {
        format!("t = {lo} to {hi} s")
    }
}

/// The varied value, the flume's figures (blank for a failed run), the sediment budget at the
/// last output (blank without one) and how the run went.
fn cells(r: &Row, number: impl Fn(f64) -> String) -> [String; 12] {
    let (kg_per_m, kg, particles) = match &r.outcome {
        Ok(f) => (
            number(f.eroded_kg_per_m),
            number(f.eroded_kg),
            f.eroded_particles.to_string(),
        ),
        Err(_) => Default::default(),
    };
    let (mobilised, far, furthest) = match &r.budget {
        Some(b) => (
            b.mobilised.to_string(),
            b.travelled_far.to_string(),
            number(b.furthest_m),
        ),
        None => Default::default(),
    };
    [
        r.value.clone(),
        kg_per_m,
        kg,
        particles,
        mobilised,
        far,
        furthest,
        number(r.time_s),
        format!("{:.3}", r.wall_s),
        r.steps.to_string(),
        r.recoveries.to_string(),
        r.status().to_string(),
    ]
}

fn print_table(key: &str, rows: &[Row]) {
    let mut t = Table::new([
        key,
        "eroded kg/m",
        "eroded kg",
        "eroded particles",
        "mobilised",
        "over 10 cm",
        "furthest (m)",
        "t reached (s)",
        "wall (s)",
        "steps",
        "recoveries",
        "status",
    ]);
    for r in rows {
        t.row(cells(r, sig));
    }
    println!();
    print!("{t}");
}

/// sweep.csv: the varied key heads the first column; numbers at full precision.
fn write_csv(path: &Path, key: &str, rows: &[Row]) -> Result<()> {
    let mut text = format!(
        "{},eroded_kg_per_m,eroded_kg,eroded_particles,mobilised,travelled_far,furthest_m,time_s,wall_s,steps,recoveries,status\n",
        field(key)
    );
    for r in rows {
        let row: Vec<String> = cells(r, |v| v.to_string())
            .iter()
            .map(|c| field(c))
            .collect();
        writeln!(text, "{}", row.join(","))?;
    }
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ladder_keeps_its_order() {
        let ladder = Ladder::parse("phases.1.sediment.ks_over_d50=7, 1,3").expect("parses");
        assert_eq!(ladder.key, "phases.1.sediment.ks_over_d50");
        assert_eq!(ladder.values, ["7", "1", "3"]);
    }

    #[test]
    fn malformed_ladders_are_refused_with_the_reason() {
        for (spec, reason) in [
            ("phases.1.sediment.ks_over_d50", "has no '='"),
            ("phases.1.sediment.ks_over_d50=", "lists no values"),
            ("=1,2", "names no field"),
            ("numerics.dp_m=0.01,,0.02", "an empty value"),
            ("numerics.dp_m=0.01,0.01", "lists 0.01 twice"),
        ] {
            let err = Ladder::parse(spec).expect_err(spec).to_string();
            assert!(err.contains(reason), "{spec}: {err}");
        }
    }

    #[test]
    fn a_run_folder_is_named_by_its_place_and_a_file_safe_value() {
        assert_eq!(run_dir_name(0, "3"), "01_3");
        assert_eq!(run_dir_name(9, "0.004"), "10_0.004");
        assert_eq!(run_dir_name(2, "{x: [1, 2]}"), "03__x___1__2__");
        assert_eq!(run_dir_name(0, &"9".repeat(50)).len(), 43);
    }

    #[test]
    fn a_failed_run_has_blank_figures_and_its_error() {
        let row = Row {
            value: "10".into(),
            time_s: 0.2,
            wall_s: 1.5,
            steps: 40,
            recoveries: 3,
            outcome: Err("simulation blew up at t = 0.25 s, step 41".into()),
            budget: None,
        };
        let dir = std::env::temp_dir().join(format!("flume-sweep-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("sweep.csv");
        write_csv(&path, "phases.1.sediment.ks_over_d50", &[row]).expect("writes");
        let text = std::fs::read_to_string(&path).expect("written");
        assert_eq!(
            text.lines().nth(1),
            Some("10,,,,,,,0.2,1.500,40,3,\"simulation blew up at t = 0.25 s, step 41\"")
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
