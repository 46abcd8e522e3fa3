//! Checked axes: the values a grid takes along each, and the value at a quantile `u` in [0, 1) for
//! Latin-hypercube and random sampling.
use crate::error::{Result, SweepError};
use crate::keypath::KeyPath;
use crate::spec::{AxisSpec, Distribution, DrawSpec, Scale};
use colcos_sim::rng::SimRng;
use rand::Rng;

/// One checked axis.
#[derive(Clone, Debug)]
pub struct Axis {
    /// Column name.
    pub name: String,
    pub keys: Vec<KeyPath>,
    pub kind: AxisKind,
    pub integer: bool,
    /// Values are spread on a log scale (plots use a log axis).
    pub log: bool,
}

#[derive(Clone, Debug)]
pub enum AxisKind {
    List(Vec<toml::Value>),
    Range {
        from: f64,
        to: f64,
        steps: Option<usize>,
        log: bool,
    },
    Draw {
        dist: Distribution,
        a: f64,
        b: f64,
        count: Option<usize>,
    },
}

impl Axis {
    /// Checks `axes[index]` of the sweep file.
    pub fn from_spec(index: usize, s: &AxisSpec) -> Result<Axis> {
        let at = |k: &str| format!("axes[{index}].{k}");
        let keys: Vec<String> = match (&s.key, &s.keys) {
            (Some(k), None) => vec![k.clone()],
            (None, Some(ks)) if !ks.is_empty() => ks.clone(),
            (None, Some(_)) => {
                return Err(SweepError::invalid(
                    at("keys"),
                    "[]",
                    "needs at least one key",
                ));
            }
            (Some(k), Some(_)) => {
                return Err(SweepError::invalid(
                    at("key"),
                    format!("\"{k}\""),
                    "give `key` or `keys`, not both",
                ));
            }
            (None, None) => {
                return Err(SweepError::invalid(
                    format!("axes[{index}]"),
                    "(no key)",
                    "an axis needs `key` (or `keys`): the scenario key path it sets",
                ));
            }
        };
        let keys = keys
            .iter()
            .enumerate()
            .map(|(n, k)| {
                let name = if s.key.is_some() {
                    at("key")
                } else {
                    at(&format!("keys[{n}]"))
                };
                KeyPath::parse(k).map_err(|r| SweepError::invalid(name, format!("\"{k}\""), r))
            })
            .collect::<Result<Vec<_>>>()?;
        let given = [s.values.is_some(), s.range.is_some(), s.draw.is_some()];
        if given.iter().filter(|&&g| g).count() != 1 {
            return Err(SweepError::invalid(
                format!("axes[{index}]"),
                keys[0].to_string(),
                "give exactly one of `values`, `range` and `draw`",
            ));
        }
        let finite = |k: &str, v: f64| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(SweepError::invalid(at(k), v, "must be a finite number"))
            }
        };
        let mut log = false;
        let kind = if let Some(values) = &s.values {
            if values.is_empty() {
                return Err(SweepError::invalid(
                    at("values"),
                    "[]",
                    "needs at least one value",
                ));
            }
            for (n, v) in values.iter().enumerate() {
                if matches!(v, toml::Value::Float(f) if !f.is_finite()) {
                    return Err(SweepError::invalid(
                        at(&format!("values[{n}]")),
                        v,
                        "must be a finite number",
                    ));
                }
            }
            AxisKind::List(values.clone())
        } else if let Some(r) = &s.range {
            let (from, to) = (finite("range.from", r.from)?, finite("range.to", r.to)?);
            log = r.scale == Scale::Log;
            if log && from <= 0.0 {
                return Err(SweepError::invalid(
                    at("range.from"),
                    from,
                    "a log range needs ends > 0",
                ));
            }
            if log && to <= 0.0 {
                return Err(SweepError::invalid(
                    at("range.to"),
                    to,
                    "a log range needs ends > 0",
                ));
            }
            if r.steps == Some(0) {
                return Err(SweepError::invalid(
                    at("range.steps"),
                    0,
                    "must be at least 1",
                ));
            }
            AxisKind::Range {
                from,
                to,
                steps: r.steps,
                log,
            }
        } else {
            let d = s.draw.as_ref().expect("one of the three");
            let (a, b) = check_draw(d, &at)?;
            log = d.distribution == Distribution::LogUniform;
            if d.count == Some(0) {
                return Err(SweepError::invalid(
                    at("draw.count"),
                    0,
                    "must be at least 1",
                ));
            }
            AxisKind::Draw {
                dist: d.distribution,
                a,
                b,
                count: d.count,
            }
        };
        let name = s.name.clone().unwrap_or_else(|| keys[0].to_string());
        if name.is_empty() || name.contains([',', '"', '\n']) {
            return Err(SweepError::invalid(
                at("name"),
                format!("\"{name}\""),
                "a column name: not empty, no commas, quotes or line breaks",
            ));
        }
        Ok(Axis {
            name,
            keys,
            kind,
            integer: s.integer,
            log,
        })
    }

    /// The values of a grid along this axis; `draw` axes draw theirs from `rng`.
    pub fn grid_values(&self, index: usize, rng: &mut SimRng) -> Result<Vec<toml::Value>> {
        Ok(match &self.kind {
            AxisKind::List(v) => v.clone(),
            AxisKind::Range {
                from,
                to,
                steps,
                log,
            } => {
                let steps = steps.ok_or_else(|| {
                    SweepError::invalid(
                        format!("axes[{index}].range.steps"),
                        "(missing)",
                        "a grid needs the number of values of a range",
                    )
                })?;
                (0..steps)
                    .map(|k| {
                        let u = if steps == 1 {
                            0.0
                        } else {
                            k as f64 / (steps - 1) as f64
                        };
                        self.number(round_generated(interpolate(*from, *to, u, *log)))
                    })
                    .collect()
            }
            AxisKind::Draw { count, .. } => {
                let count = count.ok_or_else(|| {
                    SweepError::invalid(
                        format!("axes[{index}].draw.count"),
                        "(missing)",
                        "a grid needs the number of draws",
                    )
                })?;
                (0..count).map(|_| self.at_quantile(unit(rng))).collect()
            }
        })
    }

    /// The value at quantile `u` in [0, 1): a list's element `floor(u n)`, a range's point at `u`
    /// (in log space for a log range), a distribution's inverse CDF.
    pub fn at_quantile(&self, u: f64) -> toml::Value {
        let u = u.clamp(0.0, 1.0 - 1e-12);
        match &self.kind {
            AxisKind::List(v) => v[((u * v.len() as f64) as usize).min(v.len() - 1)].clone(),
            AxisKind::Range { from, to, log, .. } => {
                self.number(round_generated(interpolate(*from, *to, u, *log)))
            }
            AxisKind::Draw { dist, a, b, .. } => {
                let u = u.max(1e-12);
                self.number(match dist {
                    Distribution::Uniform => a + (b - a) * u,
                    Distribution::LogUniform => (a.ln() + (b.ln() - a.ln()) * u).exp(),
                    Distribution::Normal => a + b * inverse_normal_cdf(u),
                    Distribution::LogNormal => (a + b * inverse_normal_cdf(u)).exp(),
                })
            }
        }
    }

    fn number(&self, x: f64) -> toml::Value {
        if self.integer {
            toml::Value::Integer(x.round() as i64)
        } else {
            toml::Value::Float(x)
        }
    }
}

