use colcos::experiment::{case1::*, layout::TrailLayout};
use colcos::sim::behaviour::paper::*;
use colcos::sim::behaviour::WheelCommand;
use colcos::sim::prelude::*;
fn main() {
    let g: usize = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(2);
    let trial: u64 = std::env::args().nth(2).map(|s| s.parse().unwrap()).unwrap_or(0);
    let cfg = Case1Config::new(TrailLayout::a(), 1, 1);
    let sc = cfg.scenario(g).unwrap();
    let mut w = World::with_index(&sc, trial).unwrap();
    preload_steady_state(&mut w);
    w.step_with_commands(&[WheelCommand::STOP]);
    let params: ForagingParams = toml::Value::Table(cfg.forage.clone()).try_into().unwrap();
    let mut f = Foraging::new(params);
    let mut rng = colcos::sim::rng::stream(1, trial, 99);
    for k in 0..600 {
        let obs = w.observations()[0];
        let d = f.decide(&obs, &mut rng);
        // re-run act path equivalently
        let cmd = match d {
            ForagingDecision::FollowLap => f.steer(&obs, Trail::Lap),
            ForagingDecision::FollowCyan => f.steer(&obs, Trail::Cyan),
            ForagingDecision::Bifurcation { side, .. } | ForagingDecision::TurnInto { side, .. } => f.turn_into(side, 0.026),
            ForagingDecision::Committed { trail, .. } => f.steer(&obs, trail),
            _ => WheelCommand::new(0.1, 0.1),
        };
        let p = w.poses()[0];
        if k % 5 == 0 {
            let i = |n: usize| format!("{:.2}/{:.2}/{:.2}", obs.intensity[n][0], obs.intensity[n][1], obs.intensity[n][2]);
            println!("{k:4} t={:.2} pos=({:.3},{:.3}) h={:6.1} R={} F={} L={} B={} {:?} cmd=({:.3},{:.3})", obs.time, p.pos.x, p.pos.y, p.heading.to_degrees(), i(0), i(1), i(2), i(3), d, cmd.left, cmd.right);
        }
        w.step_with_commands(&[cmd]);
    }
}
