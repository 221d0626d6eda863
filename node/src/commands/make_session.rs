//! `flume-twin make-session`: the sensor topics of a flume session, made from a simple
//! hydraulic model and a stated sensor noise model, written as a recording. It makes the
//! bundled `tests/data/ulbra_session.mcap`; anyone can remake it, or a longer one.
//!
//! The hydraulic model, for an open flume with a horizontal bed:
//! - The steady water surface for unit discharge q = Q / W is the 1-D reference of
//!   `flume_solver::hydraulics` (the weir's rating, the drop into the collector pit, the
//!   backwater curve over the bed with Strickler's n for the sand), on the case's geometry as
//!   written and with the bed's friction alone, as the 2-D twin has it (the glass side walls'
//!   share is left out: a twin without a wall-shear term could not follow it).
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
//! at 2 m3/h; this model fills the bed and the pit of `ulbra_flume.yaml` in 12 s.

use crate::adapters::bag::BagWriter;
use crate::adapters::topics;
use crate::cli::MakeSessionArgs;
use anyhow::{Context, Result, bail};
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::flume_msgs::{Discharge, WaterLevel};
use flume_msgs::std_msgs::Header;
use flume_solver::Case;
use flume_solver::hydraulics::{Channel, DX_M, Profile};

/// Length over which the filling front's level rises from the bed, m.
const FRONT_M: f64 = 0.1;
const INFLOW_RATE_HZ: f64 = 2.0;
const INFLOW_SIGMA_REL: f64 = 0.01;
const GAUGE_RATE_HZ: f64 = 10.0;
const GAUGE_SIGMA_M: f64 = 0.5e-3;
const GAUGE_RESOLUTION_M: f64 = 1e-4;
const LATENCY_S: f64 = 0.002;

/// The levels a session's gauges read, m above the floor, at time `t` with the discharge
/// history `schedule` ((from t, Q) rows, the first at 0).
pub struct LevelModel {
    channel: Channel,
    width_m: f64,
    schedule: Vec<(f64, f64)>,
    profiles: Vec<Profile>,
    /// The time the front reaches the weir, s.
    filled_s: f64,
}

impl LevelModel {
    pub fn new(channel: Channel, width_m: f64, schedule: Vec<(f64, f64)>) -> Result<LevelModel> {
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
        let profiles: Vec<Profile> = schedule
            .iter()
            .map(|s| channel.steady(s.1, width_m))
            .collect();
        let filled_s = profiles[0].volume_m2(&channel.weir) * width_m / schedule[0].1;
        if let Some(early) = schedule.iter().skip(1).find(|s| s.0 < filled_s) {
            bail!(
                "a discharge change at t = {} s comes before the flume has filled ({filled_s:.1} s); \
                 the model covers changes on a filled flume only",
                early.0
            );
        }
        Ok(LevelModel {
            channel,
            width_m,
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
        if t < self.filled_s {
            // The front is where the water that has entered fills the steady profile from the
            // inlet wall.
            let depths = &self.profiles[0].depths_m;
            let entered_m2 = self.schedule[0].1 * t / self.width_m;
            let mut stored_m2 = 0.0;
            let wet_columns = depths
                .iter()
                .take_while(|h| {
                    stored_m2 += *h * DX_M;
                    stored_m2 < entered_m2
                })
                .count();
            let front = c.x_inlet_m + wet_columns as f64 * DX_M;
            let wet = ((front - x) / FRONT_M).clamp(0.0, 1.0);
            return c.bed_m + wet * (self.profiles[0].level_m(x) - c.bed_m);
        }
        let mut level = self.profiles[0].level_m(x);
        for (i, &(t_change, q)) in self.schedule.iter().enumerate().skip(1) {
            if t < t_change {
                break;
            }
            let (old, new) = (&self.profiles[i - 1], &self.profiles[i]);
            let dq = (q - self.schedule[i - 1].1) / self.width_m;
            let dv = new.volume_m2(&c.weir) - old.volume_m2(&c.weir);
            let tau = (dv / dq).abs().max(1e-3);
            let relaxed = 1.0 - (-(t - t_change) / tau).exp();
            level += (new.level_m(x) - level) * relaxed;
        }
        level
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

/// The discharge from t = 0 (the case's) and, with `--change-at-s`, the one it changes to.
fn schedule(args: &MakeSessionArgs, case_m3_per_s: f64) -> Result<Vec<(f64, f64)>> {
    let mut schedule = vec![(0.0, case_m3_per_s)];
    if let Some(t) = args.change_at_s {
        let q = args
            .change_to_m3_per_h
            .context("--change-at-s needs --change-to-m3-per-h")?
            / 3600.0;
        schedule.push((t, q));
    }
    Ok(schedule)
}

pub fn run(args: &MakeSessionArgs) -> Result<()> {
    let case = Case::from_path_with(&args.case, &args.set).context("the case file was refused")?;
    let flume = case
        .open_flume
        .clone()
        .context("the case has no open flume")?;
    let channel = Channel::from_case(&case).map_err(anyhow::Error::msg)?;
    let model = LevelModel::new(
        channel,
        flume.width_m,
        schedule(args, flume.inflow_m3_per_s)?,
    )?;
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
        let case = Case::from_path(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../launch_configs/ulbra_flume.yaml"
        )))
        .expect("the bundled case");
        Channel::from_case(&case).expect("a flume")
    }

    #[test]
    fn the_front_fills_the_flume_with_the_water_that_entered() {
        let q = 2.0 / 3600.0;
        let w = 0.086;
        let m = LevelModel::new(ulbra(), w, vec![(0.0, q), (60.0, 1.25 * q)]).expect("valid");
        let steady = ulbra().steady(q, w);
        assert!((m.filled_s() - steady.volume_m2(&ulbra().weir) * w / q).abs() < 1e-9);
        // Dry ahead of the front, wet behind it.
        let t = 0.3 * m.filled_s();
        assert_eq!(m.level(2.0, t), 0.055);
        assert!(m.level(0.2, t) > 0.055 + 0.015);
        // Once filled, the steady profile.
        assert_eq!(m.level(1.0, 59.0), steady.level_m(1.0));
        // The change relaxes towards the higher profile.
        let before = m.level(1.0, 59.9);
        let after = m.level(1.0, 200.0);
        let higher = ulbra().steady(1.25 * q, w).level_m(1.0);
        assert!(after > before);
        assert!((after - higher).abs() < 1e-6);
        assert!(
            LevelModel::new(ulbra(), w, vec![(0.0, q), (1.0, q)]).is_err(),
            "before filling"
        );
        assert!(LevelModel::new(ulbra(), w, vec![(0.0, -q)]).is_err());
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
