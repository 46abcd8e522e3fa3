//! The robots' end of the serial protocol, for the twin: reads host command frames from a byte
//! channel (a pseudo-terminal, so the bridge's real serial code runs, or UDP), applies them to the
//! simulated robots, and answers data requests with 96-byte telemetry frames.
use super::plant::{FIRMWARE_TIMEOUT, TwinArena};
use crate::onboard::{OnboardFleet, RawReadings};
use crate::protocol::colias::{
    BROADCAST_ID, COMMAND_LEN, CommandPacket, FrameDecoder, HostCommand, MotionKind, Telemetry,
    colour_from_sim,
};
use colcos_sim::behaviour::WheelCommand;
use image::RgbImage;
use std::io::{Read, Write};
use std::net::{SocketAddr, UdpSocket};

/// Raw bytes both ways, never blocking.
pub trait ByteChannel: Send {
    /// Appends what has arrived.
    fn read_available(&mut self, out: &mut Vec<u8>);
    /// Sends `bytes` (dropped if there is no peer yet or the channel is full).
    fn send(&mut self, bytes: &[u8]);
    fn describe(&self) -> String;
}

/// A UDP socket: commands arrive as datagrams; replies go to whoever sent the last one.
pub struct UdpChannel {
    socket: UdpSocket,
    peer: Option<SocketAddr>,
}

impl UdpChannel {
    pub fn bind(addr: &str) -> std::io::Result<UdpChannel> {
        let socket = UdpSocket::bind(addr)?;
        socket.set_nonblocking(true)?;
        Ok(UdpChannel { socket, peer: None })
    }
    pub fn local_addr(&self) -> std::io::Result<SocketAddr> {
        self.socket.local_addr()
    }
}

impl ByteChannel for UdpChannel {
    fn read_available(&mut self, out: &mut Vec<u8>) {
        let mut buf = [0u8; 2048];
        while let Ok((k, from)) = self.socket.recv_from(&mut buf) {
            self.peer = Some(from);
            out.extend_from_slice(&buf[..k]);
        }
    }
    fn send(&mut self, bytes: &[u8]) {
        if let Some(peer) = self.peer {
            let _ = self.socket.send_to(bytes, peer);
        }
    }
    fn describe(&self) -> String {
        format!(
            "udp {}",
            self.local_addr().map(|a| a.to_string()).unwrap_or_default()
        )
    }
}

/// The robots' side of a pseudo-terminal pair; the bridge opens the other side by its path.
pub struct PtyChannel {
    port: serialport::TTYPort,
    /// The side the bridge opens, kept open so the pair lives while the twin does.
    _peer: serialport::TTYPort,
    peer_path: String,
}

impl PtyChannel {
    pub fn open() -> serialport::Result<PtyChannel> {
        let (mut port, peer) = serialport::TTYPort::pair()?;
        use serialport::SerialPort;
        port.set_timeout(std::time::Duration::from_millis(0))?;
        let peer_path = peer.name().unwrap_or_default();
        Ok(PtyChannel {
            port,
            _peer: peer,
            peer_path,
        })
    }
    /// The device path the bridge opens (`serial://` + this).
    pub fn peer_path(&self) -> &str {
        &self.peer_path
    }
}

impl ByteChannel for PtyChannel {
    fn read_available(&mut self, out: &mut Vec<u8>) {
        let mut buf = [0u8; 1024];
        while let Ok(k) = self.port.read(&mut buf) {
            if k == 0 {
                break;
            }
            out.extend_from_slice(&buf[..k]);
        }
    }
    fn send(&mut self, bytes: &[u8]) {
        let _ = self.port.write_all(bytes);
    }
    fn describe(&self) -> String {
        format!("pty {}", self.peer_path)
    }
}

/// Faults the robots' end can play.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RobotFaults {
    /// Radio IDs of robots that stop answering (they neither obey nor reply).
    pub deaf: Vec<u8>,
    /// Send a few garbage bytes before every telemetry frame.
    pub garbage: bool,
}

/// A command as the twin received it, for its log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Received {
    /// Twin time of receipt, s.
    pub t: f64,
    /// Wall-clock moment of receipt (safety bounds are measured on it).
    pub at: std::time::Instant,
    pub packet: CommandPacket,
}

/// Most telemetry frames one `DR` may ask for.
const MAX_REQUEST: u8 = 8;

pub struct RobotEnd {
    channel: Box<dyn ByteChannel>,
    decoder: FrameDecoder<COMMAND_LEN>,
    bytes: Vec<u8>,
    payloads: Vec<[u8; COMMAND_LEN]>,
    /// Radio ID of each robot, in scenario order.
    radio: Vec<u8>,
    /// The faults, shared so they can be switched while the twin runs.
    pub faults: std::sync::Arc<std::sync::Mutex<RobotFaults>>,
    /// Every command received, in order.
    pub log: Vec<Received>,
    /// Payloads that were framed right but did not decode.
    pub rejected: u64,
    /// The robots' on-board policy, when their firmware carries one.
    onboard: Option<OnboardFleet>,
}

impl RobotEnd {
    pub fn new(channel: Box<dyn ByteChannel>, radio: Vec<u8>) -> RobotEnd {
        RobotEnd {
            channel,
            decoder: FrameDecoder::new(),
            bytes: Vec::new(),
            payloads: Vec::new(),
            radio,
            faults: Default::default(),
            log: Vec::new(),
            rejected: 0,
            onboard: None,
        }
    }

    /// Flashes the robots with an on-board policy (`None`: firmware without one).
    pub fn set_onboard(&mut self, fleet: Option<OnboardFleet>) {
        self.onboard = fleet;
    }
    pub fn onboard(&self) -> Option<&OnboardFleet> {
        self.onboard.as_ref()
    }

