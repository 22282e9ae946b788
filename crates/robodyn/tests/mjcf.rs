//! MJCF: the tree, orientations in MuJoCo's default degrees, classes, errors with element and line.

use robodyn::algo::frame_pose;
use robodyn::io::load_mjcf_str;
use robodyn::spatial::Transform;
use robodyn::{Data, Joint, Model};

/// The placement of the frame `name` at the model's neutral configuration.
fn neutral_pose(model: &Model, name: &str) -> Transform {
    let mut data = Data::new(model);
    let q = model.neutral();
    frame_pose(
        model,
        &mut data,
        q.as_slice(),
        model.frame_index(name).unwrap(),
    )
    .unwrap()
}

const ARM: &str = r#"<mujoco model="arm">
  <default>
    <joint axis="0 1 0" armature="0.5"/>
    <default class="slider"><joint type="slide" axis="1 0 0"/></default>
  </default>
  <worldbody>
    <body name="upper" pos="0 0 1" axisangle="0 0 1 90">
      <inertial pos="0 0 -0.2" mass="1" diaginertia="0.01 0.01 0.001"/>
      <joint name="shoulder"/>
      <body name="lower" pos="0 0 -0.4">
        <inertial pos="0 0 0" mass="0.5" diaginertia="0.001 0.001 0.001"/>
        <joint name="slide" class="slider" range="-0.1 0.1"/>
        <site name="tip" pos="0 0 -0.3"/>
      </body>
    </body>
    <body name="free_box" pos="1 0 0"><freejoint/><inertial mass="1" diaginertia="1 1 1"/></body>
  </worldbody>
  <actuator><motor joint="shoulder"/></actuator>
</mujoco>"#;

