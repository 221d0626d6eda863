//! The solver's observations as the twin's messages: the bed profile, the eroded mass and the
//! gauge comparison. Quantities the solver could not give (a dry gauge, a column without sand)
//! are NaN, as ROS float fields say "no value".

use super::visual::bed_lines;
use flume_msgs::flume_msgs::{BedProfile, ErodedMass, GaugeComparison, GaugeResidual};
use flume_msgs::std_msgs::Header;
use flume_msgs::visualization_msgs::MarkerArray;
use flume_solver::Observations;

fn nan_if_none(v: Option<f64>) -> f64 {
    v.unwrap_or(f64::NAN)
}

pub fn bed_profile(obs: &Observations, header: Header) -> BedProfile {
    let bed = |f: fn(&flume_solver::BedInterfaces) -> Option<f64>| -> Vec<f64> {
        obs.profile
            .iter()
            .map(|c| nan_if_none(c.bed.as_ref().and_then(f)))
            .collect()
    };
    BedProfile {
        header,
        x_m: obs.profile.iter().map(|c| c.x_m).collect(),
        zb_m: bed(|b| b.zb_m),
        zs_m: bed(|b| b.zs_m),
        zw_m: bed(|b| b.zw_m),
    }
}

pub fn eroded_mass(obs: &Observations, header: Header) -> Option<ErodedMass> {
    obs.flume.as_ref().map(|f| ErodedMass {
        header,
        eroded_kg_per_m: f.eroded_kg_per_m,
        eroded_kg: f.eroded_kg,
        rate_kg_per_s: f.eroded_rate_kg_per_s,
        particles: f.eroded_particles,
    })
}

pub fn comparison(
    obs: &Observations,
    measured: &[Option<f64>],
    stale: &[bool],
    header: Header,
) -> GaugeComparison {
    GaugeComparison {
        header,
        gauges: obs
            .gauges
            .iter()
            .zip(measured.iter().zip(stale))
            .map(|(g, (m, &stale))| {
                let predicted = nan_if_none(g.level_m);
                let measured = nan_if_none(*m);
                GaugeResidual {
                    name: g.name.clone(),
                    predicted_m: predicted,
                    measured_m: measured,
                    residual_m: predicted - measured,
                    stale,
                }
            })
            .collect(),
    }
}

/// The twin's outputs for one observation, in the order they go out.
pub struct Outputs {
    pub marker: MarkerArray,
    pub bed: BedProfile,
    /// None without an open flume.
    pub eroded: Option<ErodedMass>,
    pub comparison: GaugeComparison,
}

impl Outputs {
    /// The outputs of `obs` under `header`, each gauge compared with `measured` (its reading
    /// at the output's time) and marked `stale`.
    pub fn of(
        obs: &Observations,
        header: Header,
        measured: &[Option<f64>],
        stale: &[bool],
    ) -> Outputs {
        let bed = bed_profile(obs, header.clone());
        Outputs {
            marker: bed_lines(&header, &bed.x_m, &bed.zs_m, &bed.zw_m),
            eroded: eroded_mass(obs, header.clone()),
            comparison: comparison(obs, measured, stale, header),
            bed,
        }
    }
}
