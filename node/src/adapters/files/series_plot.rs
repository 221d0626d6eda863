//! The PNGs of a run's time series, from the rows gauges.csv and eroded_mass.csv get:
//! `gauges.png`, each gauge's predicted level against the measured one over time (one panel
//! per gauge, the residuals of all of them in a panel below), which is what a researcher
//! replaying a session compares most; and `eroded_mass.png`, the eroded sediment over time.
//! `simulate` has no measurements: its gauge panels show the prediction alone and say so.

use super::bed_plot::font_registered;
use super::{Drawn, draw_png};
use anyhow::Result;
use flume_msgs::flume_msgs::{ErodedMass, GaugeComparison};
use flume_solver::Observations;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Pixel width of the plots, and height of one panel.
pub(super) const WIDTH: u32 = 1200;
pub(super) const PANEL_HEIGHT: u32 = 260;
const PREDICTED: RGBColor = RGBColor(40, 90, 200);
const MEASURED: RGBColor = RGBColor(200, 80, 40);
/// The residual line of gauge k (P1, P2, P3, then around again), none of them the level
/// panels' colours.
const GAUGE_COLOURS: [RGBColor; 4] = [
    RGBColor(0, 160, 190),
    RGBColor(40, 150, 70),
    RGBColor(130, 60, 160),
    RGBColor(200, 160, 0),
];

pub(super) type Chart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// One gauge's levels at each output: time (s), predicted and measured (m), None where the
/// gauge is dry or has no sample.
struct GaugeRows {
    name: String,
    rows: Vec<(f64, Option<f64>, Option<f64>)>,
}

/// The time series of a run, gathered output by output and drawn at its end.
pub struct SeriesPlots {
    gauges: Vec<GaugeRows>,
    /// Whether the levels are compared with measured ones (a replay) or stand alone.
    measured: bool,
    /// Time (s) and eroded mass (kg per m of width), for an open flume.
    eroded: Vec<(f64, f64)>,
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

impl SeriesPlots {
    /// For `simulate`: predicted levels only.
    pub fn predicted_only() -> SeriesPlots {
        SeriesPlots {
            gauges: Vec::new(),
            measured: false,
            eroded: Vec::new(),
        }
    }

    /// For `replay`: predicted against measured levels.
    pub fn compared() -> SeriesPlots {
        SeriesPlots {
            measured: true,
            ..SeriesPlots::predicted_only()
        }
    }

    /// Gauge `k`'s rows; the gauges come in the case's order at every output, so the first
    /// output adds each in turn.
    fn gauge(&mut self, k: usize, name: &str) -> &mut GaugeRows {
        if self.gauges.len() == k {
            self.gauges.push(GaugeRows {
                name: name.to_string(),
                rows: Vec::new(),
            });
        }
        &mut self.gauges[k]
    }

    fn gauges_row(&mut self, k: usize, name: &str, row: (f64, Option<f64>, Option<f64>)) {
        self.gauge(k, name).rows.push(row);
    }

    /// An output of `simulate`, as its gauges.csv and eroded_mass.csv rows have it.
    pub fn observe(&mut self, obs: &Observations) {
        for (k, g) in obs.gauges.iter().enumerate() {
            self.gauges_row(k, &g.name, (obs.time_s, g.level_m, None));
        }
        if let Some(f) = &obs.flume {
            self.eroded.push((obs.time_s, f.eroded_kg_per_m));
        }
    }

    /// An output of `replay` at `t_s` s: the gauge comparison and the eroded mass it sends.
    pub fn compare(&mut self, t_s: f64, cmp: &GaugeComparison, eroded: Option<&ErodedMass>) {
        for (k, g) in cmp.gauges.iter().enumerate() {
            let row = (t_s, finite(g.predicted_m), finite(g.measured_m));
            self.gauges_row(k, &g.name, row);
        }
        if let Some(e) = eroded {
            self.eroded.push((t_s, e.eroded_kg_per_m));
        }
    }

