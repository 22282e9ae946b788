//! DH tables (the ECE 470 notes' convention is the modified one): transforms, and the same robots as URDF.

mod common;

use common::{assert_close, CLOSED_FORM_TOLERANCE};
use robodyn::algo::*;
use robodyn::io::{bundled_model, load_dh_file, load_dh_str};
use robodyn::Data;

/// Agreement between a DH model and the URDF written from the same numbers (the URDF stores
/// angles with 10 significant digits).
const SAME_ROBOT_TOLERANCE: f64 = 1e-9;

/// The ECE 470 notes' 2-link planar arm, modified DH: frames {1}, {2} and the tool frame {3}.
const PLANAR2: &str = r#"
name = "planar2_dh"
convention = "modified"
gravity = [0.0, -9.81, 0.0]
tool = { xyz = [0.5, 0.0, 0.0] }

[[joint]]
name = "joint1"
type = "revolute"
a = 0.0
alpha = 0.0
d = 0.0
theta = 0.0
mass = 2.0
com = [1.0, 0.0, 0.0]   # link 1's point mass, at joint 2

[[joint]]
name = "joint2"
type = "revolute"
a = 1.0
alpha = 0
d = 0
theta = 0
mass = 1.0
com = [0.5, 0.0, 0.0]   # link 2's point mass, at the tool
"#;

fn pose_of(
    model: &robodyn::Model,
    data: &mut Data,
    q: &[f64],
    frame: &str,
) -> nalgebra::Matrix4<f64> {
    frame_pose(model, data, q, model.frame_index(frame).unwrap())
        .unwrap()
        .to_homogeneous()
}

#[test]
fn seed_001_planar_arm_transforms_and_dynamics() {
    let model = load_dh_str(PLANAR2, "planar2.toml").unwrap();
    let reference = bundled_model("planar2", false).unwrap();
    let (mut data, mut reference_data) = (Data::new(&model), Data::new(&reference));
    let (l1, l2) = (1.0, 0.5);
    for q in [[0.3_f64, -0.7], [1.2, 2.1], [-2.5, 0.4]] {
        let (c1, s1, c2, s2) = (q[0].cos(), q[0].sin(), q[1].cos(), q[1].sin());
        // the ECE 470 notes: ⁰₁T = Rz(θ1), ¹₂T = [Rz(θ2), (l1, 0, 0)], ²₃T = [1, (l2, 0, 0)]
        let t01 = nalgebra::Matrix4::new(
            c1, -s1, 0.0, 0.0, s1, c1, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        );
        let t12 = nalgebra::Matrix4::new(
            c2, -s2, 0.0, l1, s2, c2, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        );
        let t23 = nalgebra::Matrix4::new(
            1.0, 0.0, 0.0, l2, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        );
        assert_close(
            "⁰₁T",
            pose_of(&model, &mut data, &q, "joint1").as_slice(),
            t01.as_slice(),
            CLOSED_FORM_TOLERANCE,
        );
        assert_close(
            "⁰₂T",
            pose_of(&model, &mut data, &q, "joint2").as_slice(),
            (t01 * t12).as_slice(),
            CLOSED_FORM_TOLERANCE,
        );
        let tool = pose_of(&model, &mut data, &q, "tool");
        assert_close(
            "⁰₃T",
            tool.as_slice(),
            (t01 * t12 * t23).as_slice(),
            CLOSED_FORM_TOLERANCE,
        );
        // the same arm as the bundled URDF
        let (v, a) = ([0.4, -1.0], [0.3, 0.8]);
        let tau = rnea(&model, &mut data, &q, &v, &a, None).unwrap().clone();
        let expected = rnea(&reference, &mut reference_data, &q, &v, &a, None).unwrap();
        assert_close(
            "τ",
            tau.as_slice(),
            expected.as_slice(),
            CLOSED_FORM_TOLERANCE,
        );
    }
}

