//! One robot's fit: the latency and motor lag by a search over their grid (a profile of the weighted
//! sum of squares, with the wheel scales solved in closed form at every point, as they enter
//! linearly), then refined; uncertainties from the least-squares covariance (scales) and the
//! curvature of the profile (latency, lag). A parameter the data cannot pin down is reported as
//! unidentifiable with the reason, never as a number.
use super::param::Param;
use super::response::Response;
use super::sensor::SensorFit;
use super::windows::{Window, windows};
use nalgebra::{Matrix2, Vector2};

/// What one robot's fit found.
#[derive(Clone, Debug)]
pub struct RobotFit {
    pub index: usize,
    /// (left, right) and their uncertainties.
    pub wheel_scale: Param<[f64; 2]>,
    /// s.
    pub motor_lag: Param<f64>,
    /// s, from a command leaving the bridge to the wheels taking it.
    pub latency: Param<f64>,
    /// Windows of motion the fit used, and those left out as collisions (outliers).
    pub windows: usize,
    pub outliers: usize,
    /// RMS residual of the heading turned (rad) and the distance driven (m) per window.
    pub rms: [f64; 2],
    /// The colour sensor's gain and offset (from the telemetry; [`super::identify`] fills it in).
    pub sensor: SensorFit,
}

/// What the fit searches over and needs.
#[derive(Clone, Copy, Debug)]
pub struct FitOptions {
    /// Distance between the wheels, m (`[robot] wheel_base`).
    pub wheel_base: f64,
    /// Largest latency searched, s.
    pub max_latency: f64,
    /// Largest motor lag searched, s.
    pub max_lag: f64,
    /// Window length, s.
    pub span: f64,
    /// Fewest windows of motion a fit needs.
    pub min_windows: usize,
    /// The simulator's time step the result is for, s (`dt`): a step moves a robot at the speed
    /// its wheels reach at the step's end, half a step ahead of a continuous motor, so the latency
    /// written is the continuous one plus half a step (the simulator then reproduces the timing).
    pub step: f64,
    /// How much older every pose is than its logged age says, s: the tracker's fastest delivery,
    /// which the bridge takes for the tracker's clock offset and so leaves out of the ages. `None`:
    /// the `tracker_latency` the log was recorded with (the scenario's `[tracker] latency`, as
    /// `colcos calibrate latency` measures it). Left in, it would count as the robots' latency.
    pub pose_delay: Option<f64>,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            wheel_base: 0.026,
            max_latency: 0.3,
            max_lag: 0.5,
            span: 0.1,
            min_windows: 50,
            step: 0.02,
            pose_delay: None,
        }
    }
}

/// The least-squares solution at one (latency, lag).
struct Solved {
    /// Weighted sum of squares.
    ssr: f64,
    scale: Vector2<f64>,
    /// Normal matrix (weighted), for the covariance.
    normal: Matrix2<f64>,
}