    /// Draws `dir/gauges.png` and, for an open flume, `dir/eroded_mass.png`; the paths back.
    pub fn draw(&self, dir: &Path, case_name: &str) -> Result<Vec<PathBuf>> {
        let mut drawn = Vec::new();
        if self.gauges.iter().any(|g| g.rows.len() > 1) {
            let path = dir.join("gauges.png");
            self.draw_gauges(&path, case_name)?;
            drawn.push(path);
        }
        if self.eroded.len() > 1 {
            let path = dir.join("eroded_mass.png");
            draw_eroded(&path, case_name, &self.eroded)?;
            drawn.push(path);
        }
        Ok(drawn)
    }

    fn draw_gauges(&self, path: &Path, case_name: &str) -> Result<()> {
        let t_end = self
            .gauges
            .iter()
            .flat_map(|g| g.rows.iter().map(|r| r.0))
            .fold(0.0, f64::max);
        let panels = self.gauges.len() + usize::from(self.measured);
        let text = font_registered();
        draw_png(path, || {
            let height = PANEL_HEIGHT * panels as u32;
            let root = BitMapBackend::new(path, (WIDTH, height)).into_drawing_area();
            root.fill(&WHITE)?;
            let areas = root.split_evenly((panels, 1));
            for (area, g) in areas.iter().zip(&self.gauges) {
                let caption = if self.measured {
                    format!(
                        "{case_name}: gauge {}, predicted and measured level",
                        g.name
                    )
                } else {
                    format!(
                        "{case_name}: gauge {}, predicted level (no measurements in a simulation)",
                        g.name
                    )
                };
                gauge_panel(area, &caption, g, t_end, text)?;
            }
            if self.measured
                && let Some(area) = areas.last()
            {
                residual_panel(area, case_name, &self.gauges, t_end, text)?;
            }
            root.present()?;
            Ok(())
        })
    }
}

/// The (t, v) runs of `points` between the missing values: a gap breaks the line.
fn segments(points: impl Iterator<Item = (f64, Option<f64>)>) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for (t, v) in points {
        match v {
            Some(v) => out.last_mut().map_or((), |s| s.push((t, v))),
            None => out.push(Vec::new()),
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

/// A y range around `values` with a margin, never empty.
fn y_range(values: impl Iterator<Item = f64>, least: f64) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !lo.is_finite() {
        return 0.0..2.0 * least;
    }
    let margin = (0.1 * (hi - lo)).max(least);
    (lo - margin)..(hi + margin)
}

/// A panel's axes on `area`: its caption, the time axis to `t_end` and `y`.
pub(super) fn axes<'a, 'b: 'a>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    caption: &str,
    y_desc: &str,
    t_end: f64,
    y: std::ops::Range<f64>,
    text: bool,
) -> Result<Chart<'a, 'b>, Box<dyn std::error::Error + Send + Sync>> {
    let mut builder = ChartBuilder::on(area);
    builder.margin(10);
    if text {
        builder
            .caption(caption, ("sans-serif", 18))
            .x_label_area_size(35)
            .y_label_area_size(75);
    }
    let mut chart = builder.build_cartesian_2d(0.0..t_end.max(1e-9), y)?;
    let mut mesh = chart.configure_mesh();
    mesh.light_line_style(RGBColor(238, 238, 238));
    if text {
        mesh.x_desc("simulated time (s)").y_desc(y_desc);
    } else {
        mesh.disable_x_axis().disable_y_axis();
    }
    mesh.draw()?;
    Ok(chart)
}

/// Draws each run of `line` in `colour`, the first labelled `label` for the legend.
pub(super) fn lines<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    line: Vec<Vec<(f64, f64)>>,
    colour: RGBColor,
    label: &str,
    text: bool,
) -> Drawn {
    for (k, seg) in line.into_iter().enumerate() {
        let series = chart.draw_series(LineSeries::new(seg, colour.stroke_width(2)))?;
        if text && k == 0 {
            series.label(label).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        }
    }
    Ok(())
}

pub(super) fn legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, text: bool) -> Drawn {
    if text {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            // Levels rise from a still flume and residuals start at zero: the upper left is
            // where the lines are least often.
            .position(SeriesLabelPosition::UpperLeft)
            .draw()?;
    }
    Ok(())
}

