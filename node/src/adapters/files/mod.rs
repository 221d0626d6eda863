//! Files a run leaves behind: the gauge time series (CSV), particle snapshots (VTK), the
//! plot of the final bed, the gauges', the eroded mass's and the sediment budget's time series
//! (PNG) and a sweep's chart of eroded mass (PNG).

pub mod bed_plot;
pub mod budget_plot;
pub mod csv;
pub mod inflow;
pub mod outputs;
pub mod series_plot;
pub mod sweep_plot;
pub mod vtk;

/// What plotters' drawing calls give back.
pub type Drawn = Result<(), Box<dyn std::error::Error + Send + Sync>>;

/// Draws a picture into `path` with `draw`; plotters' error is said with the file's name.
pub fn draw_png(path: &std::path::Path, draw: impl FnOnce() -> Drawn) -> anyhow::Result<()> {
    use anyhow::Context as _;
    draw()
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("cannot draw {}", path.display()))
}
