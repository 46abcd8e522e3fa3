//! Trail following: steer toward the side whose colour sensor sees more of one channel; wander when
//! off the trail.
use super::param_doc::ParamDoc;
use super::{Behaviour, Observation, Wander, WheelCommand};
use crate::channel::Channel;
use crate::rng::SimRng;
use serde::{Deserialize, Serialize};

/// Parameters of [`Follow`] as written in a scenario's `params` table.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FollowParams {
    /// Channel to follow.
    pub channel: Channel,
    /// Base wheel speed, m/s.
    pub speed: f32,
    /// Wheel speed difference per unit of left-right intensity difference, m/s.
    pub sensitivity: f32,
    /// Mean intensity (0..1) below which the robot is off the trail and wanders.
    pub threshold: f32,
}

impl Default for FollowParams {
    fn default() -> Self {
        FollowParams {
            channel: Channel::B,
            speed: 0.1,
            sensitivity: 0.6,
            threshold: 0.05,
        }
    }
}

impl FollowParams {
    /// Every key of the `params` table of `follow`, as `colcos behaviours` prints it.
    pub const DOCS: &'static [ParamDoc] = &[
        ParamDoc {
            name: "channel",
            ty: "string",
            default: "\"b\"",
            meaning: "colour channel of the trail to follow: \"r\", \"g\" or \"b\"",
        },
        ParamDoc {
            name: "speed",
            ty: "float, m/s, >= 0",
            default: "0.1",
            meaning: "base wheel speed on the trail, and the wandering speed off it",
        },
        ParamDoc {
            name: "sensitivity",
            ty: "float, m/s",
            default: "0.6",
            meaning: "wheel speed difference per unit of left-right intensity difference",
        },
        ParamDoc {
            name: "threshold",
            ty: "float, 0..1, >= 0",
            default: "0.05",
            meaning: "mean intensity of the channel below which the robot is off the trail and wanders",
        },
    ];
}

pub struct Follow {
    pub channel: usize,
    pub speed: f32,
    pub sensitivity: f32,
    pub threshold: f32,
    off_trail: Wander,
}

impl Follow {
    pub fn new(channel: usize, speed: f32, sensitivity: f32, threshold: f32) -> Self {
        Follow {
            channel,
            speed,
            sensitivity,
            threshold,
            off_trail: Wander::new(speed),
        }
    }

    /// The steering rule alone: the right wheel speeds up when the left sensor (n = 2) sees more than
    /// the right one (n = 0), turning the robot toward the trail.
    pub fn steer(&self, obs: &Observation) -> WheelCommand {
        let diff = obs.intensity[2][self.channel] - obs.intensity[0][self.channel];
        let turn = self.sensitivity * diff;
        WheelCommand::new(self.speed - turn, self.speed + turn)
    }
}

impl Behaviour for Follow {
    fn name(&self) -> &str {
        "follow"
    }
    fn act(&mut self, obs: &Observation, rng: &mut SimRng) -> WheelCommand {
        if obs.strength(self.channel) < self.threshold {
            self.off_trail.act(obs, rng)
        } else {
            self.steer(obs)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_toward_the_stronger_side() {
        let f = Follow::new(2, 0.1, 0.5, 0.05);
        let mut obs = Observation::default();
        obs.intensity[2][2] = 0.8; // left
        obs.intensity[0][2] = 0.2; // right
        let cmd = f.steer(&obs);
        assert!(cmd.right > cmd.left, "{cmd:?}");
        obs.intensity[2][2] = 0.2;
        obs.intensity[0][2] = 0.8;
        let cmd = f.steer(&obs);
        assert!(cmd.left > cmd.right, "{cmd:?}");
    }
}
