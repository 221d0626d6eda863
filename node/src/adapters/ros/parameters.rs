//! The node's parameters as `ros2 param` sees them: declared from the settings, checked by
//! them (a refusal carries its reason), applied to the settings the twin reads, announced on
//! `/parameter_events`, and served through rcl_interfaces' six services in both request
//! mappings (see [`super::services`]). ros2-client's own parameter services answer only
//! Fast DDS's mapping, and its spinner, which serves them, subscribes `/clock` with a type
//! that clashes with the `/clock` the twin publishes; the node serves them itself instead.

use super::args::ParamValue;
use super::services::{Call, Mapping, Offered};
use crate::twin::settings::{Settings, describe};
use anyhow::Result;
use futures::stream::SelectAll;
use futures::{Stream, StreamExt};
use ros2_client::parameters::raw;
use ros2_client::rcl_interfaces::{
    DescribeParametersRequest, DescribeParametersResponse, GetParameterTypesRequest,
    GetParameterTypesResponse, GetParametersRequest, GetParametersResponse, ListParametersRequest,
    ListParametersResponse, ListParametersResult, SetParametersAtomicallyResponse,
    SetParametersRequest, SetParametersResponse,
};
use ros2_client::{Node, NodeOptions, ParameterValue, QosProfile, RmwRequestId, ServiceTypeName};
use std::pin::Pin;
use std::sync::{Arc, Mutex};

/// A parameter value from ROS as ours; arrays are none of our parameters.
fn from_ros(value: &ParameterValue) -> Option<ParamValue> {
    match value {
        ParameterValue::Boolean(b) => Some(ParamValue::Bool(*b)),
        ParameterValue::Integer(i) => Some(ParamValue::Integer(*i)),
        ParameterValue::Double(d) => Some(ParamValue::Double(*d)),
        ParameterValue::String(t) => Some(ParamValue::String(t.clone())),
        _ => None,
    }
}

/// One of our parameter values as ROS declares it.
fn to_ros(value: ParamValue) -> ParameterValue {
    match value {
        ParamValue::Bool(b) => ParameterValue::Boolean(b),
        ParamValue::Integer(i) => ParameterValue::Integer(i),
        ParamValue::Double(d) => ParameterValue::Double(d),
        ParamValue::String(t) => ParameterValue::String(t),
    }
}

fn locked(m: &Mutex<Settings>) -> std::sync::MutexGuard<'_, Settings> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// The node's options with its parameters declared: a set is checked against the settings
/// (refused with the reason) and then applied to the settings the twin reads.
pub fn live_parameters(options: NodeOptions, live: &Arc<Mutex<Settings>>) -> NodeOptions {
    let check = Arc::clone(live);
    let set = Arc::clone(live);
    let initial = locked(live).clone();
    let mut options = options.start_parameter_services(false);
    for (name, value) in initial.declared() {
        options = options.declare_parameter(&name, to_ros(value));
    }
    options
        .parameter_validator(Box::new(move |name, value| {
            let value =
                from_ros(value).ok_or_else(|| format!("{name}: arrays are not accepted"))?;
            locked(&check)
                .clone()
                .apply(name, &value)
                .map_err(|r| format!("{name}: {r}"))
        }))
        .parameter_set_action(Box::new(move |name, value| {
            let value =
                from_ros(value).ok_or_else(|| format!("{name}: arrays are not accepted"))?;
            locked(&set)
                .apply(name, &value)
                .map_err(|r| format!("{name}: {r}"))?;
            log::info!("parameter {name} set to {value:?}");
            Ok(())
        }))
}

/// A call to one of the parameter services.
pub enum Request {
    Get(GetParametersRequest),
    Types(GetParameterTypesRequest),
    Set(SetParametersRequest),
    SetAtomically(SetParametersRequest),
    List(ListParametersRequest),
    Describe(DescribeParametersRequest),
}

pub type ParameterCall = Call<Request>;
pub type ParameterStream<'a> = Pin<Box<dyn Stream<Item = ParameterCall> + Send + 'a>>;

/// rcl_interfaces' parameter services under the node's name.
pub struct ParameterServices {
    get: Offered<GetParametersRequest, GetParametersResponse>,
    types: Offered<GetParameterTypesRequest, GetParameterTypesResponse>,
    set: Offered<SetParametersRequest, SetParametersResponse>,
    set_atomically: Offered<SetParametersRequest, SetParametersAtomicallyResponse>,
    list: Offered<ListParametersRequest, ListParametersResponse>,
    describe: Offered<DescribeParametersRequest, DescribeParametersResponse>,
}

