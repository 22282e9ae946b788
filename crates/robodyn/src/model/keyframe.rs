//! Named states a model file declares (MJCF `<keyframe><key>`), in robodyn's coordinates.

use super::Model;
use crate::error::{Error, Result};
use nalgebra::DVector;

/// A state the model file names (MuJoCo's keyframe), such as Menagerie's `home`: where a
/// simulation starts and what its actuators are told. `q` and `v` are in robodyn's layout
/// (quaternions scalar last; a free joint's linear velocity in its body's axes, where MuJoCo's
/// `qvel` has world axes).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Keyframe {
    /// The key's `name` (empty when the file gives none).
    pub name: String,
    /// The simulation time the key holds (s).
    pub time: f64,
    /// The configuration, nq.
    pub q: DVector<f64>,
    /// The velocity, nv.
    pub v: DVector<f64>,
    /// The actuators' controls, one per actuator of the file in its order (MuJoCo's `ctrl`).
    pub ctrl: DVector<f64>,
    /// The actuators' activations, one per actuator with activation dynamics (MuJoCo's `act`).
    #[serde(default)]
    pub act: DVector<f64>,
    /// The plastic springs' references (MuJoCo's `plastic`, [`crate::model::plastic`]).
    #[serde(default)]
    pub plastic: DVector<f64>,
}

impl Model {
    /// The keyframe called `key`; an error lists the model's keyframes when there is none.
    pub fn keyframe(&self, key: &str) -> Result<&Keyframe> {
        self.keyframes
            .iter()
            .find(|k| k.name == key)
            .ok_or_else(|| {
                let names: Vec<String> = self
                    .keyframes
                    .iter()
                    .map(|k| format!("'{}'", k.name))
                    .collect();
                let known = if names.is_empty() {
                    "the model has none".to_string()
                } else {
                    format!("one of {}", names.join(", "))
                };
                Error::InvalidValue {
                    argument: "key".into(),
                    message: format!("expected a keyframe of the model ({known}), got '{key}'"),
                }
            })
    }
}
