//! What the solver reports at each output interval: free-surface gauges, pressure probes,
//! the surge front and the state's health figures.

use crate::config::Case;
use crate::contract::{Extremes, from_order_key};
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
    /// The layers along the flume (`observations.profile` of the case), upstream first.
    pub profile: Vec<ProfileColumn>,
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
    /// Particles per region of the scour model: index 1-5 as in Figure 2 of the paper (5 is
    /// water), 0 walls and parked particles; for a multiphase case only.
    pub region_counts: Option<[u32; 6]>,
    /// Discharge, eroded mass and reservoir of an open flume.
    pub flume: Option<FlumeObservation>,
}

/// What an open flume reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlumeObservation {
    /// Discharge at the inlet, m3/s.
    pub inflow_m3_per_s: f64,
    /// Sediment particles collected (or gone over the weir) since the start.
    pub eroded_particles: u64,
    /// Under `van_rijn_exner`, the mass the flow has worn off the sand as bed load, in
    /// particles: passed over the bed's last held grain into the pit, or carried by grains the
    /// bed has let go; 0 under any other erosion, whose wear is not conserved.
    pub worn_particles: f64,
    /// Eroded mass per metre of width, kg/m, and times the flume width, kg: Eq. 34 on the
    /// particles collected, plus [`FlumeObservation::worn_particles`].
    pub eroded_kg_per_m: f64,
    pub eroded_kg: f64,
    /// Eroded mass per second since the previous observation, kg/s (whole width).
    pub eroded_rate_kg_per_s: f64,
    /// Particles parked (out of the flow, available to the inlet).
    pub parked_particles: u64,
    /// Inlet particles not placed for want of parked ones, since the start.
    pub starved_particles: u64,
    /// Inlet spots left empty since the start because a particle sat within dp / 2 of them,
    /// and the particles the inlet has placed: the inflow falls short by the ratio of the
    /// first to their sum.
    pub blocked_particles: u64,
    pub injected_particles: u64,
    /// Water particles the bed's pores have taken (and parked) since the start.
    pub soaked_particles: u64,
    /// Particles excluded for a density out of range since the start (recycled through the
    /// inlet; `crate::health`), and how many of them were sediment.
    pub excluded_particles: u64,
    pub excluded_sediment: u64,
}

impl FlumeObservation {
    /// Share of the inflow's particles that the inlet could not place since the start, 0-1.
    pub fn blocked_share(&self) -> f64 {
        crate::flume::blocked_share(self.blocked_particles, self.injected_particles)
    }
}

/// The top of each fluid phase's layer and the free surface along one vertical line.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileColumn {
    /// Horizontal position of the column, m.
    pub x_m: f64,
    /// Free surface (all fluid phases together), m; None when the column is dry.
    pub surface_m: Option<f64>,
    /// Top of each phase's layer, in the case's phase order, m; None where the phase is absent.
    pub layer_tops_m: Vec<Option<f64>>,
    /// The paper's three interfaces, for a case with a sediment phase.
    pub bed: Option<BedInterfaces>,
}

/// The interfaces of Zubeldia et al. (2018) Section 3.3 along one vertical line, m, each None
/// where the column does not hold it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BedInterfaces {
    /// Moving / immobile grains: the top of the un-yielded (region 1) sediment.
    pub zb_m: Option<f64>,
    /// Water / moving grains: the top of the sediment, moving or not.
    pub zs_m: Option<f64>,
    /// The free surface.
    pub zw_m: Option<f64>,
}

/// A vertical line of sample points from the tank floor to above its top, dp / 2 apart.
struct Column {
    position: Vec<f64>,
    heights: Vec<f64>,
}

impl Column {
    fn new(case: &Case, h: f64, position: Vec<f64>) -> Column {
        let d = case.dim();
        let step = 0.5 * case.numerics.dp_m;
        let bottom = case.domain.min_m[d - 1];
        let top = case.domain.max_m[d - 1] + 2.0 * h;
        let n = ((top - bottom) / step).ceil() as usize + 1;
        Column {
            position,
            heights: (0..n).map(|k| bottom + k as f64 * step).collect(),
        }
    }

    fn push_points(&self, points: &mut Vec<[f32; 4]>) {
        let d = self.position.len() + 1;
        for &z in &self.heights {
            let mut p = [0.0f32; 4];
            for (pk, v) in p.iter_mut().zip(&self.position) {
                *pk = *v as f32;
            }
            p[d - 1] = z as f32;
            points.push(p);
        }
    }

