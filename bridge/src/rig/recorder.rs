//! The rig log: everything that crossed a wire (poses in, commands out, telemetry in, displayed frames'
//! hashes, safety events), timestamped, as MCAP (Foxglove and the `mcap` CLI open it). Messages are
//! written unchunked and flushed every tick, so a killed run keeps all but its last moments.
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// What a message is; each topic is one MCAP channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Topic {
    /// Poses as the loop took them, our frame: JSON `[{"id", "x", "y", "heading", "age", "fresh"}]`
    /// (age: s since capture, from the tracker's clock as estimated here).
    Poses,
    /// A command frame as sent to the link, the bytes on the wire.
    Commands,
    /// A telemetry frame as received, the bytes on the wire.
    Telemetry,
    /// A displayed frame: JSON `{"tick", "width", "height", "fnv1a"}`.
    Frames,
    /// Safety stops, reconnections, overruns: JSON `{"kind", "robot", "detail"}`.
    Events,
    /// The end of a loop tick: JSON `{"tick", "t", "step", "stopped", "commands"}`: its time since the
    /// start and the time the fields advanced (s), the robots the watchdog held stopped, and how many
    /// command frames the tick sent (the `/commands` messages just before). With the poses and
    /// telemetry before it, everything a replay needs to give the same command bytes again.
    Ticks,
    /// A stop frame the watchdog or the exit guard sent, the bytes on the wire.
    Stops,
}

impl Topic {
    pub const ALL: [Topic; 7] = [
        Topic::Poses,
        Topic::Commands,
        Topic::Telemetry,
        Topic::Frames,
        Topic::Events,
        Topic::Ticks,
        Topic::Stops,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Topic::Poses => "/poses",
            Topic::Commands => "/commands",
            Topic::Telemetry => "/telemetry",
            Topic::Frames => "/frames",
            Topic::Events => "/events",
            Topic::Ticks => "/ticks",
            Topic::Stops => "/stops",
        }
    }
    fn encoding(self) -> &'static str {
        match self {
            Topic::Commands | Topic::Telemetry | Topic::Stops => "application/octet-stream",
            _ => "json",
        }
    }
    fn from_name(name: &str) -> Option<Topic> {
        Topic::ALL.into_iter().find(|t| t.name() == name)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum RecorderError {
    #[error("rig log {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("rig log: {0}")]
    Mcap(#[from] mcap::McapError),
}

pub struct Recorder {
    writer: mcap::Writer<BufWriter<File>>,
    channels: [u16; 7],
    sequence: u32,
}

impl Recorder {
    /// A new log at `path` (replacing any file there).
    pub fn create(path: &Path) -> Result<Recorder, RecorderError> {
        let file = File::create(path).map_err(|source| RecorderError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let mut writer = mcap::WriteOptions::new()
            .use_chunks(false)
            .compression(None)
            .profile("")
            .create(BufWriter::new(file))?;
        let mut channels = [0u16; 7];
        for (c, topic) in channels.iter_mut().zip(Topic::ALL) {
            *c = writer.add_channel(0, topic.name(), topic.encoding(), &BTreeMap::new())?;
        }
        Ok(Recorder {
            writer,
            channels,
            sequence: 0,
        })
    }

    /// Records `data` on `topic` at `t_ns` ns since the Unix epoch.
    pub fn record(&mut self, topic: Topic, t_ns: u64, data: &[u8]) -> Result<(), RecorderError> {
        let channel_id = self.channels[Topic::ALL.iter().position(|t| *t == topic).unwrap_or(0)];
        self.sequence = self.sequence.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: t_ns,
            publish_time: t_ns,
        };
        self.writer.write_to_known_channel(&header, data)?;
        Ok(())
    }

    /// Writes a metadata record `name` of key-value strings (what the run ran with).
    pub fn write_metadata(
        &mut self,
        name: &str,
        values: BTreeMap<String, String>,
    ) -> Result<(), RecorderError> {
        self.writer.write_metadata(&mcap::records::Metadata {
            name: name.into(),
            metadata: values,
        })?;
        Ok(())
    }

    /// Pushes everything recorded so far to the file.
    pub fn flush(&mut self) -> Result<(), RecorderError> {
        self.writer.flush()?;
        Ok(())
    }

    /// Writes the summary and closes the log.
    pub fn finish(mut self) -> Result<(), RecorderError> {
        self.writer.finish()?;
        Ok(())
    }
}

/// One message of a rig log.
#[derive(Clone, Debug, PartialEq)]
pub struct Recorded {
    pub topic: Topic,
    pub t_ns: u64,
    pub data: Vec<u8>,
}

/// Every message of the log `bytes`, in file order; a log cut short by a killed run yields the
/// messages before the cut.
pub fn read_log(bytes: &[u8]) -> Vec<Recorded> {
    let options = mcap::read::Options::IgnoreEndMagic.into();
    let Ok(stream) = mcap::MessageStream::new_with_options(bytes, options) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for message in stream {
        let Ok(m) = message else { break };
        if let Some(topic) = Topic::from_name(&m.channel.topic) {
            out.push(Recorded {
                topic,
                t_ns: m.log_time,
                data: m.data.into_owned(),
            });
        }
    }
    out
}

/// The metadata records of the log `bytes` (name, key-value strings), in file order; a log cut short
/// yields those before the cut.
pub fn read_metadata(bytes: &[u8]) -> Vec<(String, BTreeMap<String, String>)> {
    let options = mcap::read::Options::IgnoreEndMagic.into();
    let Ok(reader) = mcap::read::LinearReader::new_with_options(bytes, options) else {
        return Vec::new();
    };
    reader
        .map_while(|r| r.ok())
        .filter_map(|r| match r {
            mcap::records::Record::Metadata(m) => Some((m.name, m.metadata)),
            _ => None,
        })
        .collect()
}

/// FNV-1a (64-bit) of a frame's bytes, for the log.
pub(crate) fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_come_back_in_order_also_from_a_log_cut_short() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rig.mcap");
        let mut rec = Recorder::create(&path).unwrap();
        for k in 0..50u64 {
            rec.record(Topic::Commands, k * 1000, &[1, 0xFE, k as u8, 0xFE, 1])
                .unwrap();
            rec.record(Topic::Poses, k * 1000 + 1, b"{}").unwrap();
        }
        rec.flush().unwrap();
        // A killed run: the file as flushed, without the summary.
        let cut = std::fs::read(&path).unwrap();
        rec.finish().unwrap();
        let whole = std::fs::read(&path).unwrap();
        for bytes in [&whole, &cut] {
            let log = read_log(bytes);
            assert_eq!(log.len(), 100);
            assert_eq!(log[4].topic, Topic::Commands);
            assert_eq!(log[4].data, vec![1, 0xFE, 2, 0xFE, 1]);
            assert_eq!(log[5].topic, Topic::Poses);
            assert_eq!(log[5].t_ns, 2001);
        }
    }

    #[test]
    fn metadata_comes_back_beside_the_messages() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rig.mcap");
        let mut rec = Recorder::create(&path).unwrap();
        let values: BTreeMap<String, String> = [("rig_latency".to_string(), "0.031".to_string())]
            .into_iter()
            .collect();
        rec.write_metadata("rig", values.clone()).unwrap();
        rec.record(Topic::Poses, 5, b"{}").unwrap();
        rec.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(read_metadata(&bytes), vec![("rig".to_string(), values)]);
        assert_eq!(read_log(&bytes).len(), 1);
    }
}
