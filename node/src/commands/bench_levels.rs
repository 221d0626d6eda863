//! `flume-twin bench --levels`: the open flume run at a constant discharge to a steady state at
//! each resolution, its levels at the gauges against the 1-D reference of
//! `flume_solver::hydraulics` on the geometry as generated at that dp (bed friction only, as a
//! 2-D model has it), and what the sensors cannot check: how far the water stands off the bed
//! and how hard the held sand pushes back.
//!
//! Per run it prints:
//! - each gauge's mean level over the last 10 s against the reference, and its drift (the last
//!   10 s' mean less the 10 s' before), and the same for a gauge added in the pool before the
//!   weir, whose level is the weir's head alone; beside the reference, how it moves with the
//!   glass walls' friction, with the pit's other limit than the one its length chooses
//!   (`hydraulics::PitFlow`) and with Strickler's n -/+20 %;
//! - the discharge over the weir and the one the inlet placed, over the last 10 s, against the
//!   discharge asked (particles parked at the outlet, dp^2 each per metre of width);
//! - the run in 10 s windows from its start, the case's gauges' levels and the weir's
//!   discharge in each, and the window from which it stayed steady (`bench_steadiness`);
//! - the run from 40 s to its end as one stretch: each gauge's trend by least squares and the
//!   weir over the whole stretch, the drift and outflow read with the least noise;
//! - at the end, the pool gauge's column: what it passes, and the weir's head counted as energy
//!   against the rating's over an even approach (a current that has not spread down carries
//!   velocity head where a still pool holds level);
//! - at the end, in 10 cm columns from x = 0.3 to 2.1 m: the 5th percentile of the water
//!   particles' heights above the column's top held sand particle (or the fixed bed's top wall
//!   particle), in dp (the cushion under the flow), and that sand particle's Tait pressure
//!   over the weight of the water above it; the median of it, and of the pressure the water
//!   feels from it (`p rho_w / rho_s`: Eq. 10 weighs a neighbour's pressure by its volume over
//!   its density).
//!
//! Nothing is asserted: the figures are for the log and the goals.

mod bed;

use super::bench_steadiness::{self, SETTLED_BY_S, Settled, Window};
use crate::adapters::table::Table;
use anyhow::{Context, Result, bail};
use bed::{print_bed, print_loose_sand};
use flume_solver::config::GaugeConfig;
use flume_solver::hydraulics::{
    Channel, GLASS_MANNING_N, PitFlow, SideWalls, filled_pit_override, fixed_bed_overrides,
};
use flume_solver::{Backend, Case, Observations, Particles, Simulation};
use std::path::Path;
use std::time::Instant;

/// How often the run is observed, s of flume time.
const OBSERVE_S: f64 = 1.0;
/// The window the levels are averaged over, and the drift measured between two of, s.
const WINDOW_S: f64 = 10.0;
/// The gauge the benchmark adds in the pool before the weir ([`with_pool_gauge`]).
const POOL_GAUGE: &str = "pool";
/// Parked water per square metre of the domain's section, particles x dp^2: enough for the
/// stored water at 4 m3/h, about 0.15 m2 at any dp.
const RESERVOIR_M2: f64 = 0.3;

/// What one run is asked.
pub struct LevelRun {
    pub dp_m: f64,
    pub m3_per_h: f64,
    pub until_s: f64,
    /// The sand bed replaced by a wall block of its shape (clear water).
    pub fixed_bed: bool,
    /// The sand bed's collector pit full of still water at the start (a fixed bed's always
    /// is).
    pub filled_pit: bool,
}

/// The counters of the open flume at an observation.
#[derive(Clone, Copy, Default)]
struct Books {
    t: f64,
    parked: u64,
    injected: u64,
    eroded: u64,
    excluded: u64,
    soaked: u64,
}

impl Books {
    /// The particles the inlet placed and those that left over the weir since `first`.
    fn since(&self, first: &Books) -> (f64, f64) {
        let d = |a: u64, b: u64| a as f64 - b as f64;
        // A parked particle left over the weir, reached the collector (sediment), was excluded
        // or went into the bed's pores; the inlet takes its particles from the parked ones.
        let injected = d(self.injected, first.injected);
        let over_weir = d(self.parked, first.parked) + injected
            - d(self.eroded, first.eroded)
            - d(self.excluded, first.excluded)
            - d(self.soaked, first.soaked);
        (injected, over_weir)
    }
}

