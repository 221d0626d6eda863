//! `--ros-args` as ROS tools pass them (`ros2 run`, `ros2 launch`): remaps (`-r from:=to`,
//! with `__ns` and `__node`), parameters (`-p name:=value`) and parameter files
//! (`--params-file FILE`, the `node: {ros__parameters: {...}}` YAML of ROS 2).

use anyhow::{Context, Result, anyhow, bail};
use serde_norway::Value;
use std::path::{Path, PathBuf};

pub use crate::twin::settings::ParamValue;

impl ParamValue {
    /// A YAML scalar, typed the way rclcpp types it: true/false, integers, floats, else text.
    fn from_yaml(v: &Value) -> Option<ParamValue> {
        match v {
            Value::Bool(b) => Some(ParamValue::Bool(*b)),
            Value::Number(n) if n.is_i64() => n.as_i64().map(ParamValue::Integer),
            Value::Number(n) => n.as_f64().map(ParamValue::Double),
            Value::String(s) => Some(ParamValue::String(s.clone())),
            _ => None,
        }
    }

    fn parse(text: &str) -> ParamValue {
        match serde_norway::from_str::<Value>(text) {
            Ok(v) => ParamValue::from_yaml(&v).unwrap_or_else(|| ParamValue::String(text.into())),
            Err(_) => ParamValue::String(text.into()),
        }
    }
}

/// What `--ros-args` said.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct RosArgs {
    /// `-r __ns:=/flume`.
    pub namespace: Option<String>,
    /// `-r __node:=twin`.
    pub node_name: Option<String>,
    /// Topic remaps `-r from:=to`, in order.
    pub remaps: Vec<(String, String)>,
    /// `-p name:=value`, in order (they override parameter files).
    pub params: Vec<(String, ParamValue)>,
    /// `--params-file FILE`, in order.
    pub params_files: Vec<PathBuf>,
}

fn split_assignment<'a>(flag: &str, text: &'a str) -> Result<(&'a str, &'a str)> {
    text.split_once(":=")
        .filter(|(k, _)| !k.is_empty())
        .ok_or_else(|| anyhow!("{flag} {text}: expected NAME:=VALUE"))
}

impl RosArgs {
    /// Parses everything after `--ros-args` (a later `--ros-args` continues the list; `--`
    /// ends it). Unknown ROS flags that need no value here are refused by name.
    pub fn parse<S: AsRef<str>>(args: &[S]) -> Result<RosArgs> {
        let mut out = RosArgs::default();
        let mut it = args.iter().map(AsRef::as_ref);
        while let Some(arg) = it.next() {
            let mut value = |flag: &str| {
                it.next()
                    .ok_or_else(|| anyhow!("{flag} needs a value"))
                    .map(str::to_string)
            };
            match arg {
                "--ros-args" => {}
                "--" => break,
                "-r" | "--remap" => {
                    let v = value(arg)?;
                    let (from, to) = split_assignment(arg, &v)?;
                    // `node:__ns:=...` addresses one node of a process; we are the only one.
                    let from = from.rsplit_once(':').map_or(from, |(_, f)| f);
                    match from {
                        "__ns" => out.namespace = Some(to.to_string()),
                        "__node" | "__name" => out.node_name = Some(to.to_string()),
                        _ => out.remaps.push((from.to_string(), to.to_string())),
                    }
                }
                "-p" | "--param" => {
                    let v = value(arg)?;
                    let (name, text) = split_assignment(arg, &v)?;
                    out.params.push((name.to_string(), ParamValue::parse(text)));
                }
                "--params-file" => out.params_files.push(PathBuf::from(value(arg)?)),
                // Logging flags: our log level comes from RUST_LOG; accept and say so.
                "--log-level" => {
                    let level = value(arg)?;
                    log::info!("--log-level {level}: flume-twin logs per RUST_LOG");
                }
                "--enable-rosout-logs"
                | "--disable-rosout-logs"
                | "--enable-stdout-logs"
                | "--disable-stdout-logs" => {}
                other => bail!("unsupported ROS argument {other:?}"),
            }
        }
        Ok(out)
    }

    /// The topic name after the remaps: the first rule whose source is the name wins.
    /// The node's full name (`/ns/name`), `default_name` unless `-r __node:=` renames it.
    pub fn node_fqn(&self, default_name: &str) -> String {
        format!(
            "{}/{}",
            self.namespace
                .as_deref()
                .unwrap_or("/")
                .trim_end_matches('/'),
            self.node_name.as_deref().unwrap_or(default_name)
        )
    }

    pub fn remap(&self, topic: &str) -> String {
        self.remaps
            .iter()
            .find(|(from, _)| from == topic)
            .map_or_else(|| topic.to_string(), |(_, to)| to.clone())
    }

    /// The parameters for node `node_fqn` (`/ns/name`): each parameter file in order (entries
    /// for `/**`, the node's name or its full name), then the `-p` values.
    pub fn parameters(&self, node_fqn: &str) -> Result<Vec<(String, ParamValue)>> {
        let mut out = Vec::new();
        for path in &self.params_files {
            out.extend(params_from_file(path, node_fqn)?);
        }
        out.extend(self.params.iter().cloned());
        Ok(out)
    }
}

