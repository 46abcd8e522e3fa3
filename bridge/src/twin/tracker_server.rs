//! The twin's SwarmCon position server: serves blocks in the exact text format to every client on a
//! TCP port, as the real server does, with faults on demand (silence, split and merged reads, garbage
//! bytes, a clock offset).
use crate::protocol::swarmcon::{
    HeaderForm, SlotPose, SlotState, TrackerEvent, TrackerFrame, write_block, write_event,
};
use std::io::Write;
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Faults the twin's tracker can play, switchable while it runs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrackerFaults {
    /// Marker IDs the camera no longer sees: their slots repeat the last pose with its old time, as
    /// the server does for a lost robot.
    pub hidden: Vec<i32>,
    /// Send nothing (the camera or the server hangs).
    pub silent: bool,
    /// Write each block in pieces of this many bytes (0: whole), so a read holds part of a block.
    pub split: usize,
    /// Hold blocks back and write this many at once (0 or 1: one by one).
    pub merge: usize,
    /// Put a line of garbage bytes before every block.
    pub garbage: bool,
    /// Added to every time the server writes, µs (the tracker's clock runs ahead of the host's).
    pub clock_offset_us: i64,
}

pub struct TrackerServer {
    addr: SocketAddr,
    clients: Arc<Mutex<Vec<TcpStream>>>,
    stop: Arc<AtomicBool>,
    faults: Arc<Mutex<TrackerFaults>>,
    held: Vec<u8>,
    held_blocks: usize,
    form: HeaderForm,
    /// The last pose and time sent for each marker, repeated while it is hidden.
    last: std::collections::HashMap<i32, (f64, f64, f64, Option<i64>)>,
    /// Calibrate commands received (their raw lines).
    received: Arc<Mutex<Vec<String>>>,
    /// When set, every block is held back by a set latency and jitter before it is written.
    delay: Option<DelayLine>,
}

/// Holds blocks back: each is written `latency + jitter * U(-1, 1)` s after it was published (never
/// before the one published before it), by a thread of its own so the twin's tick does not wait.
struct DelayLine {
    tx: std::sync::mpsc::Sender<(std::time::Instant, Vec<u8>, usize)>,
    latency: f64,
    jitter: f64,
    noise: super::camera::Noise,
    last_due: std::time::Instant,
}

