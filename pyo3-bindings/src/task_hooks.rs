//! What a task written in Python (`colcos.Task`) needs of a `VecEnv` or a plant: the step in two halves (the
//! worlds move; then the hooks' rewards and terminations end it), the state of every world as numpy
//! arrays, and the fields sampled at any points, each once per batched step over all worlds.
//! Functions of the module rather than methods: the env's own class stays about stepping.
use crate::arena_io::{self, flat, shaped};
use crate::args::guard;
use crate::errors::{Kind, to_py};
use crate::plant::{PyPlant, plant_err};
use crate::task_view::{Counters, Dims, View};
use crate::vec_env::PyVecEnv;
use colcos_env::VecEnv;
use colcos_env::encoding::OBS_DIM;
use colcos_plant::LiveEnv;
use colcos_sim::field::Pheromone;
use colcos_sim::robot::Pose;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use numpy::{PyArray1, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A batch of worlds, or a plant's one arena.
enum Core<'a> {
    Batch(&'a PyVecEnv),
    Plant(&'a PyPlant),
}

fn core_of<'a>(env: &'a Bound<'_, PyAny>) -> PyResult<Core<'a>> {
    if let Ok(b) = env.cast::<PyVecEnv>() {
        return Ok(Core::Batch(b.get()));
    }
    if let Ok(p) = env.cast::<PyPlant>() {
        return Ok(Core::Plant(p.get()));
    }
    Err(Kind::ArgumentType.err(format!(
        "env must be a colcos._core.VecEnv or Plant, got {}",
        crate::args::show(env)
    )))
}

/// The first half of a step: every world moves with `actions` and waits for `conclude`.
#[pyfunction]
fn step_deferred(
    py: Python<'_>,
    env: &Bound<'_, PyAny>,
    actions: &Bound<'_, PyAny>,
) -> PyResult<()> {
    guard(|| match core_of(env)? {
        Core::Batch(env) => arena_io::step(env, py, actions, true),
        Core::Plant(plant) => arena_io::step(plant, py, actions, true),
    })
}

/// The second half: rewards float32 `[E, N]` and terminations bool `[E, N]`.
#[pyfunction]
fn conclude(
    py: Python<'_>,
    env: &Bound<'_, PyAny>,
    rewards: PyReadonlyArrayDyn<'_, f32>,
    terminated: PyReadonlyArrayDyn<'_, bool>,
) -> PyResult<()> {
    guard(|| {
        let r = flat(&rewards);
        let t = flat(&terminated);
        match core_of(env)? {
            Core::Batch(env) => py.detach(|| env.lock().env.conclude(&r, &t)).map_err(to_py),
            Core::Plant(p) => py.detach(|| p.lock().conclude(&r, &t)).map_err(plant_err),
        }
    })
}

/// Every world's state now, as arrays: `poses`/`tracked` float32 `[E, R, 3]` (x m, y m, heading
/// rad: true, and as the tracker last delivered them; on a plant both are the tracked poses as
/// used), `seen` bool `[E, R]`, `wheels` float32 `[E, R, 2]` (the drives' wheel speeds, m/s),
/// `commands` float32 `[E, R, 2]` (the last commands, m/s), `obs` float32 `[E, N, 17]` (the
/// agents' sensor values now), `deposit_actions` float32 `[E, N, D]`, `steps` (this episode's, the
/// deferred step's included) and `episode` int64 `[E]`, `stepped` bool `[E]` (moved in the
/// deferred step; false: only reset), `time` float32 `[E]`.
#[pyfunction]
fn task_view<'py>(py: Python<'py>, env: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let v = match core_of(env)? {
            Core::Batch(env) => py.detach(|| batch_view(&env.lock().env)),
            Core::Plant(p) => py.detach(|| plant_view(&p.lock())),
        };
        let d = PyDict::new(py);
        let Dims { e, r, n, d: per } = v.dims;
        let rows = v.robots;
        d.set_item("poses", shaped(py, rows.poses, [e, r, 3])?)?;
        d.set_item("tracked", shaped(py, rows.tracked, [e, r, 3])?)?;
        d.set_item("seen", shaped(py, rows.seen, [e, r])?)?;
        d.set_item("wheels", shaped(py, rows.wheels, [e, r, 2])?)?;
        d.set_item("commands", shaped(py, rows.commands, [e, r, 2])?)?;
        d.set_item("deposit_actions", shaped(py, v.deposits, [e, n, per])?)?;
        d.set_item("obs", shaped(py, v.obs, [e, n, OBS_DIM])?)?;
        let worlds = &v.worlds;
        let steps = worlds.iter().map(|c| c.steps as i64);
        d.set_item("steps", PyArray1::from_iter(py, steps))?;
        let stepped = worlds.iter().map(|c| c.stepped);
        d.set_item("stepped", PyArray1::from_iter(py, stepped))?;
        let episode = worlds.iter().map(|c| c.episode as i64);
        d.set_item("episode", PyArray1::from_iter(py, episode))?;
        let time = worlds.iter().map(|c| c.time);
        d.set_item("time", PyArray1::from_iter(py, time))?;
        Ok(d)
    })
}

