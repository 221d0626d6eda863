//! When `bench --levels`'s flume became steady: its history in 10 s windows, and the first
//! window from which every later one meets the levels issue's two goals of steadiness, a drift
//! under 1 mm per 10 s at every gauge and the weir passing the inflow within 2 %.
//!
//! One window at the end says little: at dp = 1 cm the flume holds some 750 water particles,
//! and 2 % of 10 s of inflow is 13 of them, half a millimetre over the whole reach, about what
//! a gauge's 10 s mean wanders by. Whether a run settled shows in the windows before it.

use crate::adapters::table::Table;

/// Largest change of a gauge's mean level from one window to the next, m.
pub const DRIFT_M: f64 = 1e-3;
/// Largest share by which the weir's discharge may differ from the one asked.
pub const FLOW_SHARE: f64 = 0.02;

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
}
