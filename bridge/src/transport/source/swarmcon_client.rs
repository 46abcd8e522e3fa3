//! A TCP client of the SwarmCon / CosPhi position server: `TCP_NODELAY`, reconnection with
//! exponential backoff, and the `Calibrate` command on request.

use super::shared::{Shared, ThreadedSource};
use super::{ConnectionState, SourceOptions, frame_to_poses};
use crate::protocol::swarmcon::{StreamParser, TrackerMessage};
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::time::Duration;

/// How often a blocked read wakes to check for a stop or a command to send.
const READ_TICK: Duration = Duration::from_millis(20);

pub(super) fn spawn(addr: String, opts: SourceOptions) -> ThreadedSource {
    ThreadedSource::spawn(Shared::new(), true, move |shared| {
        run(&shared, &addr, &opts)
    })
}

fn connect(addr: &str, timeout: Duration) -> std::io::Result<TcpStream> {
    let addrs: Vec<SocketAddr> = addr.to_socket_addrs()?.collect();
    let mut last = std::io::Error::new(
        ErrorKind::NotFound,
        format!("`{addr}` resolves to no address"),
    );
    for a in addrs {
        match TcpStream::connect_timeout(&a, timeout) {
            Ok(s) => return Ok(s),
            Err(e) => last = e,
        }
    }
    Err(last)
}

fn run(shared: &Shared, addr: &str, opts: &SourceOptions) {
    let mut parser = StreamParser::new();
    let mut backoff = opts.backoff_initial;
    let mut connected_before = false;
    while !shared.stopped() {
        shared.set_state(ConnectionState::Connecting);
        let reason = match connect(addr, opts.connect_timeout) {
            Err(e) => format!("{addr}: {e}"),
            Ok(stream) => {
                if connected_before {
                    shared.lock().counters.reconnects += 1;
                }
                connected_before = true;
                backoff = opts.backoff_initial;
                parser.reset();
                shared.set_state(ConnectionState::Connected);
                serve(shared, stream, &mut parser, opts);
                format!("{addr}: the server closed the connection")
            }
        };
        if shared.stopped() {
            break;
        }
        shared.set_state(ConnectionState::Disconnected {
            retry_in: backoff,
            reason,
        });
        if !shared.sleep(backoff) {
            break;
        }
        backoff = (backoff * 2).min(opts.backoff_max);
    }
}

/// Reads one connection until it ends or the source is stopped.
fn serve(shared: &Shared, mut stream: TcpStream, parser: &mut StreamParser, opts: &SourceOptions) {
    // Poses are small and latency-bound: never wait to coalesce.
    if stream.set_nodelay(true).is_err() || stream.set_read_timeout(Some(READ_TICK)).is_err() {
        return;
    }
    let mut buf = vec![0u8; 64 * 1024];
    let mut out = Vec::new();
    while !shared.stopped() {
        let outgoing = shared.lock().outgoing.take();
        if let Some(line) = outgoing
            && stream.write_all(line.as_bytes()).is_err()
        {
            // Kept for the next connection: a calibration request should survive a reconnect.
            shared.lock().outgoing = Some(line);
            return;
        }
        match stream.read(&mut buf) {
            Ok(0) => return,
            Ok(n) => {
                let before = parser.counters();
                parser.feed_into(&buf[..n], &mut out);
                let after = parser.counters();
                {
                    let mut g = shared.lock();
                    g.counters.bytes += n as u64;
                    g.counters.errors += after.errors - before.errors;
                }
                // Only the newest frame of a read matters to a latest-pose consumer.
                let newest = out.iter().rev().find_map(|m| match m {
                    TrackerMessage::Frame(f) => Some(f),
                    _ => None,
                });
                if let Some(f) = newest {
                    shared.publish(f.t_us as f64 * 1e-6, frame_to_poses(f, &opts.transform));
                }
                for m in out.drain(..) {
                    if let TrackerMessage::Event(e) = m {
                        shared.event(e);
                    }
                }
            }
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) => {}
            Err(_) => return,
        }
    }
}