fn batch_view(env: &VecEnv) -> View {
    let s = env.spec();
    let agents = &s.agent_robots;
    let max_speed = env.scenario().spec.robot.max_wheel_speed;
    let d = env.action_decoder().deposits();
    let mut v = View::new(Dims {
        e: s.num_envs,
        r: s.num_robots,
        n: s.num_agents,
        d,
    });
    for w in 0..s.num_envs {
        let Some(world) = env.world(w) else {
            continue;
        };
        let stepped = env.is_awaiting(w);
        let c = Counters {
            steps: env.episode_steps(w) + stepped as u64,
            stepped,
            episode: env.episode(w),
            time: world.time(),
        };
        let deposits = |i| world.deposit_actions(i);
        v.push(world, world.tracked(), agents, deposits, max_speed, c);
    }
    v
}

fn plant_view(env: &LiveEnv) -> View {
    let s = env.spec();
    let host = env.host();
    let d = env.action_decoder().deposits();
    let mut v = View::new(Dims {
        e: 1,
        r: s.num_robots,
        n: s.num_agents,
        d,
    });
    let stepped = env.is_awaiting();
    let c = Counters {
        steps: env.episode_steps() + stepped as u64,
        stepped: true,
        episode: env.episode(),
        time: host.time(),
    };
    let max_speed = env.scenario().spec.robot.max_wheel_speed;
    let deposits = |i| host.deposit_actions(i);
    v.push(
        host,
        host.tracked(),
        &s.agent_robots,
        deposits,
        max_speed,
        c,
    );
    v
}

/// What stays fixed of a batch or plant, handed to Python as a dict of these keys.
#[derive(IntoPyObject)]
struct TaskInfo {
    /// (w, h) m.
    arena: (f32, f32),
    /// Per robot.
    roles: Vec<String>,
    /// The pheromones' names and their screen colours (r, g, b levels per unit).
    pheromones: Vec<String>,
    colours: Vec<[f32; 3]>,
    /// m/s.
    max_wheel_speed: f32,
    /// m.
    wheel_base: f32,
    /// s.
    dt: f32,
}

impl TaskInfo {
    fn new(sc: &Scenario, view: Option<&dyn ArenaView>) -> Self {
        let a = sc.arena_size();
        let p = &sc.spec.robot;
        TaskInfo {
            arena: (a.x, a.y),
            roles: (0..sc.robot_count())
                .map(|i| view.map_or(String::new(), |w| w.role(i).to_string()))
                .collect(),
            pheromones: sc.pheromone_names().map(String::from).collect(),
            colours: sc.spec.pheromones.iter().map(|p| p.colour).collect(),
            max_wheel_speed: p.max_wheel_speed,
            wheel_base: p.wheel_base,
            dt: sc.spec.dt,
        }
    }
}

/// What stays fixed: `arena` (w, h) m, `roles` [R], `pheromones` [F] names and their screen
/// `colours` [F] (r, g, b levels per unit), `max_wheel_speed` and
/// `wheel_base` m/s and m, `dt` s.
#[pyfunction]
fn task_info<'py>(py: Python<'py>, env: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let info = match core_of(env)? {
            Core::Batch(env) => py.detach(|| {
                let g = env.lock();
                let world = g.env.world(0).map(|w| w as &dyn ArenaView);
                TaskInfo::new(g.env.scenario(), world)
            }),
            Core::Plant(p) => py.detach(|| {
                let g = p.lock();
                TaskInfo::new(g.scenario(), Some(g.host()))
            }),
        };
        info.into_pyobject(py)
    })
}

