//! Plain-text tables for terminals and CI logs: no colours, no box-drawing characters.

use std::fmt;

/// Columns are padded to their widest cell. A column whose cells are all numbers is
/// right-aligned so that magnitudes line up; any other column is left-aligned.
pub struct Table {
    headers: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new<S: Into<String>>(headers: impl IntoIterator<Item = S>) -> Table {
        Table {
            headers: headers.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
        }
    }

    pub fn row<S: Into<String>>(&mut self, cells: impl IntoIterator<Item = S>) {
        self.rows.push(cells.into_iter().map(Into::into).collect());
    }
}

fn looks_numeric(cell: &str) -> bool {
    let s = cell.trim_start_matches(['-', '+']);
    s.starts_with(|c: char| c.is_ascii_digit())
}

impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let columns = self
            .rows
            .iter()
            .map(Vec::len)
            .chain([self.headers.len()])
            .max()
            .unwrap_or(0);
        let mut widths = vec![0; columns];
        for row in self.rows.iter().chain([&self.headers]) {
            for (w, cell) in widths.iter_mut().zip(row) {
                *w = (*w).max(cell.chars().count());
            }
        }
        let numeric: Vec<bool> = (0..columns)
            .map(|k| {
                self.rows
                    .iter()
                    .filter_map(|row| row.get(k))
                    .all(|cell| cell.is_empty() || looks_numeric(cell))
            })
            .collect();
        let line = |f: &mut fmt::Formatter<'_>, row: &[String]| -> fmt::Result {
            let mut out = String::new();
            for (k, w) in widths.iter().enumerate() {
                let cell = row.get(k).map_or("", String::as_str);
                if k > 0 {
                    out.push_str("  ");
                }
                if numeric[k] {
                    out.push_str(&format!("{cell:>w$}"));
                } else {
                    out.push_str(&format!("{cell:<w$}"));
                }
            }
            writeln!(f, "{}", out.trim_end())
        };
        line(f, &self.headers)?;
        let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
        writeln!(f, "{}", rule.join("  "))?;
        for row in &self.rows {
            line(f, row)?;
        }
        Ok(())
    }
}

/// A rate such as 1.77e6 particle-steps/s in a form that lines up in a column.
pub fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3e}")
    } else {
        "n/a".to_string()
    }
}

/// About four significant digits, whatever the magnitude (real-time factors span 1e-4..1e2).
pub fn sig(v: f64) -> String {
    if !v.is_finite() {
        "n/a".to_string()
    } else if v == 0.0 {
        "0".to_string()
    } else if !(0.01..1e5).contains(&v.abs()) {
        format!("{v:.3e}")
    } else {
        let decimals = (3 - v.abs().log10().floor() as i32).clamp(0, 5) as usize;
        format!("{v:.decimals$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_line_up() {
        let mut t = Table::new(["name", "value"]);
        t.row(["a", "1.5"]);
        t.row(["longer name", "12.25"]);
        let text = t.to_string();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "name         value");
        assert_eq!(lines[1], "-----------  -----");
        assert_eq!(lines[2], "a              1.5");
        assert_eq!(lines[3], "longer name  12.25");
    }

    #[test]
    fn a_column_with_text_is_left_aligned() {
        let mut t = Table::new(["gauge", "level"]);
        t.row(["a", "0.25 m"]);
        t.row(["b", "dry"]);
        assert_eq!(t.to_string().lines().nth(2), Some("a      0.25 m"));
    }

    #[test]
    fn sig_keeps_four_digits() {
        assert_eq!(sig(0.000812), "8.120e-4");
        assert_eq!(sig(0.5), "0.5000");
        assert_eq!(sig(12.345), "12.35");
        assert_eq!(sig(0.0), "0");
    }
}
