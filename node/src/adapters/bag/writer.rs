//! Writes a recording as rosbag2's MCAP storage plugin does: to a bag directory
//! (`directory.rs`) or, for a path ending in `.mcap`, to that file alone.
//!
//! Chunks are LZ4-compressed and close at 768 KiB (rosbag2's chunk size) or, when the writer
//! is asked to, at a flush every so often: a chunk is the unit a crash can lose, so a live
//! recording flushes each second and a `kill -9` costs at most the last second. LZ4 rather
//! than zstd because the writer shares the machine with the solver: it compresses at several
//! hundred MB/s per core, and the bed profiles and gauge series it sees are small and regular
//! enough that zstd's better ratio would buy little. After each flush the file ends as a
//! finished MCAP without a summary does (`tail.rs`), so that readers which start from the end
//! open a killed recording too.

use crate::adapters::bag::directory::{BagMetadata, is_bare_file};
use crate::adapters::bag::tail::Tail;
use anyhow::{Context, Result};
use flume_msgs::RosMessage;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// rosbag2's default chunk size for MCAP.
pub const CHUNK_BYTES: u64 = 768 * 1024;

/// The QoS a topic is offered with, as the recording stores it for `ros2 bag play`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TopicQos {
    pub reliable: bool,
    pub transient_local: bool,
    pub depth: usize,
}

impl TopicQos {
    /// rosbag2's `offered_qos_profiles` channel metadata: a YAML list of one profile, in the
    /// names Jazzy writes. Zero durations are the middleware's defaults (no deadline, no
    /// lifespan, no lease).
    pub fn offered_qos_profiles(&self) -> String {
        let zero = "\n    sec: 0\n    nsec: 0";
        format!(
            "- history: keep_last\n  depth: {}\n  reliability: {}\n  durability: {}\n  \
             deadline:{zero}\n  lifespan:{zero}\n  liveliness: automatic\n  \
             liveliness_lease_duration:{zero}\n  avoid_ros_namespace_conventions: false",
            self.depth,
            if self.reliable {
                "reliable"
            } else {
                "best_effort"
            },
            if self.transient_local {
                "transient_local"
            } else {
                "volatile"
            },
        )
    }
}

/// A channel of the recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Channel(u16);

pub struct BagWriter {
    /// The bag directory or the bare file.
    path: PathBuf,
    mcap: mcap::Writer<Tail>,
    /// A bag directory's metadata; none for a bare file.
    metadata: Option<BagMetadata>,
    sequence: u32,
    flush_every: Option<Duration>,
    last_flush: Instant,
}

impl BagWriter {
    /// Creates the bag directory `path`, or the file `path` if it ends in `.mcap`; with
    /// `flush_every`, a chunk closes at least that often.
    pub fn create(path: &Path, flush_every: Option<Duration>) -> Result<BagWriter> {
        let (metadata, file_path) = if is_bare_file(path) {
            (None, path.to_path_buf())
        } else {
            let (metadata, file) = BagMetadata::create(path)?;
            (Some(metadata), file)
        };
        let file = File::create(&file_path)
            .with_context(|| format!("cannot create {}", file_path.display()))?;
        let mcap = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("flume-twin ", env!("CARGO_PKG_VERSION")))
            .compression(Some(mcap::Compression::Lz4))
            .chunk_size(Some(CHUNK_BYTES))
            .create(Tail::new(file))
            .with_context(|| format!("cannot start the recording {}", path.display()))?;
        let mut writer = BagWriter {
            path: path.to_path_buf(),
            mcap,
            metadata,
            sequence: 0,
            flush_every,
            last_flush: Instant::now(),
        };
        // From the start the file is an MCAP that readers open, if an empty one.
        writer.flush()?;
        Ok(writer)
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// A channel for messages of type `M` on `topic`.
    pub fn channel<M: RosMessage>(&mut self, topic: &str, qos: TopicQos) -> Result<Channel> {
        self.raw_channel(
            topic,
            &M::DEF.schema_name(),
            M::DEF.full_text().as_bytes(),
            &qos.offered_qos_profiles(),
        )
    }

    /// A channel whose schema and QoS come from elsewhere (another recording).
    pub fn raw_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        definition: &[u8],
        offered_qos_profiles: &str,
    ) -> Result<Channel> {
        let schema = self
            .mcap
            .add_schema(schema_name, "ros2msg", definition)
            .with_context(|| format!("cannot add schema {schema_name}"))?;
        let metadata = BTreeMap::from([(
            "offered_qos_profiles".to_string(),
            offered_qos_profiles.to_string(),
        )]);
        let id = self
            .mcap
            .add_channel(schema, topic, "cdr", &metadata)
            .with_context(|| format!("cannot add channel {topic}"))?;
        if let Some(m) = self.metadata.as_mut() {
            m.add_channel(id, topic, schema_name, offered_qos_profiles);
        }
        Ok(Channel(id))
    }

    /// Writes `msg` in CDR, received (`log_ns`) and sent (`publish_ns`) at those times, ns
    /// since the epoch.
    pub fn write<M: Serialize>(
        &mut self,
        channel: Channel,
        msg: &M,
        log_ns: u64,
        publish_ns: u64,
    ) -> Result<()> {
        let data = cdr::serialize::<_, _, cdr::CdrLe>(msg, cdr::Infinite)
            .context("cannot encode a message as CDR")?;
        self.write_raw(channel, &data, log_ns, publish_ns)
    }

    /// Writes a message already in CDR.
    pub fn write_raw(
        &mut self,
        channel: Channel,
        data: &[u8],
        log_ns: u64,
        publish_ns: u64,
    ) -> Result<()> {
        self.sequence = self.sequence.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id: channel.0,
            sequence: self.sequence,
            log_time: log_ns,
            publish_time: publish_ns,
        };
        self.mcap
            .write_to_known_channel(&header, data)
            .with_context(|| format!("cannot write to {}", self.path.display()))?;
        if let Some(m) = self.metadata.as_mut() {
            m.count(channel.0, log_ns);
        }
        if self
            .flush_every
            .is_some_and(|every| self.last_flush.elapsed() >= every)
        {
            self.flush()?;
        }
        Ok(())
    }

    /// Closes the open chunk and hands it to the operating system: what a crash cannot take.
    /// A bag directory's metadata then counts what the file holds.
    pub fn flush(&mut self) -> Result<()> {
        self.last_flush = Instant::now();
        self.mcap
            .flush()
            .with_context(|| format!("cannot flush {}", self.path.display()))?;
        self.metadata.as_ref().map_or(Ok(()), BagMetadata::write)
    }

    /// Writes the summary and the footer, and a bag directory's metadata; without them a
    /// reader still gets every flushed chunk.
    pub fn finish(mut self) -> Result<()> {
        self.mcap
            .finish()
            .with_context(|| format!("cannot finish {}", self.path.display()))?;
        self.mcap
            .into_inner()
            .close()
            .with_context(|| format!("cannot finish {}", self.path.display()))?;
        self.metadata.as_ref().map_or(Ok(()), BagMetadata::write)
    }
}

/// Nanoseconds since the epoch of `t_s` seconds (0 before the epoch).
pub fn nanos(t_s: f64) -> u64 {
    if t_s.is_finite() && t_s > 0.0 {
        (t_s * 1e9).round() as u64
    } else {
        0
    }
}
