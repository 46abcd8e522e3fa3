//! Printed obstacles (`kind = "printed"`): drawn on the LCD in their colour, read by the colour
//! sensors through the sensor model, driven over, invisible to the bumpers.
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::output::gif::frame_image;
use colcos_sim::rng::{Stream, stream_of};
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;
use colcos_testkit::parsing::assert_all_refused;

/// One robot at `(x, 0.4)` heading along +x; `obstacle` is one `[[obstacles]]` table's body.
fn world(x: f32, obstacle: &str) -> World {
    let text = format!(
        r#"
duration = 10.0
seed = 4
[sensor]
noise = 0.0
[[robots]]
count = 1
behaviour = "wander"
placement = "explicit"
poses = [[{x}, 0.4, 0.0]]
[[obstacles]]
{obstacle}
"#
    );
    World::new(&Scenario::from_toml_str(&text, ".").unwrap()).unwrap()
}

const RED_BOX: &str = r#"shape = "box"
kind = "printed"
centre = [0.5, 0.4]
size = [0.2, 0.3]
colour = [200, 40, 0]"#;

/// A robot parked on a printed box reads, on each of its four sensors, what the sensor model gives
/// for the box's colour (no noise); off the box, what it gives for a black screen.
#[test]
fn the_colour_sensors_read_a_printed_obstacle() {
    for (x, levels) in [(0.5, [200.0, 40.0, 0.0]), (0.2, [0.0; 3])] {
        let mut w = world(x, RED_BOX);
        w.step_with_commands(&[WheelCommand::STOP]);
        let mut rng = stream_of(0, 0, Stream::Telemetry(0));
        let want = w.sensor().counts(levels, &mut rng);
        let o = &w.observations()[0];
        for k in 0..4 {
            assert_eq!(o.counts[k], want, "robot at x = {x}, sensor {k}");
        }
        if x == 0.5 {
            assert!(o.intensity[0][0] > 0.7 && o.intensity[0][2] < 0.05, "{o:?}");
        }
    }
}

/// A printed box is driven over as if it were not there (its bumpers never see it); the same box
/// physical stops the robot at its face.
#[test]
fn robots_drive_over_printed_obstacles_but_not_physical_ones() {
    let ahead = [WheelCommand {
        left: 0.1,
        right: 0.1,
    }];
    for (kind, printed) in [("printed", true), ("physical", false)] {
        let body = RED_BOX.replace("\"printed\"", &format!("{kind:?}"));
        let body = if printed {
            body
        } else {
            body.replace("colour = [200, 40, 0]", "")
        };
        let mut w = world(0.3, &body);
        let mut bumped = 0.0f32;
        for _ in 0..200 {
            w.step_with_commands(&ahead);
            bumped = bumped.max(
                w.observations()[0]
                    .bumpers
                    .iter()
                    .copied()
                    .fold(0.0, f32::max),
            );
        }
        let x = w.poses()[0].pos.x;
        if printed {
            assert!(x > 0.65, "printed: the robot stopped at x = {x}");
            assert_eq!(bumped, 0.0, "printed: the bumpers saw it");
        } else {
            // Its face at x = 0.4, the robot's radius 2 cm.
            assert!(
                (x - 0.38).abs() < 0.005,
                "physical: the robot is at x = {x}"
            );
            assert!(bumped > 0.5, "physical: the bumpers did not see it");
        }
    }
}

/// The screen image shows a printed obstacle filled in its colour, later entries over earlier ones,
/// and the robot may start on one.
#[test]
fn printed_obstacles_are_drawn_filled_in_order() {
    let two = format!(
        "{RED_BOX}\n[[obstacles]]\nshape = \"disc\"\nkind = \"printed\"\ncentre = [0.5, 0.4]\nradius = 0.05\ncolour = [0, 0, 255]"
    );
    let w = world(0.5, &two);
    let s = w.screen();
    let img = frame_image(&w, 1439, 809);
    let px = |x: f32, y: f32| {
        let (col, row) = (
            (x / s.size[0] * 1439.0) as u32,
            ((s.size[1] - y) / s.size[1] * 809.0) as u32,
        );
        img.get_pixel(col, row).0
    };
    // Inside the disc (over the box), inside the box only, outside both (the robot sits at the centre).
    assert_eq!(px(0.5, 0.43), [0, 0, 255]);
    assert_eq!(px(0.5, 0.52), [200, 40, 0]);
    assert_eq!(px(0.59, 0.28), [200, 40, 0]);
    assert_eq!(px(0.65, 0.4), [0, 0, 0]);
}