/// The points per world P of `points` of shape `shape`, which must be `[e, P, 2]`.
fn points_per_world(shape: &[usize], e: usize) -> Result<usize, String> {
    if shape.len() != 3 || shape[0] != e || shape[2] != 2 {
        return Err(format!(
            "points must have shape ({e}, P, 2) = (num_envs, points, xy), got {shape:?}"
        ));
    }
    Ok(shape[1])
}

/// Every pheromone's value at `points` float32 `[E, P, 2]` (m) of each world: float32 `[E, P, F]`.
#[pyfunction]
fn sample_fields<'py>(
    py: Python<'py>,
    env: &Bound<'py, PyAny>,
    points: PyReadonlyArrayDyn<'py, f32>,
) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        let shape = points.shape().to_vec();
        let pts = flat(&points);
        // Every pheromone's value at each world's points: (values, worlds, points, pheromones).
        let sample = |worlds: &[&[Pheromone]]| {
            let (e, p) = (worlds.len(), points_per_world(&shape, worlds.len())?);
            let f = worlds.first().map_or(0, |w| w.len());
            let mut out = Vec::with_capacity(e * p * f);
            for (phs, xy) in worlds.iter().zip(pts.chunks_exact(2 * p.max(1))) {
                for q in xy.chunks_exact(2) {
                    let at = colcos_sim::Vec2::new(q[0], q[1]);
                    out.extend(phs.iter().map(|ph| ph.value_at(at)));
                }
            }
            Ok((out, e, p, f))
        };
        let sampled = match core_of(env)? {
            Core::Batch(env) => py.detach(|| {
                let g = env.lock();
                let worlds: Vec<&[Pheromone]> = (0..g.env.spec().num_envs)
                    .filter_map(|w| g.env.world(w).map(|x| x.pheromones()))
                    .collect();
                sample(&worlds)
            }),
            Core::Plant(pl) => py.detach(|| sample(&[pl.lock().host().pheromones()])),
        };
        let (out, e, p, f) = sampled.map_err(|m: String| Kind::Action.err(m))?;
        shaped(py, out, [e, p, f])
    })
}

/// Every pheromone's value at `points` float32 `[E, P, 2]` (m) of each world as of the current
/// observations, and its gradient (per m; central differences `step` m apart on a grid, analytic for
/// Gaussian sources), exactly as a built-in task reads them: float32 `[E, P, F]` and `[E, P, F, 2]`.
#[pyfunction]
fn sample_gradients<'py>(
    py: Python<'py>,
    env: &Bound<'py, PyAny>,
    points: PyReadonlyArrayDyn<'py, f32>,
    step: f32,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    guard(|| {
        if !(step.is_finite() && step > 0.0) {
            return Err(Kind::Action.err(format!("step must be finite and > 0, got {step}")));
        }
        let shape = points.shape().to_vec();
        let pts = flat(&points);
        let sample = |worlds: &[&dyn ArenaView]| {
            let (e, p) = (worlds.len(), points_per_world(&shape, worlds.len())?);
            let f = worlds.first().map_or(0, |w| w.pheromones().len());
            let (mut values, mut grads) = (Vec::with_capacity(e * p * f), Vec::new());
            grads.reserve(2 * e * p * f);
            for (world, xy) in worlds.iter().zip(pts.chunks_exact(2 * p.max(1))) {
                for q in xy.chunks_exact(2) {
                    let at = colcos_sim::Vec2::new(q[0], q[1]);
                    for index in 0..f {
                        let (v, g) = world.pheromone_value_and_gradient_observed(index, at, step);
                        values.push(v);
                        grads.extend([g.x, g.y]);
                    }
                }
            }
            Ok((values, grads, e, p, f))
        };
        let sampled = match core_of(env)? {
            Core::Batch(env) => py.detach(|| {
                let g = env.lock();
                let worlds: Vec<&dyn ArenaView> = (0..g.env.spec().num_envs)
                    .filter_map(|w| g.env.world(w).map(|x| x as &dyn ArenaView))
                    .collect();
                sample(&worlds)
            }),
            Core::Plant(pl) => py.detach(|| {
                let g = pl.lock();
                sample(&[g.host() as &dyn ArenaView])
            }),
        };
        let (values, grads, e, p, f) = sampled.map_err(|m: String| Kind::Action.err(m))?;
        Ok((
            shaped(py, values, [e, p, f])?,
            shaped(py, grads, [e, p, f, 2])?,
        ))
    })
}

