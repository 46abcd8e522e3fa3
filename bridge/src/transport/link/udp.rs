//! The UDP wire: one frame per datagram to a twin or a network radio bridge.

use super::Wire;
use std::io::ErrorKind;
use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};

/// Datagrams read per pump at most, so a flood cannot stall the live loop.
const MAX_DATAGRAMS: usize = 256;

pub(crate) struct UdpWire {
    sock: UdpSocket,
}

impl UdpWire {
    /// Binds an ephemeral local port and sends to `remote`.
    pub(crate) fn connect(remote: &str) -> std::io::Result<Self> {
        let addr: SocketAddr = remote.to_socket_addrs()?.next().ok_or_else(|| {
            std::io::Error::new(
                ErrorKind::NotFound,
                format!("`{remote}` resolves to no address"),
            )
        })?;
        let local: SocketAddr = if addr.is_ipv4() {
            "0.0.0.0:0"
        } else {
            "[::]:0"
        }
        .parse()
        .map_err(|_| std::io::Error::new(ErrorKind::InvalidInput, "local address"))?;
        let sock = UdpSocket::bind(local)?;
        sock.connect(addr)?;
        sock.set_nonblocking(true)?;
        Ok(UdpWire { sock })
    }
}

impl Wire for UdpWire {
    fn write_frame(&mut self, frame: &[u8]) -> std::io::Result<()> {
        match self.sock.send(frame) {
            Ok(_) => Ok(()),
            // A full socket buffer loses the frame, as a radio would; the next command replaces it.
            Err(e) if e.kind() == ErrorKind::WouldBlock => Ok(()),
            Err(e) => Err(e),
        }
    }

    fn read_available(&mut self, buf: &mut Vec<u8>) -> std::io::Result<()> {
        let mut d = [0u8; 2048];
        for _ in 0..MAX_DATAGRAMS {
            match self.sock.recv(&mut d) {
                Ok(n) => buf.extend_from_slice(&d[..n]),
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) => {
                    break;
                }
                // A twin that is not up yet answers with ICMP port unreachable; keep going.
                Err(e) if e.kind() == ErrorKind::ConnectionRefused => break,
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }
}