#[test]
fn seed_001_prismatic_row() {
    // the ECE 470 notes' table, row ¹₂T: α = 0, a = 0, θ = 90°, d = q2
    let text = r#"
        convention = "modified"
        angle_unit = "degree"
        [[joint]]
        type = "prismatic"
        a = 0
        alpha = 0
        d = 0
        theta = 90
        mass = 1
    "#;
    let model = load_dh_str(text, "row.toml").unwrap();
    let mut data = Data::new(&model);
    let pose = pose_of(&model, &mut data, &[0.25], "joint1");
    let expected = nalgebra::Matrix4::new(
        0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.25, 0.0, 0.0, 0.0, 1.0,
    );
    assert_close(
        "Rz(90°) Tz(q)",
        pose.as_slice(),
        expected.as_slice(),
        CLOSED_FORM_TOLERANCE,
    );
}

#[test]
fn ur5_dh_table_is_the_bundled_ur5() {
    let path = format!("{}/../../models/ur5_dh.toml", env!("CARGO_MANIFEST_DIR"));
    let model = load_dh_file(std::path::Path::new(&path)).unwrap();
    let reference = bundled_model("ur5", false).unwrap();
    let (mut data, mut reference_data) = (Data::new(&model), Data::new(&reference));
    let mut rng = common::rng();
    for _ in 0..5 {
        let q = reference.random_configuration(&mut rng);
        let (v, a) = (
            common::random_vector(&mut rng, 6),
            common::random_vector(&mut rng, 6),
        );
        let (q, v, a) = (q.as_slice(), v.as_slice(), a.as_slice());
        // DH frame 6 is the URDF's tool0
        let tool = pose_of(&model, &mut data, q, "tool");
        assert_close(
            "tool",
            tool.as_slice(),
            pose_of(&reference, &mut reference_data, q, "tool0").as_slice(),
            SAME_ROBOT_TOLERANCE,
        );
        let m = crba(&model, &mut data, q).unwrap().clone();
        assert_close(
            "M",
            m.as_slice(),
            crba(&reference, &mut reference_data, q).unwrap().as_slice(),
            SAME_ROBOT_TOLERANCE,
        );
        let tau = rnea(&model, &mut data, q, v, a, None).unwrap().clone();
        let expected = rnea(&reference, &mut reference_data, q, v, a, None).unwrap();
        assert_close(
            "τ",
            tau.as_slice(),
            expected.as_slice(),
            SAME_ROBOT_TOLERANCE,
        );
    }
}

#[test]
fn dh_errors_name_the_file_and_the_key() {
    let row = "[[joint]]\ntype = \"revolute\"\na = 0\nalpha = 0\nd = 0\ntheta = 0\n";
    let cases = [
        ("convention = \"modified\"\n[[joint]\n".to_string(), "malformed TOML"),
        (format!("convention = \"sideways\"\n{row}"), "'convention': expected \"standard\" or \"modified\""),
        (format!("convention = \"modified\"\n{row}alpah = 1\n"), "[[joint]] 1: unknown key 'alpah'"),
        ("convention = \"modified\"\n[[joint]]\ntype = \"revolute\"\nalpha = 0\nd = 0\ntheta = 0\n".to_string(), "[[joint]] 1: missing key 'a'"),
        (format!("convention = \"modified\"\n{row}type2 = 1\n"), "unknown key 'type2'"),
        (format!("convention = \"modified\"\n{}", row.replace("revolute", "screw")), "'type': expected \"revolute\" or \"prismatic\""),
        (format!("convention = \"modified\"\n{row}inertia = [1, 1, -1, 0, 0, 0]\nmass = 1\n"), "positive semi-definite"),
        (format!("convention = \"modified\"\n{row}com = [1, 2]\n"), "'com': expected an array of 3 numbers"),
        ("convention = \"modified\"\n".to_string(), "expected [[joint]] rows"),
    ];
    for (text, expected) in cases {
        let message = load_dh_str(&text, "robot.toml").unwrap_err().to_string();
        assert!(
            message.contains(expected),
            "for:\n{text}\ngot: {message}\nexpected: {expected}"
        );
        assert!(
            message.starts_with("robot.toml") || message.starts_with("DH table"),
            "{message}"
        );
    }
}