/// Moves robots as worlds start an episode: `worlds` int64 `[W]`, `robots` int64 `[K]`, `poses`
/// float32 `[W, K, 3]` (x m, y m, heading rad). A plant's robots are where they are: refused.
#[pyfunction]
fn place_robots(
    py: Python<'_>,
    env: &Bound<'_, PyAny>,
    worlds: PyReadonlyArrayDyn<'_, i64>,
    robots: PyReadonlyArrayDyn<'_, i64>,
    poses: PyReadonlyArrayDyn<'_, f32>,
) -> PyResult<()> {
    guard(|| {
        let worlds = flat(&worlds);
        let robots = flat(&robots);
        let shape = poses.shape().to_vec();
        if shape != [worlds.len(), robots.len(), 3] {
            return Err(Kind::Action.err(format!(
                "poses must have shape ({}, {}, 3) = (worlds, robots, x y heading), got {shape:?}",
                worlds.len(),
                robots.len()
            )));
        }
        let p = flat(&poses);
        let index = |i: i64, what: &str| {
            usize::try_from(i).map_err(|_| Kind::Action.err(format!("{what} {i} is negative")))
        };
        let robots = (robots.iter().map(|&i| index(i, "robot"))).collect::<PyResult<Vec<_>>>()?;
        let Core::Batch(env) = core_of(env)? else {
            return Err(Kind::State.err(
                "robots are placed only in a simulated batch (VecEnv): a plant's robots are where they are",
            ));
        };
        let mut placed = Vec::with_capacity(worlds.len());
        for (k, &w) in worlds.iter().enumerate() {
            let row = &p[k * robots.len() * 3..(k + 1) * robots.len() * 3];
            let each = robots.iter().zip(row.chunks_exact(3));
            let poses = each
                .map(|(&i, q)| (i, Pose::new(q[0], q[1], q[2])))
                .collect();
            placed.push((index(w, "world")?, poses));
        }
        py.detach(|| {
            let mut g = env.lock();
            placed
                .iter()
                .try_for_each(|(w, poses): &(usize, Vec<(usize, Pose)>)| g.env.place(*w, poses))
        })
        .map_err(to_py)
    })
}

/// The unit vectors `(cos a, sin a)` of float32 angles `[...]` (rad), float32 `[..., 2]`: the same
/// `f32` sine and cosine as the simulator and the built-in tasks use (numpy's differ in the last bit).
#[pyfunction]
fn unit_vectors<'py>(
    py: Python<'py>,
    angles: PyReadonlyArrayDyn<'py, f32>,
) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        let mut shape = angles.shape().to_vec();
        let a = angles.as_array();
        let mut out = Vec::with_capacity(2 * a.len());
        for &t in a.iter() {
            let v = colcos_sim::Vec2::from_angle(t);
            out.extend([v.x, v.y]);
        }
        shape.push(2);
        shaped(py, out, shape)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sample_gradients, m)?)?;
    m.add_function(wrap_pyfunction!(unit_vectors, m)?)?;
    m.add_function(wrap_pyfunction!(place_robots, m)?)?;
    m.add_function(wrap_pyfunction!(step_deferred, m)?)?;
    m.add_function(wrap_pyfunction!(conclude, m)?)?;
    m.add_function(wrap_pyfunction!(task_view, m)?)?;
    m.add_function(wrap_pyfunction!(task_info, m)?)?;
    m.add_function(wrap_pyfunction!(sample_fields, m)?)?;
    Ok(())
}
