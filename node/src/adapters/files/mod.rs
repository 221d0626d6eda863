//! Files a run leaves behind: the gauge time series (CSV), particle snapshots (VTK), the
//! plot of the final bed, the gauges' and the eroded mass's time series (PNG) and a sweep's
//! chart of eroded mass (PNG).

pub mod bed_plot;
pub mod csv;
pub mod inflow;
pub mod outputs;
pub mod series_plot;
pub mod sweep_plot;
pub mod vtk;
