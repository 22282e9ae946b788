//! Robot models written by the project from published parameters, compiled into the library so
//! they need no file at run time. Sources are cited inside each URDF in `models/` (the crate's
//! `models/` links to them, so that the published crate holds them).

use crate::error::{Error, Result};
use crate::io::{urdf::load_urdf_str, LoadOptions};
use crate::model::{Model, STANDARD_GRAVITY};
use crate::spatial::Vec3;

/// (name, URDF text, gravity).
const BUNDLED: [(&str, &str, [f64; 3]); 3] = [
    (
        "ur5",
        include_str!("../../models/ur5.urdf"),
        [0.0, 0.0, -STANDARD_GRAVITY],
    ),
    // the seeds' 2-link arm moves in the x-y plane with gravity along -y
    (
        "planar2",
        include_str!("../../models/planar2.urdf"),
        [0.0, -STANDARD_GRAVITY, 0.0],
    ),
    (
        "pendulum",
        include_str!("../../models/pendulum.urdf"),
        [0.0, 0.0, -STANDARD_GRAVITY],
    ),
];

/// Names of the bundled models.
pub fn bundled_names() -> Vec<&'static str> {
    BUNDLED.iter().map(|(name, _, _)| *name).collect()
}

/// The URDF text and gravity of a bundled model, by name.
pub fn bundled_urdf(name: &str) -> Result<(&'static str, [f64; 3])> {
    BUNDLED
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, text, gravity)| (*text, *gravity))
        .ok_or_else(|| Error::InvalidValue {
            argument: "name".into(),
            message: format!(
                "expected one of the bundled models {}, got '{name}'",
                bundled_names().join(", ")
            ),
        })
}

/// A bundled model by name.
pub fn bundled_model(name: &str, floating_base: bool) -> Result<Model> {
    let (text, gravity) = bundled_urdf(name)?;
    let mut model = load_urdf_str(
        text,
        &format!("{name}.urdf (bundled)"),
        LoadOptions::floating(floating_base),
    )?;
    model.gravity = Vec3::from(gravity);
    Ok(model)
}

/// For the unit tests: the bundled UR5 on a floating base (a six-coordinate joint in the chain)
/// with armature (which makes its massless base regular), a configuration whose quaternion is a
/// unit one, and two nv vectors (a velocity, and an acceleration or torque).
#[cfg(test)]
pub(crate) fn floating_ur5_state() -> (Model, Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut model = bundled_model("ur5", true).expect("the bundled UR5 loads");
    model.armature.fill(0.1);
    let mut q: Vec<f64> = (0..model.nq).map(|k| 0.3 + 0.1 * k as f64).collect();
    let norm = q[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
    q[3..7].iter_mut().for_each(|x| *x /= norm);
    let v = (0..model.nv).map(|k| 0.2 * k as f64 - 0.5).collect();
    let x = (0..model.nv).map(|k| 1.5 - 0.3 * k as f64).collect();
    (model, q, v, x)
}
