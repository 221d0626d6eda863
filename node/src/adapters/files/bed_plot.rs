//! The PNG a run ends with: the bed interfaces of Zubeldia et al. (2018) Section 3.3 (Zb, Zs,
//! Zw) along the flume at a few times, one panel each, against the initial bed surface, as the
//! paper's Figs. 13-16 show them; a researcher sees the scour at a glance.

use super::draw_png;
use anyhow::{Result, anyhow};
use flume_solver::ProfileColumn;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use std::path::Path;
use std::sync::OnceLock;

/// Where Debian, Fedora and Arch put DejaVu Sans (Debian: fonts-dejavu-core).
const FONT_CANDIDATES: [&str; 3] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
];

/// Registers DejaVu Sans as plotters' "sans-serif" once; false when no candidate was found,
/// and the plots then go without text.
pub fn font_registered() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        for path in FONT_CANDIDATES {
            if let Ok(bytes) = std::fs::read(path) {
                // plotters keeps fonts for the life of the process.
                let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
                if register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                    return true;
                }
            }
        }
        log::warn!(
            "no DejaVu Sans font found (install fonts-dejavu-core): the plots have no labels"
        );
        false
    })
}

/// One interface as (x, z) segments: a column without it breaks the line.
fn segments(
    columns: &[ProfileColumn],
    z: impl Fn(&ProfileColumn) -> Option<f64>,
) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for c in columns {
        match z(c) {
            Some(v) => out.last_mut().map_or((), |s| s.push((c.x_m, v))),
            None => out.push(Vec::new()),
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

fn zb(c: &ProfileColumn) -> Option<f64> {
    c.bed.and_then(|b| b.zb_m)
}

fn zs(c: &ProfileColumn) -> Option<f64> {
    c.bed.and_then(|b| b.zs_m)
}

fn zw(c: &ProfileColumn) -> Option<f64> {
    c.bed.and_then(|b| b.zw_m)
}

/// Pixel height of one panel.
const PANEL_HEIGHT: u32 = 260;

type Line = (&'static str, Vec<Vec<(f64, f64)>>, RGBColor);

/// The lines of the panel of one profile.
fn panel_lines(initial: &[ProfileColumn], now: &[ProfileColumn]) -> Vec<Line> {
    vec![
        (
            "initial bed surface (Zs, t = 0)",
            segments(initial, zs),
            RGBColor(150, 150, 150),
        ),
        ("free surface Zw", segments(now, zw), RGBColor(40, 90, 200)),
        ("bed surface Zs", segments(now, zs), RGBColor(200, 130, 40)),
        ("immobile bed Zb", segments(now, zb), RGBColor(120, 30, 30)),
    ]
}

/// Whether some column of `profiles` holds sediment: a flume whose bed is a wall block (clear
/// water) has a profile but no bed to plot.
pub fn holds_sediment(profiles: &[(f64, Vec<ProfileColumn>)]) -> bool {
    profiles
        .iter()
        .any(|(_, p)| p.iter().any(|c| zs(c).is_some()))
}

/// Draws `path` (PNG, 1200 wide, one panel of `PANEL_HEIGHT` per profile): for each
/// `(t, profile)` of `profiles` Zw, Zs and Zb at t against the initial bed surface, all panels
/// on the same axes.
pub fn draw(
    path: &Path,
    case_name: &str,
    initial: &[ProfileColumn],
    profiles: &[(f64, Vec<ProfileColumn>)],
) -> Result<()> {
    if profiles.is_empty() {
        return Err(anyhow!("a bed plot needs at least one profile"));
    }
    if !holds_sediment(profiles) {
        return Err(anyhow!("no column holds sediment: nothing to plot"));
    }
    let panels: Vec<(f64, Vec<Line>)> = profiles
        .iter()
        .map(|(t, p)| (*t, panel_lines(initial, p)))
        .collect();
    let (mut z_lo, mut z_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, lines) in &panels {
        for &(_, z) in lines.iter().flat_map(|l| l.1.iter().flatten()) {
            z_lo = z_lo.min(z);
            z_hi = z_hi.max(z);
        }
    }
    let (x_lo, x_hi) = match (initial.first(), initial.last()) {
        (Some(a), Some(b)) if b.x_m > a.x_m => (a.x_m, b.x_m),
        _ => return Err(anyhow!("a bed plot needs at least two profile columns")),
    };
    let margin = (0.1 * (z_hi - z_lo)).max(0.005);
    let y = (z_lo - margin)..(z_hi + margin);
    let text = font_registered();
    draw_png(path, || {
        let height = PANEL_HEIGHT * panels.len() as u32;
        let root = BitMapBackend::new(path, (1200, height)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((panels.len(), 1));
        for (area, (t, lines)) in areas.iter().zip(panels) {
            let mut builder = ChartBuilder::on(area);
            builder.margin(10);
            if text {
                builder
                    .caption(format!("{case_name}, t = {t:.2} s"), ("sans-serif", 18))
                    .x_label_area_size(35)
                    .y_label_area_size(70);
            }
            let mut chart = builder.build_cartesian_2d(x_lo..x_hi, y.clone())?;
            let mut mesh = chart.configure_mesh();
            mesh.light_line_style(RGBColor(238, 238, 238));
            if text {
                mesh.x_desc("x (m)").y_desc("elevation (m)");
            } else {
                mesh.disable_x_axis().disable_y_axis();
            }
            mesh.draw()?;
            for (label, segs, colour) in lines {
                let mut first = true;
                for seg in segs {
                    let series = chart.draw_series(LineSeries::new(seg, colour.stroke_width(2)))?;
                    if text && first {
                        series.label(label).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                        });
                    }
                    first = false;
                }
            }
            if text {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .position(SeriesLabelPosition::LowerLeft)
                    .draw()?;
            }
        }
        root.present()?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use flume_solver::BedInterfaces;

    fn column(x: f64, zs: Option<f64>) -> ProfileColumn {
        ProfileColumn {
            x_m: x,
            surface_m: Some(0.1),
            layer_tops_m: vec![],
            bed: Some(BedInterfaces {
                zb_m: zs,
                zs_m: zs,
                zw_m: Some(0.1),
            }),
        }
    }

    #[test]
    fn a_missing_interface_breaks_the_line() {
        let cols = [
            column(0.0, Some(0.05)),
            column(0.1, None),
            column(0.2, Some(0.04)),
            column(0.3, Some(0.03)),
        ];
        assert_eq!(
            segments(&cols, zs),
            vec![vec![(0.0, 0.05)], vec![(0.2, 0.04), (0.3, 0.03)]]
        );
    }

    #[test]
    fn the_plot_is_a_png_of_the_stated_size() {
        let dir = std::env::temp_dir().join(format!("flume-bed-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("bed.png");
        let initial: Vec<_> = (0..20)
            .map(|k| column(0.1 * k as f64, Some(0.05)))
            .collect();
        let last: Vec<_> = (0..20)
            .map(|k| column(0.1 * k as f64, Some(0.05 - 0.001 * k as f64)))
            .collect();
        draw(
            &path,
            "test",
            &initial,
            &[(0.5, initial.clone()), (1.0, last)],
        )
        .expect("draws");
        let bytes = std::fs::read(&path).expect("written");
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        // IHDR: width and height, big-endian, after the signature, length and tag.
        assert_eq!(
            u32::from_be_bytes(bytes[16..20].try_into().expect("4")),
            1200
        );
        assert_eq!(
            u32::from_be_bytes(bytes[20..24].try_into().expect("4")),
            2 * PANEL_HEIGHT
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_profile_without_sediment_is_refused() {
        let cols: Vec<_> = (0..3).map(|k| column(k as f64, None)).collect();
        let profiles = [(0.0, cols.clone())];
        let err = draw(Path::new("unused.png"), "t", &cols, &profiles).expect_err("no bed");
        assert!(
            err.to_string().contains("no column holds sediment"),
            "{err}"
        );
        let err = draw(Path::new("unused.png"), "t", &cols, &[]).expect_err("no profile");
        assert!(err.to_string().contains("at least one profile"), "{err}");
    }
}
