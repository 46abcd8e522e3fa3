//! Receives JSON pose datagrams (one object per datagram, or several separated by newlines) on a
//! bound UDP address and keeps each robot's newest pose.

use super::shared::{Shared, ThreadedSource};
use super::{ConnectionState, MarkerPose, SourceError};
use crate::protocol::udp_pose::JsonPose;
use colcos_sim::robot::Pose;
use std::collections::BTreeMap;
use std::io::ErrorKind;
use std::net::UdpSocket;
use std::time::Duration;

pub(super) fn spawn(addr: &str) -> Result<ThreadedSource, SourceError> {
    let sock = UdpSocket::bind(addr)?;
    sock.set_read_timeout(Some(Duration::from_millis(20)))?;
    Ok(ThreadedSource::spawn(Shared::new(), false, move |shared| {
        run(&shared, sock)
    }))
}

fn run(shared: &Shared, sock: UdpSocket) {
    shared.set_state(ConnectionState::Connected);
    let mut poses: BTreeMap<u32, MarkerPose> = BTreeMap::new();
    let mut buf = vec![0u8; 65_536];
    while !shared.stopped() {
        let n = match sock.recv(&mut buf) {
            Ok(n) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) =>
            {
                continue;
            }
            Err(e) => {
                shared.set_state(ConnectionState::Failed(e.to_string()));
                return;
            }
        };
        let mut bad = 0;
        let mut newest = f64::NEG_INFINITY;
        for r in JsonPose::parse_lines(&buf[..n]) {
            match r {
                Ok(p) => {
                    newest = newest.max(p.t);
                    poses.insert(
                        p.id,
                        MarkerPose {
                            id: p.id,
                            pose: Pose::new(p.x as f32, p.y as f32, p.heading as f32),
                            fresh: true,
                            t: p.t,
                        },
                    );
                }
                Err(_) => bad += 1,
            }
        }
        {
            let mut g = shared.lock();
            g.counters.bytes += n as u64;
            g.counters.errors += bad;
        }
        if newest.is_finite() {
            let t = poses.values().map(|p| p.t).fold(newest, f64::max);
            let snapshot = poses
                .values()
                .map(|p| MarkerPose {
                    fresh: p.t >= t,
                    ..*p
                })
                .collect();
            shared.publish(t, snapshot);
        }
    }
}
