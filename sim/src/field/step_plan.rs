//! What one step of a grid field does: decay factor, scheme, sub-steps and wind, decided once from the
//! field's parameters and `dt`. [`GridField::step`](super::GridField::step) and the GPU backend both
//! execute a [`StepPlan`], so that their results can only differ in how a pass is computed, never in
//! which passes run or with which numbers.
use super::{DiffusionScheme, GridParams, GridSpec};
use glam::Vec2;

/// Largest explicit diffusion number `d dt / h^2` per (sub-)step.
pub const EXPLICIT_MAX_R: f32 = 0.25;
/// Largest one-sided number `d dt / h^2` per sub-step.
pub const ONE_SIDED_MAX_S: f32 = 0.5;
/// Largest Courant number per wind sub-step, per direction.
pub const WIND_MAX_CFL: f32 = 0.5;

/// One step of one grid field, in order: evaporation and static injection `Phi <- a Phi + b J`
/// (fused into the first diffusion pass where [`Diffusion::fuses_decay`]), diffusion, then wind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepPlan {
    /// Decay factor of the step.
    pub a: f32,
    /// Weight of the static injection map in the step.
    pub b: f32,
    pub diffusion: Diffusion,
    /// `None`: no wind, or a non-finite one.
    pub wind: Option<Wind>,
}

/// How a step diffuses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Diffusion {
    /// No diffusion (none set, or a one-cell grid): evaporation and injection only.
    None,
    /// `substeps` explicit passes of diffusion number `r`; the first also evaporates and injects.
    Explicit { substeps: usize, r: f32 },
    /// Backward Euler split by direction: an x-solve that also evaporates and injects, then a y-solve
    /// (skipped on a one-row grid).
    Implicit { r: f32 },
    /// Infinite diffusion: evaporation and injection, then every cell at the mean.
    Uniform,
    /// Evaporation and injection, then `substeps` one-sided passes (eq. (4)) of number `s`.
    OneSided { substeps: usize, s: f32 },
}

impl Diffusion {
    /// Whether the first diffusion pass applies `a` and `b` itself (no separate evaporation pass).
    pub fn fuses_decay(&self) -> bool {
        matches!(
            self,
            Diffusion::Explicit { .. } | Diffusion::Implicit { .. }
        )
    }
}

/// Wind advection of a step: `substeps` upwind sub-steps of Courant numbers `cx`, `cy` each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wind {
    pub substeps: usize,
    pub cx: f32,
    pub cy: f32,
}

impl Wind {
    /// The Courant number of the x sweep, when there is one (non-zero, more than one column).
    pub fn x(&self, spec: &GridSpec) -> Option<f32> {
        (self.cx != 0.0 && spec.nx > 1).then_some(self.cx)
    }
    /// The Courant number of the y sweep, when there is one (non-zero, more than one row).
    pub fn y(&self, spec: &GridSpec) -> Option<f32> {
        (self.cy != 0.0 && spec.ny > 1).then_some(self.cy)
    }
}

