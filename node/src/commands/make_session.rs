//! `flume-twin make-session`: the sensor topics of a flume session, made from a simple
//! hydraulic model and a stated sensor noise model, written as a recording. It makes the
//! bundled `tests/data/ulbra_session.mcap`; anyone can remake it, or a longer one.
//!
//! The hydraulic model, for an open flume with a horizontal bed:
//! - The steady water surface for unit discharge q = Q / W is the gradually varied flow
//!   dh/dx = -Sf / (1 - Fr^2), integrated upstream from critical depth h_c = (q^2/g)^(1/3)
//!   over the downstream weir. The friction slope is Manning's, Sf = n^2 V^2 / R^(4/3), with
//!   Strickler's n = ks^(1/6) / 21.1 for the case's sand roughness ks and the hydraulic radius
//!   of the rectangular channel, R = W h / (W + 2 h).
//! - The flume starts dry and fills from the inlet: the front is where the water that has
//!   entered, the integral of Q, fills the steady profile from the inlet wall. A gauge reads the
//!   bed ahead of the front and the steady surface behind it, over a ramp of `FRONT_M`.
//! - After a discharge change on the filled flume, each level relaxes to the new steady profile
//!   as 1 - exp(-t / tau), tau = the volume between the two profiles over the change of Q.
//!
//! The sensor model: a flow meter at 2 Hz with a Gaussian error of 1 % of the reading; gauges
//! at 10 Hz with a Gaussian error of 0.5 mm, quantised to 0.1 mm (an ultrasonic level sensor's
//! repeatability and resolution); each sample logged 2 ms after its stamp. The noise comes
//! from a seeded generator (SplitMix64 with Box-Muller), so a seed makes the same file.
//!
//! A check against the experiment: the paper's front took 8 s to reach the end of the flume
//! at 2 m3/h; this model's front takes about 10 s to reach the weir of `ulbra_flume.yaml`.

use crate::adapters::bag::BagWriter;
use crate::adapters::topics;
use crate::cli::MakeSessionArgs;
use anyhow::{Context, Result, bail};
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::flume_msgs::{Discharge, WaterLevel};
use flume_msgs::std_msgs::Header;
use flume_solver::Case;

const G: f64 = 9.81;
/// Length over which the filling front's level rises from the bed, m.
const FRONT_M: f64 = 0.1;
/// Step of the surface-profile integration, m.
const DX_M: f64 = 0.001;
const INFLOW_RATE_HZ: f64 = 2.0;
const INFLOW_SIGMA_REL: f64 = 0.01;
const GAUGE_RATE_HZ: f64 = 10.0;
const GAUGE_SIGMA_M: f64 = 0.5e-3;
const GAUGE_RESOLUTION_M: f64 = 1e-4;
const LATENCY_S: f64 = 0.002;

/// The flume as the hydraulic model sees it.
#[derive(Debug, Clone)]
pub struct Channel {
    pub width_m: f64,
    /// The inlet wall's x and the weir's x, m.
    pub x_inlet_m: f64,
    pub x_weir_m: f64,
    pub bed_m: f64,
    pub weir_crest_m: f64,
    pub manning_n: f64,
}

impl Channel {
    pub fn from_case(case: &Case) -> Result<Channel> {
        let Some(flume) = &case.open_flume else {
            bail!("{}: a session needs an open flume", case.name);
        };
        if case.dim() != 2 {
            bail!("{}: the session model is for 2-D flumes", case.name);
        }
        let sediments: Vec<&str> = case
            .phases
            .iter()
            .filter(|p| p.sediment.is_some())
            .map(|p| p.name.as_str())
            .collect();
        let bed_m = case
            .fluid_blocks
            .iter()
            .filter(|b| sediments.contains(&b.phase.as_str()))
            .map(|b| b.max_m[1])
            .fold(case.domain.min_m[1], f64::max);
        let ks_m = case
            .phases
            .iter()
            .find_map(|p| p.sediment.as_ref())
            .map_or(1e-3, |s| s.ks_over_d50 * s.d50_m);
        Ok(Channel {
            width_m: flume.width_m,
            x_inlet_m: case.domain.min_m[0],
            x_weir_m: case.domain.max_m[0],
            bed_m,
            weir_crest_m: flume.outlet_weir_m,
            manning_n: ks_m.powf(1.0 / 6.0) / 21.1,
        })
    }

    /// The steady depth over the bed, m, at `DX_M` steps from the inlet wall to the weir, for
    /// discharge `q_m3_per_s`.
    pub fn steady_depths(&self, q_m3_per_s: f64) -> Vec<f64> {
        let q = q_m3_per_s / self.width_m;
        let hc = (q * q / G).cbrt();
        let n = ((self.x_weir_m - self.x_inlet_m) / DX_M).ceil() as usize;
        let mut h = vec![0.0; n + 1];
        // The critical section is on the crest; the integration starts just above it, where
        // the equation is regular.
        h[n] = (self.weir_crest_m + hc - self.bed_m).max(hc) * 1.001;
        for k in (0..n).rev() {
            let d = h[k + 1];
            let v = q / d;
            let r = self.width_m * d / (self.width_m + 2.0 * d);
            let sf = self.manning_n.powi(2) * v * v / r.powf(4.0 / 3.0);
            let fr2 = (v * v / (G * d)).min(0.99);
            h[k] = d + sf / (1.0 - fr2) * DX_M;
        }
        h
    }

