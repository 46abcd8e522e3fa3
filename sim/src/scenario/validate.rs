//! Checks a parsed scenario for values that cannot be simulated, before anything runs. Every error
//! names the key path and the bad value.

use super::Scenario;
use super::limits::{self, *};
use super::spec::*;
use crate::error::{Result, SimError};

fn positive(key: &str, v: f32) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SimError::invalid(key, v, "must be a finite number > 0"))
    }
}

fn non_negative(key: &str, v: f32) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(SimError::invalid(key, v, "must be a finite number >= 0"))
    }
}

fn finite(key: &str, v: f32) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SimError::invalid(key, v, "must be finite"))
    }
}

/// `v` is at most `max`; the error says so with `unit` (and any reason) after the number.
fn at_most(key: &str, v: f32, max: f32, unit: &str) -> Result<()> {
    if v > max {
        Err(SimError::invalid(key, v, format!("at most {max} {unit}")))
    } else {
        Ok(())
    }
}

pub(super) fn validate(sc: &Scenario) -> Result<()> {
    let s = &sc.spec;
    positive("duration", s.duration)?;
    positive("dt", s.dt)?;
    if s.dt > 0.5 {
        return Err(SimError::invalid(
            "dt",
            s.dt,
            "time step longer than 0.5 s cannot resolve robot motion",
        ));
    }
    if s.duration / s.dt > 1e9 {
        return Err(SimError::invalid(
            "duration",
            s.duration,
            "more than 1e9 steps",
        ));
    }
    // The screen first: without `arena.size` the arena is the screen, and its errors name the key
    // the file set.
    positive("screen.size[0]", s.screen.size[0])?;
    positive("screen.size[1]", s.screen.size[1])?;
    if let Some(size) = s.arena.size {
        positive("arena.size[0]", size[0])?;
        positive("arena.size[1]", size[1])?;
    }
    for (i, r) in s.screen.resolution.iter().enumerate() {
        if *r == 0 || *r > 65536 {
            return Err(SimError::invalid(
                format!("screen.resolution[{i}]"),
                r,
                "must be 1..=65536 pixels",
            ));
        }
    }
    let grid = validate_field(sc)?;
    validate_robot_params(sc)?;
    validate_pheromones(sc, &grid)?;
    validate_robots(sc)?;
    s.rig.validate(sc.robot_count())?;
    s.randomize.validate()?;
    super::individual::validate_entries(&s.individual.robot, "individual.robot", sc.robot_count())?;
    Ok(())
}

fn validate_field(sc: &Scenario) -> Result<crate::field::GridSpec> {
    let s = &sc.spec;
    let arena = sc.arena_size();
    positive("field.cell", s.field.cell)?;
    if s.field.cell > arena.min_element() / 2.0 {
        return Err(SimError::invalid(
            "field.cell",
            s.field.cell,
            format!("larger than half the arena ({} m)", arena.min_element()),
        ));
    }
    let grid = limits::check_grid(sc)?;
    positive("output.gif_width", s.output.gif_width as f32)?;
    // The frame is rendered in memory at this size, and GIF sides are 16-bit (no GIF: not used).
    let (w, sz) = (s.output.gif_width, s.screen.size);
    let gif_height = ((w as f32 * sz[1] / sz[0]).round() as u32).max(1);
    if s.output.gif_interval > 0.0 && (w > MAX_GIF_SIDE || gif_height > MAX_GIF_SIDE) {
        return Err(SimError::invalid(
            "output.gif_width",
            w,
            format!(
                "the frames would be {w} x {gif_height} px (screen aspect {} x {}): at most {MAX_GIF_SIDE} px a side",
                sz[0], sz[1]
            ),
        ));
    }
    non_negative("output.gif_interval", s.output.gif_interval)?;
    if s.output.log_every == 0 {
        return Err(SimError::invalid("output.log_every", 0, "must be >= 1"));
    }
    Ok(grid)
}