/// A uniform draw in [0, 1) from the top 53 bits of one 64-bit draw.
pub fn unit(rng: &mut SimRng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A computed range value to 12 significant digits: `exp(ln 2.5 + ...)` gives 5.000000000000001 where
/// the user meant 5, and 12 digits are far finer than any simulated parameter.
pub fn round_generated(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{x:.11e}").parse().unwrap_or(x)
}

fn interpolate(from: f64, to: f64, u: f64, log: bool) -> f64 {
    if log {
        (from.ln() + (to.ln() - from.ln()) * u).exp()
    } else {
        from + (to - from) * u
    }
}

/// The two parameters of a distribution: (low, high) or (mean, sd).
fn check_draw(d: &DrawSpec, at: &dyn Fn(&str) -> String) -> Result<(f64, f64)> {
    let need = |k: &str, v: Option<f64>| {
        let v = v.ok_or_else(|| {
            SweepError::invalid(
                at(&format!("draw.{k}")),
                "(missing)",
                format!("{:?} draws need `{k}`", d.distribution).to_lowercase(),
            )
        })?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(SweepError::invalid(
                at(&format!("draw.{k}")),
                v,
                "must be a finite number",
            ))
        }
    };
    let unused = |k: &str, v: Option<f64>| match v {
        Some(v) => Err(SweepError::invalid(
            at(&format!("draw.{k}")),
            v,
            "not a parameter of this distribution",
        )),
        None => Ok(()),
    };
    match d.distribution {
        Distribution::Uniform | Distribution::LogUniform => {
            unused("mean", d.mean)?;
            unused("sd", d.sd)?;
            let (low, high) = (need("low", d.low)?, need("high", d.high)?);
            if high <= low {
                return Err(SweepError::invalid(
                    at("draw.high"),
                    high,
                    "must be above `low`",
                ));
            }
            if d.distribution == Distribution::LogUniform && low <= 0.0 {
                return Err(SweepError::invalid(
                    at("draw.low"),
                    low,
                    "log_uniform needs low > 0",
                ));
            }
            Ok((low, high))
        }
        Distribution::Normal | Distribution::LogNormal => {
            unused("low", d.low)?;
            unused("high", d.high)?;
            let (mean, sd) = (need("mean", d.mean)?, need("sd", d.sd)?);
            if sd <= 0.0 {
                return Err(SweepError::invalid(at("draw.sd"), sd, "must be > 0"));
            }
            Ok((mean, sd))
        }
    }
}

