//! Reads a recording, or as much of one as is sound: a file cut short by a crash, or damaged
//! on the way, gives every message up to the damage and a sentence saying where it stopped.

use crate::adapters::bag::directory::recordings_in;
use anyhow::{Context, Result, bail};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use serde::de::DeserializeOwned;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

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
        let mut records = Records::default();
        let damage = records.read(&bytes).err().map(|e| {
            let last = records.messages.last().map_or(String::new(), |m| {
                format!(" (the last logged at {} ns)", m.log_ns)
            });
            format!(
                "{} is damaged: read {} messages{last}, then: {e}",
                path.display(),
                records.messages.len()
            )
        });
        Ok(BagFile {
            messages: records.messages,
            damage,
        })
    }
}

/// The longest record, or decompressed chunk, a recording may hold. The recorder closes a
/// chunk every second, a few hundred kB of the twin's topics; the file's own length is no
/// bound, since a chunk decompresses to more than it takes (a recording killed part way held a
/// chunk that decompresses to 61 kB, more than the whole file).
const RECORD_LIMIT_BYTES: usize = 1 << 30;

/// The schemas, channels and messages of one file, as its records are read.
#[derive(Default)]
struct Records {
    /// Schema id: its name and definition.
    schemas: HashMap<u16, (String, Arc<[u8]>)>,
    channels: HashMap<u16, mcap::records::Channel>,
    messages: Vec<BagMessage>,
}

impl Records {
    /// Reads `bytes` up to the data section's end, or to the first damage, which it returns.
    /// Each chunk's CRC is checked before any of its records is used, and no record or
    /// decompressed chunk may claim more than [`RECORD_LIMIT_BYTES`]: a flipped bit in a
    /// chunk's compressed records once decompressed into a record length of 249 GB, and the
    /// reader that trusted it aborted.
    fn read(&mut self, bytes: &[u8]) -> Result<(), mcap::McapError> {
        let options = LinearReaderOptions::default()
            .with_skip_end_magic(true)
            .with_validate_chunk_crcs(true)
            .with_prevalidate_chunk_crcs(true)
            .with_record_length_limit(RECORD_LIMIT_BYTES);
        let mut reader = LinearReader::new_with_options(options);
        let mut rest = bytes;
        while let Some(event) = reader.next_event() {
            let wanted = match event? {
                LinearReadEvent::ReadRequest(n) => n.min(rest.len()),
                LinearReadEvent::Record { data, opcode } => {
                    if !self.add(mcap::parse_record(opcode, data)?)? {
                        return Ok(());
                    }
                    continue;
                }
            };
            reader.insert(wanted).copy_from_slice(&rest[..wanted]);
            reader.notify_read(wanted);
            rest = &rest[wanted..];
        }
        Ok(())
    }

    /// Takes one record; false at the data section's end. A channel whose schema was never
    /// declared, or a message on a channel never declared, is damage, as mcap's own reader
    /// has it: neither can be given a type or a topic.
    fn add(&mut self, record: mcap::records::Record<'_>) -> Result<bool, mcap::McapError> {
        use mcap::McapError;
        use mcap::records::Record;
        match record {
            Record::Schema { header, data } => {
                self.schemas
                    .entry(header.id)
                    .or_insert_with(|| (header.name, data.as_ref().into()));
            }
            Record::Channel(channel) => {
                // Schema 0 is "no schema".
                if channel.schema_id != 0 && !self.schemas.contains_key(&channel.schema_id) {
                    return Err(McapError::UnknownSchema(channel.topic, channel.schema_id));
                }
                self.channels.insert(channel.id, channel);
            }
            Record::Message { header, data } => {
                let Some(channel) = self.channels.get(&header.channel_id) else {
                    return Err(McapError::UnknownChannel(
                        header.sequence,
                        header.channel_id,
                    ));
                };
                let (schema_name, definition) = self
                    .schemas
                    .get(&channel.schema_id)
                    .cloned()
                    .unwrap_or_else(|| (String::new(), Arc::from(&[][..])));
                self.messages.push(BagMessage {
                    topic: channel.topic.clone(),
                    schema_name,
                    definition,
                    offered_qos_profiles: channel.metadata.get("offered_qos_profiles").cloned(),
                    log_ns: header.log_time,
                    publish_ns: header.publish_time,
                    data: data.into_owned(),
                });
            }
            Record::DataEnd(_) => return Ok(false),
            _ => {}
        }
        Ok(true)
    }
}