/// Fits robot `index` from its commands and poses.
pub fn fit_robot(
    index: usize,
    commands: &[(f64, [f64; 2])],
    poses: &[(f64, [f64; 3])],
    opts: &FitOptions,
) -> RobotFit {
    let all = windows(poses, opts.span, 2.5 * opts.span);
    let moving: Vec<Window> = all
        .iter()
        .copied()
        .filter(|w| w.a > commands.first().map_or(f64::INFINITY, |c| c.0))
        .collect();
    let mut fit = RobotFit {
        index,
        wheel_scale: Err(String::new()),
        motor_lag: Err(String::new()),
        latency: Err(String::new()),
        windows: moving.len(),
        outliers: 0,
        rms: [f64::NAN; 2],
        sensor: SensorFit::none("not fitted: identification was given no telemetry", 0),
    };
    let driven: f64 = moving.iter().map(|w| w.driven.abs()).sum();
    if moving.len() < opts.min_windows || driven < 0.05 {
        let why = format!(
            "too little data: {} windows of {} s with commands and poses and {driven:.3} m driven \
             (at least {} windows and 0.05 m needed)",
            moving.len(),
            opts.span,
            opts.min_windows
        );
        fit.wheel_scale = Err(why.clone());
        fit.motor_lag = Err(why.clone());
        fit.latency = Err(why);
        return fit;
    }
    let (t0, t1) = (
        moving[0].a - opts.max_latency - 0.01,
        moving[moving.len() - 1].b,
    );
    let b = opts.wheel_base;
    // Pass 1, equal weights (both rows in metres), all windows: a first optimum, the residuals'
    // spread per row kind, and the collisions (residuals far beyond it) to leave out.
    let mut problem = Problem {
        commands,
        windows: moving,
        t0,
        t1,
        b,
        weights: [1.0, 1.0],
    };
    let (mut lat, mut tau) = problem.search(opts);
    let before = problem.windows.len();
    let mut spread = [1.0, 1.0];
    // Collisions (a robot pushing a wall drives nowhere) bias every parameter: leave out the windows
    // far off the fit, fit again, until none is left out (three rounds at most).
    for _ in 0..3 {
        spread = problem.robust_spread(lat, tau);
        problem.weights = [1.0 / spread[0].max(1e-9), 1.0 / spread[1].max(1e-9)];
        let n = problem.windows.len();
        problem.drop_outliers(lat, tau, 3.5);
        (lat, tau) = problem.search(opts);
        if problem.windows.len() == n {
            break;
        }
    }
    fit.outliers = before - problem.windows.len();
    fit.windows = problem.windows.len();
    let best = problem.solve(&problem.response(tau), lat);
    let dof = (problem.windows.len() * 2).saturating_sub(4).max(1) as f64;
    // Rows in units of their own spread: the sum of squares is a chi-square once scaled so.
    let unit = best.ssr / dof;
    fit.rms = [spread[0] / b, spread[1] / 2.0];
    let cov = best.normal.try_inverse().map(|m| m * unit);
    fit.wheel_scale = match cov {
        Some(c) if c[(0, 0)] > 0.0 && c[(1, 1)] > 0.0 => {
            let sd = [c[(0, 0)].sqrt(), c[(1, 1)].sqrt()];
            if sd[0] > 0.1 || sd[1] > 0.1 || best.scale.iter().any(|s| *s <= 0.0) {
                Err(format!(
                    "unidentifiable: the wheels' motion does not pin their scales (sd {:.2}, {:.2})",
                    sd[0], sd[1]
                ))
            } else {
                Ok(([best.scale[0], best.scale[1]], sd))
            }
        }
        _ => Err(
            "unidentifiable: both wheels always turned together (no turning or no driving)".into(),
        ),
    };
    // Profile curvature: chi-square rises by 1 one standard deviation away.
    let chi = |lat: f64, tau: f64| problem.solve(&problem.response(tau), lat).ssr / unit;
    let c0 = chi(lat, tau);
    let dl = 0.002;
    let curv_l = (chi(lat + dl, tau) + chi(lat - dl, tau) - 2.0 * c0) / (dl * dl);
    let sd_l = (2.0 / curv_l).sqrt();
    fit.latency = if lat >= opts.max_latency - 0.002 {
        Err(format!(
            "unidentifiable: the best latency is at the searched limit {} s",
            opts.max_latency
        ))
    } else if lat <= -opts.step + 0.001 {
        Err(format!(
            "unidentifiable: the poses move {} s or more before the commands that drive them \
             (is the tracker's latency, --pose-delay, too large?)",
            opts.step
        ))
    } else if !(sd_l.is_finite() && sd_l < 0.02) {
        Err("unidentifiable: the commands changed too little to time their effect".into())
    } else {
        Ok(((lat + 0.5 * opts.step).max(0.0), sd_l))
    };
    let dt = (0.2 * tau).max(0.002);
    let curv_t = (chi(lat, tau + dt) + chi(lat, (tau - dt).max(0.0)) - 2.0 * c0) / (dt * dt);
    let sd_t = (2.0 / curv_t).sqrt();
    fit.motor_lag = if tau >= opts.max_lag * 0.99 {
        Err(format!(
            "unidentifiable: the best motor lag is at the searched limit {} s",
            opts.max_lag
        ))
    } else if !(sd_t.is_finite() && sd_t < (0.5 * tau).max(0.01)) {
        Err("unidentifiable: the commands changed too little to see the motors' lag".into())
    } else {
        Ok((tau, sd_t))
    };
    fit
}

struct Problem<'a> {
    commands: &'a [(f64, [f64; 2])],
    windows: Vec<Window>,
    t0: f64,
    t1: f64,
    b: f64,
    /// Weights of the turning and the driving rows.
    weights: [f64; 2],
}

