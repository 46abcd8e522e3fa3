//! What an arena shows its agents and users: observation rows, the global state, screen patches and
//! the rendered screen with the robots on it; for a simulated world of the batch or a rig's host alike.
use crate::config::PatchConfig;
use crate::encoding::{self, OBS_DIM};
use crate::task::Task;
use colcos_sim::world::ArenaView;

pub fn write_obs(world: &dyn ArenaView, agents: &[usize], max_speed: f32, out: &mut [f32]) {
    let obs = world.observations();
    for (&i, o) in agents.iter().zip(out.chunks_exact_mut(OBS_DIM)) {
        encoding::encode(&obs[i], max_speed, o);
    }
}

/// Entries of each agent's observation under `task`: the sensor values and the task's extras.
pub fn obs_dim(task: &dyn Task) -> usize {
    OBS_DIM + task.extra_observations().len()
}

/// The observation rows of `task`'s agents, [`obs_dim`] entries each: the sensor values, then the
/// task's extra entries ([`Task::observe`] with the episode's memory `state`).
pub fn write_task_obs(
    world: &dyn ArenaView,
    task: &dyn Task,
    state: &[u32],
    max_speed: f32,
    out: &mut [f32],
) {
    let dim = obs_dim(task);
    if dim == OBS_DIM {
        return write_obs(world, task.agents(), max_speed, out);
    }
    let obs = world.observations();
    for (k, (&i, row)) in task
        .agents()
        .iter()
        .zip(out.chunks_exact_mut(dim))
        .enumerate()
    {
        encoding::encode(&obs[i], max_speed, &mut row[..OBS_DIM]);
        task.observe(world, state, k, &mut row[OBS_DIM..]);
    }
}

/// Global state: per robot `x / W * 2 - 1`, `y / H * 2 - 1`, `cos`, `sin` of the heading; then the
/// episode's elapsed fraction.
pub fn write_state(world: &dyn ArenaView, steps: u64, max_cycles: u64, out: &mut [f32]) {
    let arena = world.arena();
    for (i, (p, o)) in world
        .poses()
        .iter()
        .zip(out.chunks_exact_mut(4))
        .enumerate()
    {
        let forward = world.forward(i);
        o[0] = (2.0 * p.pos.x / arena.x - 1.0).clamp(-1.0, 1.0);
        o[1] = (2.0 * p.pos.y / arena.y - 1.0).clamp(-1.0, 1.0);
        o[2] = forward.x;
        o[3] = forward.y;
    }
    if let Some(last) = out.last_mut() {
        *last = (steps as f32 / max_cycles.max(1) as f32).min(1.0);
    }
}

pub fn write_patch(world: &dyn ArenaView, agents: &[usize], cfg: &PatchConfig, out: &mut [u8]) {
    let len = cfg.pixels * cfg.pixels * 3;
    let poses = world.poses();
    for (&i, o) in agents.iter().zip(out.chunks_exact_mut(len)) {
        crate::patch::sample(world.pheromones(), world.screen(), &poses[i], cfg, o);
    }
}

/// Screen image with robots: agents white, scripted robots coloured by order of their role.
pub fn render_world(world: &dyn ArenaView, agents: &[usize], width: u32) -> image::RgbImage {
    render_world_with(world, world.pheromones(), agents, width)
}

/// [`render_world`] with the screen drawn from `pheromones` (the world's fields as held elsewhere:
/// the GPU batch's).
pub fn render_world_with(
    world: &dyn ArenaView,
    pheromones: &[colcos_sim::field::Pheromone],
    agents: &[usize],
    width: u32,
) -> image::RgbImage {
    let screen = world.screen();
    let width = width.max(16);
    let height = ((width as f32 * screen.size[1] / screen.size[0]).round() as u32).max(1);
    let mut img = colcos_sim::screen::render(pheromones, screen, width, height);
    colcos_sim::output::draw::obstacles(&mut img, screen, world.obstacles());
    const OTHERS: [[u8; 3]; 4] = [[255, 200, 0], [255, 0, 255], [0, 200, 255], [150, 150, 150]];
    let mut roles: Vec<&str> = Vec::new();
    let colours: Vec<image::Rgb<u8>> = (0..world.robot_count())
        .map(|i| {
            if agents.contains(&i) {
                return image::Rgb([240, 240, 240]);
            }
            let role = world.role(i);
            let k = roles.iter().position(|r| *r == role).unwrap_or_else(|| {
                roles.push(role);
                roles.len() - 1
            });
            image::Rgb(OTHERS[k % OTHERS.len()])
        })
        .collect();
    colcos_sim::output::draw::robots(
        &mut img,
        screen,
        world.poses(),
        world.robot_params().radius,
        &colours,
    );
    img
}
