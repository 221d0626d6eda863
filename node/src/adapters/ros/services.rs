//! A service as every ROS 2 DDS middleware calls it. rmw_fastrtps (the default) and
//! ros2-client carry a request's id in the sample's inline QoS; rmw_cyclonedds puts a 16-byte
//! header (its client's id and sequence number) at the start of the payload and drops any reply
//! without that header echoed. One ros2-client server answers one of these mappings, so each
//! service is offered twice on the same topics, and each request is answered once, by the
//! server of its client's mapping.

use anyhow::{Context as _, Result, anyhow};
use futures::{Stream, StreamExt};
use ros2_client::{
    Message, Name, Node, QosProfile, RmwRequestId, Server, ServiceMapping, ServiceTypeName,
};
use std::fmt::Debug;

/// How a request's id travelled, so its reply goes back the same way.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mapping {
    /// Inline QoS (rmw_fastrtps, ros2-client, RTI's "extended" mapping).
    Enhanced,
    /// The payload header of rmw_cyclonedds.
    Cyclone,
}

/// One call: how it came, its id, what it asks.
#[derive(Debug)]
pub struct Call<Q> {
    pub mapping: Mapping,
    pub id: RmwRequestId,
    pub request: Q,
}

/// Eclipse Cyclone DDS's vendor id, the first two bytes of every GUID its participants make.
const CYCLONE_VENDOR: [u8; 2] = [0x01, 0x10];

/// Whether the client that sent a request runs on Cyclone DDS. Both mappings keep the client
/// participant's GUID prefix in the id, and its first two bytes name the DDS vendor.
fn from_cyclone(id: &RmwRequestId) -> bool {
    id.writer_gid.to_bytes16()[..2] == CYCLONE_VENDOR
}

/// A service offered in both mappings.
pub struct Offered<Q: Message, A: Message> {
    name: String,
    enhanced: Server<Q, A>,
    cyclone: Server<Q, A>,
}

impl<Q, A> Offered<Q, A>
where
    Q: Message + Clone + Debug + Send + Sync + 'static,
    A: Message + Send + Sync + 'static,
{
    /// Service `name` under node path `node_path` (`/ns/node`), of type `kind`.
    pub fn create(
        node: &mut Node,
        node_path: &str,
        name: &str,
        kind: &ServiceTypeName,
        qos: &QosProfile,
    ) -> Result<Self> {
        let full = Name::new(node_path, name).map_err(|e| anyhow!("service {name}: {e}"))?;
        let mut server = |mapping| {
            node.create_server::<Q, A>(mapping, &full, kind, qos.clone(), qos.clone())
                .with_context(|| format!("cannot offer the {name} service"))
        };
        Ok(Offered {
            name: name.to_string(),
            enhanced: server(ServiceMapping::Enhanced)?,
            cyclone: server(ServiceMapping::Cyclone)?,
        })
    }

    /// Every call, whichever mapping it came in. Each server also sees the other mapping's
    /// requests: read with the wrong layout they either fail to decode or decode into
    /// nonsense, and the vendor of the client tells which server answers. A request no
    /// server can read is logged and dropped; its client's call times out, as with rclcpp.
    pub fn calls(&self) -> impl Stream<Item = Call<Q>> + Send + '_ {
        let keep = move |mapping: Mapping| {
            move |r: ros2_client::ReadResult<(RmwRequestId, Q)>| {
                let call = match r {
                    Ok((id, request)) => ((mapping == Mapping::Cyclone) == from_cyclone(&id))
                        .then_some(Call {
                            mapping,
                            id,
                            request,
                        }),
                    Err(e) => {
                        log::debug!("{} ({mapping:?}): a request not read: {e:?}", self.name);
                        None
                    }
                };
                futures::future::ready(call)
            }
        };
        futures::stream::select(
            self.enhanced
                .receive_request_stream()
                .filter_map(keep(Mapping::Enhanced)),
            self.cyclone
                .receive_request_stream()
                .filter_map(keep(Mapping::Cyclone)),
        )
    }

    /// Answers `call` in its mapping; a reply that cannot be sent is logged.
    pub async fn reply(&self, mapping: Mapping, id: RmwRequestId, answer: A) {
        let server = match mapping {
            Mapping::Enhanced => &self.enhanced,
            Mapping::Cyclone => &self.cyclone,
        };
        if let Err(e) = server.async_send_response(id, answer).await {
            log::warn!("the {} reply could not be sent: {e:?}", self.name);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ros2_client::Gid;

    fn id(first: [u8; 2]) -> RmwRequestId {
        let mut gid = [7u8; 16];
        gid[..2].copy_from_slice(&first);
        RmwRequestId {
            writer_gid: Gid::from(gid),
            sequence_number: 1,
        }
    }

    #[test]
    fn only_cyclone_s_vendor_id_is_a_cyclone_client() {
        assert!(from_cyclone(&id([0x01, 0x10])));
        // eProsima (Fast DDS), RustDDS (ros2-client), RTI Connext
        for other in [[0x01, 0x0f], [0x01, 0x12], [0x01, 0x01]] {
            assert!(!from_cyclone(&id(other)), "{other:?}");
        }
    }
}
