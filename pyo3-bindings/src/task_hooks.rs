//! What a task written in Python (`colcos.Task`) needs of a `VecEnv`: the step in two halves (the
//! worlds move; then the hooks' rewards and terminations end it), the state of every world as numpy
//! arrays, and the fields sampled at any points, each once per batched step over all worlds.
//! Functions of the module rather than methods: the env's own class stays about stepping.
use crate::args::guard;
use crate::errors::{Kind, to_py};
use crate::vec_env::{Owned, PyVecEnv, action_width, owned_actions};
use colcos_env::Actions;
use colcos_env::encoding::OBS_DIM;
use colcos_env::world_output::write_obs;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn env_of<'a, 'py>(env: &'a Bound<'py, PyAny>) -> PyResult<&'a Bound<'py, PyVecEnv>> {
    env.cast::<PyVecEnv>().map_err(|_| {
        Kind::ArgumentType.err(format!(
            "env must be a colcos._core.VecEnv, got {}",
            crate::args::show(env)
        ))
    })
}

/// The first half of a step: every world moves with `actions` and waits for `conclude`.
#[pyfunction]
fn step_deferred(
    py: Python<'_>,
    env: &Bound<'_, PyAny>,
    actions: &Bound<'_, PyAny>,
) -> PyResult<()> {
    guard(|| {
        let env = env_of(env)?.get();
        let (e, n, width) = py.detach(|| {
            let g = env.lock();
            let s = g.env.spec();
            (s.num_envs, s.num_agents, action_width(&s.action))
        });
        let acts = owned_actions(actions, e, n, width)?;
        py.detach(|| {
            let mut g = env.lock();
            match &acts {
                Owned::Discrete(a) => g.env.step_deferred(Actions::Discrete(a)),
                Owned::Continuous(a) => g.env.step_deferred(Actions::Continuous(a)),
            }
        })
        .map_err(to_py)
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
        let env = env_of(env)?.get();
        let r: Vec<f32> = rewards.as_array().iter().copied().collect();
        let t: Vec<bool> = terminated.as_array().iter().copied().collect();
        py.detach(|| env.lock().env.conclude(&r, &t)).map_err(to_py)
    })
}

/// Every world's state now, as arrays: `poses`/`tracked` float32 `[E, R, 3]` (x m, y m, heading
/// rad; true, and as the tracker last delivered them), `seen` bool `[E, R]`, `wheels` float32
/// `[E, R, 2]` (the drives' wheel speeds, m/s), `commands` float32 `[E, R, 2]` (the last commands,
/// m/s), `obs` float32 `[E, N, 17]` (the agents' sensor values now), `deposit_actions` float32
/// `[E, N, D]`, `steps` (this episode's, the deferred step's
/// included) and `episode` int64 `[E]`, `stepped` bool `[E]` (moved in the deferred step; false:
/// only reset), `time` float32 `[E]`.
#[pyfunction]
fn task_view<'py>(py: Python<'py>, env: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let env = env_of(env)?.get();
        struct View {
            e: usize,
            r: usize,
            n: usize,
            d: usize,
            poses: Vec<f32>,
            tracked: Vec<f32>,
            seen: Vec<bool>,
            wheels: Vec<f32>,
            commands: Vec<f32>,
            deposits: Vec<f32>,
            obs: Vec<f32>,
            steps: Vec<i64>,
            stepped: Vec<bool>,
            episode: Vec<i64>,
            time: Vec<f32>,
        }
        let v = py.detach(|| {
            let g = env.lock();
            let s = g.env.spec();
            let (e, r, n) = (s.num_envs, s.num_robots, s.num_agents);
            let agents = s.agent_robots.clone();
            let d = g.env.action_decoder().deposits();
            let mut v = View {
                e,
                r,
                n,
                d,
                poses: Vec::with_capacity(e * r * 3),
                tracked: Vec::with_capacity(e * r * 3),
                seen: Vec::with_capacity(e * r),
                wheels: Vec::with_capacity(e * r * 2),
                commands: Vec::with_capacity(e * r * 2),
                deposits: Vec::with_capacity(e * n * d),
                obs: vec![0.0; e * n * OBS_DIM],
                steps: Vec::with_capacity(e),
                stepped: Vec::with_capacity(e),
                episode: Vec::with_capacity(e),
                time: Vec::with_capacity(e),
            };
            let max_speed = g.env.scenario().spec.robot.max_wheel_speed;
            for w in 0..e {
                let Some(world) = g.env.world(w) else {
                    continue;
                };
                // The observations of now (the outputs are written when the step is concluded).
                let part = &mut v.obs[w * n * OBS_DIM..(w + 1) * n * OBS_DIM];
                write_obs(world, &agents, max_speed, part);
                for p in world.poses() {
                    v.poses.extend([p.pos.x, p.pos.y, p.heading]);
                }
                for t in world.tracked() {
                    v.tracked
                        .extend([t.pose.pos.x, t.pose.pos.y, t.pose.heading]);
                    v.seen.push(t.seen);
                }
                for slot in world.robots() {
                    v.wheels.extend([slot.drive.left, slot.drive.right]);
                    v.commands.extend([slot.command.left, slot.command.right]);
                }
                for &i in &agents {
                    v.deposits.extend_from_slice(world.deposit_actions(i));
                }
                // Counting the step a deferred step's world has just taken.
                let stepped = g.env.is_awaiting(w);
                v.steps.push(g.env.episode_steps(w) as i64 + stepped as i64);
                v.stepped.push(stepped);
                v.episode.push(g.env.episode(w) as i64);
                v.time.push(world.time());
            }
            v
        });
        let d = PyDict::new(py);
        let (e, r, n) = (v.e, v.r, v.n);
        d.set_item("poses", PyArray1::from_vec(py, v.poses).reshape([e, r, 3])?)?;
        d.set_item(
            "tracked",
            PyArray1::from_vec(py, v.tracked).reshape([e, r, 3])?,
        )?;
        d.set_item("seen", PyArray1::from_vec(py, v.seen).reshape([e, r])?)?;
        d.set_item(
            "wheels",
            PyArray1::from_vec(py, v.wheels).reshape([e, r, 2])?,
        )?;
        d.set_item(
            "commands",
            PyArray1::from_vec(py, v.commands).reshape([e, r, 2])?,
        )?;
        d.set_item(
            "deposit_actions",
            PyArray1::from_vec(py, v.deposits).reshape([e, n, v.d])?,
        )?;
        d.set_item(
            "obs",
            PyArray1::from_vec(py, v.obs).reshape([e, n, OBS_DIM])?,
        )?;
        d.set_item("steps", PyArray1::from_vec(py, v.steps))?;
        d.set_item("stepped", PyArray1::from_vec(py, v.stepped))?;
        d.set_item("episode", PyArray1::from_vec(py, v.episode))?;
        d.set_item("time", PyArray1::from_vec(py, v.time))?;
        Ok(d)
    })
}