    fn volume_m3(&self, depths: &[f64], upto: usize) -> f64 {
        depths[..upto.min(depths.len())].iter().sum::<f64>() * DX_M * self.width_m
    }
}

/// The levels a session's gauges read, m above the floor, at time `t` with the discharge
/// history `schedule` ((from t, Q) rows, the first at 0).
pub struct LevelModel {
    channel: Channel,
    schedule: Vec<(f64, f64)>,
    profiles: Vec<Vec<f64>>,
    /// The time the front reaches the weir, s.
    filled_s: f64,
}

impl LevelModel {
    pub fn new(channel: Channel, schedule: Vec<(f64, f64)>) -> Result<LevelModel> {
        if schedule.first().is_none_or(|s| s.0 != 0.0) {
            bail!("the discharge schedule must start at t = 0");
        }
        if let Some(bad) = schedule.iter().find(|s| !(s.1.is_finite() && s.1 > 0.0)) {
            bail!(
                "discharge {} m3/s at t = {} s is not positive",
                bad.1,
                bad.0
            );
        }
        let profiles: Vec<Vec<f64>> = schedule
            .iter()
            .map(|s| channel.steady_depths(s.1))
            .collect();
        let filled_s = channel.volume_m3(&profiles[0], usize::MAX) / schedule[0].1;
        if let Some(early) = schedule.iter().skip(1).find(|s| s.0 < filled_s) {
            bail!(
                "a discharge change at t = {} s comes before the flume has filled ({filled_s:.1} s); \
                 the model covers changes on a filled flume only",
                early.0
            );
        }
        Ok(LevelModel {
            channel,
            schedule,
            profiles,
            filled_s,
        })
    }

    /// When the filling front reaches the weir, s.
    pub fn filled_s(&self) -> f64 {
        self.filled_s
    }

    /// The discharge in force at `t`, m3/s.
    pub fn discharge(&self, t: f64) -> f64 {
        self.schedule
            .iter()
            .rev()
            .find(|s| s.0 <= t)
            .map_or(self.schedule[0].1, |s| s.1)
    }

    /// The water level at `x` at `t`, m above the floor (the bed's level where it is dry).
    pub fn level(&self, x: f64, t: f64) -> f64 {
        let c = &self.channel;
        let k =
            (((x - c.x_inlet_m) / DX_M).round().max(0.0) as usize).min(self.profiles[0].len() - 1);
        if t < self.filled_s {
            let depths = &self.profiles[0];
            let entered = self.schedule[0].1 * t;
            let front = (0..depths.len())
                .find(|&j| c.volume_m3(depths, j) >= entered)
                .unwrap_or(depths.len()) as f64
                * DX_M
                + c.x_inlet_m;
            let wet = ((front - x) / FRONT_M).clamp(0.0, 1.0);
            return c.bed_m + wet * depths[k];
        }
        let mut depth = self.profiles[0][k];
        for (i, &(t_change, q)) in self.schedule.iter().enumerate().skip(1) {
            if t < t_change {
                break;
            }
            let old = &self.profiles[i - 1];
            let new = &self.profiles[i];
            let dq = q - self.schedule[i - 1].1;
            let dv = c.volume_m3(new, usize::MAX) - c.volume_m3(old, usize::MAX);
            let tau = (dv / dq).abs().max(1e-3);
            let relaxed = 1.0 - (-(t - t_change) / tau).exp();
            depth += (new[k] - depth) * relaxed;
        }
        c.bed_m + depth
    }
}

/// SplitMix64 and Box-Muller: a documented generator, so a seed remakes the file anywhere.
pub struct Noise(u64);

