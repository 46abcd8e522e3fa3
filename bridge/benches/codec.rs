//! Codec throughput: a command frame and a telemetry frame encoded and decoded (target under 1 us a
//! frame), and the tracker parser on blocks of 100 robots (target at least 10,000 blocks/s). Prints
//! each figure and its ratio to the target, then runs the criterion groups.

use colcos_bridge::protocol::colias::{
    CommandDecoder, CommandPacket, HostCommand, Telemetry, TelemetryDecoder,
};
use colcos_bridge::protocol::swarmcon::{
    HeaderForm, SlotPose, StreamParser, TrackerFrame, write_block,
};
use criterion::{Criterion, Throughput};
use std::hint::black_box;
use std::time::{Duration, Instant};

fn command_round_trip(dec: &mut CommandDecoder, out: &mut Vec<[u8; 32]>, i: u32) -> CommandPacket {
    let p = CommandPacket::new(
        (i % 20) as u8,
        i,
        HostCommand::WheelSpeeds {
            left: 0.1,
            right: -0.2,
        },
    );
    let frame = p.to_frame();
    out.clear();
    dec.feed_into(black_box(&frame), out);
    CommandPacket::decode(&out[0]).unwrap_or(p)
}

fn telemetry_round_trip(dec: &mut TelemetryDecoder, out: &mut Vec<[u8; 96]>, i: u32) -> Telemetry {
    let t = Telemetry {
        id: (i % 20) as u8,
        sys_t_ms: i,
        colour: [[i as u16; 3]; 4],
        ..Telemetry::default()
    };
    let frame = t.to_frame();
    out.clear();
    dec.feed_into(black_box(&frame), out);
    Telemetry::decode(&out[0])
}

fn block_of_100() -> Vec<u8> {
    let robots = (0..100)
        .map(|i| SlotPose {
            id: i,
            x: 0.01 * i as f64 - 0.2,
            y: 0.8 - 0.007 * i as f64,
            yaw_deg: 3.6 * i as f64 - 180.0,
            last_seen_us: if i % 7 == 0 {
                1_699_999_999_000_000
            } else {
                1_700_000_000_000_000
            },
            state: SlotPose::state_for(0, 0),
        })
        .collect();
    let f = TrackerFrame {
        t_us: 1_700_000_000_000_000,
        found: 86,
        tracked: 100,
        updated: Some(86),
        robots,
    };
    write_block(&f, HeaderForm::Updated, false).into_bytes()
}

/// Runs `f` for about `budget` and returns seconds per call.
fn time_per_call(budget: Duration, mut f: impl FnMut(u32)) -> f64 {
    let mut n = 0u32;
    let start = Instant::now();
    while start.elapsed() < budget {
        for _ in 0..1000 {
            f(n);
            n = n.wrapping_add(1);
        }
    }
    start.elapsed().as_secs_f64() / n as f64
}

fn report_targets() {
    let budget = Duration::from_millis(300);
    let (mut cd, mut co) = (CommandDecoder::new(), Vec::new());
    let cmd = time_per_call(budget, |i| {
        black_box(command_round_trip(&mut cd, &mut co, i));
    });
    let (mut td, mut to) = (TelemetryDecoder::new(), Vec::new());
    let tel = time_per_call(budget, |i| {
        black_box(telemetry_round_trip(&mut td, &mut to, i));
    });
    let block = block_of_100();
    let mut parser = StreamParser::new();
    let mut out = Vec::new();
    let per_block = time_per_call(budget, |_| {
        out.clear();
        parser.feed_into(black_box(&block), &mut out);
    });
    assert_eq!(parser.counters().errors, 0);
    let blocks_per_s = 1.0 / per_block;
    println!("target check (higher ratio is better):");
    println!(
        "  command frame encode+decode   {:8.1} ns/frame  target 1000 ns     ratio {:6.1}x",
        cmd * 1e9,
        1e-6 / cmd
    );
    println!(
        "  telemetry frame encode+decode {:8.1} ns/frame  target 1000 ns     ratio {:6.1}x",
        tel * 1e9,
        1e-6 / tel
    );
    println!(
        "  tracker block of 100 robots   {:8.0} blocks/s  target 10000/s     ratio {:6.1}x  ({:.1} us/block, {:.0} MB/s)",
        blocks_per_s,
        blocks_per_s / 1e4,
        per_block * 1e6,
        block.len() as f64 / per_block / 1e6
    );
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("colias");
    g.throughput(Throughput::Elements(1));
    let (mut cd, mut co) = (CommandDecoder::new(), Vec::new());
    let mut i = 0u32;
    g.bench_function("command_encode_decode", |b| {
        b.iter(|| {
            i = i.wrapping_add(1);
            command_round_trip(&mut cd, &mut co, i)
        })
    });
    let (mut td, mut to) = (TelemetryDecoder::new(), Vec::new());
    g.bench_function("telemetry_encode_decode", |b| {
        b.iter(|| {
            i = i.wrapping_add(1);
            telemetry_round_trip(&mut td, &mut to, i)
        })
    });
    g.finish();

    let block = block_of_100();
    let mut g = c.benchmark_group("swarmcon");
    g.throughput(Throughput::Elements(1));
    let mut parser = StreamParser::new();
    let mut out = Vec::new();
    g.bench_function("parse_block_100_robots", |b| {
        b.iter(|| {
            out.clear();
            parser.feed_into(black_box(&block), &mut out);
            out.len()
        })
    });
    g.finish();
}

fn main() {
    report_targets();
    let mut c = Criterion::default().configure_from_args();
    benches(&mut c);
    c.final_summary();
}