fn validate_robot_params(sc: &Scenario) -> Result<()> {
    let s = &sc.spec;
    positive("robot.radius", s.robot.radius)?;
    positive("robot.mass", s.robot.mass)?;
    positive("robot.wheel_base", s.robot.wheel_base)?;
    if s.robot.wheel_base > 2.0 * s.robot.radius {
        return Err(SimError::invalid(
            "robot.wheel_base",
            s.robot.wheel_base,
            format!(
                "the wheels must fit under the robot (diameter {} m)",
                2.0 * s.robot.radius
            ),
        ));
    }
    positive("robot.max_wheel_speed", s.robot.max_wheel_speed)?;
    non_negative("robot.motor_lag", s.robot.motor_lag)?;
    let c = &s.sensor;
    non_negative("sensor.footprint_radius", c.footprint_radius)?;
    let reach = crate::sensors::SENSOR_RADIUS + c.footprint_radius;
    if reach > s.robot.radius {
        return Err(SimError::invalid(
            "sensor.footprint_radius",
            c.footprint_radius,
            format!(
                "the colour sensors sit {} m from the centre: their footprint reaches {reach} m, \
                 beyond the robot's radius {} m",
                crate::sensors::SENSOR_RADIUS,
                s.robot.radius
            ),
        ));
    }
    positive("sensor.gamma", c.gamma)?;
    positive("sensor.gain", c.gain)?;
    positive("sensor.integration_ms", c.integration_ms)?;
    non_negative("sensor.dark_counts", c.dark_counts)?;
    non_negative("sensor.noise", c.noise)?;
    if c.per_robot && s.rig.colour_calibration.is_none() {
        return Err(SimError::invalid(
            "sensor.per_robot",
            true,
            "needs the file of the robots' fitted sensors (colcos calibrate colour) in [rig] colour_calibration",
        ));
    }
    for (i, row) in c.crosstalk.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            non_negative(&format!("sensor.crosstalk[{i}][{j}]"), *v)?;
        }
    }
    if det3(&c.crosstalk).abs() < 1e-6 {
        return Err(SimError::invalid(
            "sensor.crosstalk",
            format!("{:?}", c.crosstalk),
            "matrix is singular: the sensor could not be calibrated",
        ));
    }
    non_negative("bumper.range", s.bumper.range)?;
    for (i, a) in s.bumper.angles.iter().enumerate() {
        finite(&format!("bumper.angles[{i}]"), *a)?;
    }
    let t = &s.tracker;
    positive("tracker.rate_hz", t.rate_hz)?;
    at_most(
        "tracker.rate_hz",
        t.rate_hz,
        MAX_TRACKER_RATE_HZ,
        "Hz (every frame is simulated)",
    )?;
    non_negative("tracker.latency", t.latency)?;
    at_most("tracker.latency", t.latency, MAX_TRACKER_LATENCY, "s")?;
    // Every frame captured but not yet delivered is held in memory.
    let in_flight = (t.rate_hz * t.latency).ceil().max(1.0) as f64 * sc.robot_count() as f64;
    if in_flight > MAX_POSES_IN_FLIGHT {
        return Err(SimError::invalid(
            "tracker.latency",
            t.latency,
            format!(
                "{in_flight:.0} tracked poses in flight (rate_hz x latency x robots), more than {MAX_POSES_IN_FLIGHT:.0e}"
            ),
        ));
    }
    non_negative("tracker.position_noise", t.position_noise)?;
    non_negative("tracker.heading_noise", t.heading_noise)?;
    if !(0.0..1.0).contains(&t.dropout) {
        return Err(SimError::invalid(
            "tracker.dropout",
            t.dropout,
            "must be in [0, 1)",
        ));
    }
    Ok(())
}