impl Noise {
    pub fn new(seed: u64) -> Noise {
        Noise(seed)
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1].
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn gaussian(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

pub fn run(args: &MakeSessionArgs) -> Result<()> {
    let case = Case::from_path_with(&args.case, &args.set).context("the case file was refused")?;
    let flume = case
        .open_flume
        .clone()
        .context("the case has no open flume")?;
    let channel = Channel::from_case(&case)?;
    let mut schedule = vec![(0.0, flume.inflow_m3_per_s)];
    if let Some(t) = args.change_at_s {
        let q = args
            .change_to_m3_per_h
            .context("--change-at-s needs --change-to-m3-per-h")?
            / 3600.0;
        schedule.push((t, q));
    }
    let model = LevelModel::new(channel, schedule)?;
    let mut bag = BagWriter::create(&args.out, None)?;
    let frame_id = "flume".to_string();
    let inflow_ch =
        bag.channel::<Discharge>(&format!("/{}", topics::INFLOW), topics::INFLOW_QOS)?;
    let gauges: Vec<(f64, _)> = case
        .observations
        .gauges
        .iter()
        .map(|g| {
            let ch = bag.channel::<WaterLevel>(
                &format!("/{}", topics::gauge(&g.name)),
                topics::GAUGE_QOS,
            )?;
            Ok((g.position_m[0], ch))
        })
        .collect::<Result<_>>()?;
    let mut noise = Noise::new(args.seed);
    let start = args.start_epoch_s;
    let header = |t: f64| -> Result<Header> {
        Ok(Header {
            stamp: Time::from_secs_f64(start + t).context("a stamp out of ROS's time range")?,
            frame_id: frame_id.clone(),
        })
    };
    // Both sensors on one 10 Hz tick, the flow meter on every fifth: the file is in log order.
    let ticks = (args.duration_s * GAUGE_RATE_HZ).round() as u64;
    let every = (GAUGE_RATE_HZ / INFLOW_RATE_HZ).round() as u64;
    let mut written = 0u64;
    for k in 0..=ticks {
        let t = k as f64 / GAUGE_RATE_HZ;
        let h = header(t)?;
        let log_ns = crate::adapters::bag::writer::nanos(start + t + LATENCY_S);
        let stamp_ns = h.stamp.as_nanos().unwrap_or(0);
        if k % every == 0 {
            let q = model.discharge(t) * (1.0 + INFLOW_SIGMA_REL * noise.gaussian());
            let msg = Discharge {
                header: h.clone(),
                discharge_m3_per_s: q.max(0.0),
            };
            bag.write(inflow_ch, &msg, log_ns, stamp_ns)?;
            written += 1;
        }
        for (x, ch) in &gauges {
            let level = model.level(*x, t) + GAUGE_SIGMA_M * noise.gaussian();
            let msg = WaterLevel {
                header: h.clone(),
                level_m: (level / GAUGE_RESOLUTION_M).round() * GAUGE_RESOLUTION_M,
            };
            bag.write(*ch, &msg, log_ns, stamp_ns)?;
            written += 1;
        }
        // A chunk a second, as the live recorder writes: a damaged file loses a second.
        if (k + 1) % GAUGE_RATE_HZ as u64 == 0 {
            bag.flush()?;
        }
    }
    bag.finish()?;
    println!(
        "{}: {written} messages over {} s; the flume fills in {:.1} s",
        args.out.display(),
        args.duration_s,
        model.filled_s()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulbra() -> Channel {
        Channel {
            width_m: 0.086,
            x_inlet_m: 0.0,
            x_weir_m: 2.5,
            bed_m: 0.055,
            weir_crest_m: 0.055,
            manning_n: 0.0012f64.powf(1.0 / 6.0) / 21.1,
        }
    }

    #[test]
    fn the_steady_surface_rises_upstream_from_critical_depth() {
        let c = ulbra();
        let q = 2.0 / 3600.0;
        let h = c.steady_depths(q);
        // q = 6.46e-3 m2/s: h_c = (q^2 / g)^(1/3) = 16.2 mm.
        let hc = ((q / 0.086f64).powi(2) / 9.81).cbrt();
        assert!((hc - 0.0162).abs() < 1e-4, "{hc}");
        assert!((h[h.len() - 1] - hc).abs() < 1e-4);
        assert!(h.windows(2).all(|w| w[0] >= w[1]), "a backwater curve");
        // Over 2.5 m at a friction slope of a few 1e-3 the depth grows by millimetres, not
        // centimetres: a subcritical flow of 2-3 cm over the whole bed.
        assert!(h[0] > hc + 0.002 && h[0] < 0.035, "{}", h[0]);
    }

    #[test]
    fn the_front_fills_the_flume_with_the_water_that_entered() {
        let q = 2.0 / 3600.0;
        let m = LevelModel::new(ulbra(), vec![(0.0, q), (60.0, 1.25 * q)]).expect("valid");
        let v = ulbra().volume_m3(&ulbra().steady_depths(q), usize::MAX);
        assert!((m.filled_s() - v / q).abs() < 1e-9);
        // Dry ahead of the front, wet behind it.
        let t = 0.5 * m.filled_s();
        assert_eq!(m.level(2.4, t), 0.055);
        assert!(m.level(0.2, t) > 0.055 + 0.015);
        // The change relaxes towards the higher profile.
        let before = m.level(1.0, 59.9);
        let after = m.level(1.0, 200.0);
        let h = ulbra().steady_depths(1.25 * q);
        assert!(after > before);
        assert!((after - 0.055 - h[1000]).abs() < 1e-6);
        assert!(
            LevelModel::new(ulbra(), vec![(0.0, q), (1.0, q)]).is_err(),
            "before filling"
        );
        assert!(LevelModel::new(ulbra(), vec![(0.0, -q)]).is_err());
    }

    #[test]
    fn the_noise_is_standard_normal() {
        let mut n = Noise::new(7);
        let x: Vec<f64> = (0..20000).map(|_| n.gaussian()).collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64;
        // Standard errors: 1 / sqrt(20000) = 0.007 for the mean, 0.01 for the variance.
        assert!(mean.abs() < 0.03, "{mean}");
        assert!((var - 1.0).abs() < 0.04, "{var}");
        assert_eq!(
            Noise::new(7).gaussian(),
            x[0],
            "a seed remakes the sequence"
        );
    }
}