pub fn run(flume: &Path, set: &[String], runs: &[LevelRun]) -> Result<()> {
    if runs.is_empty() {
        bail!("--levels: no resolution to run");
    }
    // Every case is built before the first run, so a bad value fails at once.
    let cases = runs
        .iter()
        .map(|r| level_case(flume, set, r))
        .collect::<Result<Vec<_>>>()?;
    let backend = Backend::choose().context("cannot open a backend")?;
    println!("backend: {}", backend.describe());
    for (r, (case, channel)) in runs.iter().zip(&cases) {
        run_one(&backend, case, channel, r)?;
    }
    Ok(())
}

/// The flume at `r`'s resolution and discharge, with a reservoir large enough for the water it
/// stores unless `--set` sizes it, and its bed made wall when asked: the case file with
/// overrides, validated as `--set` is. The reference is the sand bed's as generated at that
/// dp, a fixed bed's too.
fn level_case(flume: &Path, set: &[String], r: &LevelRun) -> Result<(Case, Channel)> {
    let mut overrides = vec![format!(
        "open_flume.reservoir_particles={}",
        (RESERVOIR_M2 / (r.dp_m * r.dp_m)).ceil()
    )];
    overrides.extend_from_slice(set);
    overrides.extend([
        format!("numerics.dp_m={}", r.dp_m),
        format!("open_flume.inflow_m3_per_s={}", r.m3_per_h / 3600.0),
        format!("time.end_s={}", r.until_s),
    ]);
    let sand = Case::from_path_with(flume, &overrides)
        .with_context(|| format!("the flume at dp = {} m was refused", r.dp_m))?;
    let channel = Channel::as_generated(&sand).map_err(anyhow::Error::msg)?;
    if r.filled_pit && !r.fixed_bed {
        overrides.push(filled_pit_override(&sand).map_err(anyhow::Error::msg)?);
        let filled = Case::from_path_with(flume, &overrides)
            .with_context(|| format!("the flume with its pit filled at dp = {} m", r.dp_m))?;
        return Ok((with_pool_gauge(filled, &channel), channel));
    }
    if !r.fixed_bed {
        return Ok((with_pool_gauge(sand, &channel), channel));
    }
    overrides.extend(fixed_bed_overrides(&sand).map_err(anyhow::Error::msg)?);
    let fixed = Case::from_path_with(flume, &overrides)
        .with_context(|| format!("the fixed-bed flume at dp = {} m was refused", r.dp_m))?;
    Ok((with_pool_gauge(fixed, &channel), channel))
}

/// The case with one more gauge, "pool", halfway between the bed's end and the weir: the
/// weir's own head, apart from the friction over the bed that the gauges upstream add to it.
fn with_pool_gauge(mut case: Case, channel: &Channel) -> Case {
    case.observations.gauges.push(GaugeConfig {
        name: POOL_GAUGE.into(),
        position_m: vec![0.5 * (channel.x_bed_end_m + channel.weir.x_m)],
    });
    case
}

