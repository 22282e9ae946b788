//! `<keyframe>`: each `<key>` becomes a [`Keyframe`] in robodyn's coordinates.
//!
//! MuJoCo's `qpos` lists each joint's coordinates in the tree's order, as robodyn's q does, with
//! quaternions scalar first (robodyn's: last), normalised here as MuJoCo normalises them before
//! use; its `qvel` gives a free joint's linear velocity in world axes (robodyn's: in the body's).
//! As in MuJoCo (4.0), a list may be shorter than the model's: it gives the first entries, and
//! the rest are those of `qpos0` (the neutral configuration) for `qpos`, zeros for `qvel`, `act`
//! and `ctrl`, the springs' own references for `plastic` (its ball references quaternions as in
//! `qpos`); a longer list is an error. A key without `time` is at 0.
//! `mpos`/`mquat` (mocap bodies) are not read: a warning each.

use super::Reader;
use crate::error::Result;
use crate::io::xml::{parse_number_list, parse_numbers};
use crate::model::{Keyframe, Model, PlasticSlot};
use nalgebra::{DVector, Quaternion, UnitQuaternion, Vector3};
use roxmltree::Node;

impl<'a> Reader<'a> {
    /// The keys of the `<keyframe>` sections among `sections`, in order, into
    /// `model.keyframes` (after the tree is built: a key's layout is the model's).
    pub(super) fn read_keyframes(
        &self,
        sections: &[Node<'a, 'a>],
        model: &mut Model,
    ) -> Result<()> {
        let actuators = model.nu();
        for section in sections.iter().filter(|c| c.has_tag_name("keyframe")) {
            for key in self.children(*section)? {
                let keyframe = self.keyframe(key, model, actuators)?;
                model.keyframes.push(keyframe);
            }
        }
        Ok(())
    }

    /// One `<key>`.
    fn keyframe(&self, key: Node<'a, 'a>, model: &mut Model, actuators: usize) -> Result<Keyframe> {
        // a list attribute's numbers over `defaults` (at most as many), or `defaults`
        let list = |name: &str, defaults: Vec<f64>| -> Result<Vec<f64>> {
            let Some(text) = key.attribute(name) else {
                return Ok(defaults);
            };
            let values = parse_number_list(text, name).map_err(|m| self.error(key, m))?;
            if values.len() > defaults.len() {
                let message = format!(
                    "attribute '{name}': expected at most {} numbers, got {}",
                    defaults.len(),
                    values.len()
                );
                return Err(self.error(key, message));
            }
            let mut filled = defaults;
            filled[..values.len()].copy_from_slice(&values);
            Ok(filled)
        };
        let time = match key.attribute("time") {
            Some(text) => parse_numbers::<1>(text, "time").map_err(|m| self.error(key, m))?[0],
            None => 0.0,
        };
        // qpos over qpos0, or qpos0 itself (not normalised again)
        let q = if key.has_attribute("qpos") {
            let qpos = list("qpos", configuration_to_mujoco(model, &model.neutral()))?;
            self.configuration_from_mujoco(key, model, &qpos)
        } else {
            model.neutral()
        };
        let qvel = list("qvel", vec![0.0; model.nv])?;
        let v = velocity_from_mujoco(model, &q, &qvel);
        let ctrl = list("ctrl", vec![0.0; actuators])?;
        let act = list("act", vec![0.0; model.na()])?;
        let initial = plastic_to_mujoco(model, model.initial_plastic());
        let plastic = plastic_from_mujoco(model, list("plastic", initial)?);
        for name in ["mpos", "mquat"] {
            if key.attribute(name).is_some() {
                model.warnings.push(format!(
                    "{}: attribute '{name}' not read (robodyn models no mocap bodies)",
                    self.location(key)
                ));
            }
        }
        Ok(Keyframe {
            name: key.attribute("name").unwrap_or("").to_string(),
            time,
            q,
            v,
            ctrl: DVector::from_vec(ctrl),
            act: DVector::from_vec(act),
            plastic: DVector::from_vec(plastic),
        })
    }

