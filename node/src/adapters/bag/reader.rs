//! Reads a recording, or as much of one as is sound: a file cut short by a crash, or damaged
//! on the way, gives every message up to the damage and a sentence saying where it stopped.

use crate::adapters::bag::directory::recordings_in;
use anyhow::{Context, Result, bail};
use serde::de::DeserializeOwned;
use std::path::Path;

/// One message as recorded: its topic, its type's schema name and its CDR bytes.
#[derive(Debug, Clone)]
pub struct BagMessage {
    pub topic: String,
    pub schema_name: String,
    /// The definition the recording stores for the type.
    pub definition: std::sync::Arc<[u8]>,
    pub offered_qos_profiles: Option<String>,
    pub log_ns: u64,
    pub publish_ns: u64,
    pub data: Vec<u8>,
}

impl BagMessage {
    pub fn decode<M: DeserializeOwned>(&self) -> Result<M> {
        cdr::deserialize::<M>(&self.data).with_context(|| {
            format!(
                "a {} message on {} (logged at {} ns) is not valid CDR",
                self.schema_name, self.topic, self.log_ns
            )
        })
    }
}

/// The readable part of a recording.
#[derive(Debug)]
pub struct BagFile {
    pub messages: Vec<BagMessage>,
    /// Why reading stopped before the end, if it did.
    pub damage: Option<String>,
}

impl BagFile {
    /// Reads `path`: a bag directory (each MCAP file its metadata lists, or the one inside)
    /// or an MCAP file. A file that is not an MCAP recording at all is an error; one damaged
    /// part way is not: its readable part comes back with `damage` saying what stopped it.
    pub fn read(path: &Path) -> Result<BagFile> {
        if !path.is_dir() {
            return BagFile::read_file(path);
        }
        let mut bag = BagFile {
            messages: Vec::new(),
            damage: None,
        };
        for file in recordings_in(path)? {
            let part = BagFile::read_file(&file)?;
            bag.messages.extend(part.messages);
            // A split bag's later files follow the damage: none of them is read.
            if part.damage.is_some() {
                bag.damage = part.damage;
                break;
            }
        }
        Ok(bag)
    }

    fn read_file(path: &Path) -> Result<BagFile> {
        let bytes = std::fs::read(path)
            .with_context(|| format!("cannot read the recording {}", path.display()))?;
        if !bytes.starts_with(mcap::MAGIC) {
            bail!(
                "{} is not an MCAP recording (it does not start with MCAP's magic bytes)",
                path.display()
            );
        }
        let options = mcap::read::Options::IgnoreEndMagic | mcap::read::Options::ValidateChunkCrcs;
        let stream = mcap::MessageStream::new_with_options(&bytes, options)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let mut messages = Vec::new();
        let mut damage = None;
        let mut definitions: Vec<(u16, std::sync::Arc<[u8]>)> = Vec::new();
        for item in stream {
            match item {
                Ok(m) => {
                    let (schema_name, definition) = match &m.channel.schema {
                        Some(s) => {
                            let def = match definitions.iter().find(|(id, _)| *id == s.id) {
                                Some((_, d)) => d.clone(),
                                None => {
                                    let d: std::sync::Arc<[u8]> = s.data.as_ref().into();
                                    definitions.push((s.id, d.clone()));
                                    d
                                }
                            };
                            (s.name.clone(), def)
                        }
                        None => (String::new(), std::sync::Arc::from(&[][..])),
                    };
                    messages.push(BagMessage {
                        topic: m.channel.topic.clone(),
                        schema_name,
                        definition,
                        offered_qos_profiles: m
                            .channel
                            .metadata
                            .get("offered_qos_profiles")
                            .cloned(),
                        log_ns: m.log_time,
                        publish_ns: m.publish_time,
                        data: m.data.into_owned(),
                    });
                }
                Err(e) => {
                    let last = messages.last().map_or(String::new(), |m: &BagMessage| {
                        format!(" (the last logged at {} ns)", m.log_ns)
                    });
                    damage = Some(format!(
                        "{} is damaged: read {} messages{last}, then: {e}",
                        path.display(),
                        messages.len()
                    ));
                    break;
                }
            }
        }
        Ok(BagFile { messages, damage })
    }
}
