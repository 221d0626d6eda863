//! What the solver reports at each output interval: free-surface gauges, pressure probes,
//! the surge front and the state's health figures.

use crate::config::Case;
use crate::gpu::params::{Extremes, from_order_key};
use crate::physics::probe::{ProbeSums, free_surface_level};

/// Kernel fullness at which a gauge puts the free surface: half a kernel's worth of fluid,
/// the value of a flat surface for a symmetric kernel (the SWL gauge of DualSPHysics).
pub const SURFACE_FULLNESS: f32 = 0.5;

#[derive(Debug, Clone, PartialEq)]
pub struct GaugeReading {
    pub name: String,
    /// Free-surface elevation, m; None when the gauge's column holds no water.
    pub level_m: Option<f64>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ProbeReading {
    pub name: String,
    /// Shepard-interpolated pressure, Pa; None when the probe is out of the water.
    pub pressure_pa: Option<f64>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Observations {
    pub time_s: f64,
    pub steps: u64,
    /// The CFL time step of the last step (steps landing on an output time are shorter), s.
    pub dt_s: f64,
    pub gauges: Vec<GaugeReading>,
    pub probes: Vec<ProbeReading>,
    /// Largest x of any fluid particle, m (the surge front of a dam break); None without fluid.
    pub front_m: Option<f64>,
    pub max_speed_m_per_s: f64,
    /// Largest |rho / rho0 - 1| over fluid particles.
    pub max_density_error: f64,
    pub fluid_particles: u32,
    /// Blow-ups recovered from since the start (see `Simulation::recoveries`).
    pub recoveries: u32,
    /// The CFL number in force.
    pub cfl: f64,
}

/// The sample points of every gauge column and probe, in the order the GPU evaluates them.
pub struct ProbeLayout {
    pub points: Vec<[f32; 4]>,
    gauges: Vec<(String, Vec<f64>)>,
    probes: Vec<String>,
}

impl ProbeLayout {
    pub fn new(case: &Case, h: f64) -> ProbeLayout {
        let d = case.dim();
        let step = 0.5 * case.numerics.dp_m;
        let bottom = case.domain.min_m[d - 1];
        let top = case.domain.max_m[d - 1] + 2.0 * h;
        let n = ((top - bottom) / step).ceil() as usize + 1;
        let mut points = Vec::new();
        let mut gauges = Vec::new();
        for g in &case.observations.gauges {
            let heights: Vec<f64> = (0..n).map(|k| bottom + k as f64 * step).collect();
            for &z in &heights {
                let mut p = [0.0f32; 4];
                p[..d - 1]
                    .copy_from_slice(&g.position_m.iter().map(|v| *v as f32).collect::<Vec<_>>());
                p[d - 1] = z as f32;
                points.push(p);
            }
            gauges.push((g.name.clone(), heights));
        }
        let mut probes = Vec::new();
        for p in &case.observations.pressure_probes {
            let mut q = [0.0f32; 4];
            for (qk, v) in q.iter_mut().zip(&p.position_m) {
                *qk = *v as f32;
            }
            points.push(q);
            probes.push(p.name.clone());
        }
        ProbeLayout {
            points,
            gauges,
            probes,
        }
    }

    pub fn observations(
        &self,
        time_s: f64,
        steps: u64,
        dt_s: f64,
        sums: &[[f32; 2]],
        ext: &Extremes,
    ) -> Observations {
        let mut offset = 0;
        let mut gauges = Vec::new();
        for (name, heights) in &self.gauges {
            let fullness: Vec<f32> = sums[offset..offset + heights.len()]
                .iter()
                .map(|s| s[0])
                .collect();
            offset += heights.len();
            gauges.push(GaugeReading {
                name: name.clone(),
                level_m: free_surface_level(heights, &fullness, SURFACE_FULLNESS),
            });
        }
        let probes = self
            .probes
            .iter()
            .zip(&sums[offset..])
            .map(|(name, s)| ProbeReading {
                name: name.clone(),
                pressure_pa: ProbeSums {
                    fullness: s[0],
                    pressure_sum: s[1],
                }
                .pressure()
                .map(f64::from),
            })
            .collect();
        Observations {
            time_s,
            steps,
            dt_s,
            gauges,
            probes,
            front_m: (ext.fluid_count > 0).then(|| f64::from(from_order_key(ext.front_key))),
            max_speed_m_per_s: f64::from(f32::from_bits(ext.max_speed_bits)),
            max_density_error: f64::from(f32::from_bits(ext.max_rho_err_bits)),
            fluid_particles: ext.fluid_count,
            recoveries: 0,
            cfl: 0.0,
        }
    }
}
