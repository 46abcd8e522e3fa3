//! Many worlds' grids in one resident batch ([`WorldFields`], cut into parts of two worlds here):
//! worlds that hand their grids to the batch and sense from its sums observe what worlds stepping on
//! the CPU observe, step for step, through a world rebuilt mid-run; their fields stay within 1e-5.
mod common;
use colcos_gpu::WorldFields;
use colcos_sim::field::{FieldModel, Kernel};
use colcos_sim::prelude::*;
use colcos_testkit::scenarios::three_maps;
use common::{compare, ctx};

/// Three grid pheromones with static maps (one diffusing) and a cone trail laid by every robot.
fn scenario() -> Scenario {
    three_maps(1e-5, 5)
        .name("batch")
        .seed(9)
        .cell(0.01)
        .build()
        .unwrap()
}

/// Loads world `w` into the batch: its fields and its sensors' footprints.
fn load(fields: &mut WorldFields, w: usize, world: &World) {
    fields.load_world(w, world.pheromones()).unwrap();
    let sets: Vec<u32> = (0..world.robot_count())
        .flat_map(|i| [fields.footprint(&world.footprint_offsets(i)); 4])
        .collect();
    fields.set_footprints(w, &sets).unwrap();
}

#[test]
fn worlds_sensing_from_the_batch_observe_what_cpu_worlds_observe() {
    let Some(ctx) = ctx() else { return };
    let sc = scenario();
    let n = 5;
    let mut cpu: Vec<World> = (0..n)
        .map(|w| World::with_index(&sc, w as u64).unwrap())
        .collect();
    let mut gpu: Vec<World> = (0..n)
        .map(|w| World::with_index(&sc, w as u64).unwrap())
        .collect();
    let robots = gpu[0].robot_count();
    let screen = *gpu[0].screen();
    let mut fields =
        WorldFields::in_parts(ctx, gpu[0].pheromones(), n, 4 * robots, screen, 2).unwrap();
    assert_eq!(fields.parts(), 3, "five worlds in parts of two");
    for (w, world) in gpu.iter_mut().enumerate() {
        load(&mut fields, w, world);
        world.set_external_grids(true);
    }
    let dt = sc.spec.dt;
    let mut sums = Vec::new();
    for step in 1..=60 {
        if step == 25 {
            // A new episode of world 3 on both sides.
            cpu[3] = World::with_index(&sc, 103).unwrap();
            gpu[3] = World::with_index(&sc, 103).unwrap();
            load(&mut fields, 3, &gpu[3]);
            gpu[3].set_external_grids(true);
        }
        cpu.iter_mut().for_each(World::step);
        gpu.iter_mut().for_each(World::step);
        let trails: Vec<_> = gpu.iter().map(|w| w.trail_segments()).collect();
        fields.queue_trails(|w| Some(trails[w])).unwrap();
        fields.step(dt).unwrap();
        let per_world = 4 * robots;
        for (c, world) in fields.centres_mut().chunks_mut(per_world).zip(&gpu) {
            for i in 0..robots {
                for (k, p) in world.sensor_centres(i).iter().enumerate() {
                    c[4 * i + k] = [p.x, p.y];
                }
            }
        }
        fields.sense(&mut sums).unwrap();
        assert_eq!(sums.len(), n * per_world);
        for (w, world) in gpu.iter_mut().enumerate() {
            world.sense_from_sums(&sums[w * per_world..(w + 1) * per_world]);
            for (i, (a, b)) in cpu[w]
                .observations()
                .iter()
                .zip(world.observations())
                .enumerate()
            {
                assert_eq!(a.counts, b.counts, "step {step}, world {w}, robot {i}");
                assert_eq!(
                    a.intensity, b.intensity,
                    "step {step}, world {w}, robot {i}"
                );
            }
            assert_eq!(cpu[w].poses(), world.poses(), "step {step}, world {w}");
        }
    }
    let mut laid = 0;
    for (w, world) in cpu.iter().enumerate() {
        let got = fields.read_world(w).unwrap();
        for (k, p) in world.pheromones().iter().enumerate() {
            let FieldModel::Grid(g) = &p.model else {
                panic!("grid pheromones")
            };
            let (err, _) = compare(&got[k], g.values());
            assert!(
                err <= 1e-5,
                "world {w}, pheromone {k}: relative error {err:e}"
            );
            if k == 2 {
                laid += g.values().iter().filter(|&&v| v > 0.0).count();
            }
        }
    }
    assert!(laid > 100, "the robots laid {laid} cells of blue");
}

#[test]
fn a_trail_on_a_pheromone_the_worlds_lack_is_an_error_naming_it() {
    let Some(ctx) = ctx() else { return };
    let sc = scenario();
    let world = World::with_index(&sc, 0).unwrap();
    let robots = world.robot_count();
    let mut fields =
        WorldFields::new(ctx, world.pheromones(), 2, 4 * robots, *world.screen()).unwrap();
    let bad = [colcos_sim::world::TrailSegment {
        pheromone: 7,
        kernel: Kernel::Disc { radius: 0.01 },
        from: Vec2::new(0.1, 0.1),
        to: Vec2::new(0.2, 0.1),
        amount: 1.0,
    }];
    let good: [colcos_sim::world::TrailSegment; 0] = [];
    let err = fields
        .queue_trails(|w| Some(if w == 1 { &bad[..] } else { &good[..] }))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("world 1: a trail on pheromone 7 of 3"),
        "{err}"
    );
    // A world that does not step this time is not read.
    fields
        .queue_trails(|w| (w == 0).then_some(&good[..]))
        .unwrap();
}
