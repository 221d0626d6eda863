//! When `bench --levels`'s flume became steady: its history in 10 s windows, and the first
//! window from which every later one meets the levels issue's two goals of steadiness, a drift
//! under 1 mm per 10 s at every gauge and the weir passing the inflow within 2 %.
//!
//! One window at the end says little: at dp = 1 cm the flume holds some 750 water particles,
//! and 2 % of 10 s of inflow is 13 of them, half a millimetre over the whole reach, about what
//! a gauge's 10 s mean wanders by. Whether a run settled shows in the windows before it.
//!
//! The windows' rule asks every 10 s mean to stay within 1 mm of the one before, so a level
//! that wanders about a steady mean by half a millimetre fails it by chance. The drift itself
//! is the trend: [`Settled`] takes the run from [`SETTLED_BY_S`] to its end as one stretch, each
//! gauge's least-squares slope over its observations and the weir's discharge over the whole
//! stretch, the same two goals read on the estimate with the least noise.

use crate::adapters::table::Table;

/// Largest change of a gauge's mean level from one window to the next, m.
pub const DRIFT_M: f64 = 1e-3;
/// Largest share by which the weir's discharge may differ from the one asked.
pub const FLOW_SHARE: f64 = 0.02;

/// The time by which the levels issue asks the flume to be steady, s.
pub const SETTLED_BY_S: f64 = 40.0;

/// The span over which a trend is quoted, s: the drift's goal is per 10 s.
const TREND_PER_S: f64 = 10.0;

/// One window of the run.
#[derive(Clone, Debug, PartialEq)]
pub struct Window {
    pub from_s: f64,
    pub to_s: f64,
    /// Each gauge's mean level, m; `None` where the gauge saw no water.
    pub levels_m: Vec<Option<f64>>,
    /// The discharge over the weir over the one asked.
    pub over_weir: f64,
}

/// Whether window `w` is steady after `before`: the weir within [`FLOW_SHARE`] of the inflow,
/// and every gauge within [`DRIFT_M`] of its level in `before` (a gauge dry in either fails).
fn steady_after(before: &Window, w: &Window) -> bool {
    let levels = before
        .levels_m
        .iter()
        .zip(&w.levels_m)
        .all(|pair| match pair {
            (Some(a), Some(b)) => (b - a).abs() < DRIFT_M,
            _ => false,
        });
    levels && (w.over_weir - 1.0).abs() <= FLOW_SHARE
}

/// The end of the first window from which every window to the last is steady after the one
/// before it, s; `None` when the last is not (the first window, with none before it, never
/// counts).
pub fn steady_from(windows: &[Window]) -> Option<f64> {
    let mut first = None;
    for pair in windows.windows(2).rev() {
        if !steady_after(&pair[0], &pair[1]) {
            break;
        }
        first = Some(pair[1].to_s);
    }
    first
}

/// The windows as a table (level and change from the window before per gauge, the weir's
/// discharge against the one asked), and when the run became steady.
pub fn print(gauges: &[String], windows: &[Window]) {
    if windows.is_empty() {
        return;
    }
    let headers = std::iter::once("window (s)".to_string())
        .chain(gauges.iter().map(|g| format!("{g} (mm, change)")))
        .chain(["over the weir".to_string()]);
    let mut table = Table::new(headers);
    let mut before: Option<&Window> = None;
    for w in windows {
        let cell = |k: usize| {
            let now = w.levels_m.get(k).copied().flatten();
            let prev = before.and_then(|b| b.levels_m.get(k).copied().flatten());
            match (now, prev) {
                (Some(a), Some(b)) => format!("{:.1} ({:+.1})", 1e3 * a, 1e3 * (a - b)),
                (Some(a), None) => format!("{:.1}", 1e3 * a),
                _ => "dry".to_string(),
            }
        };
        let row = std::iter::once(format!("{:.0}-{:.0}", w.from_s, w.to_s))
            .chain((0..gauges.len()).map(cell))
            .chain([format!("{:+.1} %", 100.0 * (w.over_weir - 1.0))]);
        table.row(row);
        before = Some(w);
    }
    print!("{table}");
    match steady_from(windows) {
        Some(t) => println!(
            "steady from the window ending at {t:.0} s on (every gauge within {:.0} mm of the \
             window before, the weir within {:.0} % of the inflow; the goal: by 40 s)",
            1e3 * DRIFT_M,
            100.0 * FLOW_SHARE
        ),
        None => println!(
            "not steady: the last window moved a gauge by {:.0} mm or more, found one dry, or \
             had the weir more than {:.0} % off the inflow",
            1e3 * DRIFT_M,
            100.0 * FLOW_SHARE
        ),
    }
}

