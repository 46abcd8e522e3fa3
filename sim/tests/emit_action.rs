//! Gaussian pheromone laid by action: an emitter with `when = "action"` emits nothing until its
//! robot's action entry reaches 0.5, is refreshed at the robot while it stays there, and below it
//! stays where it was switched off and evaporates, exactly as eq. (5) says.
use colcos_sim::field::FieldModel;
use colcos_sim::prelude::*;
use colcos_sim::scenario::{EmitSpec, PheromoneSpec, RobotGroupSpec, ScenarioBuilder};

/// A robot whose alarm emitter its agent switches, and one whose alarm follows it; 10 s.
fn scenario() -> Scenario {
    let alarm = || EmitSpec::follow("alarm", 1.0, [0.05, 0.05], 2.0);
    ScenarioBuilder::new()
        .pheromone(PheromoneSpec::gaussian("alarm", [255.0, 0.0, 0.0]).with_evaporation(2.0))
        .robots(RobotGroupSpec::new(1, "wander").with_emit(alarm().when_action()))
        .robots(RobotGroupSpec::new(1, "wander").with_emit(alarm()))
        .build()
        .unwrap()
}

/// The switched source's (centre, start) and the field's value at the first robot.
fn source(world: &World) -> (glam::Vec2, f32, f32) {
    let FieldModel::Gaussian(g) = &world.pheromones()[0].model else {
        panic!("alarm is gaussian")
    };
    let s = &g.sources[0];
    let here = world.pheromones()[0].value_at(world.poses()[0].pos);
    (s.centre, s.start, here)
}

#[test]
fn an_emitter_switched_by_action_emits_only_while_on() {
    let sc = scenario();
    assert_eq!(sc.spec.robots[0].action_count(), 1);
    assert_eq!(sc.spec.robots[1].action_count(), 0);
    let mut world = World::new(&sc).unwrap();
    assert_eq!(world.deposit_actions(0).len(), 1);
    assert!(world.deposit_actions(1).is_empty());
    // Off (never switched on, or just below the threshold): nothing emitted.
    for f in [0.0, 0.49] {
        world.set_deposit_actions(0, [f]);
        world.step();
        let (_, start, _) = source(&world);
        assert!(start.is_infinite(), "emitted at action {f}");
    }
    // On: refreshed at the robot every step.
    world.set_deposit_actions(0, [0.5]);
    for _ in 0..5 {
        world.step();
        let (centre, _, here) = source(&world);
        let tracked = world.tracked()[0].pose.pos;
        assert!(centre.distance(tracked) < 1e-6, "{centre} vs {tracked}");
        assert!(here > 0.5, "value at the robot {here}");
    }
    // Off again: the source stays where it was last refreshed and its clock does not restart.
    let (centre, start, _) = source(&world);
    world.set_deposit_actions(0, [0.0]);
    for _ in 0..50 {
        world.step();
        assert_eq!(source(&world).0, centre);
        assert_eq!(source(&world).1, start);
    }
    let FieldModel::Gaussian(g) = &world.pheromones()[0].model else {
        unreachable!()
    };
    let at_centre = g.sources[0].value_at(centre, g.time);
    // Eq. (5) at the centre: k / (2 pi sigma_x sigma_y) e^(-(t - start) / evaporation).
    let peak = 1.0 / (2.0 * std::f32::consts::PI * 0.05 * 0.05);
    let expected = peak * (-(g.time - start) / 2.0).exp();
    assert!(
        (at_centre - expected).abs() < 1e-4 * peak,
        "{at_centre} vs {expected}"
    );
}