fn gauge_panel(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    caption: &str,
    g: &GaugeRows,
    t_end: f64,
    text: bool,
) -> Drawn {
    let values: Vec<f64> = g.rows.iter().flat_map(|r| [r.1, r.2]).flatten().collect();
    // A gauge that never saw water has no line to label: the caption says why it is empty.
    let caption = match values.is_empty() {
        true => format!("{caption}: dry throughout"),
        false => caption.to_string(),
    };
    let y = y_range(values.iter().copied(), 0.002);
    let mut chart = axes(area, &caption, "water level (m)", t_end, y, text)?;
    let predicted = segments(g.rows.iter().map(|r| (r.0, r.1)));
    lines(&mut chart, predicted, PREDICTED, "predicted (twin)", text)?;
    let measured = segments(g.rows.iter().map(|r| (r.0, r.2)));
    lines(&mut chart, measured, MEASURED, "measured (sensor)", text)?;
    legend(&mut chart, text && !values.is_empty())
}

/// Predicted minus measured level of every gauge, in mm, around a zero line.
fn residual_panel(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    case_name: &str,
    gauges: &[GaugeRows],
    t_end: f64,
    text: bool,
) -> Drawn {
    let residual = |r: &(f64, Option<f64>, Option<f64>)| Some(1e3 * (r.1? - r.2?));
    let values = gauges
        .iter()
        .flat_map(|g| g.rows.iter().filter_map(residual));
    let y = y_range(values.chain([0.0]), 0.5);
    let caption = format!("{case_name}: residual, predicted minus measured");
    let mut chart = axes(area, &caption, "residual (mm)", t_end, y, text)?;
    chart.draw_series(LineSeries::new(
        [(0.0, 0.0), (t_end, 0.0)],
        RGBColor(120, 120, 120).stroke_width(1),
    ))?;
    for (k, g) in gauges.iter().enumerate() {
        let line = segments(g.rows.iter().map(|r| (r.0, residual(r))));
        let colour = GAUGE_COLOURS[k % GAUGE_COLOURS.len()];
        lines(&mut chart, line, colour, &g.name, text)?;
    }
    legend(&mut chart, text)
}