    /// Where `fullness` (one value per height) drops through one half, top-most.
    fn level(&self, sums: &[[f32; 4]], fullness: impl Fn(&[f32; 4]) -> f32) -> Option<f64> {
        let values: Vec<f32> = sums.iter().map(fullness).collect();
        free_surface_level(&self.heights, &values, SURFACE_FULLNESS)
    }
}

/// The sample points of every gauge column, profile column and probe, in the order the GPU
/// evaluates them. Each point's sums are the pressure sum and the fullness of phases 1-3.
pub struct ProbeLayout {
    pub points: Vec<[f32; 4]>,
    gauges: Vec<(String, Column)>,
    profile: Vec<Column>,
    probes: Vec<String>,
    fluid_phases: usize,
    /// GPU phase index of the sediment, if any.
    sediment_phase: Option<usize>,
}

/// Fullness of all fluid phases together; with a sediment the third slot is not a phase.
fn total_fullness(s: &[f32; 4], with_sediment: bool) -> f32 {
    if with_sediment {
        s[1] + s[2]
    } else {
        s[1] + s[2] + s[3]
    }
}

impl ProbeLayout {
    pub fn new(case: &Case, h: f64) -> ProbeLayout {
        let mut points = Vec::new();
        let gauges: Vec<(String, Column)> = case
            .observations
            .gauges
            .iter()
            .map(|g| (g.name.clone(), Column::new(case, h, g.position_m.clone())))
            .collect();
        let profile: Vec<Column> = case
            .observations
            .profile
            .iter()
            .flat_map(|p| p.positions(case.dim()))
            .map(|x| Column::new(case, h, x))
            .collect();
        for c in gauges.iter().map(|g| &g.1).chain(&profile) {
            c.push_points(&mut points);
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
            profile,
            probes,
            fluid_phases: case.phases.len(),
            sediment_phase: case.sediment_phases().map(|(k, _)| k + 1),
        }
    }

    pub fn observations(
        &self,
        time_s: f64,
        steps: u64,
        dt_s: f64,
        sums: &[[f32; 4]],
        ext: &Extremes,
    ) -> Observations {
        let sediment = self.sediment_phase.is_some();
        let total = |v: &[f32; 4]| total_fullness(v, sediment);
        let mut rest = sums;
        let mut take = |n: usize| {
            let (head, tail) = rest.split_at(n.min(rest.len()));
            rest = tail;
            head
        };
        let gauges = self
            .gauges
            .iter()
            .map(|(name, column)| GaugeReading {
                name: name.clone(),
                level_m: column.level(take(column.heights.len()), total),
            })
            .collect();
        let profile = self
            .profile
            .iter()
            .map(|column| {
                let s = take(column.heights.len());
                let surface_m = column.level(s, total);
                let layer_tops_m: Vec<Option<f64>> = (1..=self.fluid_phases)
                    .map(|k| column.level(s, |v| v[k]))
                    .collect();
                // The probe stage puts the immobile sediment's fullness in the third slot.
                let bed = self.sediment_phase.map(|k| BedInterfaces {
                    zb_m: column.level(s, |v| v[3]),
                    zs_m: layer_tops_m[k - 1],
                    zw_m: surface_m,
                });
                ProfileColumn {
                    x_m: column.position[0],
                    surface_m,
                    layer_tops_m,
                    bed,
                }
            })
            .collect();
        let probes = self
            .probes
            .iter()
            .zip(take(self.probes.len()))
            .map(|(name, s)| ProbeReading {
                name: name.clone(),
                pressure_pa: ProbeSums {
                    fullness: total(s),
                    pressure_sum: s[0],
                    phase_fullness: [0.0, s[1], s[2], if sediment { 0.0 } else { s[3] }],
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
            profile,
            front_m: (ext.fluid_count > 0).then(|| f64::from(from_order_key(ext.front_key))),
            max_speed_m_per_s: f64::from(f32::from_bits(ext.max_speed_bits)),
            max_density_error: f64::from(f32::from_bits(ext.max_rho_err_bits)),
            fluid_particles: ext.fluid_count,
            recoveries: 0,
            cfl: 0.0,
            region_counts: None,
            flume: None,
        }
    }
}
