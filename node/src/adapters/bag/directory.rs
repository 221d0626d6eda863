//! rosbag2's bag directory: `DIR/metadata.yaml` beside `DIR/DIR_0.mcap`, as `ros2 bag record
//! -s mcap` leaves it, so that `ros2 bag info|play` and the `rosbags` library open what the
//! twin records. The metadata follows rosbag2 Jazzy (version 9: each topic's offered QoS as a
//! YAML list). It is written when the recording starts and again at each flush and at the
//! end, each time whole under a temporary name and then renamed over the last: a recording
//! killed part way keeps one that lists every topic and counts what its flushed chunks hold.

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use serde_norway::Value;
use std::path::{Path, PathBuf};

/// rosbag2 Jazzy's metadata version.
const VERSION: u32 = 9;

/// A path ending in `.mcap` is a bare MCAP file; anything else a bag directory.
pub fn is_bare_file(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

/// One topic of the bag as its metadata lists it.
struct Topic {
    name: String,
    type_name: String,
    offered_qos_profiles: String,
    count: u64,
}

/// What a bag directory's metadata says, kept up to date as messages are written.
pub struct BagMetadata {
    dir: PathBuf,
    file_name: String,
    topics: Vec<Topic>,
    /// Each channel id's topic, by index into `topics`.
    channel_topics: Vec<(u16, usize)>,
    first_ns: u64,
    last_ns: u64,
    count: u64,
}

impl BagMetadata {
    /// Creates the directory `dir` (which must not hold anything yet, as rosbag2 will not
    /// record into a used one) and its metadata; the MCAP file to write inside comes back.
    pub fn create(dir: &Path) -> Result<(BagMetadata, PathBuf)> {
        let Some(stem) = dir.file_name().and_then(|n| n.to_str()) else {
            bail!(
                "{}: a bag directory needs a name (its file is named after it)",
                dir.display()
            );
        };
        if std::fs::read_dir(dir).is_ok_and(|mut entries| entries.next().is_some()) {
            bail!(
                "{} already exists and is not empty: a recording goes to a new bag directory \
                 (or to a FILE.mcap)",
                dir.display()
            );
        }
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the bag directory {}", dir.display()))?;
        let file_name = format!("{stem}_0.mcap");
        let metadata = BagMetadata {
            dir: dir.to_path_buf(),
            file_name: file_name.clone(),
            topics: Vec::new(),
            channel_topics: Vec::new(),
            first_ns: u64::MAX,
            last_ns: 0,
            count: 0,
        };
        metadata.write()?;
        Ok((metadata, dir.join(file_name)))
    }

    /// Lists `channel`'s topic (once per topic and type).
    pub fn add_channel(&mut self, channel: u16, topic: &str, type_name: &str, qos: &str) {
        let k = match self
            .topics
            .iter()
            .position(|t| t.name == topic && t.type_name == type_name)
        {
            Some(k) => k,
            None => {
                self.topics.push(Topic {
                    name: topic.to_string(),
                    type_name: type_name.to_string(),
                    offered_qos_profiles: qos.to_string(),
                    count: 0,
                });
                self.topics.len() - 1
            }
        };
        self.channel_topics.push((channel, k));
    }

    /// Counts a message on `channel` logged at `log_ns`.
    pub fn count(&mut self, channel: u16, log_ns: u64) {
        if let Some(&(_, k)) = self.channel_topics.iter().find(|(c, _)| *c == channel) {
            self.topics[k].count += 1;
        }
        self.count += 1;
        self.first_ns = self.first_ns.min(log_ns);
        self.last_ns = self.last_ns.max(log_ns);
    }

    /// Writes `metadata.yaml` whole, replacing the last one only once it is complete.
    pub fn write(&self) -> Result<()> {
        let path = self.dir.join("metadata.yaml");
        let text = serde_norway::to_string(&self.document())
            .context("cannot write the bag's metadata as YAML")?;
        let tmp = self.dir.join("metadata.yaml.part");
        std::fs::write(&tmp, text)
            .and_then(|()| std::fs::rename(&tmp, &path))
            .with_context(|| format!("cannot write {}", path.display()))
    }

    fn document(&self) -> Document<'_> {
        let (start, duration) = if self.count == 0 {
            (0, 0)
        } else {
            (self.first_ns, self.last_ns - self.first_ns)
        };
        let topics = self
            .topics
            .iter()
            .map(|t| TopicWithCount {
                topic_metadata: TopicMetadata {
                    name: &t.name,
                    type_name: &t.type_name,
                    serialization_format: "cdr",
                    offered_qos_profiles: qos_list(&t.offered_qos_profiles),
                    type_description_hash: "",
                },
                message_count: t.count,
            })
            .collect();
        Document {
            rosbag2_bagfile_information: Information {
                version: VERSION,
                storage_identifier: "mcap",
                duration: Nanoseconds {
                    nanoseconds: duration,
                },
                starting_time: SinceEpoch {
                    nanoseconds_since_epoch: start,
                },
                message_count: self.count,
                topics_with_message_count: topics,
                compression_format: "",
                compression_mode: "",
                relative_file_paths: vec![&self.file_name],
                files: vec![FileInformation {
                    path: &self.file_name,
                    starting_time: SinceEpoch {
                        nanoseconds_since_epoch: start,
                    },
                    duration: Nanoseconds {
                        nanoseconds: duration,
                    },
                    message_count: self.count,
                }],
                custom_data: None,
                ros_distro: "jazzy",
            },
        }
    }
}