/// Draws `path`: the eroded mass per metre of width over time.
fn draw_eroded(path: &Path, case_name: &str, eroded: &[(f64, f64)]) -> Result<()> {
    let t_end = eroded.iter().map(|e| e.0).fold(0.0, f64::max);
    // A mass: from zero up, with room above the largest.
    let top = eroded.iter().map(|e| e.1).fold(0.0, f64::max);
    let y = 0.0..(1.1 * top).max(1e-3);
    let last = eroded.last().map_or(0.0, |e| e.1);
    let text = font_registered();
    draw_png(path, || {
        let root = BitMapBackend::new(path, (WIDTH, 2 * PANEL_HEIGHT)).into_drawing_area();
        root.fill(&WHITE)?;
        let caption = format!("{case_name}: eroded sediment, {last:.4} kg/m at {t_end:.1} s");
        let mut chart = axes(&root, &caption, "eroded mass (kg/m)", t_end, y, text)?;
        let line = vec![eroded.to_vec()];
        lines(
            &mut chart,
            line,
            RGBColor(170, 110, 40),
            "eroded mass",
            text,
        )?;
        legend(&mut chart, text)?;
        root.present()?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use flume_msgs::flume_msgs::GaugeResidual;

    /// The plots of a replay whose one gauge reads `level(t)` predicted and 5 cm measured, and
    /// whose eroded mass grows as `level` does; the PNGs' pixels back, RGB rows of `WIDTH`.
    fn drawn(name: &str, level: impl Fn(f64) -> f64) -> (Vec<u8>, Vec<u8>) {
        let dir = std::env::temp_dir().join(format!("flume-series-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let mut plots = SeriesPlots::compared();
        for k in 0..=50 {
            let t = k as f64 * 0.2;
            let cmp = GaugeComparison {
                gauges: vec![GaugeResidual {
                    name: "P1".into(),
                    predicted_m: level(t),
                    measured_m: 0.05,
                    residual_m: level(t) - 0.05,
                    stale: false,
                }],
                ..Default::default()
            };
            let eroded = ErodedMass {
                eroded_kg_per_m: level(t),
                ..Default::default()
            };
            plots.compare(t, &cmp, Some(&eroded));
        }
        let paths = plots.draw(&dir, "test").expect("draws");
        assert_eq!(paths, [dir.join("gauges.png"), dir.join("eroded_mass.png")]);
        let pixels = paths.iter().map(|p| rgb(p)).collect::<Vec<_>>();
        std::fs::remove_dir_all(&dir).ok();
        (pixels[0].clone(), pixels[1].clone())
    }

    fn rgb(path: &Path) -> Vec<u8> {
        let decoder = png::Decoder::new(std::fs::File::open(path).expect("opens"));
        let mut reader = decoder.read_info().expect("a PNG");
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).expect("decodes");
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.width, WIDTH);
        buf.truncate(info.buffer_size());
        buf
    }

    /// The mean row, within rows `rows`, of the pixels of column `x` near `colour`.
    fn row_of(pixels: &[u8], x: u32, rows: std::ops::Range<u32>, colour: RGBColor) -> f64 {
        let near = |p: &[u8]| {
            p.iter()
                .zip([colour.0, colour.1, colour.2])
                .all(|(a, b)| a.abs_diff(b) < 40)
        };
        let hits: Vec<u32> = rows
            .filter(|y| {
                let at = 3 * (y * WIDTH + x) as usize;
                near(&pixels[at..at + 3])
            })
            .collect();
        assert!(!hits.is_empty(), "no line at column {x}");
        hits.iter().sum::<u32>() as f64 / hits.len() as f64
    }

    #[test]
    fn the_lines_follow_the_data() {
        let rising = |t: f64| 0.04 + 0.002 * t;
        let falling = |t: f64| 0.06 - 0.002 * t;
        for (name, level, up) in [
            ("up", &rising as &dyn Fn(f64) -> f64, true),
            ("down", &falling, false),
        ] {
            let (gauges, eroded) = drawn(name, level);
            // Gauge P1's panel: the predicted line higher on the image (a smaller row) later
            // on where the level rises; the measured line flat.
            let panel = 0..PANEL_HEIGHT;
            let (early, late) = (2 * WIDTH / 5, 4 * WIDTH / 5);
            let rise = row_of(&gauges, early, panel.clone(), PREDICTED)
                - row_of(&gauges, late, panel.clone(), PREDICTED);
            assert_eq!(rise > 10.0, up, "{name}: {rise}");
            assert_eq!(rise < -10.0, !up, "{name}: {rise}");
            let flat = row_of(&gauges, early, panel.clone(), MEASURED)
                - row_of(&gauges, late, panel, MEASURED);
            assert!(flat.abs() < 2.0, "{name}: {flat}");
            // The residual panel below: P1's residual goes as its level does.
            let below = PANEL_HEIGHT..2 * PANEL_HEIGHT;
            let rise = row_of(&gauges, early, below.clone(), GAUGE_COLOURS[0])
                - row_of(&gauges, late, below, GAUGE_COLOURS[0]);
            assert_eq!(rise > 10.0, up, "{name} residual: {rise}");
            let rows = 0..2 * PANEL_HEIGHT;
            let brown = RGBColor(170, 110, 40);
            let rise =
                row_of(&eroded, early, rows.clone(), brown) - row_of(&eroded, late, rows, brown);
            assert_eq!(rise > 10.0, up, "{name} eroded: {rise}");
        }
    }

    #[test]
    fn a_simulation_draws_the_prediction_alone() {
        let dir = std::env::temp_dir().join(format!("flume-series-{}-sim", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let mut plots = SeriesPlots::predicted_only();
        for k in 0..10 {
            plots.gauges_row(0, "P1", (k as f64, Some(0.05 + 1e-3 * k as f64), None));
        }
        let paths = plots.draw(&dir, "test").expect("draws");
        assert_eq!(paths, [dir.join("gauges.png")], "no eroded mass: no plot");
        let pixels = rgb(&paths[0]);
        // One panel, no residuals, and nothing in the measured colour.
        assert_eq!(pixels.len(), 3 * (WIDTH * PANEL_HEIGHT) as usize);
        row_of(&pixels, 3 * WIDTH / 5, 0..PANEL_HEIGHT, PREDICTED);
        let measured = pixels
            .chunks(3)
            .filter(|p| p == &[MEASURED.0, MEASURED.1, MEASURED.2]);
        assert_eq!(measured.count(), 0);
        std::fs::remove_dir_all(&dir).ok();
    }
}
