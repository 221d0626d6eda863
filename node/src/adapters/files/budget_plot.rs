//! `sediment_budget.png`: where the sand the flow has moved is over time, in grains, as
//! sediment_budget.csv has it (`flume_solver::budget`): every grain mobilised so far, and the
//! places they are in, which add up to it; and the mass a pick-up worn away has taken off
//! grains still held, which no count of whole grains sees.

use super::bed_plot::font_registered;
use super::draw_png;
use super::series_plot::{PANEL_HEIGHT, WIDTH, axes, legend, lines};
use anyhow::Result;
use flume_solver::budget::BudgetRow;
use plotters::prelude::*;
use std::path::Path;

/// The lines: a label, its colour and what it reads of a row.
type Line = (&'static str, RGBColor, fn(&BudgetRow) -> f64);

const LINES: [Line; 7] = [
    ("mobilised", RGBColor(0, 0, 0), |r| r.mobilised as f64),
    ("moving", RGBColor(200, 80, 40), |r| r.moving as f64),
    ("suspended", RGBColor(130, 60, 160), |r| r.suspended as f64),
    ("deposited again", RGBColor(40, 150, 70), |r| {
        r.deposited as f64
    }),
    ("past the bed", RGBColor(0, 160, 190), |r| r.past_bed as f64),
    ("collected", RGBColor(170, 110, 40), |r| r.collected as f64),
    ("worn off held grains", RGBColor(150, 150, 150), |r| r.worn),
];

/// Draws `path` from the budget's rows, one line per place.
pub fn draw(path: &Path, case_name: &str, rows: &[BudgetRow]) -> Result<()> {
    let t_end = rows.iter().map(|r| r.time_s).fold(0.0, f64::max);
    let top = rows
        .iter()
        .map(|r| (r.mobilised as f64).max(r.worn))
        .fold(0.0, f64::max);
    let y = 0.0..(1.1 * top).max(1.0);
    let (mobilised, far) = rows
        .last()
        .map_or((0, 0), |r| (r.mobilised, r.travelled_far));
    let text = font_registered();
    draw_png(path, || {
        let root = BitMapBackend::new(path, (WIDTH, 2 * PANEL_HEIGHT)).into_drawing_area();
        root.fill(&WHITE)?;
        let caption = format!(
            "{case_name}: sediment budget, {mobilised} grains mobilised by {t_end:.1} s, \
             {far} of them moved over 10 cm"
        );
        let mut chart = axes(&root, &caption, "grains", t_end, y, text)?;
        for (label, colour, read) in LINES {
            let line = vec![rows.iter().map(|r| (r.time_s, read(r))).collect()];
            lines(&mut chart, line, colour, label, text)?;
        }
        legend(&mut chart, text)?;
        root.present()?;
        Ok(())
    })
}
