//! A discharge time series for `simulate --inflow`: CSV rows `t_s, q_m3_per_s`, times
//! increasing, the discharge held from each row's time to the next (a header row and `#`
//! comments are allowed). A bad row is refused with its line number and the reason, before the
//! run starts.

use anyhow::{Context, Result, bail};
use std::path::Path;

#[derive(Debug, Clone, PartialEq)]
pub struct InflowSeries {
    /// (time, discharge), s and m3/s, times strictly increasing.
    points: Vec<(f64, f64)>,
}

impl InflowSeries {
    pub fn from_path(path: &Path) -> Result<InflowSeries> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read the inflow series {}", path.display()))?;
        InflowSeries::parse(&text).with_context(|| format!("inflow series {}", path.display()))
    }

    pub fn parse(text: &str) -> Result<InflowSeries> {
        let mut points: Vec<(f64, f64)> = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let n = k + 1;
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            if cells.len() != 2 {
                bail!("line {n}: expected two values `t_s,q_m3_per_s`, got `{line}`");
            }
            let (Ok(t), Ok(q)) = (cells[0].parse::<f64>(), cells[1].parse::<f64>()) else {
                if points.is_empty() && n == 1 {
                    // A header row.
                    continue;
                }
                bail!("line {n}: `{line}` is not two numbers");
            };
            if !(t.is_finite() && t >= 0.0) {
                bail!("line {n}: time {t} s must be finite and >= 0");
            }
            if !(q.is_finite() && q >= 0.0) {
                bail!("line {n}: discharge {q} m3/s must be finite and >= 0");
            }
            if let Some(&(t_prev, _)) = points.last()
                && t <= t_prev
            {
                bail!("line {n}: time {t} s does not come after {t_prev} s");
            }
            points.push((t, q));
        }
        if points.is_empty() {
            bail!("no rows");
        }
        Ok(InflowSeries { points })
    }

    /// The discharge in force at time `t_s` (the first row's before it starts), m3/s.
    pub fn discharge_at(&self, t_s: f64) -> f64 {
        self.points
            .iter()
            .rev()
            .find(|(t, _)| *t <= t_s)
            .unwrap_or(&self.points[0])
            .1
    }

    /// Times in (from_s, to_s) at which the discharge changes.
    pub fn changes_between(&self, from_s: f64, to_s: f64) -> Vec<f64> {
        self.points
            .iter()
            .map(|(t, _)| *t)
            .filter(|t| *t > from_s && *t < to_s)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_hold_until_the_next() {
        let s = InflowSeries::parse("t_s,q_m3_per_s\n0,0.0005\n# step\n10, 0.001\n").unwrap();
        assert_eq!(s.discharge_at(0.0), 0.0005);
        assert_eq!(s.discharge_at(9.99), 0.0005);
        assert_eq!(s.discharge_at(10.0), 0.001);
        assert_eq!(s.discharge_at(1e6), 0.001);
        assert_eq!(s.changes_between(0.0, 20.0), vec![10.0]);
        assert!(s.changes_between(0.0, 10.0).is_empty());
    }

    #[test]
    fn bad_rows_name_their_line() {
        for (text, want) in [
            ("0,0.001\n5,-0.001\n", "line 2: discharge -0.001"),
            ("0,0.001\n5,NaN\n", "line 2: discharge NaN"),
            (
                "0,0.001\n0,0.002\n",
                "line 2: time 0 s does not come after 0 s",
            ),
            ("0,0.001\nx,y\n", "line 2: `x,y` is not two numbers"),
            ("0;0.001\n", "line 1: expected two values"),
            ("t,q\n", "no rows"),
        ] {
            let e = format!("{:#}", InflowSeries::parse(text).unwrap_err());
            assert!(e.contains(want), "{text:?}: {e}");
        }
    }
}
