//! The frame stream: a second sink of the displayed screen, standing in for the light path from the
//! LCD to the robots' colour sensors (a digital twin subscribes to it). Over TCP, each frame is
//! `b"CCFR"`, `u32` width, `u32` height (little-endian), `f64` host time (s), then `width x height x 3`
//! bytes of RGB, row 0 at the top of the panel. A slow subscriber misses frames; it never holds the
//! host up.
use image::RgbImage;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

const MAGIC: &[u8; 4] = b"CCFR";
/// Largest frame side accepted from the wire (an 8K panel fits).
pub(crate) const MAX_SIDE: u32 = 8192;
/// A subscriber that cannot take a frame within this time misses it.
const SEND_TIMEOUT: Duration = Duration::from_millis(20);

/// Publishes frames to every subscriber that connects.
pub struct FrameServer {
    addr: SocketAddr,
    clients: Arc<Mutex<Vec<TcpStream>>>,
    stop: Arc<AtomicBool>,
    /// Reused: header and pixels of the frame being sent.
    buffer: Vec<u8>,
}

impl FrameServer {
    /// Listens on `addr` (e.g. `127.0.0.1:0` for any free port).
    pub fn bind(addr: impl ToSocketAddrs) -> std::io::Result<FrameServer> {
        let listener = TcpListener::bind(addr)?;
        let addr = listener.local_addr()?;
        listener.set_nonblocking(true)?;
        let clients = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let (c, s) = (clients.clone(), stop.clone());
        std::thread::Builder::new()
            .name("frame-server".into())
            .spawn(move || accept_loop(listener, c, s))?;
        Ok(FrameServer {
            addr,
            clients,
            stop,
            buffer: Vec::new(),
        })
    }

    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Number of connected subscribers.
    pub fn subscribers(&self) -> usize {
        self.clients.lock().map(|c| c.len()).unwrap_or(0)
    }

    /// Sends `frame` (shown at host time `time`) to every subscriber; one that fails is dropped.
    pub fn publish(&mut self, frame: &RgbImage, time: f64) {
        let Ok(mut clients) = self.clients.lock() else {
            return;
        };
        if clients.is_empty() {
            return;
        }
        self.buffer.clear();
        self.buffer.extend_from_slice(MAGIC);
        self.buffer.extend_from_slice(&frame.width().to_le_bytes());
        self.buffer.extend_from_slice(&frame.height().to_le_bytes());
        self.buffer.extend_from_slice(&time.to_le_bytes());
        self.buffer.extend_from_slice(frame.as_raw());
        let buffer = &self.buffer;
        clients.retain_mut(|c| c.write_all(buffer).is_ok());
    }
}

impl Drop for FrameServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

fn accept_loop(listener: TcpListener, clients: Arc<Mutex<Vec<TcpStream>>>, stop: Arc<AtomicBool>) {
    while !stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((stream, _)) => {
                let _ = stream.set_nodelay(true);
                let _ = stream.set_write_timeout(Some(SEND_TIMEOUT));
                if let Ok(mut c) = clients.lock() {
                    c.push(stream);
                }
            }
            Err(_) => std::thread::sleep(Duration::from_millis(10)),
        }
    }
}

/// The latest frame received, with its host time.
pub(crate) type LatestFrame = Arc<Mutex<Option<(Arc<RgbImage>, f64)>>>;

/// Subscribes to a [`FrameServer`]: a background thread keeps the latest frame, reconnecting when the
/// server goes away; a malformed stream is dropped and reconnected.
pub(crate) struct FrameClient {
    latest: LatestFrame,
    stop: Arc<AtomicBool>,
}