impl ParameterServices {
    pub fn create(node: &mut Node, node_path: &str) -> Result<Self> {
        // rclcpp's parameter services keep 1000 requests (rmw_qos_profile_parameters).
        let qos = QosProfile::publisher_default()
            .history(ros2_client::qos::History::KeepLast { depth: 1000 });
        let kind = |t| ServiceTypeName::new("rcl_interfaces", t);
        Ok(ParameterServices {
            get: Offered::create(
                node,
                node_path,
                "get_parameters",
                &kind("GetParameters"),
                &qos,
            )?,
            types: Offered::create(
                node,
                node_path,
                "get_parameter_types",
                &kind("GetParameterTypes"),
                &qos,
            )?,
            set: Offered::create(
                node,
                node_path,
                "set_parameters",
                &kind("SetParameters"),
                &qos,
            )?,
            set_atomically: Offered::create(
                node,
                node_path,
                "set_parameters_atomically",
                &kind("SetParametersAtomically"),
                &qos,
            )?,
            list: Offered::create(
                node,
                node_path,
                "list_parameters",
                &kind("ListParameters"),
                &qos,
            )?,
            describe: Offered::create(
                node,
                node_path,
                "describe_parameters",
                &kind("DescribeParameters"),
                &qos,
            )?,
        })
    }

    /// Every parameter call, whichever service and mapping.
    pub fn calls(&self) -> SelectAll<ParameterStream<'_>> {
        fn tag<'a, Q: Send + 'a>(
            s: impl Stream<Item = Call<Q>> + Send + 'a,
            wrap: fn(Q) -> Request,
        ) -> ParameterStream<'a> {
            Box::pin(s.map(move |c| Call {
                mapping: c.mapping,
                id: c.id,
                request: wrap(c.request),
            }))
        }
        futures::stream::select_all([
            tag(self.get.calls(), Request::Get),
            tag(self.types.calls(), Request::Types),
            tag(self.set.calls(), Request::Set),
            tag(self.set_atomically.calls(), Request::SetAtomically),
            tag(self.list.calls(), Request::List),
            tag(self.describe.calls(), Request::Describe),
        ])
    }

    /// Answers a call from the node's parameters; a set goes through the node, so it is
    /// checked, applied and announced on `/parameter_events`.
    pub async fn answer(&self, node: &Node, live: &Mutex<Settings>, call: ParameterCall) {
        let (m, id): (Mapping, RmwRequestId) = (call.mapping, call.id);
        match call.request {
            Request::Get(q) => {
                let values = q.names.iter().map(|n| value(node, n).into()).collect();
                self.get
                    .reply(m, id, GetParametersResponse { values })
                    .await
            }
            Request::Types(q) => {
                let values = q
                    .names
                    .iter()
                    .map(|n| ParameterValue::to_parameter_type_raw(&value(node, n)))
                    .collect();
                self.types
                    .reply(m, id, GetParameterTypesResponse { values })
                    .await
            }
            Request::Set(q) => {
                let results = q.parameter.into_iter().map(|p| set(node, p)).collect();
                self.set
                    .reply(m, id, SetParametersResponse { results })
                    .await
            }
            Request::SetAtomically(q) => {
                let result = set_atomically(node, live, q.parameter);
                let answer = SetParametersAtomicallyResponse { result };
                self.set_atomically.reply(m, id, answer).await
            }
            Request::List(q) => {
                let result = list(&node.list_parameters(), &q.prefixes, q.depth);
                self.list
                    .reply(m, id, ListParametersResponse { result })
                    .await
            }
            Request::Describe(q) => {
                let values = q.names.iter().map(|n| descriptor(node, n)).collect();
                self.describe
                    .reply(m, id, DescribeParametersResponse { values })
                    .await
            }
        }
    }
}

fn value(node: &Node, name: &str) -> ParameterValue {
    node.get_parameter(name).unwrap_or(ParameterValue::NotSet)
}

fn outcome(r: Result<(), String>) -> raw::SetParametersResult {
    let successful = r.is_ok();
    raw::SetParametersResult {
        successful,
        reason: r.err().unwrap_or_default(),
    }
}

fn set(node: &Node, p: raw::Parameter) -> raw::SetParametersResult {
    let value = ParameterValue::from(p.value);
    let r = node.set_parameter(&p.name, value);
    if let Err(reason) = &r {
        log::warn!("a parameter was refused: {reason}");
    }
    outcome(r)
}

