//! Pre-flight check of a scenario's behaviours: a few episodes on a digital twin started here (with
//! the scenario's calibration and tracker model), measured as the rig would be, before the behaviours
//! may drive the real robots. Refused, with every limit broken named, when the shield had to turn or
//! cap commands too often, a robot reached the arena's edge, robots ran into each other, or the loop
//! overran its ticks. `colcos.preflight` does the same for a Python policy.
use crate::PlantError;
use crate::driver::TwinThread;
use colcos_bridge::calibrate::RigCalibration;
use colcos_bridge::rig::{LiveOptions, LiveSession, RigEnds};
use colcos_bridge::{SourceOptions, open_pose_source, open_robot_link};
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use std::time::Instant;

/// What the behaviours may do on the twin and still be let onto the rig.
#[derive(Clone, Copy, Debug)]
pub struct PreflightLimits {
    /// Robot-ticks the shield turned from a virtual wall, fraction.
    pub walled: f64,
    /// Robot-ticks whose wheel speeds the shield capped, fraction.
    pub capped: f64,
    /// Ticks with a robot's body past the arena's edge by more than `edge_tolerance` (tracked
    /// poses), count.
    pub boundary: u64,
    /// How far a body may reach past the edge before it counts, m; `None`: 3 mm or five standard
    /// deviations of the tracker's position noise, whichever is larger (a robot pushed against the
    /// wall shows a few millimetres past it in that noise).
    pub edge_tolerance: Option<f32>,
    /// Ticks with two robots overlapping by more than 5 mm (tracked poses), fraction.
    pub collisions: f64,
    /// Ticks that overran their slot, fraction.
    pub overruns: f64,
}

impl Default for PreflightLimits {
    fn default() -> Self {
        PreflightLimits {
            walled: 0.05,
            capped: 0.05,
            boundary: 0,
            edge_tolerance: None,
            collisions: 0.02,
            overruns: 0.02,
        }
    }
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PreflightReport {
    pub episodes: usize,
    #[serde(flatten)]
    pub counts: PreflightCounts,
    pub stops: Vec<String>,
    /// The farthest any body reached past the edge, if one did.
    pub worst_boundary: Option<PastEdge>,
    /// Each limit broken, with its value.
    pub broken: Vec<String>,
}

/// The ticks of every episode, and those of them that count against the limits.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct PreflightCounts {
    pub ticks: u64,
    pub robot_ticks: u64,
    /// Robot-ticks the shield turned from a virtual wall, and those it capped.
    pub walled: u64,
    pub capped: u64,
    /// Ticks with a body past the edge, with robots overlapping, and overrun.
    pub boundary: u64,
    pub collisions: u64,
    pub overruns: u64,
}

impl PreflightCounts {
    /// Each limit's name, the value it is checked on (a fraction of the ticks or robot-ticks, or a
    /// count) and the limit.
    fn against(&self, limits: &PreflightLimits) -> [(&'static str, f64, f64); 5] {
        let frac = |n: u64, d: u64| n as f64 / d.max(1) as f64;
        [
            ("walled", frac(self.walled, self.robot_ticks), limits.walled),
            ("capped", frac(self.capped, self.robot_ticks), limits.capped),
            ("boundary", self.boundary as f64, limits.boundary as f64),
            (
                "collisions",
                frac(self.collisions, self.ticks),
                limits.collisions,
            ),
            ("overruns", frac(self.overruns, self.ticks), limits.overruns),
        ]
    }
}

/// Where a body reached farthest past the arena's edge.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct PastEdge {
    pub robot: usize,
    pub episode: usize,
    pub tick: u64,
    /// How far the body reached past the edge, m.
    pub past: f32,
}

/// Runs `episodes` episodes of `seconds` s (seeds `seed, seed + 1, ...`) and checks `limits`.
pub fn check(
    scenario: &Scenario,
    episodes: usize,
    seconds: f64,
    limits: &PreflightLimits,
) -> Result<PreflightReport, PlantError> {
    let mut r = PreflightReport::default();
    let radius = scenario.spec.robot.radius;
    let arena = scenario.arena_size();
    let tolerance = limits
        .edge_tolerance
        .unwrap_or_else(|| (5.0 * scenario.spec.tracker.position_noise).max(0.003));
    for k in 0..episodes {
        let mut sc = scenario.clone();
        sc.spec.seed = scenario.spec.seed.wrapping_add(k as u64);
        let twin = TwinThread::start(&sc)?;
        let calibration = RigCalibration::load(&sc)
            .map_err(|e| PlantError::Io(format!("rig.screen_calibration: {e}")))?;
        let source = open_pose_source(
            &twin.tracker_url,
            &SourceOptions::new(calibration.frame_transform(&sc)),
        )?;
        let ends = RigEnds {
            source,
            link: open_robot_link(&twin.robots_url)?,
            frames: None,
        };
        let mut session = LiveSession::new(&sc, ends, LiveOptions::default())?;
        let start = Instant::now();
        let mut tick = 0u64;
        while start.elapsed().as_secs_f64() < seconds {
            session.tick(&[])?;
            let core = session.core();
            let host = core.host();
            let seen: Vec<(usize, glam::Vec2)> = (host.tracked().iter())
                .zip(ArenaView::poses(host))
                .enumerate()
                .filter(|(_, (t, _))| t.seen)
                .map(|(i, (_, p))| (i, p.pos))
                .collect();
            r.counts.ticks += 1;
            r.counts.robot_ticks += seen.len() as u64;
            for i in core.interventions() {
                r.counts.walled += i.walled as u64;
                r.counts.capped += i.capped as u64;
            }
            // How far the body reaches past the nearest edge (negative: inside).
            let past = |p: glam::Vec2| radius - p.min(arena - p).min_element();
            let mut beyond = false;
            for &(robot, p) in &seen {
                let d = past(p);
                beyond |= d > tolerance;
                if d > 0.0 && r.worst_boundary.is_none_or(|w| d > w.past) {
                    r.worst_boundary = Some(PastEdge {
                        robot,
                        episode: k,
                        tick,
                        past: d,
                    });
                }
            }
            r.counts.boundary += beyond as u64;
            let touching = seen.iter().enumerate().any(|(i, (_, a))| {
                seen[..i]
                    .iter()
                    .any(|(_, b)| a.distance(*b) < 2.0 * radius - 0.005)
            });
            r.counts.collisions += touching as u64;
            session.wait_next();
            tick += 1;
        }
        let report = session.report();
        r.counts.overruns += report.overruns;
        r.stops.extend(report.stops);
        r.episodes += 1;
        drop(session);
        drop(twin);
    }
    for (name, value, limit) in r.counts.against(limits) {
        if value > limit {
            let mut text = format!("{name} = {value:.4} over the limit {limit}");
            if let ("boundary", Some(w)) = (name, r.worst_boundary) {
                text.push_str(&format!(
                    " (farthest: robot {} in episode {} at tick {}, {:.1} mm past the edge)",
                    w.robot,
                    w.episode,
                    w.tick,
                    w.past * 1e3
                ));
            }
            r.broken.push(text);
        }
    }
    Ok(r)
}