/// The run from [`SETTLED_BY_S`] to its end as one stretch.
#[derive(Clone, Debug, PartialEq)]
pub struct Settled {
    pub from_s: f64,
    pub to_s: f64,
    /// Each gauge's observations in the stretch, (t s, level m); `None` where it saw no water.
    pub levels_m: Vec<Vec<(f64, Option<f64>)>>,
    /// The discharge over the weir over the stretch over the one asked.
    pub over_weir: f64,
}

/// The least-squares slope of `samples` (t, value), per unit of t; `None` with fewer than two
/// distinct times.
pub fn trend(samples: &[(f64, f64)]) -> Option<f64> {
    let n = samples.len() as f64;
    let mean = |f: fn(&(f64, f64)) -> f64| samples.iter().map(f).sum::<f64>() / n;
    let (t0, y0) = (mean(|s| s.0), mean(|s| s.1));
    let stt: f64 = samples.iter().map(|s| (s.0 - t0).powi(2)).sum();
    let sty: f64 = samples.iter().map(|s| (s.0 - t0) * (s.1 - y0)).sum();
    (stt > 0.0).then(|| sty / stt)
}

impl Settled {
    /// Each gauge's trend, m per [`TREND_PER_S`]; `None` where the gauge was dry at any
    /// observation of the stretch, or saw fewer than two.
    pub fn trends(&self) -> Vec<Option<f64>> {
        self.levels_m
            .iter()
            .map(|obs| {
                let wet: Option<Vec<(f64, f64)>> =
                    obs.iter().map(|&(t, l)| l.map(|l| (t, l))).collect();
                trend(&wet?).map(|per_s| per_s * TREND_PER_S)
            })
            .collect()
    }

    /// Whether the stretch is steady: every gauge's trend under [`DRIFT_M`] per 10 s, and the
    /// weir within [`FLOW_SHARE`] of the inflow over it.
    pub fn steady(&self) -> bool {
        let trends = self.trends();
        trends.iter().all(|t| t.is_some_and(|t| t.abs() < DRIFT_M))
            && (self.over_weir - 1.0).abs() <= FLOW_SHARE
    }

