//! Files a run leaves behind: the gauge time series (CSV) and particle snapshots (VTK).

pub mod csv;
pub mod vtk;
