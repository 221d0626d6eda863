//! Files a run leaves behind: the gauge time series (CSV), particle snapshots (VTK) and the
//! plot of the final bed (PNG).

pub mod bed_plot;
pub mod csv;
pub mod recorder;
pub mod vtk;
