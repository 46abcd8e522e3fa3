//! The drive model identification fits, in closed form over a time grid: a wheel's speed is its
//! command, delayed by the latency, through a first-order lag, times the wheel's scale. The scale is
//! linear, so for given latency and lag only the integrated unit-scale response of each wheel over
//! each window between two poses is needed; the latency only shifts the time axis, so one filter
//! pass per lag serves every latency.

/// Time step of the grid the response is integrated on, s (well under a tick and the latencies to
/// resolve).
pub const GRID: f64 = 0.0005;

/// The integrated response of one robot's two wheels to its commands, for one motor lag.
pub struct Response {
    t0: f64,
    /// Per grid point, the running integral of each wheel's lagged (undelayed) command, m.
    integral: Vec<[f64; 2]>,
}

impl Response {
    /// The response to `commands` (time sent, (left, right) m/s; held until the next) with time
    /// constant `tau` s, from `t0` to `t1`.
    pub fn new(commands: &[(f64, [f64; 2])], tau: f64, t0: f64, t1: f64) -> Response {
        let n = ((t1 - t0) / GRID).ceil().max(1.0) as usize + 1;
        let alpha = if tau > 0.0 {
            -(-GRID / tau).exp_m1()
        } else {
            1.0
        };
        let mut integral = Vec::with_capacity(n);
        let (mut v, mut acc, mut next) = ([0.0f64; 2], [0.0f64; 2], 0usize);
        let mut cmd = [0.0f64; 2];
        for k in 0..n {
            let t = t0 + k as f64 * GRID;
            while next < commands.len() && commands[next].0 <= t {
                cmd = commands[next].1;
                next += 1;
            }
            integral.push(acc);
            for w in 0..2 {
                // Exact first-order step over the grid step, and its exact integral.
                let start = v[w];
                v[w] += (cmd[w] - v[w]) * alpha;
                acc[w] += cmd[w] * GRID - (v[w] - start) * tau.max(0.0);
            }
        }
        Response { t0, integral }
    }

    /// The running integral at `t` (linear between grid points; 0 before the grid).
    fn at(&self, t: f64) -> [f64; 2] {
        let x = (t - self.t0) / GRID;
        if x <= 0.0 {
            return [0.0; 2];
        }
        let k = x.floor() as usize;
        let last = self.integral.len() - 1;
        if k >= last {
            return self.integral[last];
        }
        let f = x - k as f64;
        let (a, b) = (self.integral[k], self.integral[k + 1]);
        [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f]
    }

    /// Each wheel's distance at unit scale over `[a, b]` with the commands `latency` s late, m.
    pub fn distance(&self, a: f64, b: f64, latency: f64) -> [f64; 2] {
        let (x, y) = (self.at(a - latency), self.at(b - latency));
        [y[0] - x[0], y[1] - x[1]]
    }
}