/// What stays fixed: `arena` (w, h) m, `roles` [R], `pheromones` [F] names, `max_wheel_speed` and
/// `wheel_base` m/s and m, `dt` s.
#[pyfunction]
fn task_info<'py>(py: Python<'py>, env: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let env = env_of(env)?.get();
        let (arena, roles, names, speed, base, dt) = py.detach(|| {
            let g = env.lock();
            let sc = g.env.scenario();
            let world = g.env.world(0);
            let roles: Vec<String> = (0..sc.robot_count())
                .map(|i| world.map_or(String::new(), |w| w.role(i).to_string()))
                .collect();
            let names: Vec<String> = sc.spec.pheromones.iter().map(|p| p.name.clone()).collect();
            let a = sc.arena_size();
            let p = &sc.spec.robot;
            (
                (a.x, a.y),
                roles,
                names,
                p.max_wheel_speed,
                p.wheel_base,
                sc.spec.dt,
            )
        });
        let d = PyDict::new(py);
        d.set_item("arena", arena)?;
        d.set_item("roles", roles)?;
        d.set_item("pheromones", names)?;
        d.set_item("max_wheel_speed", speed)?;
        d.set_item("wheel_base", base)?;
        d.set_item("dt", dt)?;
        Ok(d)
    })
}

/// Every pheromone's value at `points` float32 `[E, P, 2]` (m) of each world: float32 `[E, P, F]`.
#[pyfunction]
fn sample_fields<'py>(
    py: Python<'py>,
    env: &Bound<'py, PyAny>,
    points: PyReadonlyArrayDyn<'py, f32>,
) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        let env = env_of(env)?.get();
        let shape = points.shape().to_vec();
        let pts: Vec<f32> = points.as_array().iter().copied().collect();
        let (out, e, p, f) = py
            .detach(|| {
                let g = env.lock();
                let e = g.env.spec().num_envs;
                let f = g.env.scenario().spec.pheromones.len();
                if shape.len() != 3 || shape[0] != e || shape[2] != 2 {
                    return Err(format!(
                        "points must have shape ({e}, P, 2) = (num_envs, points, xy), got {shape:?}"
                    ));
                }
                let p = shape[1];
                let mut out = Vec::with_capacity(e * p * f);
                for w in 0..e {
                    let Some(world) = g.env.world(w) else {
                        continue;
                    };
                    for xy in pts[w * p * 2..(w + 1) * p * 2].chunks_exact(2) {
                        let at = colcos_sim::Vec2::new(xy[0], xy[1]);
                        out.extend(world.pheromones().iter().map(|ph| ph.value_at(at)));
                    }
                }
                Ok((out, e, p, f))
            })
            .map_err(|m| Kind::Action.err(m))?;
        Ok(PyArray1::from_vec(py, out).reshape([e, p, f])?.into_any())
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(step_deferred, m)?)?;
    m.add_function(wrap_pyfunction!(conclude, m)?)?;
    m.add_function(wrap_pyfunction!(task_view, m)?)?;
    m.add_function(wrap_pyfunction!(task_info, m)?)?;
    m.add_function(wrap_pyfunction!(sample_fields, m)?)?;
    Ok(())
}
