//! `World::skip_unread_colour`: the colour of robots nobody reads is not evaluated (they read 0), and
//! nothing else moves by a bit: every pose, every other robot's reading, every random stream.
use colcos_sim::prelude::*;
use colcos_testkit::scenarios::case_ii_like;

fn bits(o: &colcos_sim::behaviour::Observation) -> ([[u16; 3]; 4], [[u32; 3]; 4], [u32; 3]) {
    (
        o.counts,
        o.intensity.map(|c| c.map(f32::to_bits)),
        o.bumpers.map(f32::to_bits),
    )
}

/// Case II's leader wanders (its behaviour reads no colour) with noisy sensors: skipped, it reads 0
/// while its pose, which its wander draws from the same stream as its sensor noise, and the five
/// followers' readings stay those of a world that reads everything.
#[test]
fn a_skipped_robot_reads_zero_and_nothing_else_moves() {
    let sc = case_ii_like();
    let mut full = World::new(&sc).unwrap();
    let mut skip = World::new(&sc).unwrap();
    skip.skip_unread_colour(&[]);
    let mut read = World::new(&sc).unwrap();
    read.skip_unread_colour(&[0]); // an observer is read whatever its behaviour
    let n = full.robot_count();
    for step in 0..sc.steps() {
        full.step();
        skip.step();
        read.step();
        for i in 0..n {
            let (f, s) = (&full.observations()[i], &skip.observations()[i]);
            assert_eq!(full.poses()[i], skip.poses()[i], "robot {i}, step {step}");
            assert_eq!(
                bits(f),
                bits(&read.observations()[i]),
                "robot {i}, step {step}"
            );
            if i == 0 {
                assert_eq!((s.counts, s.intensity), ([[0; 3]; 4], [[0.0; 3]; 4]));
                assert_eq!(f.bumpers.map(f32::to_bits), s.bumpers.map(f32::to_bits));
                assert!(
                    f.counts.iter().flatten().any(|&c| c > 0),
                    "the leader sees the dark counts at least"
                );
            } else {
                assert_eq!(bits(f), bits(s), "robot {i}, step {step}");
            }
        }
    }
}

/// A robot given a new behaviour is read again.
#[test]
fn a_new_behaviour_is_read() {
    let sc = case_ii_like();
    let mut w = World::new(&sc).unwrap();
    w.skip_unread_colour(&[]);
    w.step();
    assert_eq!(w.observations()[0].counts, [[0; 3]; 4]);
    let wander = colcos_sim::behaviour::Wander::new(0.05);
    w.set_behaviour(0, Box::new(wander));
    w.step();
    assert_ne!(w.observations()[0].counts, [[0; 3]; 4]);
}