impl StepPlan {
    /// The plan of a step of `dt` seconds; `None` when nothing happens (`dt` not positive, empty grid).
    ///
    /// `decay_carry` is the field's running log of (exact cumulative decay / applied cumulative
    /// decay): the f32 factor applied is chosen so that the product of the factors tracks `exp(-t/e)`
    /// within one rounding over any number of steps. It is updated here, so plan each step once.
    pub fn new(
        spec: &GridSpec,
        params: &GridParams,
        dt: f32,
        decay_carry: &mut f64,
    ) -> Option<StepPlan> {
        if dt.is_nan() || dt <= 0.0 || spec.is_empty() {
            return None;
        }
        let GridSpec { nx, ny, cell } = *spec;
        let e = params.evaporation as f64;
        let dtd = dt as f64;
        let (a, b) = if e.is_finite() && e > 0.0 {
            // b = e (1 - a) is the exact injection for the factor applied (steady state e J).
            let ln_a = -dtd / e + *decay_carry;
            let a = ln_a.exp() as f32;
            *decay_carry = ln_a - (a as f64).ln();
            (a, (e * (1.0 - a as f64)) as f32)
        } else if e.is_finite() {
            // e <= 0: the pheromone vanishes at once; the injection of this step is not kept either.
            (0.0, 0.0)
        } else {
            (1.0, dt)
        };
        let d = params.diffusion.max(0.0);
        let r = if d.is_finite() {
            d * dt / (cell * cell)
        } else {
            f32::INFINITY
        };
        let diffusion = if !(r > 0.0 && (nx > 1 || ny > 1)) {
            Diffusion::None
        } else {
            match params.scheme {
                DiffusionScheme::Auto if r <= EXPLICIT_MAX_R => {
                    Diffusion::Explicit { substeps: 1, r }
                }
                DiffusionScheme::Auto | DiffusionScheme::Implicit => {
                    if r.is_finite() {
                        Diffusion::Implicit { r }
                    } else {
                        Diffusion::Uniform
                    }
                }
                DiffusionScheme::Explicit => {
                    let n = substeps(r, EXPLICIT_MAX_R);
                    Diffusion::Explicit {
                        substeps: n,
                        r: r / n as f32,
                    }
                }
                DiffusionScheme::OneSided => {
                    let n = substeps(r, ONE_SIDED_MAX_S);
                    Diffusion::OneSided {
                        substeps: n,
                        s: r / n as f32,
                    }
                }
            }
        };
        let w = params.wind;
        let wind = (w != Vec2::ZERO && w.is_finite()).then(|| {
            let cx = w.x * dt / cell;
            let cy = w.y * dt / cell;
            let n = substeps(cx.abs().max(cy.abs()), WIND_MAX_CFL);
            Wind {
                substeps: n,
                cx: cx / n as f32,
                cy: cy / n as f32,
            }
        });
        Some(StepPlan {
            a,
            b,
            diffusion,
            wind,
        })
    }
}

/// Number of sub-steps that bring `x` down to at most `max` each.
fn substeps(x: f32, max: f32) -> usize {
    if x <= max {
        1
    } else {
        ((x / max).ceil() as usize).max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(params: GridParams, dt: f32) -> StepPlan {
        let spec = GridSpec::new(10, 8, 0.01);
        StepPlan::new(&spec, &params, dt, &mut 0.0).expect("a step")
    }

    #[test]
    fn schemes_and_substeps() {
        let p = |d: f32, scheme| GridParams {
            diffusion: d,
            scheme,
            ..Default::default()
        };
        // r = d dt / h^2 = d * 0.1 / 1e-4.
        assert_eq!(
            plan(p(2e-4, DiffusionScheme::Auto), 0.1).diffusion,
            Diffusion::Explicit {
                substeps: 1,
                r: 2e-4 * 0.1 / (0.01 * 0.01)
            }
        );
        assert!(matches!(
            plan(p(9e-4, DiffusionScheme::Auto), 0.1).diffusion,
            Diffusion::Implicit { .. }
        ));
        assert!(matches!(
            plan(p(9e-4, DiffusionScheme::Explicit), 0.1).diffusion,
            Diffusion::Explicit { substeps: 4, .. }
        ));
        assert!(matches!(
            plan(p(9e-4, DiffusionScheme::OneSided), 0.1).diffusion,
            Diffusion::OneSided { substeps: 2, .. }
        ));
        assert_eq!(
            plan(p(f32::INFINITY, DiffusionScheme::Implicit), 0.1).diffusion,
            Diffusion::Uniform
        );
        assert_eq!(
            plan(p(0.0, DiffusionScheme::Auto), 0.1).diffusion,
            Diffusion::None
        );
    }

    #[test]
    fn nothing_to_plan() {
        let spec = GridSpec::new(4, 4, 0.01);
        for dt in [0.0, -1.0, f32::NAN] {
            assert!(StepPlan::new(&spec, &GridParams::default(), dt, &mut 0.0).is_none());
        }
        let empty = GridSpec { nx: 0, ..spec };
        assert!(StepPlan::new(&empty, &GridParams::default(), 0.1, &mut 0.0).is_none());
    }

    #[test]
    fn wind_substeps_keep_the_courant_number() {
        let p = GridParams {
            wind: Vec2::new(0.12, -0.03),
            ..Default::default()
        };
        let w = plan(p, 0.1).wind.expect("wind");
        assert_eq!(w.substeps, 3);
        assert!(w.cx.abs() <= WIND_MAX_CFL && w.cy.abs() <= WIND_MAX_CFL);
    }
}
