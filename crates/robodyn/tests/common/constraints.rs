//! The constraint fixtures of the constrained-dynamics tests: every kind on the branching tree,
//! a polynomial coupling on the UR5, and a closed four-bar.

use super::*;
use nalgebra::DVector;
use robodyn::algo::{constraint_jacobian, ConstraintData};
use robodyn::constraint::{
    Attachment, Constraint, ConstraintKind, ConstraintReference, ConstraintSet,
};
use robodyn::spatial::{Transform, Vec3};

pub fn body_of(model: &Model, joint: &str) -> usize {
    model.joint_names.iter().position(|n| n == joint).unwrap()
}

pub fn at(model: &Model, frame: &str, offset: [f64; 3]) -> Attachment {
    Attachment {
        frame: Some(model.frame_index(frame).unwrap()),
        placement: Transform::from_translation(&Vec3::from(offset)),
    }
}

pub fn constraint(kind: ConstraintKind, reference: ConstraintReference) -> Constraint {
    Constraint { kind, reference }
}

/// Every kind on the branching floating tree: a point held to the world, a masked frame held in
/// local axes, a loop between two moving points, a distance and a joint coupling.
pub fn tree_constraints(model: &Model) -> Vec<Constraint> {
    use ConstraintReference::{Local, World};
    let mut mask = [true; 6];
    mask[4] = false;
    let offset_to = Attachment {
        frame: None,
        placement: Transform::from_translation(&Vec3::new(0.3, -0.2, 0.1)),
    };
    vec![
        constraint(
            ConstraintKind::Point {
                first: at(model, "tip", [0.01, 0.02, 0.0]),
                second: Some(offset_to),
            },
            World,
        ),
        constraint(
            ConstraintKind::Frame {
                first: at(model, "shin", [0.0, 0.0, -0.3]),
                second: None,
                mask,
            },
            Local,
        ),
        constraint(
            ConstraintKind::Point {
                first: at(model, "forearm", [0.1, 0.0, 0.0]),
                second: Some(at(model, "thigh", [0.0, 0.05, -0.1])),
            },
            Local,
        ),
        constraint(
            ConstraintKind::Distance {
                first: at(model, "finger", [0.0, 0.0, 0.0]),
                second: at(model, "base", [0.1, 0.0, 0.0]),
                length: 0.5,
            },
            World,
        ),
    ]
}

/// A coupling of the UR5's wrist joints: w3 = 0.5 w1 + 0.2 w1² − 0.1 about references.
pub fn coupling(model: &Model) -> Constraint {
    constraint(
        ConstraintKind::Coupling {
            follower: body_of(model, "wrist_3_joint"),
            leader: Some(body_of(model, "wrist_1_joint")),
            polynomial: [-0.1, 0.5, 0.2, 0.0, 0.0],
            references: (0.3, -0.2),
        },
        ConstraintReference::World,
    )
}

pub fn cases() -> Vec<(&'static str, Model, Vec<Constraint>)> {
    let tree = test_model("tree");
    let tree_set = tree_constraints(&tree);
    let ur5 = test_model("ur5");
    let ur5_set = vec![coupling(&ur5)];
    vec![("tree", tree, tree_set), ("ur5", ur5, ur5_set)]
}

pub const FOUR_BAR_URDF: &str = r#"<robot name="four_bar">
  <link name="ground"/>
  <joint name="crank_joint" type="continuous"><parent link="ground"/><child link="crank"/>
    <axis xyz="0 1 0"/></joint>
  <link name="crank"><inertial><origin xyz="0.1 0 0"/><mass value="0.5"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="2e-3" iyz="0" izz="2e-3"/></inertial></link>
  <joint name="coupler_joint" type="continuous"><parent link="crank"/><child link="coupler"/>
    <origin xyz="0.2 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="coupler"><inertial><origin xyz="0.3 0 0"/><mass value="1.0"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="3e-2" iyz="0" izz="3e-2"/></inertial></link>
  <joint name="rocker_joint" type="continuous"><parent link="coupler"/><child link="rocker"/>
    <origin xyz="0.6 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="rocker"><inertial><origin xyz="0.25 0 0"/><mass value="0.8"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1.7e-2" iyz="0" izz="1.7e-2"/></inertial></link>
  <joint name="tip_joint" type="fixed"><parent link="rocker"/><child link="tip"/>
    <origin xyz="0.5 0 0"/></joint>
  <link name="tip"/>
</robot>"#;

/// The four-bar, its closure (the tip's x and z held at the ground pivot) and a configuration
/// that closes it, found by Newton's method on the coupler and rocker angles.
pub fn four_bar() -> (Model, ConstraintSet, DVector<f64>) {
    let options = robodyn::io::LoadOptions::floating(false);
    let model = robodyn::io::load_urdf_str(FOUR_BAR_URDF, "four_bar.urdf", options).unwrap();
    let pivot = Attachment {
        frame: None,
        placement: Transform::from_translation(&Vec3::new(0.6, 0.0, 0.0)),
    };
    let closure = ConstraintKind::Frame {
        first: at(&model, "tip", [0.0; 3]),
        second: Some(pivot),
        mask: [true, false, true, false, false, false],
    };
    let set = ConstraintSet::new(
        &model,
        vec![constraint(closure, ConstraintReference::World)],
    )
    .unwrap();
    let (mut data, mut c) = (Data::new(&model), ConstraintData::new(&model, &set));
    let mut q = DVector::from_vec(vec![1.2, -1.6, -1.4]);
    for _ in 0..50 {
        constraint_jacobian(&model, &mut data, &mut c, &set, q.as_slice()).unwrap();
        let free = c.jacobian.columns(1, 2).into_owned();
        let step = free.lu().solve(&c.error).unwrap();
        q[1] -= step[0];
        q[2] -= step[1];
    }
    constraint_jacobian(&model, &mut data, &mut c, &set, q.as_slice()).unwrap();
    assert!(c.error.amax() < 1e-14, "the four-bar closes: {}", c.error);
    (model, set, q)
}
