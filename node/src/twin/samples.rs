//! Sensor samples as the twin takes them, from the wire or from a recording: the message as it
//! came (so it can be recorded), and what the input gate needs from it.

use crate::twin::gate::{GaugeSample, InputGate, Reading};
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::flume_msgs::{Discharge, WaterLevel};
use flume_msgs::sensor_msgs::Range;

/// A sample of the inflow, or of gauge `k` (the case's k-th gauge).
#[derive(Debug, Clone)]
pub enum Sample {
    Inflow(Discharge),
    Level(usize, WaterLevel),
    Range(usize, Range),
}

/// What the gate and the pacer take from a sample.
#[derive(Debug, Clone, Copy)]
pub enum Input {
    Inflow { stamp_s: f64, q: f64 },
    Gauge { index: usize, sample: GaugeSample },
}

/// A sample the gate let through: a discharge, or gauge `index`'s level above the floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Admitted {
    Inflow {
        stamp_s: f64,
        q: f64,
    },
    Level {
        index: usize,
        stamp_s: f64,
        level_m: f64,
    },
}

impl Input {
    pub fn stamp_s(&self) -> f64 {
        match self {
            Input::Inflow { stamp_s, .. } => *stamp_s,
            Input::Gauge { sample, .. } => sample.stamp_s,
        }
    }

    /// Passes the sample through `gate` at node-clock time `now`; a range becomes a level
    /// below its gauge's mount height (`mount_height_m`, by gauge). None when refused (the
    /// gate has logged and counted it).
    pub fn admit(
        self,
        gate: &mut InputGate,
        gauge_names: &[String],
        mount_height_m: &[f64],
        now: f64,
    ) -> Option<Admitted> {
        match self {
            Input::Inflow { stamp_s, q } => gate
                .discharge("inflow", stamp_s, q, now)
                .ok()
                .map(|()| Admitted::Inflow { stamp_s, q }),
            Input::Gauge { index, sample } => {
                let (name, stamp_s) = (&gauge_names[index], sample.stamp_s);
                let level = match sample.reading {
                    Reading::Level(l) => gate.level(name, stamp_s, l, now).map(|()| l),
                    Reading::Range { range, min, max } => {
                        gate.range(name, stamp_s, range, (min, max), mount_height_m[index], now)
                    }
                };
                level.ok().map(|level_m| Admitted::Level {
                    index,
                    stamp_s,
                    level_m,
                })
            }
        }
    }
}

impl Sample {
    pub fn stamp(&self) -> Time {
        match self {
            Sample::Inflow(m) => m.header.stamp,
            Sample::Level(_, m) => m.header.stamp,
            Sample::Range(_, m) => m.header.stamp,
        }
    }

    pub fn set_stamp(&mut self, stamp: Time) {
        match self {
            Sample::Inflow(m) => m.header.stamp = stamp,
            Sample::Level(_, m) => m.header.stamp = stamp,
            Sample::Range(_, m) => m.header.stamp = stamp,
        }
    }

    pub fn input(&self) -> Input {
        let stamp_s = self.stamp().as_secs_f64();
        match self {
            Sample::Inflow(m) => Input::Inflow {
                stamp_s,
                q: m.discharge_m3_per_s,
            },
            Sample::Level(index, m) => Input::Gauge {
                index: *index,
                sample: GaugeSample {
                    stamp_s,
                    reading: Reading::Level(m.level_m),
                },
            },
            Sample::Range(index, m) => Input::Gauge {
                index: *index,
                sample: GaugeSample {
                    stamp_s,
                    reading: Reading::Range {
                        range: f64::from(m.range),
                        min: f64::from(m.min_range),
                        max: f64::from(m.max_range),
                    },
                },
            },
        }
    }
}
