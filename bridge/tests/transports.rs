//! The transports over loopback: a SwarmCon server that splits blocks over many writes, closes and
//! comes back; JSON poses over UDP; replay files; the serial link over a real pseudo-terminal; the
//! UDP robot link.

use colcos_bridge::protocol::colias::{
    CommandDecoder, CommandPacket, HostCommand, MotionKind, Telemetry,
};
use colcos_bridge::protocol::swarmcon::{Calibrate, FrameTransform, TrackerEvent};
use colcos_bridge::transport::ConnectionState;
use colcos_bridge::transport::{AirtimeScheduler, Link, RobotLink, SerialWire, open_robot_link};
use colcos_bridge::{SourceOptions, open_pose_source};
use std::io::{Read, Write};
use std::net::{TcpListener, UdpSocket};
use std::time::{Duration, Instant};

/// Polls `f` until it returns `Some` or `limit` passes.
fn wait_for<T>(limit: Duration, mut f: impl FnMut() -> Option<T>) -> Option<T> {
    let end = Instant::now() + limit;
    while Instant::now() < end {
        if let Some(v) = f() {
            return Some(v);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    None
}

fn options() -> SourceOptions {
    let mut o = SourceOptions::new(FrameTransform::new(0.8));
    o.backoff_initial = Duration::from_millis(20);
    o.backoff_max = Duration::from_millis(100);
    o
}

#[test]
fn swarmcon_client_reads_split_blocks_calibrates_and_reconnects() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let server = std::thread::spawn(move || {
        // First connection: blocks split over many small writes, then `Calibrated` after the
        // client's command, then `Closed` and a hang-up.
        let (mut s, _) = listener.accept().unwrap();
        s.set_nodelay(true).unwrap();
        let block = b"Detected 1 of 2 at 1000000 \nRobot 004 0.100 0.200 90.000 1000000 \nRobot 005 -0.050 0.300 0.000 -1 \n";
        for chunk in block.chunks(7) {
            s.write_all(chunk).unwrap();
            std::thread::sleep(Duration::from_millis(1));
        }
        s.set_read_timeout(Some(Duration::from_secs(3))).unwrap();
        let mut cmd = Vec::new();
        let mut b = [0u8; 128];
        while !cmd.contains(&b'\n') {
            let n = s.read(&mut b).unwrap();
            assert!(n > 0, "client hung up before calibrating");
            cmd.extend_from_slice(&b[..n]);
        }
        s.write_all(b"Detected 0 of 0 at 1000001 \nCalibrated\nClosed\n")
            .unwrap();
        drop(s);
        // Second connection: the client came back.
        let (mut s, _) = listener.accept().unwrap();
        s.write_all(b"Detected 1 of 1 at 2000000. \nRobot 004 0.400 0.200 0.000 2000000 \n")
            .unwrap();
        std::thread::sleep(Duration::from_millis(300));
        String::from_utf8(cmd).unwrap()
    });
    let mut src = open_pose_source(&format!("swarmcon://{addr}"), &options()).unwrap();
    let snap = wait_for(Duration::from_secs(3), || src.poll()).expect("first frame");
    assert_eq!(snap.poses.len(), 1, "never-seen slot is left out");
    let p = snap.poses[0];
    assert_eq!(p.id, 4);
    assert!((p.pose.pos.x - 0.1).abs() < 1e-6 && (p.pose.pos.y - 0.6).abs() < 1e-6);
    assert!((p.pose.heading + std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    assert!(p.fresh);
    assert_eq!(src.state(), ConnectionState::Connected);
    let cal = Calibrate {
        robots: 2,
        field_length: 1.439,
        field_width: 0.809,
        camera_height: 1.8,
        robot_diameter: 0.04,
        robot_height: 0.035,
    };
    src.request_calibration(&cal).unwrap();
    let mut events = Vec::new();
    wait_for(Duration::from_secs(3), || {
        events.extend(src.take_events());
        (events.len() >= 2).then_some(())
    })
    .expect("events");
    assert_eq!(events, vec![TrackerEvent::Calibrated, TrackerEvent::Closed]);
    let snap = wait_for(Duration::from_secs(3), || src.poll().filter(|s| s.t > 1.5))
        .expect("frame after reconnect");
    assert!((snap.poses[0].pose.pos.x - 0.4).abs() < 1e-6);
    assert_eq!(src.counters().reconnects, 1);
    assert_eq!(src.counters().errors, 0);
    assert_eq!(
        server.join().unwrap(),
        "Calibrate 2 1.439 0.809 1.800 0.040 0.035 \n"
    );
}

#[test]
fn swarmcon_client_backs_off_while_no_server() {
    let port = {
        let l = TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().port()
    };
    let src = open_pose_source(&format!("swarmcon://127.0.0.1:{port}"), &options()).unwrap();
    let state = wait_for(Duration::from_secs(2), || match src.state() {
        s @ ConnectionState::Disconnected { .. } => Some(s),
        _ => None,
    });
    assert!(state.is_some());
    assert!(src.latest().is_none());
}

#[test]
fn udp_json_poses_merge_per_robot() {
    let probe = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = probe.local_addr().unwrap();
    drop(probe);
    let mut src = open_pose_source(&format!("udp://{addr}"), &options()).unwrap();
    let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
    tx.send_to(br#"{"id":1,"x":0.1,"y":0.2,"heading":0.5,"t":1.0}"#, addr)
        .unwrap();
    tx.send_to(b"not json", addr).unwrap();
    tx.send_to(br#"{"id":2,"x":0.3,"y":0.4,"heading":-0.5,"t":1.1}"#, addr)
        .unwrap();
    let snap = wait_for(Duration::from_secs(3), || {
        src.poll().filter(|s| s.poses.len() == 2)
    })
    .expect("two robots");
    assert_eq!(snap.poses[0].id, 1);
    assert!(!snap.poses[0].fresh && snap.poses[1].fresh);
    assert!((snap.poses[1].pose.heading + 0.5).abs() < 1e-6);
    wait_for(Duration::from_secs(1), || {
        (src.counters().errors == 1).then_some(())
    })
    .expect("bad datagram counted");
    assert!(
        src.request_calibration(&Calibrate {
            robots: 1,
            field_length: 1.0,
            field_width: 1.0,
            camera_height: 1.0,
            robot_diameter: 0.04,
            robot_height: 0.03
        })
        .is_err()
    );
}

#[test]
fn replay_of_server_log_and_of_captured_stream() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("server.log");
    std::fs::write(
        &log,
        "Frame 1 Time 1000000 Object 000 003 0.10000 0.20000 1.57080 \n\
         Frame 1 Time 1000000 Object 001 004 0.30000 0.40000 0.00000 \n\
         Frame 2 Time 1050000 Object 000 003 0.11000 0.20000 1.57080 \n",
    )
    .unwrap();
    let mut src =
        open_pose_source(&format!("replay://{}?speed=4", log.display()), &options()).unwrap();
    wait_for(Duration::from_secs(2), || {
        (src.state() == ConnectionState::Finished).then_some(())
    })
    .expect("finished");
    let snap = src.poll().unwrap();
    assert_eq!(snap.seq, 2);
    assert_eq!(snap.poses.len(), 1);
    assert!((snap.poses[0].pose.pos.x - 0.11).abs() < 1e-6);
    // Image yaw +90 degrees is -90 degrees in the simulator.
    assert!((snap.poses[0].pose.heading + std::f32::consts::FRAC_PI_2).abs() < 1e-4);

    let cap = dir.path().join("stream.txt");
    std::fs::write(
        &cap,
        "Detected 1 of 1 at 5. \nRobot 009 0.500 0.100 0.000 5 \nClosed\n",
    )
    .unwrap();
    let mut src =
        open_pose_source(&format!("replay://{}?speed=max", cap.display()), &options()).unwrap();
    let snap = wait_for(Duration::from_secs(2), || src.poll()).expect("frame");
    assert_eq!(snap.poses[0].id, 9);

    let bad = dir.path().join("bad.log");
    std::fs::write(&bad, "Frame 1 Time x Object 0 0 0 0 0\n").unwrap();
    let e = open_pose_source(&format!("replay://{}", bad.display()), &options())
        .err()
        .unwrap();
    assert!(e.to_string().contains("line 1"), "{e}");
}

#[cfg(unix)]
#[test]
fn serial_link_over_a_pseudo_terminal() {
    use serialport::{SerialPort, TTYPort};
    let (host, mut robot) = TTYPort::pair().expect("pty pair");
    robot.set_timeout(Duration::from_millis(50)).unwrap();
    let mut link = Link::new(
        SerialWire::from_port(Box::new(host)),
        AirtimeScheduler::new(115_200),
    );
    for id in 0..3u8 {
        link.send(CommandPacket::new(
            id,
            10,
            HostCommand::WheelSpeeds {
                left: 0.1,
                right: 0.2,
            },
        ));
    }
    link.send(CommandPacket::new(
        0,
        11,
        HostCommand::Motion {
            kind: MotionKind::Stop,
            speed: 0.0,
        },
    ));
    assert_eq!(link.pump().unwrap(), 3);

    // The robot side reads the frames.
    let mut dec = CommandDecoder::new();
    let mut got = Vec::new();
    wait_for(Duration::from_secs(2), || {
        let mut b = [0u8; 256];
        if let Ok(n) = robot.read(&mut b) {
            got.extend(dec.feed(&b[..n]));
        }
        (got.len() >= 3).then_some(())
    })
    .expect("three frames");
    let cmds: Vec<CommandPacket> = got
        .iter()
        .map(|p| CommandPacket::decode(p).unwrap())
        .collect();
    assert_eq!(
        cmds[0].command,
        HostCommand::Motion {
            kind: MotionKind::Stop,
            speed: 0.0
        }
    );
    assert_eq!(cmds[0].t_ms, 11);

    // And answers with telemetry, split by garbage.
    let t = Telemetry {
        id: 2,
        sys_t_ms: 77,
        colour: [[1, 2, 3]; 4],
        ..Telemetry::default()
    };
    let mut bytes = vec![0xAA, 0x01];
    bytes.extend(t.to_frame());
    robot.write_all(&bytes).unwrap();
    robot.flush().unwrap();
    let tel = wait_for(Duration::from_secs(2), || {
        link.pump().unwrap();
        let v = link.take_telemetry();
        (!v.is_empty()).then_some(v)
    })
    .expect("telemetry");
    assert_eq!(tel, vec![t]);
    let c = link.counters();
    assert_eq!(
        (c.scheduler.sent, c.scheduler.superseded, c.telemetry),
        (3, 1, 1)
    );
    assert_eq!(c.skipped_bytes, 2);
}

#[test]
fn udp_robot_link_sends_frames_and_receives_telemetry() {
    let twin = UdpSocket::bind("127.0.0.1:0").unwrap();
    twin.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
    let mut link = open_robot_link(&format!("udp://{}", twin.local_addr().unwrap())).unwrap();
    link.send(CommandPacket::new(5, 1, HostCommand::RequestTelemetry(1)));
    assert_eq!(link.pump().unwrap(), 1);
    let mut b = [0u8; 256];
    let (n, from) = twin.recv_from(&mut b).unwrap();
    assert_eq!(n, 36);
    let t = Telemetry {
        id: 5,
        ..Telemetry::default()
    };
    twin.send_to(&t.to_frame(), from).unwrap();
    let tel = wait_for(Duration::from_secs(2), || {
        link.pump().unwrap();
        let v = link.take_telemetry();
        (!v.is_empty()).then_some(v)
    })
    .expect("telemetry");
    assert_eq!(tel[0].id, 5);
    assert!(open_robot_link("serial:///dev/does-not-exist-colcos").is_err());
}