    /// MuJoCo's qpos in robodyn's layout: each quaternion `[w, x, y, z]` normalised and turned
    /// to `[x, y, z, w]`; a zero quaternion is the identity, as in MuJoCo, with a warning.
    fn configuration_from_mujoco(
        &self,
        key: Node<'a, 'a>,
        model: &mut Model,
        qpos: &[f64],
    ) -> DVector<f64> {
        let mut q = DVector::from_column_slice(qpos);
        for i in 1..model.nbodies() {
            let Some(offset) = model.joints()[i].quaternion_offset() else {
                continue;
            };
            let start = model.q_range(i).start + offset;
            let [w, x, y, z] = [0, 1, 2, 3].map(|k| qpos[start + k]);
            let quaternion = Quaternion::new(w, x, y, z);
            let unit =
                UnitQuaternion::try_new(quaternion, f64::MIN_POSITIVE).unwrap_or_else(|| {
                    model.warnings.push(format!(
                    "{}: the quaternion of joint '{}' in 'qpos' is zero; taken as the identity, \
                     as MuJoCo takes it",
                    self.location(key),
                    model.joint_names[i]
                ));
                    UnitQuaternion::identity()
                });
            q.as_mut_slice()[start..start + 4].copy_from_slice(unit.coords.as_slice());
        }
        q
    }
}

/// Robodyn's configuration `q` in MuJoCo's qpos layout: each quaternion turned to `[w, x, y, z]`.
fn configuration_to_mujoco(model: &Model, q: &DVector<f64>) -> Vec<f64> {
    let mut qpos = q.as_slice().to_vec();
    for i in 1..model.nbodies() {
        if let Some(offset) = model.joints()[i].quaternion_offset() {
            let start = model.q_range(i).start + offset;
            qpos[start..start + 4].rotate_right(1);
        }
    }
    qpos
}

/// A plastic state in MuJoCo's layout: each ball's reference quaternion turned to
/// `[w, x, y, z]`.
fn plastic_to_mujoco(model: &Model, mut plastic: Vec<f64>) -> Vec<f64> {
    for start in ball_references(model) {
        plastic[start..start + 4].rotate_right(1);
    }
    plastic
}

/// MuJoCo's plastic state in robodyn's layout: each ball's reference quaternion normalised
/// (where not zero) and turned to `[x, y, z, w]`.
fn plastic_from_mujoco(model: &Model, mut plastic: Vec<f64>) -> Vec<f64> {
    for start in ball_references(model) {
        let quaternion = &mut plastic[start..start + 4];
        let norm = quaternion.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm > 0.0 {
            quaternion.iter_mut().for_each(|x| *x /= norm);
        }
        quaternion.rotate_left(1);
    }
    plastic
}

/// Where each plastic ball's reference quaternion starts in the plastic state.
fn ball_references(model: &Model) -> Vec<usize> {
    let ball = |slot| matches!(slot, PlasticSlot::Joint(i) if model.joints()[i].nq() == 4);
    model
        .plastic_slots()
        .filter(|(slot, _)| ball(*slot))
        .map(|(_, start)| start)
        .collect()
}

/// MuJoCo's qvel in robodyn's layout at configuration `q`: a free joint's linear velocity
/// turned from world axes into its body's, `v_body = Rᵀ v_world`; every other entry as it is.
fn velocity_from_mujoco(model: &Model, q: &DVector<f64>, qvel: &[f64]) -> DVector<f64> {
    let mut v = DVector::from_column_slice(qvel);
    for i in (1..model.nbodies()).filter(|&i| model.joints()[i].kind() == "free") {
        let (iq, iv) = (model.q_range(i).start, model.v_range(i).start);
        let [x, y, z, w] = [3, 4, 5, 6].map(|k| q[iq + k]);
        let rotation = UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z));
        let world = Vector3::new(qvel[iv], qvel[iv + 1], qvel[iv + 2]);
        let body = rotation.inverse_transform_vector(&world);
        v.as_mut_slice()[iv..iv + 3].copy_from_slice(body.as_slice());
    }
    v
}
