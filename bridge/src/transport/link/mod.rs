//! Robot links behind one trait: commands go out through an airtime scheduler, telemetry comes back
//! through a resynchronising frame decoder, over a serial port or UDP.

mod scheduler;
mod serial;
mod udp;

pub use scheduler::{AirtimeScheduler, SchedulerCounters};
pub use serial::SerialWire;
use udp::UdpWire;

use super::url::{LinkUrl, UrlError};
use crate::protocol::colias::{CommandPacket, Telemetry, TelemetryDecoder};
use std::time::Instant;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum LinkError {
    #[error(transparent)]
    Url(#[from] UrlError),
    #[error("serial port: {0}")]
    Serial(#[from] serialport::Error),
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// Writing to or reading from an open link failed; `link` is its URL.
    #[error("robot link {link}: {error}")]
    Wire { link: String, error: std::io::Error },
}

/// Running totals of a link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkCounters {
    pub scheduler: SchedulerCounters,
    /// Commands waiting for airtime.
    pub pending: usize,
    pub bytes_in: u64,
    pub telemetry: u64,
    /// Received bytes that were not part of a valid telemetry frame.
    pub skipped_bytes: u64,
}

/// The robots as the live loop sees them. Nothing blocks for longer than one frame's write.
pub trait RobotLink: Send {
    /// Queues a command; an unsent older command for the same robot is replaced.
    fn send(&mut self, packet: CommandPacket);
    /// Writes what the airtime budget allows now and reads whatever has arrived; returns the number
    /// of frames written. Call it every tick.
    fn pump(&mut self) -> Result<usize, LinkError>;
    /// Telemetry decoded since the last call.
    fn take_telemetry(&mut self) -> Vec<Telemetry>;
    fn counters(&self) -> LinkCounters;
    /// Writes `packet` (a stop) at once, ahead of the airtime schedule, and drops every queued
    /// command: a robot that was stopped must not be restarted by a command queued before the stop.
    fn stop_now(&mut self, packet: CommandPacket) -> Result<(), LinkError>;
}

/// A byte channel to the robots.
pub trait Wire: Send {
    /// Writes one whole frame.
    fn write_frame(&mut self, frame: &[u8]) -> std::io::Result<()>;
    /// Appends whatever bytes are available without waiting.
    fn read_available(&mut self, buf: &mut Vec<u8>) -> std::io::Result<()>;
}

/// The [`RobotLink`] over any [`Wire`].
pub struct Link<W: Wire> {
    wire: W,
    scheduler: AirtimeScheduler,
    decoder: TelemetryDecoder,
    rx: Vec<u8>,
    telemetry: Vec<Telemetry>,
    bytes_in: u64,
    received: u64,
    /// What its errors call it (the URL it was opened from).
    name: String,
}

/// Telemetry kept for the live loop if it stops reading: about ten seconds of a full channel.
const MAX_TELEMETRY: usize = 1024;

impl<W: Wire> Link<W> {
    pub fn new(wire: W, scheduler: AirtimeScheduler) -> Self {
        Link {
            wire,
            scheduler,
            decoder: TelemetryDecoder::new(),
            rx: Vec::new(),
            telemetry: Vec::new(),
            bytes_in: 0,
            received: 0,
            name: "(unnamed)".into(),
        }
    }

    /// The link, its errors naming it `name` (the URL it was opened from).
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }

    fn wire_err(&self, error: std::io::Error) -> LinkError {
        LinkError::Wire {
            link: self.name.clone(),
            error,
        }
    }

    pub fn wire_mut(&mut self) -> &mut W {
        &mut self.wire
    }
}

impl<W: Wire> RobotLink for Link<W> {
    fn send(&mut self, packet: CommandPacket) {
        self.scheduler.submit(packet);
    }

    fn pump(&mut self) -> Result<usize, LinkError> {
        let mut written = 0;
        while let Some(p) = self.scheduler.next_due(Instant::now()) {
            let frame = p.to_frame();
            self.wire
                .write_frame(&frame)
                .map_err(|e| self.wire_err(e))?;
            written += 1;
        }
        self.rx.clear();
        if let Err(e) = self.wire.read_available(&mut self.rx) {
            return Err(self.wire_err(e));
        }
        self.bytes_in += self.rx.len() as u64;
        let mut frames = Vec::new();
        self.decoder.feed_into(&self.rx, &mut frames);
        self.received += frames.len() as u64;
        self.telemetry.extend(frames.iter().map(Telemetry::decode));
        if self.telemetry.len() > MAX_TELEMETRY {
            let excess = self.telemetry.len() - MAX_TELEMETRY;
            self.telemetry.drain(..excess);
        }
        Ok(written)
    }

    fn take_telemetry(&mut self) -> Vec<Telemetry> {
        std::mem::take(&mut self.telemetry)
    }

    fn stop_now(&mut self, packet: CommandPacket) -> Result<(), LinkError> {
        self.scheduler.clear();
        let frame = packet.to_frame();
        self.wire.write_frame(&frame).map_err(|e| self.wire_err(e))
    }

    fn counters(&self) -> LinkCounters {
        LinkCounters {
            scheduler: self.scheduler.counters(),
            pending: self.scheduler.pending(),
            bytes_in: self.bytes_in,
            telemetry: self.received,
            skipped_bytes: self.decoder.counters().skipped,
        }
    }
}

/// Opens the link a URL names.
pub fn open_robot_link(url: &str) -> Result<Box<dyn RobotLink>, LinkError> {
    let open_err = |error| LinkError::Wire {
        link: url.to_string(),
        error,
    };
    Ok(match url.parse::<LinkUrl>()? {
        LinkUrl::Serial { device, baud } => Box::new(
            Link::new(
                SerialWire::open(&device, baud)?,
                AirtimeScheduler::new(baud),
            )
            .named(url),
        ),
        LinkUrl::Udp { host, port, baud } => Box::new(
            Link::new(
                UdpWire::connect(&format!("{host}:{port}")).map_err(open_err)?,
                AirtimeScheduler::new(baud),
            )
            .named(url),
        ),
    })
}