fn det3(m: &[[f32; 3]; 3]) -> f32 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// `preload` sets the field to `e J`, the steady state of eq. (2) only without diffusion or wind.
fn check_preload(i: usize, p: &super::spec::PheromoneSpec) -> Result<()> {
    let why = if p.maps.is_empty() {
        "needs static maps (the steady state is e J of the maps)"
    } else if p.evaporation.is_none() {
        "needs an evaporation time (without it the field grows for ever)"
    } else if p.diffusion != 0.0 || p.wind != [0.0, 0.0] {
        "needs diffusion = 0 and no wind (e J is the steady state of evaporation alone)"
    } else {
        return Ok(());
    };
    Err(SimError::invalid(
        format!("pheromones[{i}].preload"),
        "true",
        why,
    ))
}

fn validate_pheromones(sc: &Scenario, grid: &crate::field::GridSpec) -> Result<()> {
    let s = &sc.spec;
    for (i, p) in s.pheromones.iter().enumerate() {
        let k = |f: &str| format!("pheromones[{i}].{f}");
        if p.name.trim().is_empty() {
            return Err(SimError::invalid(k("name"), "\"\"", "must not be empty"));
        }
        if s.pheromones[..i].iter().any(|q| q.name == p.name) {
            return Err(SimError::invalid(
                k("name"),
                format!("{:?}", p.name),
                "another pheromone has this name",
            ));
        }
        for (c, v) in p.colour.iter().enumerate() {
            non_negative(&format!("pheromones[{i}].colour[{c}]"), *v)?;
        }
        if let Some(e) = p.evaporation {
            positive(&k("evaporation"), e)?;
        }
        match p.model {
            ModelKind::Grid => {
                non_negative(&k("diffusion"), p.diffusion)?;
                finite(&k("wind[0]"), p.wind[0])?;
                finite(&k("wind[1]"), p.wind[1])?;
                if !p.sources.is_empty() {
                    return Err(SimError::invalid(
                        k("sources"),
                        p.sources.len(),
                        "fixed Gaussian sources need model = \"gaussian\"",
                    ));
                }
                limits::check_substeps(sc, i, grid)?;
                if p.preload {
                    check_preload(i, p)?;
                }
                for (m, map) in p.maps.iter().enumerate() {
                    let key = format!("pheromones[{i}].maps[{m}]");
                    validate_map(&key, map)?;
                    limits::check_polyline(&key, map, grid)?;
                    if let MapSpec::Image { image, .. } = map {
                        limits::check_image(&key, image, &sc.base_dir)?;
                    }
                }
            }
            ModelKind::Gaussian => {
                if p.evaporation.is_none() {
                    return Err(SimError::invalid(
                        k("evaporation"),
                        "missing",
                        "the Gaussian model needs an evaporation time",
                    ));
                }
                if p.preload {
                    return Err(SimError::invalid(
                        k("preload"),
                        "true",
                        "pre-loading static maps belongs to the grid model",
                    ));
                }
                if p.diffusion != 0.0 || p.wind != [0.0, 0.0] || !p.maps.is_empty() {
                    return Err(SimError::invalid(
                        k("model"),
                        "\"gaussian\"",
                        "diffusion, wind and maps belong to the grid model",
                    ));
                }
                for (j, src) in p.sources.iter().enumerate() {
                    let key = format!("pheromones[{i}].sources[{j}]");
                    validate_gaussian(&key, src.k, src.sigma, src.rho, src.evaporation)?;
                    non_negative(&format!("{key}.start"), src.start)?;
                    finite(&format!("{key}.centre[0]"), src.centre[0])?;
                    finite(&format!("{key}.centre[1]"), src.centre[1])?;
                }
            }
        }
    }
    Ok(())
}

fn validate_map(key: &str, map: &MapSpec) -> Result<()> {
    non_negative(&format!("{key}.rate"), map.rate())?;
    // Which keys a map has was checked as the file was read (`MapSpec`'s `MapFields`).
    if let MapSpec::Polyline {
        polyline, width, ..
    } = map
    {
        if polyline.len() < 2 {
            return Err(SimError::invalid(
                format!("{key}.polyline"),
                polyline.len(),
                "needs at least 2 points",
            ));
        }
        for (n, pt) in polyline.iter().enumerate() {
            finite(&format!("{key}.polyline[{n}][0]"), pt[0])?;
            finite(&format!("{key}.polyline[{n}][1]"), pt[1])?;
        }
        positive(&format!("{key}.width"), *width)?;
    }
    Ok(())
}

