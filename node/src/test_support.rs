//! What more than one module's unit tests build.

use flume_solver::Observations;

/// Observations at `time_s` of nothing: no gauge, probe, profile or flume. A test fills in
/// the fields it reads.
pub fn observations_at(time_s: f64) -> Observations {
    Observations {
        time_s,
        steps: 1,
        dt_s: 1e-4,
        gauges: vec![],
        probes: vec![],
        profile: vec![],
        front_m: None,
        max_speed_m_per_s: 0.0,
        max_density_error: 0.0,
        fluid_particles: 0,
        recoveries: 0,
        cfl: 0.2,
        region_counts: None,
        flume: None,
    }
}
