//! The node's settings: the command line's, then parameter files and `-p` (which win), then
//! `ros2 param set` on a running node. Each is checked here, with the reason for a refusal.

use anyhow::{Result, anyhow};

/// A parameter value as the command line or a parameter file gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    Bool(bool),
    Integer(i64),
    Double(f64),
    String(String),
}

impl ParamValue {
    /// The value as a number, for numeric parameters set as integers (`-p rate:=2`).
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            ParamValue::Integer(i) => Some(*i as f64),
            ParamValue::Double(d) => Some(*d),
            _ => None,
        }
    }
}

/// The pace of a run as its command line gives it, before any parameter.
#[derive(Debug, Clone, Copy)]
pub struct Pace {
    pub target_rtf: f64,
    pub publish_rate_hz: f64,
    pub stale_after_s: f64,
}

/// Settings of a run, from the command line, then parameter files and `-p` (which win).
#[derive(Debug, Clone)]
pub struct Settings {
    pub target_rtf: f64,
    pub publish_rate_hz: f64,
    pub stale_after_s: f64,
    pub frame_id: String,
    /// The gauges' topic names (p1, p2, ...) and the height of each range sensor above the
    /// flume floor, m (parameters `gauge_mount_height_m.p1`, ...).
    pub gauges: Vec<String>,
    pub mount_height_m: Vec<f64>,
    /// The node's time is `/clock` (read at start only).
    pub use_sim_time: bool,
}

impl Settings {
    /// Settings for gauges `gauges` (topic names), range sensors mounted at `flume_top_m`
    /// unless a parameter says otherwise.
    pub fn new(
        pace: Pace,
        gauges: &[String],
        flume_top_m: f64,
        params: &[(String, ParamValue)],
    ) -> Result<Settings> {
        let mut s = Settings {
            target_rtf: pace.target_rtf,
            publish_rate_hz: pace.publish_rate_hz,
            stale_after_s: pace.stale_after_s,
            frame_id: "flume".into(),
            gauges: gauges.to_vec(),
            mount_height_m: vec![flume_top_m; gauges.len()],
            use_sim_time: false,
        };
        s.apply_at_start(params, |_| true)?;
        Ok(s)
    }

    /// Applies the parameters given at start (files, `-p`) that `wanted` names. A name that is
    /// none of the node's, or a gauge this case does not have, is said and skipped: a
    /// parameter file may serve several cases. A bad value is an error.
    fn apply_at_start(
        &mut self,
        params: &[(String, ParamValue)],
        wanted: impl Fn(&str) -> bool,
    ) -> Result<()> {
        for (name, value) in params {
            let known = match name.strip_prefix(MOUNT_HEIGHT) {
                Some(g) => self.gauges.iter().any(|n| n == g),
                None => PARAMETERS.contains(&name.as_str()),
            };
            if !known {
                log::warn!("parameter {name} is not one of flume_twin's for this case; ignored");
            } else if wanted(name) {
                self.apply(name, value)
                    .map_err(|reason| anyhow!("parameter {name}: {reason}"))?;
            }
        }
        Ok(())
    }

    /// The settings of an in-process replay: the gauges' mount heights and when a gauge is
    /// stale; the pace, publish rate and clock are a live node's and mean nothing to it.
    pub fn for_replay(gauges: &[String], mount_height_m: Vec<f64>, stale_after_s: f64) -> Settings {
        Settings {
            target_rtf: 1.0,
            publish_rate_hz: f64::INFINITY,
            stale_after_s,
            frame_id: "flume".into(),
            gauges: gauges.to_vec(),
            mount_height_m,
            use_sim_time: false,
        }
    }