impl TrackerServer {
    /// Listens on `addr` (loopback unless told otherwise), writing headers of `form`.
    pub fn bind(addr: impl ToSocketAddrs, form: HeaderForm) -> std::io::Result<TrackerServer> {
        let listener = TcpListener::bind(addr)?;
        let addr = listener.local_addr()?;
        listener.set_nonblocking(true)?;
        let clients = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let received = Arc::new(Mutex::new(Vec::new()));
        let (c, s, r) = (clients.clone(), stop.clone(), received.clone());
        std::thread::Builder::new()
            .name("twin-tracker".into())
            .spawn(move || accept_loop(listener, c, s, r))?;
        Ok(TrackerServer {
            addr,
            clients,
            stop,
            faults: Arc::new(Mutex::new(TrackerFaults::default())),
            held: Vec::new(),
            held_blocks: 0,
            form,
            last: Default::default(),
            received,
            delay: None,
        })
    }

    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }
    pub fn clients(&self) -> usize {
        self.clients.lock().map(|c| c.len()).unwrap_or(0)
    }
    /// The faults, to switch while the server runs.
    pub fn faults(&self) -> Arc<Mutex<TrackerFaults>> {
        self.faults.clone()
    }
    /// Lines the clients sent (`Calibrate ...`).
    pub fn received(&self) -> Vec<String> {
        self.received.lock().map(|r| r.clone()).unwrap_or_default()
    }

    /// Holds every block back by `latency` s plus a uniform jitter of up to `jitter` s either way
    /// (a camera and tracker that take this long from capture to delivery); 0 and 0: none.
    pub fn set_delay(&mut self, latency: f64, jitter: f64, seed: u64) {
        if !(latency > 0.0 || jitter > 0.0) {
            self.delay = None;
            return;
        }
        let (tx, rx) = std::sync::mpsc::channel::<(std::time::Instant, Vec<u8>, usize)>();
        let clients = self.clients.clone();
        let spawned = std::thread::Builder::new()
            .name("twin-tracker-delay".into())
            .spawn(move || {
                for (due, bytes, split) in rx {
                    let now = std::time::Instant::now();
                    if due > now {
                        std::thread::sleep(due - now);
                    }
                    write_to(&clients, &bytes, split);
                }
            });
        self.delay = spawned.ok().map(|_| DelayLine {
            tx,
            latency: latency.max(0.0),
            jitter: jitter.max(0.0),
            noise: super::camera::Noise::new(seed),
            last_due: std::time::Instant::now(),
        });
    }

    /// Sends one block: `poses` are (marker id, x, y, yaw_deg, last seen µs or `None` if never) in the
    /// tracker's frame, `t_us` the frame time.
    pub fn publish(&mut self, t_us: i64, poses: &[(i32, f64, f64, f64, Option<i64>)]) {
        let faults = self.faults.lock().map(|f| f.clone()).unwrap_or_default();
        if faults.silent {
            return;
        }
        let shift = |t: i64| t.saturating_add(faults.clock_offset_us);
        let t = shift(t_us);
        let robots: Vec<SlotPose> = poses
            .iter()
            .map(|&(id, x, y, yaw_deg, seen)| {
                let (x, y, yaw_deg, seen) = if faults.hidden.contains(&id) {
                    *self.last.entry(id).or_insert((x, y, yaw_deg, seen))
                } else {
                    self.last.insert(id, (x, y, yaw_deg, seen));
                    (x, y, yaw_deg, seen)
                };
                let last_seen_us = seen.map(shift).unwrap_or(-1);
                SlotPose {
                    id,
                    x,
                    y,
                    yaw_deg,
                    last_seen_us,
                    state: SlotPose::state_for(last_seen_us, t),
                }
            })
            .collect();
        let found = robots
            .iter()
            .filter(|r| r.state == SlotState::Fresh)
            .count() as i32;
        let frame = TrackerFrame {
            t_us: t,
            found,
            tracked: robots.len() as i32,
            updated: Some(found),
            robots,
        };
        if faults.garbage {
            self.held
                .extend_from_slice(b"\x00\xff garbage \xfe\x01 Robot x y\n");
        }
        self.held
            .extend_from_slice(write_block(&frame, self.form, false).as_bytes());
        self.held_blocks += 1;
        if self.held_blocks >= faults.merge.max(1) {
            let bytes = std::mem::take(&mut self.held);
            self.held_blocks = 0;
            self.write_all(&bytes, faults.split);
        }
    }

    /// Sends `Closed` and closes every connection, as the server does when it stops.
    pub fn close(&mut self) {
        let mut s = String::new();
        write_event(&mut s, TrackerEvent::Closed);
        self.write_all(s.as_bytes(), 0);
        if let Some(line) = &self.delay {
            // What is held back goes out first.
            std::thread::sleep(Duration::from_secs_f64(line.latency + line.jitter + 0.02));
        }
        if let Ok(mut c) = self.clients.lock() {
            for client in c.drain(..) {
                let _ = client.shutdown(std::net::Shutdown::Both);
            }
        }
    }

    fn write_all(&mut self, bytes: &[u8], split: usize) {
        match &mut self.delay {
            Some(line) => {
                let d = line.latency + line.jitter * (2.0 * line.noise.uniform() - 1.0);
                let due = std::time::Instant::now() + Duration::from_secs_f64(d.max(0.0));
                line.last_due = due.max(line.last_due);
                let _ = line.tx.send((line.last_due, bytes.to_vec(), split));
            }
            None => write_to(&self.clients, bytes, split),
        }
    }
}

fn write_to(clients: &Mutex<Vec<TcpStream>>, bytes: &[u8], split: usize) {
    let Ok(mut clients) = clients.lock() else {
        return;
    };
    clients.retain_mut(|c| {
        if split == 0 {
            c.write_all(bytes).is_ok()
        } else {
            bytes
                .chunks(split)
                .all(|piece| c.write_all(piece).and_then(|_| c.flush()).is_ok())
        }
    });
}

impl Drop for TrackerServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

fn accept_loop(
    listener: TcpListener,
    clients: Arc<Mutex<Vec<TcpStream>>>,
    stop: Arc<AtomicBool>,
    received: Arc<Mutex<Vec<String>>>,
) {
    let mut readers: Vec<(TcpStream, Vec<u8>)> = Vec::new();
    while !stop.load(Ordering::Relaxed) {
        if let Ok((stream, _)) = listener.accept() {
            let _ = stream.set_nodelay(true);
            let _ = stream.set_write_timeout(Some(Duration::from_millis(50)));
            if let Ok(reader) = stream.try_clone() {
                let _ = reader.set_nonblocking(true);
                readers.push((reader, Vec::new()));
            }
            if let Ok(mut c) = clients.lock() {
                c.push(stream);
            }
        }
        // Lines from the clients (`Calibrate ...`), bounded per client.
        readers.retain_mut(|(r, buf)| {
            let mut chunk = [0u8; 256];
            match std::io::Read::read(r, &mut chunk) {
                Ok(0) => false,
                Ok(k) => {
                    buf.extend_from_slice(&chunk[..k]);
                    while let Some(end) = buf.iter().position(|&b| b == b'\n') {
                        let line: Vec<u8> = buf.drain(..=end).collect();
                        if let Ok(mut rec) = received.lock() {
                            rec.push(String::from_utf8_lossy(&line).trim_end().to_string());
                        }
                    }
                    buf.truncate(4096);
                    true
                }
                Err(e) => e.kind() == std::io::ErrorKind::WouldBlock,
            }
        });
        std::thread::sleep(Duration::from_millis(5));
    }
}
