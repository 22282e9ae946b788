//! Shared helpers of the integration tests: the models they run on and the tolerances.
#![allow(dead_code)]

pub mod constraints;

use nalgebra::{DMatrix, DVector};
use rand::{rngs::StdRng, Rng, SeedableRng};
use robodyn::algo::{jacobian, Reference};
use robodyn::io::{bundled_model, load_urdf_str, LoadOptions};
use robodyn::{Data, Model};

/// Identities between exact algorithms (M from RNEA, ABA∘RNEA, ...), relative to the magnitude.
pub const IDENTITY_TOLERANCE: f64 = 1e-10;
/// Closed forms from the lecture notes.
pub const CLOSED_FORM_TOLERANCE: f64 = 1e-12;
/// Central finite differences with step `FD_STEP`.
pub const FD_TOLERANCE: f64 = 1e-6;
pub const FD_STEP: f64 = 1e-6;

/// A branching tree exercising every joint type: a free base, a spherical shoulder, revolute and
/// prismatic joints about oblique axes, fixed links merged with offsets and rotated inertials.
pub const TREE_URDF: &str = r#"<robot name="tree">
  <link name="base"><inertial><origin xyz="0.1 0 0.05" rpy="0.1 0.2 0.3"/><mass value="4"/>
    <inertia ixx="0.3" ixy="0.01" ixz="0.02" iyy="0.25" iyz="0.03" izz="0.2"/></inertial></link>
  <joint name="ball" type="spherical"><parent link="base"/><child link="arm"/>
    <origin xyz="0.2 0.1 0.3" rpy="0.3 -0.2 0.5"/></joint>
  <link name="arm"><inertial><origin xyz="0 0 0.2" rpy="0 0.4 0"/><mass value="1.5"/>
    <inertia ixx="0.05" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.01"/></inertial></link>
  <joint name="elbow" type="revolute"><parent link="arm"/><child link="forearm"/>
    <origin xyz="0 0 0.4" rpy="0 0 0.7"/><axis xyz="1 1 0"/><limit lower="-2" upper="2" effort="10" velocity="3"/></joint>
  <link name="forearm"><inertial><origin xyz="0.1 0 0.1"/><mass value="1"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.02" iyz="0" izz="0.005"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="forearm"/><child link="finger"/>
    <origin xyz="0.1 0.2 0" rpy="0.5 0 0"/><axis xyz="0 0.6 0.8"/><limit lower="-0.5" upper="0.5" effort="10" velocity="1"/></joint>
  <link name="finger"><inertial><origin xyz="0 0.05 0"/><mass value="0.3"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/></inertial></link>
  <joint name="tip_fixed" type="fixed"><parent link="finger"/><child link="tip"/>
    <origin xyz="0 0.1 0.02" rpy="0 0 1"/></joint>
  <link name="tip"><inertial><origin xyz="0.01 0 0"/><mass value="0.1"/>
    <inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.0001"/></inertial></link>
  <joint name="leg" type="continuous"><parent link="base"/><child link="thigh"/>
    <origin xyz="-0.2 0 -0.1" rpy="0 0.3 0"/><axis xyz="0 1 0"/></joint>
  <link name="thigh"><inertial><origin xyz="0 0 -0.2"/><mass value="2"/>
    <inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.004"/></inertial></link>
  <joint name="knee" type="revolute"><parent link="thigh"/><child link="shin"/>
    <origin xyz="0 0 -0.4"/><axis xyz="0 1 0"/><limit lower="-2" upper="0" effort="10" velocity="3"/></joint>
  <link name="shin"><inertial><origin xyz="0 0 -0.2"/><mass value="1"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.002"/></inertial></link>
</robot>"#;

/// The models every identity runs on: the bundled ones (fixed and floating base) and the tree.
pub fn test_models() -> Vec<(&'static str, Model)> {
    let mut tree =
        load_urdf_str(TREE_URDF, "tree.urdf", LoadOptions::floating(true)).expect("tree loads");
    // rotor inertia on a few joints, so armature is checked everywhere
    tree.armature[6] = 0.05;
    tree.armature[9] = 0.02;
    let mut ur5_armature = bundled_model("ur5", false).unwrap();
    ur5_armature.armature.fill(0.1);
    // the UR5's base link is massless: floating, it needs a mass or its base could spin freely
    let mut ur5_floating = bundled_model("ur5", true).unwrap();
    ur5_floating.inertias[1] = robodyn::spatial::Inertia::from_com(
        4.0,
        &robodyn::spatial::Vec3::new(0.0, 0.0, 0.02),
        &robodyn::spatial::Mat3::from_diagonal_element(0.01),
    );
    vec![
        ("ur5", bundled_model("ur5", false).unwrap()),
        ("ur5 floating", ur5_floating),
        ("ur5 armature", ur5_armature),
        ("planar2", bundled_model("planar2", false).unwrap()),
        ("pendulum", bundled_model("pendulum", false).unwrap()),
        ("tree", tree),
    ]
}

/// The test model called `name`.
pub fn test_model(name: &str) -> Model {
    let mut models = test_models().into_iter();
    models.find(|(model, _)| *model == name).unwrap().1
}

/// `model` as if its bodies were not in depth-first order (`subtree_dof_end` cleared): the
/// algorithms with two forms (CRBA) take their world-coordinate one.
pub fn not_depth_first(model: &Model) -> Model {
    model.without_subtree_order()
}

pub fn rng() -> StdRng {
    StdRng::seed_from_u64(2026)
}

/// A vector of `n` uniform values in [-1, 1].
pub fn random_vector<R: Rng>(rng: &mut R, n: usize) -> nalgebra::DVector<f64> {
    nalgebra::DVector::from_fn(n, |_, _| rng.random_range(-1.0..1.0))
}

/// Asserts `|a - b| <= tol * max(1, |b|)` entry by entry.
pub fn assert_close(label: &str, a: &[f64], b: &[f64], tol: f64) {
    assert_eq!(a.len(), b.len(), "{label}: lengths differ");
    let scale = b.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= tol * scale,
            "{label}: entry {k}: {x} vs {y} (difference {:e}, tolerance {:e})",
            (x - y).abs(),
            tol * scale
        );
    }
}

/// J at q ⊕ h q̇, for finite differences along a motion.
pub fn jacobian_along(
    model: &Model,
    data: &mut Data,
    q: &DVector<f64>,
    v: &DVector<f64>,
    h: f64,
    frame: usize,
    reference: Reference,
) -> DMatrix<f64> {
    let moved = displaced(model, q, &(v * h));
    jacobian(model, data, moved.as_slice(), frame, reference)
        .unwrap()
        .clone()
}

/// q ⊕ step, on the joints' Lie groups.
pub fn displaced(model: &Model, q: &DVector<f64>, step: &DVector<f64>) -> DVector<f64> {
    let mut moved = DVector::zeros(model.nq);
    model
        .integrate(q.as_slice(), step.as_slice(), moved.as_mut_slice())
        .unwrap();
    moved
}

/// h times the k-th unit vector of length n.
pub fn unit_step(n: usize, k: usize, h: f64) -> DVector<f64> {
    DVector::from_fn(n, |i, _| if i == k { h } else { 0.0 })
}

/// Random (q, v, a) for a model.
pub fn state(
    model: &Model,
    rng: &mut rand::rngs::StdRng,
) -> (DVector<f64>, DVector<f64>, DVector<f64>) {
    (
        model.random_configuration(rng),
        random_vector(rng, model.nv),
        random_vector(rng, model.nv),
    )
}