pub(super) fn validate_gaussian(
    key: &str,
    k: f32,
    sigma: [f32; 2],
    rho: f32,
    evaporation: f32,
) -> Result<()> {
    non_negative(&format!("{key}.k"), k)?;
    positive(&format!("{key}.sigma[0]"), sigma[0])?;
    positive(&format!("{key}.sigma[1]"), sigma[1])?;
    if !(rho.is_finite() && rho.abs() < 1.0) {
        return Err(SimError::invalid(
            format!("{key}.rho"),
            rho,
            "must satisfy |rho| < 1",
        ));
    }
    positive(&format!("{key}.evaporation"), evaporation)
}

fn validate_robots(sc: &Scenario) -> Result<()> {
    let s = &sc.spec;
    let arena = sc.arena_size();
    let r = s.robot.radius;
    if 2.0 * r >= arena.min_element() {
        return Err(SimError::invalid(
            "robot.radius",
            r,
            "a robot does not fit in the arena",
        ));
    }
    let mut footprint = 0.0f64;
    let mut total = 0usize;
    for (g, group) in s.robots.iter().enumerate() {
        let k = |f: &str| format!("robots[{g}].{f}");
        total = total.saturating_add(group.count);
        if total > MAX_ROBOTS {
            return Err(SimError::invalid(
                k("count"),
                group.count,
                format!("more than {MAX_ROBOTS} robots in the scenario"),
            ));
        }
        group.build_behaviour(&s.robot, &format!("robots[{g}]"))?;
        let region = group.region.unwrap_or([0.0, 0.0, arena.x, arena.y]);
        for (n, v) in region.iter().enumerate() {
            finite(&format!("robots[{g}].region[{n}]"), *v)?;
        }
        if region[0] < 0.0
            || region[1] < 0.0
            || region[2] > arena.x + 1e-6
            || region[3] > arena.y + 1e-6
            || region[2] <= region[0]
            || region[3] <= region[1]
        {
            return Err(SimError::invalid(
                k("region"),
                format!("{region:?}"),
                format!(
                    "must be [x0, y0, x1, y1] with x0 < x1, y0 < y1 inside the {} x {} m arena",
                    arena.x, arena.y
                ),
            ));
        }
        let (w, h) = (region[2] - region[0], region[3] - region[1]);
        if w < 2.0 * r || h < 2.0 * r {
            return Err(SimError::invalid(
                k("region"),
                format!("{region:?}"),
                "smaller than one robot",
            ));
        }
        // Square packing of discs in the region: beyond it, random placement cannot succeed.
        let capacity = ((w / (2.0 * r)).floor() * (h / (2.0 * r)).floor()) as usize;
        if group.placement != Placement::Explicit && group.count > capacity {
            return Err(SimError::invalid(
                k("count"),
                group.count,
                format!("{capacity} robots of radius {r} m at most fit in region {region:?}"),
            ));
        }
        footprint += group.count as f64 * (2.0 * r as f64).powi(2);
        if group.placement == Placement::Explicit {
            if group.poses.len() != group.count {
                return Err(SimError::invalid(
                    k("poses"),
                    group.poses.len(),
                    format!(
                        "explicit placement needs exactly `count` = {} poses",
                        group.count
                    ),
                ));
            }
            for (n, p) in group.poses.iter().enumerate() {
                if !p[2].is_finite() {
                    return Err(SimError::invalid(
                        format!("robots[{g}].poses[{n}][2]"),
                        p[2],
                        "the heading must be a finite number of degrees",
                    ));
                }
                if !(p[0] >= r && p[0] <= arena.x - r && p[1] >= r && p[1] <= arena.y - r) {
                    return Err(SimError::invalid(
                        format!("robots[{g}].poses[{n}]"),
                        format!("{p:?}"),
                        format!(
                            "the robot (radius {r} m) is not inside the arena: x must be in [{r}, {}], y in [{r}, {}] m",
                            arena.x - r,
                            arena.y - r
                        ),
                    ));
                }
            }
        } else if !group.poses.is_empty() {
            return Err(SimError::invalid(
                k("poses"),
                group.poses.len(),
                "poses are only used with placement = \"explicit\"",
            ));
        }
        let trails = (group.deposits.iter().enumerate())
            .map(|(d, dep)| {
                (
                    format!("robots[{g}].deposits[{d}]"),
                    dep.pheromone.as_str(),
                    dep.kernel,
                    "rate",
                    dep.rate,
                )
            })
            .chain(group.deposit_actions.iter().enumerate().map(|(d, dep)| {
                (
                    format!("robots[{g}].deposit_actions[{d}]"),
                    dep.pheromone.as_str(),
                    dep.kernel,
                    "max_rate",
                    dep.max_rate,
                )
            }));
        for (key, pheromone, kernel, rate_key, rate) in trails {
            let p = find_pheromone(sc, &format!("{key}.pheromone"), pheromone)?;
            if s.pheromones[p].model != ModelKind::Grid {
                return Err(SimError::invalid(
                    format!("{key}.pheromone"),
                    format!("{pheromone:?}"),
                    "trail deposits need a grid pheromone (an agent lays a gaussian one with \
                     `emits = [{ ..., when = \"action\" }]`)",
                ));
            }
            non_negative(&format!("{key}.{rate_key}"), rate)?;
            let (name, size) = match kernel {
                crate::field::Kernel::Disc { radius } | crate::field::Kernel::Cone { radius } => {
                    ("radius", radius)
                }
                crate::field::Kernel::Gaussian { sigma } => ("sigma", sigma),
            };
            positive(&format!("{key}.kernel.{name}"), size)?;
        }
        for (e, emit) in group.emits.iter().enumerate() {
            let key = format!("robots[{g}].emits[{e}]");
            let p = find_pheromone(sc, &format!("{key}.pheromone"), &emit.pheromone)?;
            if s.pheromones[p].model != ModelKind::Gaussian {
                return Err(SimError::invalid(
                    format!("{key}.pheromone"),
                    format!("{:?}", emit.pheromone),
                    "emitted sources need a gaussian pheromone",
                ));
            }
            validate_gaussian(&key, emit.k, emit.sigma, emit.rho, emit.evaporation)?;
            if let EmitWhen::Near { role, distance } = &emit.when {
                positive(&format!("{key}.when.near.distance"), *distance)?;
                if !s.robots.iter().any(|gr| &gr.role == role) {
                    return Err(SimError::invalid(
                        format!("{key}.when.near.role"),
                        format!("{role:?}"),
                        "no robot group has this role",
                    ));
                }
            }
        }
    }
    if footprint > (arena.x * arena.y) as f64 {
        return Err(SimError::invalid(
            "robots",
            sc.robot_count(),
            "the robots together cover more than the arena",
        ));
    }
    limits::check_step_work(sc, &crate::field::GridSpec::covering(arena, s.field.cell))?;
    // The placement the world runs for world 0, from the same stream.
    let mut rng = crate::rng::stream_of(s.seed, 0, crate::rng::Stream::Placement);
    let obstacles = sc.obstacles()?;
    super::placement::place(sc, &obstacles, &mut rng).map(|_| ())
}

fn find_pheromone(sc: &Scenario, key: &str, name: &str) -> Result<usize> {
    sc.pheromone_index(name).ok_or_else(|| {
        let known: Vec<_> = sc.pheromone_names().collect();
        SimError::invalid(
            key,
            format!("{name:?}"),
            format!("no pheromone of that name (known: {known:?})"),
        )
    })
}