    pub fn describe(&self) -> String {
        self.channel.describe()
    }

    /// Handles every frame that arrived: commands go to `plant`, data requests are answered with
    /// telemetry read from `frame` (the displayed screen).
    pub fn poll(&mut self, plant: &mut TwinArena, frame: Option<&RgbImage>) {
        self.bytes.clear();
        self.channel.read_available(&mut self.bytes);
        self.payloads.clear();
        self.decoder.feed_into(&self.bytes, &mut self.payloads);
        let payloads = std::mem::take(&mut self.payloads);
        let faults = self.faults.lock().map(|f| f.clone()).unwrap_or_default();
        for p in &payloads {
            let Ok(packet) = CommandPacket::decode(p) else {
                self.rejected += 1;
                continue;
            };
            self.log.push(Received {
                t: plant.time(),
                at: std::time::Instant::now(),
                packet,
            });
            let targets: Vec<usize> = if packet.id == BROADCAST_ID {
                (0..self.radio.len()).collect()
            } else {
                self.radio
                    .iter()
                    .position(|&r| r == packet.id)
                    .into_iter()
                    .collect()
            };
            for i in targets {
                if faults.deaf.contains(&self.radio[i]) {
                    continue;
                }
                if let Some(fleet) = &mut self.onboard {
                    fleet.hear(i, &packet.command);
                    // Firmware with a policy counts any frame for it as the link being alive.
                    plant.keep_alive(i);
                }
                match packet.command {
                    HostCommand::WheelSpeeds { left, right } => {
                        plant.hear(Some(i), WheelCommand { left, right })
                    }
                    HostCommand::Motion { kind, speed } => plant.hear(Some(i), motion(kind, speed)),
                    HostCommand::RequestTelemetry(n) => {
                        for _ in 0..n.min(MAX_REQUEST) {
                            let t = self.telemetry(plant, i, frame);
                            if faults.garbage {
                                self.channel.send(&[0xFE, 0x01, 0x00, 0x01]);
                            }
                            self.channel.send(&t.to_frame());
                        }
                    }
                    HostCommand::WriteParams(_)
                    | HostCommand::WriteParamsAt { .. }
                    | HostCommand::RunPolicy { .. } => {}
                }
            }
        }
        self.payloads = payloads;
        self.run_onboard(plant, frame);
    }

    /// One control tick of every robot running its on-board policy, on its own readings.
    fn run_onboard(&mut self, plant: &mut TwinArena, frame: Option<&RgbImage>) {
        let Some(fleet) = &mut self.onboard else {
            return;
        };
        for i in 0..self.radio.len() {
            if !fleet.running(i) {
                continue;
            }
            if plant.heard_age(i) > FIRMWARE_TIMEOUT {
                fleet.lose_link(i);
                // Its own stop: nothing was heard, so the link timeout is not refreshed.
                plant.drive(i, WheelCommand::STOP);
                continue;
            }
            let colour = colour_from_sim(plant.colour_counts(i, frame));
            let (ir_on, ir_off) = bumper_counts(plant.bumpers(i));
            let cmd = fleet.control(
                i,
                &RawReadings {
                    colour,
                    ir_on,
                    ir_off,
                },
            );
            plant.drive(i, cmd);
        }
    }

    fn telemetry(&self, plant: &mut TwinArena, i: usize, frame: Option<&RgbImage>) -> Telemetry {
        let colour = colour_from_sim(plant.colour_counts(i, frame));
        let (tcrt_on, tcrt_off) = bumper_counts(plant.bumpers(i));
        let mut t = Telemetry {
            id: self.radio[i],
            sys_t_ms: (plant.time() * 1e3) as u32,
            v_bat: 200,
            colour,
            tcrt_off,
            tcrt_on,
            ..Telemetry::default()
        };
        if let Some(fleet) = &self.onboard {
            t.set_onboard(&fleet.status(i, plant.command(i)));
        }
        t
    }
}

/// The twin's IR bumper counts: `BUMPER_DARK` with nothing in range, plus `BUMPER_SPAN` at contact
/// (emitter on minus emitter off is proportional to the reading in [0, 1]).
pub const BUMPER_DARK: u16 = 100;
pub const BUMPER_SPAN: u16 = 3000;

/// The twin's IR counts (emitter on, emitter off) for bumper readings in [0, 1].
fn bumper_counts(bumpers: [f32; 3]) -> ([u16; 3], [u16; 3]) {
    let on = bumpers.map(|b| BUMPER_DARK + (b.clamp(0.0, 1.0) * BUMPER_SPAN as f32).round() as u16);
    (on, [BUMPER_DARK; 3])
}

/// A bumper reading in [0, 1] from the emitter-on and emitter-off counts (the twin's scale).
pub fn bumper_reading(on: u16, off: u16) -> f32 {
    (on.saturating_sub(off) as f32 / BUMPER_SPAN as f32).clamp(0.0, 1.0)
}

/// Wheel speeds for an old firmware motion command, as that firmware drives.
pub fn motion(kind: MotionKind, speed: f32) -> WheelCommand {
    let s = if speed.is_finite() { speed } else { 0.0 };
    match kind {
        MotionKind::Forward | MotionKind::Start => WheelCommand { left: s, right: s },
        MotionKind::Backward => WheelCommand {
            left: -s,
            right: -s,
        },
        MotionKind::TurnLeft => WheelCommand { left: -s, right: s },
        MotionKind::TurnRight => WheelCommand { left: s, right: -s },
        MotionKind::Stop => WheelCommand::STOP,
    }
}