impl FrameClient {
    pub(crate) fn connect(addr: SocketAddr) -> FrameClient {
        let latest: LatestFrame = Arc::new(Mutex::new(None));
        let stop = Arc::new(AtomicBool::new(false));
        let (l, s) = (latest.clone(), stop.clone());
        let _ = std::thread::Builder::new()
            .name("frame-client".into())
            .spawn(move || {
                while !s.load(Ordering::Relaxed) {
                    if let Ok(stream) =
                        TcpStream::connect_timeout(&addr, Duration::from_millis(200))
                    {
                        let _ = stream.set_read_timeout(Some(Duration::from_millis(200)));
                        read_frames(stream, &l, &s);
                    }
                    std::thread::sleep(Duration::from_millis(50));
                }
            });
        FrameClient { latest, stop }
    }

    /// The latest frame and its host time, if any arrived.
    pub(crate) fn latest(&self) -> Option<(Arc<RgbImage>, f64)> {
        self.latest.lock().ok().and_then(|l| l.clone())
    }
}

impl Drop for FrameClient {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

/// Reads frames until the stream ends, fails or breaks the format.
fn read_frames(mut stream: TcpStream, latest: &LatestFrame, stop: &AtomicBool) {
    let mut header = [0u8; 20];
    while !stop.load(Ordering::Relaxed) {
        if read_full(&mut stream, &mut header, stop).is_err() || &header[..4] != MAGIC {
            return;
        }
        let side =
            |k: usize| u32::from_le_bytes([header[k], header[k + 1], header[k + 2], header[k + 3]]);
        let (w, h) = (side(4), side(8));
        let time = f64::from_le_bytes(header[12..20].try_into().unwrap_or([0; 8]));
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE || !time.is_finite() {
            return;
        }
        let mut pixels = vec![0u8; w as usize * h as usize * 3];
        if read_full(&mut stream, &mut pixels, stop).is_err() {
            return;
        }
        let Some(img) = RgbImage::from_raw(w, h, pixels) else {
            return;
        };
        if let Ok(mut l) = latest.lock() {
            *l = Some((Arc::new(img), time));
        }
    }
}

/// `read_exact` that keeps waiting through read timeouts until `stop` is set.
fn read_full(stream: &mut TcpStream, buf: &mut [u8], stop: &AtomicBool) -> std::io::Result<()> {
    let mut filled = 0;
    while filled < buf.len() {
        if stop.load(Ordering::Relaxed) {
            return Err(std::io::ErrorKind::Interrupted.into());
        }
        match stream.read(&mut buf[filled..]) {
            Ok(0) => return Err(std::io::ErrorKind::UnexpectedEof.into()),
            Ok(n) => filled += n,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    fn wait<T>(mut f: impl FnMut() -> Option<T>) -> T {
        let t0 = Instant::now();
        loop {
            if let Some(v) = f() {
                return v;
            }
            assert!(t0.elapsed() < Duration::from_secs(5), "timed out");
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    #[test]
    fn a_subscriber_gets_the_latest_frame_and_garbage_is_refused() {
        let mut server = FrameServer::bind("127.0.0.1:0").unwrap();
        let client = FrameClient::connect(server.local_addr());
        wait(|| (server.subscribers() == 1).then_some(()));
        let mut img = RgbImage::new(6, 4);
        img.put_pixel(5, 3, image::Rgb([9, 8, 7]));
        server.publish(&img, 1.25);
        let (got, t) = wait(|| client.latest());
        assert_eq!(t, 1.25);
        assert_eq!(*got, img);

        // A server that sends an absurd size: the client drops it and keeps its last frame.
        let bad = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = bad.local_addr().unwrap();
        let c2 = FrameClient::connect(addr);
        let (mut s, _) = bad.accept().unwrap();
        let mut header = MAGIC.to_vec();
        header.extend_from_slice(&u32::MAX.to_le_bytes());
        header.extend_from_slice(&u32::MAX.to_le_bytes());
        header.extend_from_slice(&0f64.to_le_bytes());
        s.write_all(&header).unwrap();
        std::thread::sleep(Duration::from_millis(100));
        assert!(c2.latest().is_none());
    }
}