impl Problem<'_> {
    fn response(&self, tau: f64) -> Response {
        Response::new(self.commands, tau, self.t0, self.t1)
    }

    /// Turning: b * turned = s_r R_r - s_l R_l; driving: 2 * driven = s_l R_l + s_r R_r.
    fn rows(&self, w: &Window, r: [f64; 2]) -> [([f64; 2], f64); 2] {
        [
            ([-r[0], r[1]], self.b * w.turned),
            ([r[0], r[1]], 2.0 * w.driven),
        ]
    }

    fn solve(&self, resp: &Response, latency: f64) -> Solved {
        let mut normal = Matrix2::zeros();
        let mut rhs = Vector2::zeros();
        let mut yy = 0.0;
        for w in &self.windows {
            let r = resp.distance(w.a, w.b, latency);
            for (k, (x, y)) in self.rows(w, r).into_iter().enumerate() {
                let q = self.weights[k];
                let x = Vector2::new(x[0] * q, x[1] * q);
                let y = y * q;
                normal += x * x.transpose();
                rhs += x * y;
                yy += y * y;
            }
        }
        let scale = normal
            .try_inverse()
            .map(|m| m * rhs)
            .unwrap_or_else(Vector2::zeros);
        // SSR = y'y - 2 s'X'y + s'X'X s.
        let ssr = (yy - 2.0 * scale.dot(&rhs) + (scale.transpose() * normal * scale)[0]).max(0.0);
        Solved { ssr, scale, normal }
    }

    /// The (latency, lag) of least weighted sum of squares: a coarse grid, then a finer one around
    /// its best.
    fn search(&self, opts: &FitOptions) -> (f64, f64) {
        let mut taus = vec![0.0];
        let (lo, n) = (0.005f64, 28);
        taus.extend((0..=n).map(|k| lo * (opts.max_lag / lo).powf(k as f64 / n as f64)));
        // From a step early: the simulator's own half-step lead (see `FitOptions::step`) and more.
        let lats: Vec<f64> = (0..=((opts.max_latency + opts.step) / 0.004).round() as usize)
            .map(|k| k as f64 * 0.004 - opts.step)
            .collect();
        let mut best = (f64::INFINITY, 0.0, 0.0);
        let mut best_k = 0;
        for (k, &tau) in taus.iter().enumerate() {
            let resp = self.response(tau);
            for &lat in &lats {
                let s = self.solve(&resp, lat).ssr;
                if s < best.0 {
                    best = (s, lat, tau);
                    best_k = k;
                }
            }
        }
        // Finer: lags between the grid neighbours, latencies within two coarse steps, 0.5 ms apart.
        let (tlo, thi) = (
            taus[best_k.saturating_sub(1)],
            taus[(best_k + 1).min(taus.len() - 1)],
        );
        let (lat0, mut out) = (best.1, (best.1, best.2));
        let mut best_s = best.0;
        for j in 0..=12 {
            let tau = tlo + (thi - tlo) * j as f64 / 12.0;
            let resp = self.response(tau);
            for i in 0..=32 {
                let lat = (lat0 - 0.008 + 0.0005 * i as f64).clamp(-opts.step, opts.max_latency);
                let s = self.solve(&resp, lat).ssr;
                if s < best_s {
                    best_s = s;
                    out = (lat, tau);
                }
            }
        }
        out
    }

    /// Each row kind's residual spread at (lat, tau), robust to collisions (1.4826 x median
    /// absolute residual).
    fn robust_spread(&self, lat: f64, tau: f64) -> [f64; 2] {
        let resp = self.response(tau);
        let s = self.solve(&resp, lat).scale;
        let mut res = [Vec::new(), Vec::new()];
        for w in &self.windows {
            for (k, (x, y)) in self
                .rows(w, resp.distance(w.a, w.b, lat))
                .into_iter()
                .enumerate()
            {
                res[k].push((y - x[0] * s[0] - x[1] * s[1]).abs());
            }
        }
        res.map(|mut r| {
            r.sort_by(f64::total_cmp);
            1.4826 * r.get(r.len() / 2).copied().unwrap_or(0.0)
        })
    }

    /// Leaves out windows whose weighted residual exceeds `k` (bumps, the shield's pushes).
    fn drop_outliers(&mut self, lat: f64, tau: f64, k: f64) {
        let resp = self.response(tau);
        let s = self.solve(&resp, lat).scale;
        let keep: Vec<Window> = self
            .windows
            .iter()
            .copied()
            .filter(|w| {
                let rows = self.rows(w, resp.distance(w.a, w.b, lat));
                rows.iter().enumerate().all(|(j, (x, y))| {
                    ((y - x[0] * s[0] - x[1] * s[1]) * self.weights[j]).abs() <= k
                })
            })
            .collect();
        self.windows = keep;
    }
}
