//! Injection kernels: the shape a deposit takes around a point.
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum Kernel {
    /// 1 inside `radius`, 0 outside.
    Disc { radius: f32 },
    /// 1 at the centre, falling linearly to 0 at `radius`.
    Cone { radius: f32 },
    /// exp(-r^2 / 2 sigma^2), cut at 3 sigma.
    Gaussian { sigma: f32 },
}

impl Kernel {
    pub fn weight(&self, _distance: f32) -> f32 {
        todo!()
    }
    /// Distance beyond which the weight is zero, m.
    pub fn support(&self) -> f32 {
        todo!()
    }
}