fn params_from_file(path: &Path, node_fqn: &str) -> Result<Vec<(String, ParamValue)>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read parameter file {}", path.display()))?;
    let doc: Value = serde_norway::from_str(&text)
        .with_context(|| format!("parameter file {} is not YAML", path.display()))?;
    let Value::Mapping(nodes) = doc else {
        bail!(
            "parameter file {}: expected a map of node names",
            path.display()
        );
    };
    let base = node_fqn.rsplit('/').next().unwrap_or(node_fqn);
    let mut out = Vec::new();
    for (key, body) in &nodes {
        let key = key.as_str().unwrap_or_default();
        let ours =
            key == "/**" || key == base || key == node_fqn || key.trim_start_matches('/') == base;
        if !ours {
            continue;
        }
        let Some(Value::Mapping(params)) = body.get("ros__parameters") else {
            bail!(
                "parameter file {}: {key} has no ros__parameters map",
                path.display()
            );
        };
        flatten(params, "", &mut out, path)?;
    }
    Ok(out)
}

/// Nested maps are dotted names, as in ROS 2.
fn flatten(
    map: &serde_norway::Mapping,
    prefix: &str,
    out: &mut Vec<(String, ParamValue)>,
    path: &Path,
) -> Result<()> {
    for (k, v) in map {
        let name = format!("{prefix}{}", k.as_str().unwrap_or_default());
        match v {
            Value::Mapping(inner) => flatten(inner, &format!("{name}."), out, path)?,
            other => match ParamValue::from_yaml(other) {
                Some(p) => out.push((name, p)),
                None => bail!(
                    "parameter file {}: {name} is not a bool, number or string",
                    path.display()
                ),
            },
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remaps_names_and_parameters_are_read_as_ros_passes_them() {
        let a = RosArgs::parse(&[
            "--ros-args",
            "-r",
            "__ns:=/flume",
            "-r",
            "__node:=twin",
            "-r",
            "inflow:=/lab/q",
            "-p",
            "target_real_time_factor:=0.5",
            "-p",
            "publish_rate_hz:=2",
            "-p",
            "use_sim_time:=true",
            "-p",
            "frame_id:=flume",
            "--",
            "ignored",
        ])
        .expect("parses");
        assert_eq!(a.namespace.as_deref(), Some("/flume"));
        assert_eq!(a.node_name.as_deref(), Some("twin"));
        assert_eq!(a.remap("inflow"), "/lab/q");
        assert_eq!(a.remap("bed_profile"), "bed_profile");
        assert_eq!(
            a.params,
            vec![
                ("target_real_time_factor".into(), ParamValue::Double(0.5)),
                ("publish_rate_hz".into(), ParamValue::Integer(2)),
                ("use_sim_time".into(), ParamValue::Bool(true)),
                ("frame_id".into(), ParamValue::String("flume".into())),
            ]
        );
    }

    #[test]
    fn bad_arguments_are_refused_by_name() {
        for (args, wanted) in [
            (vec!["-r", "inflow"], "expected NAME:=VALUE"),
            (vec!["-p"], "-p needs a value"),
            (
                vec!["--frobnicate"],
                "unsupported ROS argument \"--frobnicate\"",
            ),
        ] {
            let err = RosArgs::parse(&args).expect_err("refused").to_string();
            assert!(err.contains(wanted), "{args:?}: {err}");
        }
    }

    #[test]
    fn a_parameter_file_applies_to_this_node_and_the_command_line_wins() {
        let dir = std::env::temp_dir().join(format!("flume-ros-args-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let file = dir.join("params.yaml");
        std::fs::write(
            &file,
            "/**:\n  ros__parameters:\n    publish_rate_hz: 5\nflume_twin:\n  ros__parameters:\n    target_real_time_factor: 1.0\n    gauges:\n      p1_mount_height_m: 0.3\nother_node:\n  ros__parameters:\n    publish_rate_hz: 99\n",
        )
        .expect("writes");
        let a = RosArgs::parse(&[
            "--params-file",
            file.to_str().expect("utf-8"),
            "-p",
            "target_real_time_factor:=2.0",
        ])
        .expect("parses");
        let p = a.parameters("/flume/flume_twin").expect("reads");
        assert_eq!(
            p,
            vec![
                ("publish_rate_hz".into(), ParamValue::Integer(5)),
                ("target_real_time_factor".into(), ParamValue::Double(1.0)),
                ("gauges.p1_mount_height_m".into(), ParamValue::Double(0.3)),
                ("target_real_time_factor".into(), ParamValue::Double(2.0)),
            ]
        );
        std::fs::write(&file, "flume_twin:\n  publish_rate_hz: 5\n").expect("writes");
        let err = a.parameters("/flume_twin").expect_err("no ros__parameters");
        assert!(err.to_string().contains("no ros__parameters"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