fn run_one(backend: &Backend, case: &Case, channel: &Channel, r: &LevelRun) -> Result<()> {
    println!();
    println!(
        "{} at dp = {} m, {} m3/h, {}, to t = {} s",
        case.name,
        r.dp_m,
        r.m3_per_h,
        match (r.fixed_bed, r.filled_pit) {
            (true, _) => "the bed a fixed wall (clear water)",
            (false, true) => "the sand bed, the collector pit full at the start",
            (false, false) => "the sand bed, the collector pit empty at the start",
        },
        r.until_s
    );
    let mut sim = Simulation::new(backend.clone(), case).context("cannot set up the flume")?;
    let wall = Instant::now();
    let mut history: Vec<(Books, Observations)> = Vec::new();
    let mut t = 0.0;
    while t < r.until_s - 1e-9 {
        t = (t + OBSERVE_S).min(r.until_s);
        sim.advance_to(t)
            .with_context(|| format!("the run stopped before t = {t} s"))?;
        let obs = sim.observe()?;
        let f = sim.flume().context("an open flume")?;
        let books = Books {
            t: sim.time_s(),
            parked: f.parked_particles,
            injected: f.injected_particles,
            eroded: f.eroded_particles,
            excluded: f.excluded_particles,
            soaked: f.soaked_particles,
        };
        history.push((books, obs));
    }
    let wall_s = wall.elapsed().as_secs_f64();
    println!(
        "{} particles, {} steps in {:.0} s of wall time: {:.3} x real time",
        sim.particle_count(),
        sim.steps(),
        wall_s,
        r.until_s / wall_s
    );
    print_levels(case, channel, r, &history);
    print_flow(case, r, &history);
    // The pool's gauge is the benchmark's own; the goals are the case's gauges'.
    let (own, names): (Vec<usize>, Vec<String>) = (case.observations.gauges.iter().enumerate())
        .filter(|(_, g)| g.name != POOL_GAUGE)
        .map(|(k, g)| (k, g.name.clone()))
        .unzip();
    bench_steadiness::print(&names, &windows(case, r, &own, &history));
    if let Some(settled) = settled(case, r, &own, &history) {
        settled.print(&names);
    }
    let particles = sim.read_particles()?;
    // Particles come in id order, as the region words do.
    let regions = sim.regions()?;
    print_bed(&sim, case, &particles, &regions);
    print_loose_sand(case, channel, &particles, &regions);
    print_pool(case, channel, r, &history, &particles);
    Ok(())
}

/// The observations at or after `t`, the first of them.
fn at(history: &[(Books, Observations)], t: f64) -> Option<&(Books, Observations)> {
    history.iter().find(|(b, _)| b.t >= t - 1e-6)
}

/// Mean level of gauge `g` over the observations in `(from, to]`, m.
fn mean_level(history: &[(Books, Observations)], g: usize, from: f64, to: f64) -> Option<f64> {
    let levels: Vec<f64> = history
        .iter()
        .filter(|(b, _)| b.t > from + 1e-6 && b.t <= to + 1e-6)
        .filter_map(|(_, o)| o.gauges.get(g)?.level_m)
        .collect();
    (!levels.is_empty()).then(|| levels.iter().sum::<f64>() / levels.len() as f64)
}

fn print_levels(case: &Case, channel: &Channel, r: &LevelRun, history: &[(Books, Observations)]) {
    let width = case.open_flume.as_ref().map_or(1.0, |f| f.width_m);
    let q = r.m3_per_h / 3600.0;
    let reference = channel.steady(q, width);
    let glass = Channel {
        side_walls: SideWalls::Glass {
            width_m: width,
            manning_n: GLASS_MANNING_N,
        },
        ..channel.clone()
    }
    .steady(q, width);
    // The pit's other limit than the one its length chooses (`hydraulics::PitFlow`).
    let other_pit = Channel {
        pit: match channel.pit {
            PitFlow::Expanded => PitFlow::Carried,
            PitFlow::Carried => PitFlow::Expanded,
        },
        ..channel.clone()
    }
    .steady(q, width);
    // The reference's sensitivity to its one friction parameter, which the issue asks for.
    let with_n = |factor: f64| {
        Channel {
            manning_n: factor * channel.manning_n,
            ..channel.clone()
        }
        .steady(q, width)
    };
    let (n_low, n_high) = (with_n(0.8), with_n(1.2));
    print_reference(channel, q, width);
    let end = r.until_s;
    let mut table = Table::new([
        "gauge",
        "x (m)",
        "reference (m)",
        "model (m)",
        "model - ref (mm)",
        "drift (mm/10 s)",
        "glass walls (mm)",
        "other pit limit (mm)",
        "n -/+20 % (mm)",
    ]);
    for (g, gauge) in case.observations.gauges.iter().enumerate() {
        let x = gauge.position_m[0];
        let want = reference.level_m(x);
        let now = mean_level(history, g, end - WINDOW_S, end);
        let before = mean_level(history, g, end - 2.0 * WINDOW_S, end - WINDOW_S);
        let or_dash = |v: Option<String>| v.unwrap_or_else(|| "-".to_string());
        table.row([
            gauge.name.clone(),
            format!("{x:.2}"),
            format!("{want:.4}"),
            or_dash(now.map(|v| format!("{v:.4}"))),
            or_dash(now.map(|v| format!("{:+.1}", 1e3 * (v - want)))),
            or_dash(
                now.zip(before)
                    .map(|(a, b)| format!("{:+.1}", 1e3 * (a - b))),
            ),
            format!("{:+.1}", 1e3 * (glass.level_m(x) - want)),
            format!("{:+.1}", 1e3 * (other_pit.level_m(x) - want)),
            format!(
                "{:+.1} / {:+.1}",
                1e3 * (n_low.level_m(x) - want),
                1e3 * (n_high.level_m(x) - want)
            ),
        ]);
    }
    print!("{table}");
}

