//! The recording's file as the MCAP writer sees it, kept readable through a `kill -9`.
//!
//! A finished MCAP ends with a summary, a footer and the closing magic bytes; a recording
//! killed part way ends wherever its last write stopped. Readers that scan the file (ours,
//! Python's `mcap`) still read it up to its last whole chunk, but readers that go to the end
//! first (`rosbags`, and through it a bag directory) refuse it. So each flush writes what came
//! since the last one followed by a provisional end (a DataEnd record, a Footer pointing at no
//! summary, the magic) in one write, and keeps what comes next in memory until the following
//! flush writes over that end. Between flushes the file on disk is a whole MCAP without a
//! summary; finishing writes the real end over the provisional one.

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};
use std::os::unix::fs::FileExt;

/// DataEnd (no CRC), Footer (no summary, no CRC), then the magic: an MCAP's end for a file
/// that has no summary section.
const PROVISIONAL_END: [u8; 50] = {
    let mut end = [0u8; 50];
    // DataEnd: opcode 0x0F, length 4, data_section_crc 0 (none computed).
    end[0] = 0x0f;
    end[1] = 4;
    // Footer at 13: opcode 0x02, length 20, summary_start 0, summary_offset_start 0, crc 0.
    end[13] = 0x02;
    end[14] = 20;
    let magic = b"\x89MCAP0\r\n";
    let mut k = 0;
    while k < 8 {
        end[42 + k] = magic[k];
        k += 1;
    }
    end
};

/// What a writer that never flushes (a replay's output) may hold in memory before it is
/// written out without an end: such a file is only promised whole once finished.
const MOST_HELD: usize = 8 << 20;

pub struct Tail {
    file: File,
    /// The stream from `committed` on, not yet in the file.
    held: Vec<u8>,
    /// How much of the stream is in the file.
    committed: u64,
    /// Where the next write goes in the stream.
    position: u64,
}

impl Tail {
    pub fn new(file: File) -> Tail {
        Tail {
            file,
            held: Vec::new(),
            committed: 0,
            position: 0,
        }
    }

    fn len(&self) -> u64 {
        self.committed + self.held.len() as u64
    }

    /// Writes what is held at the end of the file, with the provisional end after it or not.
    fn commit(&mut self, with_end: bool) -> io::Result<()> {
        let held = self.held.len();
        if with_end {
            self.held.extend_from_slice(&PROVISIONAL_END);
        }
        // One write, so that a kill leaves either the old end or the new one whole, bar a
        // write the kernel cuts short.
        let written = self.file.write_all_at(&self.held, self.committed);
        self.held.truncate(held);
        written?;
        self.committed += held as u64;
        self.held.clear();
        Ok(())
    }

    /// Writes what is held and drops any provisional end after it: the file is the stream,
    /// as finished.
    pub fn close(&mut self) -> io::Result<()> {
        self.commit(false)?;
        self.file.set_len(self.committed)
    }
}

impl Drop for Tail {
    /// The MCAP writer finishes the file when it is dropped; this writes that out.
    fn drop(&mut self) {
        let _ = self.close();
    }
}

impl Write for Tail {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let mut buf = buf;
        let written = buf.len();
        // A chunk's header is written again once the chunk is done; its start may already be
        // in the file when the chunk outgrew what is held.
        if self.position < self.committed {
            let n = buf.len().min((self.committed - self.position) as usize);
            self.file.write_all_at(&buf[..n], self.position)?;
            self.position += n as u64;
            buf = &buf[n..];
        }
        if !buf.is_empty() {
            let at = (self.position - self.committed) as usize;
            if self.held.len() < at {
                self.held.resize(at, 0);
            }
            let overlap = (self.held.len() - at).min(buf.len());
            self.held[at..at + overlap].copy_from_slice(&buf[..overlap]);
            self.held.extend_from_slice(&buf[overlap..]);
            self.position += buf.len() as u64;
        }
        if self.held.len() > MOST_HELD {
            self.commit(false)?;
        }
        Ok(written)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.commit(true)
    }
}

impl Seek for Tail {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        let at = match to {
            SeekFrom::Start(n) => Some(n),
            SeekFrom::End(d) => self.len().checked_add_signed(d),
            SeekFrom::Current(d) => self.position.checked_add_signed(d),
        };
        self.position = at.ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidInput, "seek before the file's start")
        })?;
        Ok(self.position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    fn temp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("flume-tail-{}-{name}", std::process::id()))
    }

    fn on_disk(path: &std::path::Path) -> Vec<u8> {
        let mut bytes = Vec::new();
        File::open(path)
            .and_then(|mut f| f.read_to_end(&mut bytes))
            .expect("reads");
        bytes
    }

    #[test]
    fn the_file_ends_provisionally_after_each_flush_and_exactly_when_closed() {
        let path = temp("stream");
        let mut tail = Tail::new(File::create(&path).expect("creates"));
        tail.write_all(b"0123456789").expect("writes");
        assert!(on_disk(&path).is_empty(), "held until a flush");
        tail.flush().expect("flushes");
        assert_eq!(
            on_disk(&path),
            [&b"0123456789"[..], &PROVISIONAL_END].concat()
        );
        // A header written again over the start of what is already in the file, and a
        // record appended after a seek to the end, as the MCAP writer does with a chunk.
        tail.write_all(b"abc").expect("writes");
        tail.seek(SeekFrom::Start(8)).expect("seeks");
        tail.write_all(b"XYZ").expect("writes");
        assert_eq!(tail.seek(SeekFrom::End(0)).expect("seeks"), 13);
        tail.write_all(b"!").expect("writes");
        tail.flush().expect("flushes");
        assert_eq!(
            on_disk(&path),
            [&b"01234567XYZbc!"[..], &PROVISIONAL_END].concat()
        );
        tail.write_all(b"end").expect("writes");
        tail.close().expect("closes");
        assert_eq!(on_disk(&path), b"01234567XYZbc!end");
        std::fs::remove_file(&path).ok();
    }
}
