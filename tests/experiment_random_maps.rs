//! Random trail maps of case I: the generator's rules (fork angles, fit, depth, food points,
//! determinism per seed).
mod common;
use colcos::experiment::layout::Corners;
use colcos::experiment::random_map::{MapRules, check_fit, coin_share, random_map, random_maps};
use colcos::sim::Vec2;

fn angle_deg(v: Vec2) -> f32 {
    v.y.atan2(v.x).to_degrees()
}

fn wrap_deg(a: f32) -> f32 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

#[test]
fn maps_follow_the_papers_rule_and_fit_the_screen() {
    let rules = MapRules::default();
    let maps = random_maps(11, 24, &rules).unwrap();
    let mut sides = std::collections::BTreeSet::new();
    let mut corners = std::collections::BTreeSet::new();
    let mut depths = std::collections::BTreeSet::new();
    for m in &maps {
        let l = &m.layout;
        check_fit(l, &rules).unwrap();
        assert!((2..=4).contains(&m.depth), "depth {}", m.depth);
        // The deepest path has exactly `depth` forks (nest and end point not counted).
        let deepest = l.ends.iter().map(|&e| l.path_to(e).len() - 2).max();
        assert_eq!(deepest, Some(m.depth), "{}", l.name);
        assert!((1..=3).contains(&m.foods.len()), "{:?}", m.foods);
        assert!(m.foods.windows(2).all(|w| w[0] < w[1]));
        assert!(m.foods.iter().all(|&f| (1..=l.ends.len()).contains(&f)));
        assert!(m.foods.len() < l.ends.len());
        sides.insert(l.nest().heading_deg as i32);
        corners.insert(matches!(l.corners, Corners::Straight));
        depths.insert(m.depth);
        // Every fork sends its two branches out at +-35 degrees from its heading (a rounded branch's
        // first 1 cm segment is a chord of its curve, so it may turn by a few degrees more).
        for k in 0..l.nodes.len() {
            let children = l.children(k);
            if children.len() < 2 {
                continue;
            }
            assert_eq!(children.len(), 2);
            for (c, want) in children.iter().zip([-35.0f32, 35.0]) {
                let e = l.edge(*c);
                let first = angle_deg(e[1] - e[0]);
                let off = wrap_deg(first - l.nodes[k].heading_deg);
                assert!(
                    (off - want).abs() < 3.0,
                    "{}: branch into node {c} leaves at {off} degrees",
                    l.name
                );
            }
        }
        // SRP: one 12 cm piece on each unrewarded branch of a fork on a food path.
        for piece in l.srp_polylines(&m.foods) {
            let len: f32 = piece.windows(2).map(|w| w[0].distance(w[1])).sum();
            assert!((len - 0.12).abs() < 0.01, "SRP piece {len} m");
        }
        assert!(!l.srp_polylines(&m.foods).is_empty());
        let share = coin_share(l, &m.foods);
        assert!(share > 0.0 && share < 1.0, "{share}");
    }
    assert_eq!(sides.len(), 4, "nest sides {sides:?}");
    assert_eq!(corners.len(), 2, "both corner kinds");
    assert!(depths.len() >= 2, "depths {depths:?}");
}

#[test]
fn the_same_seed_gives_the_same_maps() {
    let rules = MapRules::default();
    let a = random_map(5, 3, &rules).unwrap();
    let b = random_map(5, 3, &rules).unwrap();
    assert_eq!(a.layout, b.layout);
    assert_eq!(a.foods, b.foods);
    let c = random_map(6, 3, &rules).unwrap();
    assert_ne!(a.layout, c.layout);
    let d = random_map(5, 4, &rules).unwrap();
    assert_ne!(a.layout, d.layout);
}

#[test]
fn maps_that_break_a_rule_are_refused() {
    let rules = MapRules::default();
    let m = random_map(2, 0, &rules).unwrap();
    // An end point moved onto another trail.
    let mut crossing = m.layout.clone();
    let (e0, e1) = (crossing.ends[0], *crossing.ends.last().unwrap());
    crossing.nodes[e0].pos = crossing.nodes[e1].pos + Vec2::new(0.02, 0.02);
    let err = check_fit(&crossing, &rules).unwrap_err();
    assert!(err.contains("close") || err.contains("edge"), "{err}");
    // An end point pushed off the screen.
    let mut outside = m.layout.clone();
    let e = outside.ends[0];
    outside.nodes[e].pos = Vec2::new(-0.1, 0.4);
    let err = check_fit(&outside, &rules).unwrap_err();
    assert!(err.contains("edge"), "{err}");
    // A too tight clearance cannot be met by any draw: a clear error, no panic.
    let strict = MapRules {
        clearance: 2.0,
        max_attempts: 20,
        ..MapRules::default()
    };
    let err = random_map(2, 0, &strict).unwrap_err().to_string();
    assert!(err.contains("20 draws"), "{err}");
}

#[test]
fn g3_reaches_the_food_on_random_maps_and_g1_less_often() {
    use colcos::experiment::random_run::{Tally, claims, run};
    let r = run(3, 5, 5, &toml::Table::new(), &|| {}).unwrap();
    assert_eq!(r.maps.len(), 5);
    for m in &r.maps {
        let t = Tally::of(m);
        assert!(
            t.at_food[2] >= 4,
            "{}: G3 at food {}/5",
            m.map.layout.name,
            t.at_food[2]
        );
    }
    let c = claims(&r);
    assert!(
        c.pooled.at_food[2] >= 24,
        "G3 pooled {:?}",
        c.pooled.at_food
    );
    assert!(
        c.pooled.at_food[0] < c.pooled.at_food[2],
        "{:?}",
        c.pooled.at_food
    );
    // The same seed gives the same trials.
    let again = run(3, 5, 5, &toml::Table::new(), &|| {}).unwrap();
    assert_eq!(claims(&again).pooled.at_food, c.pooled.at_food);
}

#[test]
fn the_command_line_runs_random_maps_and_refuses_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    // `colcos experiment case1 --maps random --quiet --out <dir>` and `args`.
    let case1_random = |args: &[&str]| {
        common::colcos(&[
            "experiment",
            "case1",
            "--maps",
            "random",
            "--quiet",
            "--out",
        ])
        .arg(dir.path())
        .args(args)
        .output()
        .unwrap()
    };
    let out = case1_random(&["--count", "2", "--trials", "2", "--seed", "4"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("Case I on 2 random trail maps"), "{stdout}");
    for f in ["maps.csv", "summary.md", "claims.json", "maps.png"] {
        assert!(dir.path().join("case1_random").join(f).is_file(), "{f}");
    }
    let csv = std::fs::read_to_string(dir.path().join("case1_random/maps.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    for (args, want) in [
        (["--count", "0"], "--count must be at least 1"),
        (["--foods", "1"], "--foods applies to layouts A and B"),
    ] {
        let out = case1_random(&args);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "{args:?}: {err}");
    }
}