/// The run in windows of [`WINDOW_S`] from its start: the mean level of each gauge of
/// `gauges` (indices), and the weir's discharge against the one asked.
fn windows(
    case: &Case,
    r: &LevelRun,
    gauges: &[usize],
    history: &[(Books, Observations)],
) -> Vec<Window> {
    let mut out = Vec::new();
    let mut from = 0.0;
    while from + WINDOW_S <= r.until_s + 1e-6 {
        let to = from + WINDOW_S;
        let ends = (at(history, from), at(history, to));
        let (Some((first, _)), Some((last, _))) = ends else {
            break;
        };
        // The first window's books start at the first observation.
        let Some(over_weir) = weir_share(case, r, first, last) else {
            break;
        };
        let levels_m = gauges
            .iter()
            .map(|&g| mean_level(history, g, from, to))
            .collect();
        out.push(Window {
            from_s: from,
            to_s: to,
            levels_m,
            over_weir,
        });
        from = to;
    }
    out
}

/// The run from [`SETTLED_BY_S`] to its end as one stretch, each gauge of `gauges` (indices)
/// observation by observation; `None` for a run that ends within a window of it.
fn settled(
    case: &Case,
    r: &LevelRun,
    gauges: &[usize],
    history: &[(Books, Observations)],
) -> Option<Settled> {
    if r.until_s < SETTLED_BY_S + WINDOW_S - 1e-6 {
        return None;
    }
    let (first, _) = at(history, SETTLED_BY_S)?;
    let (last, _) = history.last()?;
    let over_weir = weir_share(case, r, first, last)?;
    let stretch = history.iter().filter(|(b, _)| b.t > first.t + 1e-6);
    let levels_m = gauges
        .iter()
        .map(|&g| {
            stretch
                .clone()
                .map(|(b, o)| (b.t, o.gauges.get(g).and_then(|x| x.level_m)))
                .collect()
        })
        .collect();
    Some(Settled {
        from_s: first.t,
        to_s: last.t,
        levels_m,
        over_weir,
    })
}

/// The discharge over the weir from `first` to `last` over the one asked (particles parked at
/// the outlet, dp^2 each per metre of width); `None` over no time.
fn weir_share(case: &Case, r: &LevelRun, first: &Books, last: &Books) -> Option<f64> {
    let span = last.t - first.t;
    if span <= 0.0 {
        return None;
    }
    let dp = case.numerics.dp_m;
    let width = case.open_flume.as_ref().map_or(1.0, |f| f.width_m);
    let asked = r.m3_per_h / 3600.0 / width;
    Some(last.since(first).1 * dp * dp / span / asked)
}

/// The 1-D reference's geometry, weir, friction, pit and eddy viscosity at discharge `q`
/// (m3/s) over `width` (m).
fn print_reference(channel: &Channel, q: f64, width: f64) {
    let q_unit = q / width;
    let head = channel.weir.head_m(q_unit);
    println!(
        "1-D reference on the generated geometry: bed {:.4} m, crest {:.4} m ({:.3} m long), \
         head {:.1} mm (H / L = {:.2}; a thin plate's, Rehbock: {:.1} mm), Strickler n = {:.4}, \
         pit {:?} ({:.2} m behind a {:.3} m step); the flow's eddy viscosity kappa u* h / 6 = \
         {:.2e} m2/s",
        channel.bed_m,
        channel.weir.crest_m,
        channel.weir.length_m,
        1e3 * head,
        head / channel.weir.length_m,
        1e3 * channel.weir.sharp_head_m(q_unit),
        channel.manning_n,
        channel.pit,
        channel.weir.x_m - channel.x_bed_end_m,
        channel.bed_m - channel.weir.floor_m,
        channel.eddy_viscosity_m2_per_s(q, width),
    );
}