    /// One line: the trends, the weir, and whether both meet the goals.
    pub fn print(&self, gauges: &[String]) {
        let trends = self.trends();
        let cells: Vec<String> = gauges
            .iter()
            .zip(&trends)
            .map(|(g, t)| match t {
                Some(t) => format!("{g} {:+.2}", 1e3 * t),
                None => format!("{g} dry"),
            })
            .collect();
        println!(
            "from {:.0} to {:.0} s as one stretch: trend {} mm per 10 s (least squares over \
             the observations), the weir {:+.1} % of the inflow: {}",
            self.from_s,
            self.to_s,
            cells.join(", "),
            100.0 * (self.over_weir - 1.0),
            if self.steady() {
                "steady (every trend under 1 mm per 10 s, the weir within 2 %)"
            } else {
                "not steady (a trend of 1 mm per 10 s or more, a dry gauge, or the weir more \
                 than 2 % off)"
            }
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window(to_s: f64, mm: [f64; 2], over_weir: f64) -> Window {
        Window {
            from_s: to_s - 10.0,
            to_s,
            levels_m: mm.iter().map(|v| Some(v * 1e-3)).collect(),
            over_weir,
        }
    }

    /// Settled from the window ending at 40 s: the one before it still filled (the levels
    /// rose 2 mm, the weir passed 5 % less), and every later one stays within the goals,
    /// the last by a hair.
    #[test]
    fn the_run_settles_where_every_later_window_meets_both_goals() {
        let mut w = vec![
            window(20.0, [78.0, 75.0], 0.90),
            window(30.0, [80.0, 77.0], 0.95),
            window(40.0, [80.5, 77.2], 1.01),
            window(50.0, [80.2, 77.9], 0.985),
            window(60.0, [81.1, 77.5], 1.019),
        ];
        assert_eq!(steady_from(&w), Some(40.0));
        // A window that breaks either goal later moves the start past it.
        w[3].over_weir = 1.03;
        assert_eq!(steady_from(&w), Some(60.0));
        w[3].over_weir = 1.0;
        w[3].levels_m[1] = Some(79.0e-3);
        assert_eq!(steady_from(&w), None, "60 s is 1.5 mm under 50 s's P2");
    }

    /// A gauge that saw no water in a window is not steady, and one window alone has nothing
    /// to be steady after.
    #[test]
    fn a_dry_gauge_or_a_single_window_is_not_steady() {
        let mut w = vec![
            window(50.0, [80.0, 77.0], 1.0),
            window(60.0, [80.0, 77.0], 1.0),
        ];
        assert_eq!(steady_from(&w), Some(60.0));
        w[0].levels_m[0] = None;
        assert_eq!(steady_from(&w), None);
        assert_eq!(steady_from(&w[1..]), None);
    }

    /// The slope by hand: t = 40-44 s, levels 1, 3, 2, 5, 4 mm about their means 42 s and
    /// 3 mm: (4 + 0 + 0 + 2 + 2) / (4 + 1 + 0 + 1 + 4) = 0.8 mm per s.
    #[test]
    fn the_trend_is_the_least_squares_slope() {
        let samples: Vec<(f64, f64)> = [1.0, 3.0, 2.0, 5.0, 4.0]
            .iter()
            .enumerate()
            .map(|(k, mm)| (40.0 + k as f64, mm * 1e-3))
            .collect();
        let per_s = trend(&samples).expect("five times");
        assert!((per_s - 0.8e-3).abs() < 1e-12, "{per_s}");
        assert_eq!(trend(&samples[..1]), None);
    }

    fn stretch(mm: impl Fn(f64) -> f64, over_weir: f64) -> Settled {
        let obs = (41..=90)
            .map(|t| (t as f64, Some(mm(t as f64) * 1e-3)))
            .collect();
        Settled {
            from_s: 40.0,
            to_s: 90.0,
            levels_m: vec![obs],
            over_weir,
        }
    }

    /// A level that wanders by a millimetre about a steady mean, with a period of 25 s, is
    /// steady by the windows' rule only from 80 s and by its trend from 40 s; one that rises 1.2 mm per 10 s is not,
    /// nor is a weir 3 % off, nor a gauge dry once.
    #[test]
    fn a_level_that_wanders_about_its_mean_is_steady_and_one_that_rises_is_not() {
        let wander = |t: f64| 80.0 + (std::f64::consts::TAU * t / 25.0).sin();
        let windows: Vec<Window> = (4..9)
            .map(|k| {
                let to = 10.0 * (k + 1) as f64;
                let mean = (1..=10).map(|s| wander(to - 10.0 + s as f64)).sum::<f64>() / 10.0;
                Window {
                    from_s: to - 10.0,
                    to_s: to,
                    levels_m: vec![Some(mean * 1e-3)],
                    over_weir: 1.0,
                }
            })
            .collect();
        // Its 10 s means swing by 1.4 mm twice before they settle by chance.
        assert_eq!(steady_from(&windows), Some(80.0), "the windows' rule");
        let settled = stretch(wander, 1.0);
        let t = settled.trends()[0].expect("wet");
        assert!(t.abs() < 0.5e-3, "{t}");
        assert!(settled.steady());
        assert!(!stretch(|t| 80.0 + 0.12 * (t - 40.0), 1.0).steady());
        assert!(!stretch(wander, 1.03).steady());
        let mut dry = stretch(wander, 1.0);
        dry.levels_m[0][7].1 = None;
        assert!(!dry.steady());
    }
}