/// The standard normal quantile (Acklam's rational approximation, relative error below 1.2e-9).
pub fn inverse_normal_cdf(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.383_577_518_672_69e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_quantiles() {
        assert!(inverse_normal_cdf(0.5).abs() < 1e-9);
        assert!((inverse_normal_cdf(0.975) - 1.959964).abs() < 1e-5);
        assert!((inverse_normal_cdf(0.01) + 2.326348).abs() < 1e-5);
    }

    #[test]
    fn ranges_hit_both_ends() {
        let spec: AxisSpec = toml::from_str(
            "key = \"a.b\"\nrange = { from = 1.0, to = 100.0, steps = 3, scale = \"log\" }",
        )
        .unwrap();
        let axis = Axis::from_spec(0, &spec).unwrap();
        let v = axis
            .grid_values(0, &mut colcos_sim::rng::stream(0, 0, 0))
            .unwrap();
        let v: Vec<f64> = v.iter().map(|x| x.as_float().unwrap()).collect();
        assert_eq!(v, [1.0, 10.0, 100.0]);
    }

    #[test]
    fn range_values_are_written_as_the_user_would() {
        let values = |range: &str| {
            let spec: AxisSpec = toml::from_str(&format!("key = \"a\"\nrange = {range}")).unwrap();
            let axis = Axis::from_spec(0, &spec).unwrap();
            let v = axis
                .grid_values(0, &mut colcos_sim::rng::stream(0, 0, 0))
                .unwrap();
            v.iter().map(crate::runner::value_text).collect::<Vec<_>>()
        };
        // exp/ln alone gives 5.000000000000001, 10.000000000000002, 19.999999999999996.
        assert_eq!(
            values("{ from = 2.5, to = 40.0, steps = 5, scale = \"log\" }"),
            ["2.5", "5", "10", "20", "40"]
        );
        assert_eq!(
            values("{ from = 0.05, to = 0.8, steps = 5, scale = \"log\" }"),
            ["0.05", "0.1", "0.2", "0.4", "0.8"]
        );
        assert_eq!(
            values("{ from = 0.1, to = 0.3, steps = 5 }"),
            ["0.1", "0.15", "0.2", "0.25", "0.3"]
        );
        assert_eq!(round_generated(4.308869380063766), 4.30886938006);
    }
}