fn print_flow(case: &Case, r: &LevelRun, history: &[(Books, Observations)]) {
    let (Some((last, obs)), Some((first, _))) = (history.last(), at(history, r.until_s - WINDOW_S))
    else {
        return;
    };
    let dp = case.numerics.dp_m;
    let width = case.open_flume.as_ref().map_or(1.0, |f| f.width_m);
    let span = last.t - first.t;
    if span <= 0.0 {
        return;
    }
    let (injected, over_weir) = last.since(first);
    let d = |a: u64, b: u64| a as f64 - b as f64;
    let to_m3_per_h = |n: f64| n * dp * dp * width / span * 3600.0;
    println!(
        "over the last {span:.0} s: inflow placed {:.3} m3/h, over the weir {:.3} m3/h \
         ({:+.1} % of the {} m3/h asked), {} excluded",
        to_m3_per_h(injected),
        to_m3_per_h(over_weir),
        100.0 * (to_m3_per_h(over_weir) / r.m3_per_h - 1.0),
        r.m3_per_h,
        d(last.excluded, first.excluded)
    );
    let (worn, kg_per_m) = obs
        .flume
        .as_ref()
        .map_or((0.0, 0.0), |f| (f.worn_particles, f.eroded_kg_per_m));
    println!(
        "eroded by t = {:.0} s: {} sand particles in the collector and {worn:.2} particles' mass \
         worn off the bed as bed load, {kg_per_m:.3} kg/m (Eq. 34 with the wear)",
        last.t, last.eroded,
    );
}

/// The flow through the pool gauge's column at the run's end: what it passes, and the weir's
/// head counted as energy, `level - crest + sum(u^3) / (2 g sum(u))` over the column's water
/// particles (Chow 1959's energy coefficient times V^2 / 2g), against the rating's head plus
/// the velocity head of an even approach over the pool's depth. A surface current that
/// crosses the pit without spreading down carries head a still pool would hold as level.
fn print_pool(
    case: &Case,
    channel: &Channel,
    r: &LevelRun,
    history: &[(Books, Observations)],
    particles: &Particles,
) {
    let Some(g) = case
        .observations
        .gauges
        .iter()
        .position(|g| g.name == POOL_GAUGE)
    else {
        return;
    };
    let Some(level) = mean_level(history, g, r.until_s - WINDOW_S, r.until_s) else {
        return;
    };
    let water = water_code(case);
    let (x, dp) = (
        case.observations.gauges[g].position_m[0],
        case.numerics.dp_m,
    );
    let (sum_u, sum_u3) = (0..particles.len())
        .filter(|&i| particles.phase(i) == water)
        .filter(|&i| (f64::from(particles.positions[i][0]) - x).abs() < dp)
        .map(|i| f64::from(particles.vel_rho[i][0]))
        .fold((0.0, 0.0), |(a, b), v| (a + v, b + v * v * v));
    if sum_u <= 0.0 {
        return;
    }
    let width = case.open_flume.as_ref().map_or(1.0, |f| f.width_m);
    let q = r.m3_per_h / 3600.0 / width;
    // Each particle carries dp^2 of the section; the column is 2 dp wide.
    let passed = sum_u * dp / 2.0;
    let g0 = flume_solver::hydraulics::GRAVITY_M_PER_S2;
    let velocity_head = sum_u3 / (2.0 * g0 * sum_u);
    let weir = &channel.weir;
    let (head, sharp) = (weir.head_m(q), weir.sharp_head_m(q));
    let approach = |h: f64| {
        let v = q / (weir.height_m() + h);
        h + v * v / (2.0 * g0)
    };
    println!(
        "pool at x = {x:.2} m (t = {:.0} s): the column passes {:.2} of q; velocity head {:.1} mm; \
         the weir's energy head {:.1} mm against the rating's {:.1} mm (Rehbock's {:.1} mm) \
         over an even approach",
        r.until_s,
        passed / q,
        1e3 * velocity_head,
        1e3 * (level - weir.crest_m + velocity_head),
        1e3 * approach(head),
        1e3 * approach(sharp)
    );
}

/// The water's phase code in `Particles::phase` (the case's index plus one; the only fluid
/// phase where there is no sediment).
fn water_code(case: &Case) -> u32 {
    case.sediment_phases().map_or(1, |(_, w)| w as u32 + 1)
}

#[cfg(test)]
mod tests;