#[test]
fn a_colour_on_a_physical_obstacle_or_a_bad_one_is_refused() {
    let text = |body: &str| {
        format!(
            "duration = 1.0\n[[robots]]\ncount = 1\nbehaviour = \"wander\"\n[[obstacles]]\n{body}\n"
        )
    };
    assert_all_refused(&[
        (
            text("shape = \"disc\"\ncentre = [0.5, 0.4]\nradius = 0.05\ncolour = [1, 2, 3]"),
            &["obstacles[0].colour", "printed"],
        ),
        (
            text(
                "shape = \"disc\"\nkind = \"printed\"\ncentre = [0.5, 0.4]\nradius = 0.05\ncolour = [1, 2, 300]",
            ),
            &["obstacles[0].colour"],
        ),
        (
            text("shape = \"disc\"\nkind = \"painted\"\ncentre = [0.5, 0.4]\nradius = 0.05"),
            &["obstacles[0].kind", "printed"],
        ),
        (
            text("shape = \"disc\"\nkind = \"printed\"\ncentre = [5.0, 0.4]\nradius = 0.05"),
            &["obstacles[0].centre"],
        ),
    ]);
}

/// `scenarios/printed_track.toml`: a `follow` robot keeps to a blue loop that only the printed
/// obstacle draws (no pheromone makes it). Each of the scenario's four starting poses is run alone
/// for four seeds (together, who queues behind whom at a corner depends on the seed), 30 s each: the
/// robot is within 4 cm of the centre line more than half of each run and nine tenths on average (it
/// may overshoot a corner and find the track again), and on average goes most of the way round the
/// 1.6 m loop at its 6 cm/s.
#[test]
fn a_robot_follows_the_printed_track() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/printed_track.toml"
    );
    let sc = Scenario::from_file(path).unwrap();
    let track: Vec<glam::Vec2> = sc.spec.obstacles[0]
        .points
        .as_ref()
        .unwrap()
        .iter()
        .map(|p| glam::Vec2::from(*p))
        .collect();
    let off = |p: glam::Vec2| {
        track
            .windows(2)
            .map(|s| {
                let (a, d) = (s[0], s[1] - s[0]);
                let t = ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
                p.distance(a + t * d)
            })
            .fold(f32::INFINITY, f32::min)
    };
    let poses = sc.spec.robots[0].poses.clone();
    assert_eq!(poses.len(), 4);
    let (mut shares, mut distances) = (Vec::new(), Vec::new());
    for pose in poses {
        for seed in 1..=4 {
            let mut alone = sc.clone();
            alone.spec.seed = seed;
            alone.spec.robots[0].count = 1;
            alone.spec.robots[0].poses = vec![pose];
            let mut w = World::new(&alone).unwrap();
            let (mut steps, mut on_track, mut travelled) = (0, 0, 0.0f32);
            while !w.is_finished() {
                let before = w.poses()[0].pos;
                w.step();
                let p = w.poses()[0].pos;
                steps += 1;
                on_track += usize::from(off(p) < 0.04);
                travelled += p.distance(before);
            }
            let share = on_track as f32 / steps as f32;
            assert!(
                share > 0.5,
                "from {pose:?}, seed {seed}: on the track {share}"
            );
            shares.push(share);
            distances.push(travelled);
        }
    }
    let mean = |xs: &[f32]| xs.iter().sum::<f32>() / xs.len() as f32;
    assert!(mean(&shares) > 0.9, "{shares:?}");
    assert!(mean(&distances) > 1.0, "{distances:?}");
}