/// All or none: every value is checked against one copy of the settings before any is set.
fn set_atomically(
    node: &Node,
    live: &Mutex<Settings>,
    params: Vec<raw::Parameter>,
) -> raw::SetParametersResult {
    let mut trial = locked(live).clone();
    for p in &params {
        let checked = from_ros(&ParameterValue::from(p.value.clone()))
            .ok_or_else(|| "arrays are not accepted".to_string())
            .and_then(|v| trial.apply(&p.name, &v));
        if let Err(reason) = checked {
            log::warn!("parameters refused together: {}: {reason}", p.name);
            return outcome(Err(format!("{}: {reason}", p.name)));
        }
    }
    outcome(
        params
            .into_iter()
            .try_for_each(|p| node.set_parameter(&p.name, p.value.into())),
    )
}

/// rclcpp's listing: with no prefixes, the names with fewer than `depth` dots (0: all);
/// else each name equal to a prefix, or under `prefix.` with fewer than `depth` dots after
/// the prefix, counting the one that follows it. `prefixes` returns the namespaces (up to
/// the last dot) of the names listed.
fn list(names: &[String], prefixes: &[String], depth: u64) -> ListParametersResult {
    let shallow = |s: &str| depth == 0 || (s.matches('.').count() as u64) < depth;
    let listed: Vec<String> = names
        .iter()
        .filter(|name| {
            (prefixes.is_empty() && shallow(name))
                || prefixes.iter().any(|prefix| {
                    *name == prefix
                        || name
                            .strip_prefix(prefix.as_str())
                            .is_some_and(|rest| rest.starts_with('.') && shallow(rest))
                })
        })
        .cloned()
        .collect();
    let mut spaces: Vec<String> = Vec::new();
    for space in listed
        .iter()
        .filter_map(|n| n.rsplit_once('.').map(|(s, _)| s))
    {
        if !spaces.iter().any(|s| s == space) {
            spaces.push(space.to_string());
        }
    }
    ListParametersResult {
        names: listed,
        prefixes: spaces,
    }
}

fn descriptor(node: &Node, name: &str) -> raw::ParameterDescriptor {
    let v = value(node, name);
    let (description, constraints) = match (&v, describe(name)) {
        (ParameterValue::NotSet, _) => ("not a parameter of flume_twin", ""),
        (_, Some(d)) => d,
        (_, None) => ("", ""),
    };
    raw::ParameterDescriptor {
        name: name.to_string(),
        r#type: ParameterValue::to_parameter_type_raw(&v),
        description: description.to_string(),
        additional_constraints: constraints.to_string(),
        read_only: false,
        dynamic_typing: false,
        floating_point_range: Vec::new(),
        integer_range: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::list;

    fn names() -> Vec<String> {
        [
            "frame_id",
            "gauge_mount_height_m.p1",
            "gauge_mount_height_m.p2",
            "a.b.c",
        ]
        .map(String::from)
        .to_vec()
    }

    #[test]
    fn listing_follows_rclcpp_s_prefix_and_depth_rules() {
        let all = list(&names(), &[], 0);
        assert_eq!(all.names, names());
        assert_eq!(all.prefixes, ["gauge_mount_height_m", "a.b"]);
        // depth 1: names without a dot; depth 2: at most one dot.
        assert_eq!(list(&names(), &[], 1).names, ["frame_id"]);
        assert_eq!(list(&names(), &[], 2).names.len(), 3);
        let under = list(&names(), &["gauge_mount_height_m".into()], 0);
        assert_eq!(
            under.names,
            ["gauge_mount_height_m.p1", "gauge_mount_height_m.p2"]
        );
        assert_eq!(under.prefixes, ["gauge_mount_height_m"]);
        // The dot after the prefix counts: depth 1 lists nothing under it, depth 2 one level.
        assert!(
            list(&names(), &["gauge_mount_height_m".into()], 1)
                .names
                .is_empty()
        );
        assert_eq!(list(&names(), &["a".into()], 2).names.len(), 0);
        assert_eq!(list(&names(), &["a".into()], 3).names, ["a.b.c"]);
        // A prefix matches whole segments only.
        assert!(list(&names(), &["gauge".into()], 0).names.is_empty());
        assert_eq!(list(&names(), &["frame_id".into()], 0).names, ["frame_id"]);
    }
}