#[test]
fn tree_classes_and_degrees() {
    let model = load_mjcf_str(ARM, "arm.xml").unwrap();
    assert_eq!(
        model.joint_names[1..],
        ["shoulder", "slide", "free_box_joint0"]
    );
    assert_eq!(
        model.joints()[1],
        Joint::Revolute {
            axis: nalgebra::Vector3::y()
        }
    );
    assert_eq!(
        model.joints()[2],
        Joint::Prismatic {
            axis: nalgebra::Vector3::x()
        }
    );
    assert_eq!(model.joints()[3], Joint::Free);
    assert_eq!(model.armature.as_slice()[..2], [0.5, 0.5]);
    assert_eq!(
        (model.lower_position_limit[1], model.upper_position_limit[1]),
        (-0.1, 0.1)
    );
    // "90" is degrees by default: the upper arm's x axis points along world y
    let upper = neutral_pose(&model, "upper");
    let pose = upper.to_homogeneous();
    assert!(
        (pose[(1, 0)] - 1.0).abs() < 1e-12 && (pose[(2, 3)] - 1.0).abs() < 1e-12,
        "{pose}"
    );
    let tip = neutral_pose(&model, "tip");
    assert!((tip.translation - nalgebra::Vector3::new(0.0, 0.0, 0.3)).norm() < 1e-12);
    // the actuator section is reported, not read
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("<actuator>") && w.contains("not read")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn neutral_is_mujocos_qpos0() {
    // a free joint at its body's pose in the file, hinges and slides at their ref
    let model = load_mjcf_str(
        r#"<mujoco><worldbody>
          <body name="base" pos="0.5 -1 2" axisangle="0 0 1 90"><freejoint/>
            <inertial mass="1" diaginertia="1 1 1"/>
            <body name="link" pos="1 0 0"><joint name="hinge" axis="0 0 1" ref="30"/>
              <inertial mass="1" diaginertia="1 1 1"/>
              <body name="tip" pos="1 0 0"><joint name="slide" type="slide" ref="0.25"/>
                <inertial mass="1" diaginertia="1 1 1"/>
                <body name="ball"><joint type="ball"/><inertial mass="1" diaginertia="1 1 1"/>
                </body>
              </body>
            </body>
          </body>
        </worldbody></mujoco>"#,
        "reference.xml",
    )
    .unwrap();
    let half = std::f64::consts::FRAC_1_SQRT_2;
    let expected = [
        0.5,
        -1.0,
        2.0,
        0.0,
        0.0,
        half,
        half,               // free: the body's pose
        30f64.to_radians(), // hinge: its ref
        0.25,               // slide: its ref
        0.0,
        0.0,
        0.0,
        1.0, // ball: the identity
    ];
    let q = model.neutral();
    for (k, (a, b)) in q.iter().zip(expected).enumerate() {
        assert!((a - b).abs() < 1e-15, "q[{k}] = {a}, expected {b}");
    }
    // at q = ref every body is where the file puts it
    let tip = neutral_pose(&model, "tip");
    let expected_tip = nalgebra::Vector3::new(0.5, 1.0, 2.0);
    assert!((tip.translation - expected_tip).norm() < 1e-12, "{tip:?}");
}

#[test]
fn errors_name_element_and_line() {
    let cases = [
        ("<mujoco><worldbody>\n<body name='x'><geom type='mesh' mesh='m'/></body></worldbody></mujoco>", "<body name='x'>/<geom> (line 2): attribute 'mesh': no <mesh name='m'> in the <asset>s"),
        ("<mujoco><compiler angle='grad'/></mujoco>", "attribute 'angle'"),
        ("<mujoco><worldbody><body name='x'><body name='y'><freejoint/><inertial mass='1' diaginertia='1 1 1'/></body></body></worldbody></mujoco>", "a free joint must be"),
        ("<mujoco><worldbody><body name='x'><inertial mass='-1' diaginertia='1 1 1'/></body></worldbody></mujoco>", "mass >= 0"),
        ("<mujoco><worldbody><body", "malformed XML"),
    ];
    for (text, expected) in cases {
        let message = load_mjcf_str(text, "bad.xml").unwrap_err().to_string();
        assert!(
            message.contains(expected) && message.starts_with("bad.xml"),
            "got: {message}\nexpected: {expected}"
        );
    }
}

#[test]
fn inertia_from_a_sphere_and_a_box_geom() {
    // a sphere of radius r and a box of half-sides a, b, c at density ρ:
    // m = ρ 4/3 π r³, I = 2/5 m r²; m = 8 ρ abc, I_xx = m (b² + c²) / 3
    let text = "<mujoco><worldbody>
        <body name='ball'><joint/><geom type='sphere' size='0.1' density='2000'/></body>
        <body name='brick'><joint/><geom type='box' size='0.1 0.2 0.3' pos='1 0 0'/></body>
      </worldbody></mujoco>";
    let model = load_mjcf_str(text, "geoms.xml").unwrap();
    let ball = &model.inertias[1];
    let mass = 2000.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.1f64.powi(3);
    assert!((ball.mass - mass).abs() < 1e-12);
    assert!((ball.rotational[(0, 0)] - 0.4 * mass * 0.01).abs() < 1e-14);
    let brick = &model.inertias[2];
    let mass = 8.0 * 1000.0 * 0.1 * 0.2 * 0.3;
    assert!((brick.mass - mass).abs() < 1e-12);
    assert!((brick.com() - nalgebra::Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-14);
    // about the body origin: I_xx is unchanged by a shift along x
    assert!((brick.rotational[(0, 0)] - mass * (0.04 + 0.09) / 3.0).abs() < 1e-12);
}

#[test]
fn each_compiler_element_changes_only_what_it_sets() {
    // the second <compiler> must not reset the angle unit to degrees
    let text = "<mujoco><compiler angle='radian'/><compiler eulerseq='zyx'/><worldbody>
        <body name='turned' axisangle='0 0 1 1.5707963267948966'/></worldbody></mujoco>";
    let model = load_mjcf_str(text, "compilers.xml").unwrap();
    let pose = neutral_pose(&model, "turned").to_homogeneous();
    // a quarter turn about z: the body's x axis along world y
    assert!((pose[(1, 0)] - 1.0).abs() < 1e-12, "{pose}");
}
