//! A model as bytes and back: every field, edits made after loading included, for pickling and
//! for sending a model to worker processes.
//!
//! Layout: the 8-byte tag `robodyn\0`, the format number (u32, little-endian), the length (u16)
//! and text of the robodyn version that wrote it, then the model in postcard's compact serde
//! encoding. The format number changes whenever `Model`'s fields do; bytes of another format are
//! refused with both versions named. Decoded bytes are checked for a consistent tree before
//! they become a model, so damaged bytes are an error, never a crash later.

use crate::error::{Error, Result};
use crate::model::Model;
use crate::soft::wrap::Surface;

/// What every snapshot starts with.
const TAG: &[u8; 8] = b"robodyn\0";

/// The snapshot format: bumped whenever `Model` (or a type inside it) changes its fields.
pub const MODEL_FORMAT: u32 = 6;

/// The model as bytes.
pub fn model_to_bytes(model: &Model) -> Vec<u8> {
    let version = env!("CARGO_PKG_VERSION").as_bytes();
    let mut bytes = Vec::with_capacity(1024);
    bytes.extend_from_slice(TAG);
    bytes.extend_from_slice(&MODEL_FORMAT.to_le_bytes());
    // a version string is a few bytes: its length fits in a u16
    bytes.extend_from_slice(&(version.len() as u16).to_le_bytes());
    bytes.extend_from_slice(version);
    postcard::to_extend(model, bytes).expect("a model's fields all serialise")
}

/// The model of [`model_to_bytes`]; an error names what is wrong with bytes that are not one,
/// or come from an incompatible robodyn.
pub fn model_from_bytes(bytes: &[u8]) -> Result<Model> {
    let refuse = |message: String| Error::InvalidValue {
        argument: "bytes".into(),
        message,
    };
    let rest = bytes
        .strip_prefix(TAG)
        .ok_or_else(|| refuse("expected a robodyn model snapshot, got other bytes".into()))?;
    let (format, rest) =
        take::<4>(rest).ok_or_else(|| refuse("the snapshot is cut short".into()))?;
    let (length, rest) =
        take::<2>(rest).ok_or_else(|| refuse("the snapshot is cut short".into()))?;
    let length = u16::from_le_bytes(length) as usize;
    if rest.len() < length {
        return Err(refuse("the snapshot is cut short".into()));
    }
    let (version, payload) = rest.split_at(length);
    let version = String::from_utf8_lossy(version);
    let format = u32::from_le_bytes(format);
    if format != MODEL_FORMAT {
        return Err(refuse(format!(
            "this model was saved by robodyn {version} (model format {format}); robodyn {} reads \
             format {MODEL_FORMAT}: load the model from its file again",
            env!("CARGO_PKG_VERSION")
        )));
    }
    let mut model: Model = postcard::from_bytes(payload)
        .map_err(|e| refuse(format!("the snapshot (robodyn {version}) is damaged: {e}")))?;
    check_structure(&model)?;
    model.derive();
    Ok(model)
}

/// The first `N` bytes and the rest.
fn take<const N: usize>(bytes: &[u8]) -> Option<([u8; N], &[u8])> {
    let (head, rest) = bytes.split_first_chunk::<N>()?;
    Some((*head, rest))
}

