//! A sweep's chart: the eroded mass per metre of width each run ended with, one bar per value
//! of the varied field, evenly spaced as categories (the values need not be, as ks/d50 = 1, 2,
//! 3, 5, 7, 10 of the paper's Figure 10 are not).

use super::bed_plot::font_registered;
use super::draw_png;
use crate::adapters::table::sig;
use anyhow::{Result, anyhow};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

const SIZE: (u32, u32) = (1000, 550);
const BAR: RGBColor = RGBColor(170, 110, 40);

/// Bar k's slot on the x axis is SLOT k to SLOT (k + 1), and the bar leaves GAP free on each
/// side. Integer units: plotters formats the labels of an integer axis with bound key points,
/// not of a real one.
const SLOT: i32 = 100;
const GAP: i32 = 15;

/// The label under the bar whose slot holds `x`: the value as given.
fn category(bars: &[(String, Option<f64>)], x: i32) -> String {
    usize::try_from(x.div_euclid(SLOT))
        .ok()
        .and_then(|k| bars.get(k))
        .map_or_else(String::new, |(label, _)| label.clone())
}

/// Where bar k starts on the x axis.
fn slot(k: usize) -> i32 {
    SLOT * k as i32
}

/// Draws `path` (PNG, 1000 x 550): for each (value, kg/m), a bar with its mass on top, or
/// "failed" on the axis where the run has no mass (None).
pub fn draw(path: &Path, title: &str, key: &str, bars: &[(String, Option<f64>)]) -> Result<()> {
    if bars.is_empty() {
        return Err(anyhow!("a sweep chart needs at least one run"));
    }
    let centres: Vec<i32> = (0..bars.len()).map(|k| slot(k) + SLOT / 2).collect();
    let top = bars.iter().filter_map(|b| b.1).fold(0.0, f64::max);
    // Room above the tallest bar for its label; a sweep with no erosion at all still gets an
    // axis, with its zero-height bars labelled 0.
    let y_hi = if top > 0.0 { 1.15 * top } else { 1.0 };
    let text = font_registered();
    draw_png(path, || {
        let root = BitMapBackend::new(path, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut builder = ChartBuilder::on(&root);
        builder.margin(15);
        if text {
            builder
                .caption(title, ("sans-serif", 22))
                .x_label_area_size(50)
                .y_label_area_size(80);
        }
        let label = |x: &i32| category(bars, *x);
        // The only x key points are the bars' centres: a label under each bar, none between.
        let mut chart = builder
            .build_cartesian_2d((0..slot(bars.len())).with_key_points(centres), 0.0..y_hi)?;
        let mut mesh = chart.configure_mesh();
        mesh.disable_x_mesh()
            .light_line_style(RGBColor(238, 238, 238));
        if text {
            mesh.x_label_formatter(&label)
                .label_style(("sans-serif", 16))
                .axis_desc_style(("sans-serif", 17))
                .x_desc(key)
                .y_desc("eroded mass (kg/m)");
        } else {
            mesh.disable_x_axis().disable_y_axis();
        }
        mesh.draw()?;
        chart.draw_series(bars.iter().enumerate().filter_map(|(k, (_, v))| {
            Some(Rectangle::new(
                [(slot(k) + GAP, 0.0), (slot(k) + SLOT - GAP, (*v)?)],
                BAR.filled(),
            ))
        }))?;
        if text {
            chart.draw_series(bars.iter().enumerate().map(|(k, (_, v))| {
                let (words, colour) = v.map_or(("failed".to_string(), RED), |v| (sig(v), BLACK));
                let style = ("sans-serif", 18)
                    .into_font()
                    .color(&colour)
                    .pos(Pos::new(HPos::Center, VPos::Bottom));
                EmptyElement::at((slot(k) + SLOT / 2, v.unwrap_or(0.0)))
                    + Text::new(words, (0, -6), style)
            }))?;
        }
        root.present()?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_sit_under_the_bars_only() {
        let bars = [("1".to_string(), Some(0.5)), ("10".to_string(), None)];
        assert_eq!(category(&bars, SLOT / 2), "1");
        assert_eq!(category(&bars, SLOT + SLOT / 2), "10");
        assert_eq!(category(&bars, 2 * SLOT), "");
        assert_eq!(category(&bars, -SLOT / 2), "");
    }

    #[test]
    fn the_chart_is_a_png_of_the_stated_size_with_a_failed_run() {
        let dir = std::env::temp_dir().join(format!("flume-sweep-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("sweep.png");
        let bars = [
            ("1".to_string(), Some(0.0)),
            ("3".to_string(), Some(0.25)),
            ("10".to_string(), None),
        ];
        draw(&path, "test: eroded mass at t = 1 s", "ks_over_d50", &bars).expect("draws");
        let bytes = std::fs::read(&path).expect("written");
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        // IHDR: width and height, big-endian, after the signature, length and tag.
        assert_eq!(
            u32::from_be_bytes(bytes[16..20].try_into().expect("4")),
            SIZE.0
        );
        assert_eq!(
            u32::from_be_bytes(bytes[20..24].try_into().expect("4")),
            SIZE.1
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn an_empty_sweep_is_refused() {
        let err = draw(Path::new("unused.png"), "t", "k", &[]).expect_err("no bars");
        assert!(err.to_string().contains("at least one run"), "{err}");
    }
}