    /// Sets parameter `name`, or says why not.
    pub fn apply(&mut self, name: &str, value: &ParamValue) -> Result<(), String> {
        let number = || {
            value
                .as_f64()
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| format!("must be a positive number, got {value:?}"))
        };
        match name {
            "target_real_time_factor" => self.target_rtf = number()?,
            "publish_rate_hz" => self.publish_rate_hz = number()?,
            "stale_after_s" => self.stale_after_s = number()?,
            "frame_id" => match value {
                ParamValue::String(f) if !f.is_empty() => self.frame_id = f.clone(),
                other => return Err(format!("must be a non-empty string, got {other:?}")),
            },
            "use_sim_time" => match value {
                ParamValue::Bool(b) => self.use_sim_time = *b,
                other => return Err(format!("must be true or false, got {other:?}")),
            },
            other => match other
                .strip_prefix(MOUNT_HEIGHT)
                .and_then(|g| self.gauges.iter().position(|n| n == g))
            {
                Some(k) => self.mount_height_m[k] = number()?,
                None => return Err(format!("{other} is not a parameter of flume_twin")),
            },
        }
        Ok(())
    }

    /// The values to declare to ROS, as `ros2 param` shows them.
    pub fn declared(&self) -> Vec<(String, ParamValue)> {
        let mut out: Vec<(String, ParamValue)> = vec![
            (
                "target_real_time_factor",
                ParamValue::Double(self.target_rtf),
            ),
            ("publish_rate_hz", ParamValue::Double(self.publish_rate_hz)),
            ("stale_after_s", ParamValue::Double(self.stale_after_s)),
            ("frame_id", ParamValue::String(self.frame_id.clone())),
            ("use_sim_time", ParamValue::Bool(self.use_sim_time)),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        for (g, h) in self.gauges.iter().zip(&self.mount_height_m) {
            out.push((format!("{MOUNT_HEIGHT}{g}"), ParamValue::Double(*h)));
        }
        out
    }
}

/// The prefix of the range sensors' mount heights: `gauge_mount_height_m.p1`, m.
pub const MOUNT_HEIGHT: &str = "gauge_mount_height_m.";

/// The node's parameters besides the mount heights (use_sim_time is ROS's own).
pub const PARAMETERS: [&str; 5] = [
    "target_real_time_factor",
    "publish_rate_hz",
    "stale_after_s",
    "frame_id",
    "use_sim_time",
];

/// What a parameter means and what it accepts, as `ros2 param describe` shows it.
pub fn describe(name: &str) -> Option<(&'static str, &'static str)> {
    const POSITIVE: &str = "a positive number";
    Some(match name {
        "target_real_time_factor" => (
            "the pace the twin keeps, as simulated seconds per wall second (1 = the flume's)",
            POSITIVE,
        ),
        "publish_rate_hz" => ("how often the twin publishes its outputs, Hz", POSITIVE),
        "stale_after_s" => (
            "sensors silent this long are stale: the twin then runs on its clock at the target pace, s",
            POSITIVE,
        ),
        "frame_id" => (
            "the frame of the published profile, cloud and markers",
            "not empty",
        ),
        "use_sim_time" => (
            "the node's time is /clock; read at start, a change asks for a restart",
            "true or false",
        ),
        _ if name.starts_with(MOUNT_HEIGHT) => (
            "the height of the gauge's range sensor above the flume floor (its level is this minus the range), m",
            POSITIVE,
        ),
        _ => return None,
    })
}