/// Checks that the decoded fields make a tree the algorithms can index: one entry per body where
/// there should be, parents before children, coordinates laid out joint after joint, vectors of
/// length nq or nv, frames, visuals and mimics on existing bodies.
fn check_structure(model: &Model) -> Result<()> {
    let damaged = |message: String| Err(Error::model("model snapshot", message));
    let bodies = model.parent.len();
    let per_body = [
        ("joints", model.joints.len()),
        ("joint_names", model.joint_names.len()),
        ("body_names", model.body_names.len()),
        ("x_tree", model.x_tree.len()),
        ("inertias", model.inertias.len()),
        ("idx_q", model.idx_q.len()),
        ("idx_v", model.idx_v.len()),
        ("spring_yield", model.spring_yield.len()),
        ("actuator_gravcomp", model.actuator_gravcomp.len()),
    ];
    if bodies == 0 || model.parent[0] != 0 {
        return damaged("body 0 must be the world".into());
    }
    if let Some((name, length)) = per_body.iter().find(|(_, length)| *length != bodies) {
        return damaged(format!("{name} has {length} entries for {bodies} bodies"));
    }
    let (mut nq, mut nv) = (0, 0);
    for i in 0..bodies {
        if i > 0 && model.parent[i] >= i {
            return damaged(format!(
                "body {i}'s parent {} is not before it",
                model.parent[i]
            ));
        }
        if model.idx_q[i] != nq || model.idx_v[i] != nv {
            return damaged(format!("body {i}'s coordinates are out of place"));
        }
        nq += model.joints[i].nq();
        nv += model.joints[i].nv();
    }
    if (nq, nv) != (model.nq, model.nv) || model.dof_parent.len() != nv {
        return damaged(format!(
            "the joints have {nq} + {nv} coordinates, the model says {} + {}",
            model.nq, model.nv
        ));
    }
    let by_coordinate = [
        ("lower_position_limit", model.lower_position_limit.len(), nq),
        ("upper_position_limit", model.upper_position_limit.len(), nq),
        ("spring_reference", model.spring_reference.len(), nq),
        (
            "neutral_configuration",
            model.neutral_configuration.len(),
            nq,
        ),
        ("velocity_limit", model.velocity_limit.len(), nv),
        ("effort_limit", model.effort_limit.len(), nv),
        ("armature", model.armature.len(), nv),
        ("damping", model.damping.len(), nv),
        ("friction", model.friction.len(), nv),
        ("stiffness", model.stiffness.len(), nv),
        ("stiffness_poly", model.stiffness_poly.len(), nv),
        ("damping_poly", model.damping_poly.len(), nv),
    ];
    if let Some((name, length, expected)) = by_coordinate.iter().find(|(_, l, e)| l != e) {
        return damaged(format!("{name} has {length} entries, expected {expected}"));
    }
    if let Some(key) = model
        .keyframes
        .iter()
        .find(|k| (k.q.len(), k.v.len()) != (nq, nv))
    {
        return damaged(format!(
            "keyframe '{}' has {} + {} coordinates, expected {nq} + {nv}",
            key.name,
            key.q.len(),
            key.v.len()
        ));
    }
    let (nu, na, np) = (model.nu(), model.na(), model.nplastic());
    if let Some(key) = model
        .keyframes
        .iter()
        .find(|k| (k.ctrl.len(), k.act.len(), k.plastic.len()) != (nu, na, np))
    {
        return damaged(format!(
            "keyframe '{}' has {} controls, {} activations and {} plastic references, expected \
             {nu}, {na} and {np}",
            key.name,
            key.ctrl.len(),
            key.act.len(),
            key.plastic.len()
        ));
    }
    let bodies_named = model
        .frames
        .iter()
        .map(|f| f.body)
        .chain(model.visuals.iter().map(|v| v.body))
        .chain(model.mimics.iter().flat_map(|m| [m.joint, m.mimicked]))
        .chain(model.tendons.iter().flat_map(|t| {
            let sites = t.path.iter().filter_map(|p| match p {
                crate::model::PathPoint::Site { body, .. } => Some(*body),
                crate::model::PathPoint::Geom { side, .. } => side.map(|(body, _)| body),
                crate::model::PathPoint::Pulley { .. } => None,
            });
            t.joints.iter().map(|(body, _)| *body).chain(sites)
        }));
    let dof_parents_before = model
        .dof_parent
        .iter()
        .enumerate()
        .all(|(k, parent)| parent.is_none_or(|p| p < k));
    if bodies_named.into_iter().any(|body| body >= bodies) || !dof_parents_before {
        return damaged(
            "a frame, visual, mimic, tendon or coordinate refers to a missing one".into(),
        );
    }
    // a tendon wraps around a sphere or a cylinder of the model
    let wraps_around =
        |geom: &usize| (model.geoms.get(*geom)).is_some_and(|g| Surface::of(&g.shape).is_some());
    let wrapped = model.tendons.iter().flat_map(|t| &t.path);
    if wrapped
        .filter_map(|p| match p {
            crate::model::PathPoint::Geom { geom, .. } => Some(geom),
            _ => None,
        })
        .any(|geom| !wraps_around(geom))
    {
        return damaged("a tendon wraps around a geom that is not a sphere or cylinder".into());
    }
    // a tendon's inertia is not negative, and none on a path around a geom (no J̇ there)
    let around_geom = |t: &crate::model::Tendon| {
        (t.path.iter()).any(|p| matches!(p, crate::model::PathPoint::Geom { .. }))
    };
    if let Some(tendon) = (model.tendons.iter())
        .find(|t| t.armature.is_nan() || t.armature < 0.0 || (t.armature > 0.0 && around_geom(t)))
    {
        return damaged(format!(
            "tendon '{}' has an armature below 0 or on a path around a geom",
            tendon.name
        ));
    }
    // a range the clamps use must be ordered (a loader never makes another)
    let ordered = |range: &Option<(f64, f64)>| range.is_none_or(|(low, high)| low <= high);
    if let Some(actuator) = model
        .actuators
        .iter()
        .find(|a| !(ordered(&a.ctrl_range) && ordered(&a.force_range) && ordered(&a.act_range)))
    {
        return damaged(format!(
            "actuator '{}' has a range whose lower end is above its upper",
            actuator.name
        ));
    }
    let declared = model.constraints.iter().map(|c| c.constraint.clone());
    if let Err(error) = crate::constraint::ConstraintSet::new(model, declared.collect()) {
        return damaged(format!(
            "a declared constraint does not fit the model: {error}"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::bundled_model;

    #[test]
    fn a_model_comes_back_with_its_edits() {
        let mut model = bundled_model("ur5", true).unwrap();
        model.armature.fill(0.1);
        model.gravity.z = -3.7;
        model.inertias[3].mass = 7.5;
        let back = model_from_bytes(&model_to_bytes(&model)).unwrap();
        assert_eq!(format!("{back:?}"), format!("{model:?}"));
    }

    #[test]
    fn other_bytes_and_other_formats_are_refused_by_name() {
        let bytes = model_to_bytes(&bundled_model("pendulum", false).unwrap());
        let message = |bytes: &[u8]| model_from_bytes(bytes).unwrap_err().to_string();
        assert!(message(b"not a model").contains("expected a robodyn model snapshot"));
        assert!(message(&bytes[..11]).contains("cut short"));
        let mut other = bytes.clone();
        other[8] = other[8].wrapping_add(1);
        assert!(message(&other).contains("model format"));
        assert!(message(&bytes[..bytes.len() - 3]).contains("damaged"));
        // a consistent encoding of an inconsistent tree
        let mut model = bundled_model("pendulum", false).unwrap();
        model.parent[1] = 5;
        assert!(message(&model_to_bytes(&model)).contains("not before it"));
        let mut model = bundled_model("pendulum", false).unwrap();
        model.armature = nalgebra::DVector::zeros(3);
        assert!(message(&model_to_bytes(&model)).contains("armature has 3 entries"));
        let mut model = bundled_model("pendulum", false).unwrap();
        model.keyframes.push(crate::model::Keyframe {
            name: "home".into(),
            time: 0.0,
            q: nalgebra::DVector::zeros(5),
            v: nalgebra::DVector::zeros(1),
            ctrl: nalgebra::DVector::zeros(0),
            act: nalgebra::DVector::zeros(0),
            plastic: nalgebra::DVector::zeros(0),
        });
        assert!(message(&model_to_bytes(&model)).contains("keyframe 'home' has 5 + 1"));
        let mut model = crate::io::load_mjcf_str(
            r#"<mujoco><worldbody><body><joint name="j"/><geom size="0.1"/></body></worldbody>
               <actuator><motor name="m" joint="j" ctrlrange="-1 1"/></actuator></mujoco>"#,
            "motor.xml",
        )
        .unwrap();
        model.actuators[0].ctrl_range = Some((1.0, -1.0));
        assert!(message(&model_to_bytes(&model)).contains("actuator 'm' has a range"));
        let mut model =
            crate::io::load_mjcf_str(crate::soft::tendons::tests::CORDS, "cords.xml").unwrap();
        model.tendons[1].armature = -0.5;
        let refused = message(&model_to_bytes(&model));
        assert!(refused.contains("tendon 'tendon1' has an armature below 0"));
    }
}