/// A channel's `offered_qos_profiles` (YAML text, as the MCAP channel holds it) as the
/// metadata's list; none where the text is not a list.
fn qos_list(text: &str) -> Value {
    match serde_norway::from_str::<Value>(text) {
        Ok(list @ Value::Sequence(_)) => list,
        _ => Value::Sequence(Vec::new()),
    }
}

#[derive(Serialize)]
struct Document<'a> {
    rosbag2_bagfile_information: Information<'a>,
}

/// rosbag2's `BagMetadata`, its fields in the order rosbag2 writes them.
#[derive(Serialize)]
struct Information<'a> {
    version: u32,
    storage_identifier: &'static str,
    duration: Nanoseconds,
    starting_time: SinceEpoch,
    message_count: u64,
    topics_with_message_count: Vec<TopicWithCount<'a>>,
    compression_format: &'static str,
    compression_mode: &'static str,
    relative_file_paths: Vec<&'a str>,
    files: Vec<FileInformation<'a>>,
    custom_data: Option<()>,
    ros_distro: &'static str,
}

#[derive(Serialize)]
struct Nanoseconds {
    nanoseconds: u64,
}

#[derive(Serialize)]
struct SinceEpoch {
    nanoseconds_since_epoch: u64,
}

#[derive(Serialize)]
struct TopicWithCount<'a> {
    topic_metadata: TopicMetadata<'a>,
    message_count: u64,
}

#[derive(Serialize)]
struct TopicMetadata<'a> {
    name: &'a str,
    #[serde(rename = "type")]
    type_name: &'a str,
    serialization_format: &'static str,
    offered_qos_profiles: Value,
    type_description_hash: &'static str,
}

#[derive(Serialize)]
struct FileInformation<'a> {
    path: &'a str,
    starting_time: SinceEpoch,
    duration: Nanoseconds,
    message_count: u64,
}

/// What a reader needs of any rosbag2 version's metadata.
#[derive(Deserialize)]
struct ReadDocument {
    rosbag2_bagfile_information: ReadInformation,
}

#[derive(Deserialize)]
struct ReadInformation {
    storage_identifier: String,
    relative_file_paths: Vec<String>,
}

/// The MCAP files of the bag directory `dir`, in order: those its metadata.yaml lists or,
/// without one, the single `.mcap` inside.
pub fn recordings_in(dir: &Path) -> Result<Vec<PathBuf>> {
    let yaml = dir.join("metadata.yaml");
    if yaml.exists() {
        let text = std::fs::read_to_string(&yaml)
            .with_context(|| format!("cannot read {}", yaml.display()))?;
        let doc: ReadDocument = serde_norway::from_str(&text).with_context(|| {
            format!(
                "{} is not rosbag2 metadata (rosbag2_bagfile_information with \
                 storage_identifier and relative_file_paths)",
                yaml.display()
            )
        })?;
        let info = doc.rosbag2_bagfile_information;
        if info.storage_identifier != "mcap" {
            bail!(
                "{}: the bag's storage is {:?}; only MCAP bags can be read",
                dir.display(),
                info.storage_identifier
            );
        }
        // As rosbag2 does: the files are named relative to the directory.
        let files: Vec<PathBuf> = info
            .relative_file_paths
            .iter()
            .filter_map(|p| Path::new(p).file_name().map(|n| dir.join(n)))
            .collect();
        if files.is_empty() {
            bail!("{} lists no file to read", yaml.display());
        }
        if let Some(missing) = files.iter().find(|f| !f.exists()) {
            bail!(
                "{} lists {}, which is not there",
                yaml.display(),
                missing.display()
            );
        }
        return Ok(files);
    }
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read the directory {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_bare_file(p) && p.is_file())
        .collect();
    found.sort();
    match found.len() {
        1 => Ok(found),
        0 => bail!(
            "{} is not a recording: it holds no metadata.yaml and no .mcap file",
            dir.display()
        ),
        n => bail!(
            "{} holds {n} .mcap files and no metadata.yaml to say which to read",
            dir.display()
        ),
    }
}