/// The height of each gauge's range sensor above the floor for an in-process replay: the
/// live twin's parameters `params` (from `--ros-args -p` or `--params-file`)
/// `gauge_mount_height_m.<gauge>` (the gauge's name in lower case), else the flume's top. The
/// node's other parameters mean nothing to an in-process replay and are ignored; a name that
/// is none of the node's is said.
pub fn mount_heights(
    params: &[(String, ParamValue)],
    gauges: &[String],
    flume_top_m: f64,
) -> Result<Vec<f64>> {
    let names: Vec<String> = gauges.iter().map(|g| g.to_lowercase()).collect();
    let mut s = Settings::for_replay(&names, vec![flume_top_m; names.len()], f64::INFINITY);
    s.apply_at_start(params, |name| name.starts_with(MOUNT_HEIGHT))?;
    Ok(s.mount_height_m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::adapters::ros::args::RosArgs;
    use crate::cli::{Cli, Command};
    use clap::Parser;

    fn run_args(extra: &[&str]) -> Pace {
        let mut argv = vec!["flume-twin", "run", "case.yaml"];
        argv.extend_from_slice(extra);
        match Cli::parse_from(argv).command {
            Command::Run(a) => a.pace(),
            _ => unreachable!("parsed a run"),
        }
    }

    #[test]
    fn the_shipped_parameter_file_sets_the_node_and_bad_values_are_refused() {
        let file = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../launch_configs/flume_twin.params.yaml"
        );
        let ros =
            RosArgs::parse(&["--params-file", file, "-p", "publish_rate_hz:=4"]).expect("parses");
        let s = Settings::new(
            run_args(&[]),
            &["p1".to_string()],
            0.3,
            &ros.parameters("/flume/flume_twin").expect("reads"),
        )
        .expect("valid");
        assert_eq!(s.target_rtf, 1.0);
        assert_eq!(s.publish_rate_hz, 4.0, "-p wins over the file");
        assert_eq!(s.stale_after_s, 2.0);
        assert_eq!(s.frame_id, "flume");
        assert_eq!(s.mount_height_m, vec![0.3], "the file's p1");
        let ros = RosArgs::parse(&["-p", "gauge_mount_height_m.p1:=0.25"]).expect("parses");
        let s = Settings::new(
            run_args(&[]),
            &["p1".to_string()],
            0.3,
            &ros.parameters("/flume_twin").expect("reads"),
        )
        .expect("valid");
        assert_eq!(s.mount_height_m, vec![0.25]);
        // The file's p2 and p3 are not in this case: ignored, as is a p9 on the command line.
        let ros = RosArgs::parse(&["-p", "gauge_mount_height_m.p9:=0.25"]).expect("parses");
        let s = Settings::new(
            run_args(&[]),
            &["p1".to_string()],
            0.3,
            &ros.parameters("/flume_twin").expect("reads"),
        )
        .expect("ignored");
        assert_eq!(s.mount_height_m, vec![0.3]);
        let mut live = s.clone();
        assert!(
            live.apply("gauge_mount_height_m.p9", &ParamValue::Double(0.2))
                .is_err()
        );
        assert!(
            live.apply("gauge_mount_height_m.p1", &ParamValue::Double(-0.2))
                .is_err()
        );
        for (bad, reason) in [
            ("target_real_time_factor:=-1", "must be a positive number"),
            ("publish_rate_hz:=fast", "must be a positive number"),
            ("frame_id:=3", "must be a non-empty string"),
        ] {
            let ros = RosArgs::parse(&["-p", bad]).expect("parses");
            let err = Settings::new(
                run_args(&[]),
                &["p1".to_string()],
                0.3,
                &ros.parameters("/flume_twin").expect("reads"),
            )
            .expect_err("refused");
            assert!(err.to_string().contains(reason), "{bad}: {err}");
        }
    }

    fn heights(args: &[&str]) -> Result<Vec<f64>> {
        let gauges = ["P1".to_string(), "P2".to_string()];
        let ros = RosArgs::parse(args).expect("parses");
        mount_heights(&ros.parameters(&ros.node_fqn("flume_twin"))?, &gauges, 0.3)
    }

    #[test]
    fn range_gauges_take_the_live_twin_s_mount_heights() {
        assert_eq!(heights(&[]).expect("defaults"), vec![0.3, 0.3]);
        assert_eq!(
            heights(&[
                "-p",
                "gauge_mount_height_m.p2:=0.25",
                "-p",
                "publish_rate_hz:=4.0"
            ])
            .expect("p2 set, the rest ignored"),
            vec![0.3, 0.25]
        );
        let file = std::env::temp_dir().join(format!("mounts-{}.yaml", std::process::id()));
        std::fs::write(
            &file,
            "/flume/flume_twin:\n  ros__parameters:\n    gauge_mount_height_m:\n      p1: 0.22\n",
        )
        .expect("writes");
        let path = file.to_str().expect("utf-8");
        let h = heights(&["--params-file", path, "-r", "__ns:=/flume"]).expect("the file");
        assert_eq!(
            h,
            vec![0.22, 0.3],
            "the file's entry for the twin under /flume"
        );
        let h = heights(&["--params-file", path]).expect("the file");
        assert_eq!(
            h,
            vec![0.3, 0.3],
            "an entry for another node's name does not apply"
        );
        let _ = std::fs::remove_file(&file);
        assert_eq!(
            heights(&["-p", "gauge_mount_height_m.p9:=0.2"]).expect("p9 ignored"),
            vec![0.3, 0.3]
        );
        let err = heights(&["-p", "gauge_mount_height_m.p1:=-0.2"]).expect_err("refused");
        assert!(
            err.to_string().contains("must be a positive number"),
            "{err}"
        );
    }
}
