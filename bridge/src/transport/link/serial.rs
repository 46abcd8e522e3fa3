//! The serial-port wire (the lab's USB radio dongle), via `serialport` without libudev.

use super::Wire;
use serialport::SerialPort;
use std::io::{Read, Write};
use std::time::Duration;

/// Reads at most this much per pump; the rest waits for the next one.
const MAX_READ: usize = 64 * 1024;

pub struct SerialWire {
    port: Box<dyn SerialPort>,
}

impl SerialWire {
    /// Opens a device at `baud`, 8N1.
    pub fn open(device: &str, baud: u32) -> Result<Self, serialport::Error> {
        let port = serialport::new(device, baud)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .timeout(Duration::from_millis(50))
            .open()?;
        Ok(SerialWire { port })
    }

    /// Wraps an already open port (a pseudo-terminal in tests).
    pub fn from_port(port: Box<dyn SerialPort>) -> Self {
        SerialWire { port }
    }
}

impl Wire for SerialWire {
    fn write_frame(&mut self, frame: &[u8]) -> std::io::Result<()> {
        self.port.write_all(frame)
    }

    fn read_available(&mut self, buf: &mut Vec<u8>) -> std::io::Result<()> {
        let n = (self.port.bytes_to_read()? as usize).min(MAX_READ);
        if n == 0 {
            return Ok(());
        }
        let start = buf.len();
        buf.resize(start + n, 0);
        let got = self.port.read(&mut buf[start..])?;
        buf.truncate(start + got);
        Ok(())
    }
}
