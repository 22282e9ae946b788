//! MJCF: the tree, orientations in MuJoCo's default degrees, classes, errors with element and line.

use robodyn::algo::frame_pose;
use robodyn::io::load_mjcf_str;
use robodyn::soft::tendons::TendonKinematics;
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
    // the motor is read, on the shoulder's coordinate
    assert_eq!(model.nu(), 1);
    assert_eq!(model.actuators[0].coordinate, Some(0));
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

/// A turned free body with a ball joint and a hinge below it, two actuators, and three keys: one
/// moving, one with nothing (qpos0), one whose quaternions are not of unit norm.
const KEYED: &str = include_str!("../../../testdata/mjcf/keyframes.xml");

#[test]
fn keyframes_in_robodyns_coordinates() {
    let model = load_mjcf_str(KEYED, "keyframes.xml").unwrap();
    assert_eq!(model.keyframes.len(), 3);
    // MuJoCo's [x y z | w x y z] (normalised: w = 2 is the identity), then [w x y z] and the hinge
    let unnormalised = model.keyframe("unnormalised").unwrap();
    let q = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, -0.4];
    assert_eq!(unnormalised.q.as_slice(), &q);
    // a moving key: the free joint's linear velocity turned into its body's axes, the rest as given
    let moving = model.keyframe("moving").unwrap();
    assert_eq!(
        (moving.time, moving.ctrl.as_slice()),
        (1.5, &[0.5, -0.5][..])
    );
    assert_eq!(
        &moving.v.as_slice()[3..],
        &[0.3, -0.2, 1.0, 0.1, 0.2, 0.3, -2.0]
    );
    let speed = moving.v.rows(0, 3).norm();
    assert!((speed - (1.0f64 + 4.0 + 0.25).sqrt()).abs() < 1e-14);
    // a key with nothing holds qpos0 (the hinge at its ref, in degrees), no velocity, no control
    let empty = model.keyframe("qpos0").unwrap();
    assert_eq!(empty.q, model.neutral());
    assert_eq!(empty.q[11], 10f64.to_radians());
    assert!(empty.v.iter().chain(empty.ctrl.iter()).all(|x| *x == 0.0));
    assert_eq!(empty.ctrl.len(), 2);
    let unknown = model.keyframe("home").unwrap_err().to_string();
    assert!(
        unknown.contains("'home'") && unknown.contains("'moving'"),
        "{unknown}"
    );
}

#[test]
fn a_free_joints_velocity_turns_into_its_body_axes() {
    // the body turned 90° about z: v_body = Rᵀ v_world = (y, −x, z)
    let half = std::f64::consts::FRAC_1_SQRT_2;
    let qpos = format!("0 0 1 {half} 0 0 {half}");
    let text = KEYED.replace("0.1 0.2 1.3 0.9 0.1 -0.3 0.2", &qpos);
    let model = load_mjcf_str(&text, "keyframes.xml").unwrap();
    let v = &model.keyframes[0].v;
    let expected = [-2.0, -1.0, 0.5];
    assert!(
        (v.rows(0, 3) - nalgebra::Vector3::from(expected)).norm() < 1e-15,
        "{v}"
    );
    // the angular velocity is in the body's axes in both layouts
    assert_eq!(&v.as_slice()[3..6], &[0.3, -0.2, 1.0]);
}

#[test]
fn a_short_key_is_completed_and_a_long_one_refused_by_name() {
    // as in MuJoCo 4: the first entries given, the rest from qpos0 and zeros
    let text = KEYED.replace(
        "<key name=\"qpos0\"/>",
        r#"<key qpos="5 6 7" qvel="3" ctrl="1"/>"#,
    );
    let model = load_mjcf_str(&text, "keyframes.xml").unwrap();
    let (short, neutral) = (&model.keyframes[1], model.neutral());
    assert_eq!(&short.q.as_slice()[..3], &[5.0, 6.0, 7.0]);
    // (qpos0's quaternion normalised once more: equal to rounding)
    let rest = short.q.rows(3, 9) - neutral.rows(3, 9);
    assert!(rest.amax() < 1e-15, "{rest}");
    // (3, 0, 0) in world axes, turned into the body's
    assert!((short.v.rows(0, 3).norm() - 3.0).abs() < 1e-15);
    assert!(short.v.iter().skip(3).all(|x| *x == 0.0));
    assert_eq!(short.ctrl.as_slice(), &[1.0, 0.0]);
    for (attribute, wrong, expected) in [
        (
            "qpos",
            "qpos=\"0 0 1 1 0 0 0 1 0 0 0 0 9\"",
            "expected at most 12 numbers, got 13",
        ),
        (
            "qvel",
            "qvel=\"0 0 0 0 0 0 0 0 0 0 9\"",
            "expected at most 10 numbers, got 11",
        ),
        (
            "ctrl",
            "ctrl=\"1 2 3\"",
            "expected at most 2 numbers, got 3",
        ),
        ("time", "time=\"soon\"", "expected finite numbers"),
    ] {
        let text = KEYED.replace(
            "<key name=\"qpos0\"/>",
            &format!("<key name=\"bad\" {wrong}/>"),
        );
        let message = load_mjcf_str(&text, "keyframes.xml")
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("<key") && message.contains(attribute) && message.contains(expected),
            "{message}"
        );
    }
    // what robodyn does not model is a warning naming it
    let text = KEYED.replace("<key name=\"qpos0\"/>", r#"<key act="" mpos="0 0 0"/>"#);
    let model = load_mjcf_str(&text, "keyframes.xml").unwrap();
    let warned = |name: &str| {
        model
            .warnings
            .iter()
            .any(|w| w.contains(&format!("'{name}' not read")))
    };
    assert!(!warned("act") && warned("mpos") && !warned("mquat"));
}

#[test]
fn activation_dynamics_as_mujoco_compiles_and_integrates_them() {
    use robodyn::model::ActivationDynamics;
    let text = r#"<mujoco>
      <compiler angle="radian"/>
      <worldbody><body><joint name="j" axis="0 1 0" range="-1 3"/><geom size="0.1"/></body></worldbody>
      <actuator>
        <general joint="j" dyntype="integrator" actrange="-0.5 0.5"/>
        <motor joint="j"/>
        <general joint="j" dyntype="filter" dynprm="0.2" gainprm="3" actearly="true"/>
        <position joint="j" kp="4" timeconst="0.1"/>
        <intvelocity joint="j" kp="2" inheritrange="0.5"/>
        <cylinder joint="j" diameter="2" bias="1 2 3" timeconst="0.3"/>
        <damper joint="j" kv="5" ctrlrange="0 1"/>
      </actuator>
      <keyframe><key name="home" act="0.1 0.2"/></keyframe>
    </mujoco>"#;
    let model = load_mjcf_str(text, "act.xml").unwrap();
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let dynamics: Vec<_> = model.actuators.iter().map(|a| a.dynamics).collect();
    assert_eq!(
        dynamics,
        [
            ActivationDynamics::Integrator,
            ActivationDynamics::None,
            ActivationDynamics::Filter { time_constant: 0.2 },
            ActivationDynamics::FilterExact { time_constant: 0.1 },
            ActivationDynamics::Integrator,
            ActivationDynamics::Filter { time_constant: 0.3 },
            ActivationDynamics::None,
        ]
    );
    assert_eq!(model.na(), 5);
    // intvelocity inherits its activation's range; a cylinder's gain is its area π d²/4
    assert_eq!(model.actuators[4].act_range, Some((0.0, 2.0)));
    assert_eq!(model.actuators[5].gain[0], std::f64::consts::PI);
    assert_eq!(model.actuators[5].bias, [1.0, 2.0, 3.0]);
    assert_eq!(model.actuators[6].gain, [0.0, 0.0, -5.0]);
    let key = model.keyframe("home").unwrap();
    assert_eq!(key.act.as_slice(), [0.1, 0.2, 0.0, 0.0, 0.0]);

    // ẇ: u for an integrator, (u − w)/τ for a filter
    let ctrl = [200.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let act = [0.4, 0.5, 0.5, 0.0, 0.0];
    let mut rates = [0.0; 5];
    model.activation_rates(&ctrl, &act, &mut rates).unwrap();
    assert_eq!(rates[..3], [200.0, (1.0 - 0.5) / 0.2, (1.0 - 0.5) / 0.1]);
    // w₁: clamped to actrange; filterexact exactly
    let h = model.options.timestep;
    let mut next = act;
    model.advance_activations(&mut next, &rates, h);
    assert_eq!(next[0], 0.5);
    assert_eq!(next[1], 0.5 + h * rates[1]);
    let exact = 1.0 - 0.5 * (-h / 0.1f64).exp();
    assert!((next[2] - exact).abs() < 1e-15);
    // the force takes w₁ with actearly (the filter), else w (the position servo)
    let (q, v) = ([0.25], [0.0]);
    let force = |k: usize| {
        let mut tau = [0.0];
        let mut only = [0.0; 7];
        only[k] = ctrl[k];
        let mut w = [0.0; 5];
        let slot = model.actuators[..k]
            .iter()
            .filter(|a| a.has_activation())
            .count();
        w[slot] = act[slot];
        let mut without = model.clone();
        without.actuators = vec![model.actuators[k].clone()];
        let own = usize::from(model.actuators[k].has_activation());
        without
            .actuator_forces(
                (&q, &v),
                (&only[k..=k], &w[slot..slot + own]),
                &TendonKinematics::default(),
                &mut tau,
            )
            .unwrap();
        tau[0]
    };
    assert_eq!(force(2), 3.0 * next[1]);
    assert_eq!(force(3), 4.0 * (0.5 - 0.25));
    // what MuJoCo refuses
    for (from, to, expected) in [
        ("dynprm=\"0.2\"", "dynprm=\"0.2\" actdim=\"2\"", "'actdim'"),
        ("kv=\"5\" ctrlrange=\"0 1\"", "kv=\"5\"", "a damper needs"),
        (
            "actrange=\"-0.5 0.5\"",
            "actrange=\"0.5 -0.5\"",
            "'actrange'",
        ),
        ("timeconst=\"0.1\"", "timeconst=\"-0.1\"", "'timeconst'"),
    ] {
        let message = load_mjcf_str(&text.replace(from, to), "act.xml")
            .unwrap_err()
            .to_string();
        assert!(message.contains(expected), "{message}");
    }
    // a muscle keeps its activation's place, with a warning
    let muscle = text.replace("dyntype=\"filter\"", "dyntype=\"muscle\"");
    let model = load_mjcf_str(&muscle, "act.xml").unwrap();
    assert_eq!(model.na(), 5);
    assert!(model
        .warnings
        .iter()
        .any(|w| w.contains("dyntype 'muscle'")));
}

#[test]
fn actuators_on_hinges_with_gears_and_ranges() {
    let text = r#"<mujoco>
      <compiler angle="radian"/>
      <worldbody><body><joint name="j" axis="0 1 0" range="-1 3"/><geom size="0.1"/></body></worldbody>
      <actuator>
        <motor joint="j" gear="2" ctrlrange="-1 1"/>
        <position joint="j" kp="10" kv="2" inheritrange="0.5"/>
        <velocity joint="j" kv="3" forcerange="-1 1"/>
        <general joint="j" gaintype="affine" gainprm="1 2 3" biastype="affine" biasprm="4 5 6"/>
        <position joint="j" dampratio="1"/>
      </actuator>
    </mujoco>"#;
    let model = load_mjcf_str(text, "actuated.xml").unwrap();
    assert_eq!(model.nu(), 5);
    // inheritrange 0.5 of [−1, 3]: [0, 2] about the middle
    assert_eq!(model.actuators[1].ctrl_range, Some((0.0, 2.0)));
    // dampratio 1 on kp 1: k_v = 2 √(k_p I), I = 2/5 m r² of the sphere about its centre
    let mass = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.1f64.powi(3);
    let kv = 2.0 * (0.4 * mass * 0.01f64).sqrt();
    assert!((model.actuators[4].bias[2] + kv).abs() < 1e-14);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let (q, v) = ([0.5], [0.25]);
    let mut tau = [0.0];
    let one = |k: usize, u: f64| {
        let mut ctrl = [0.0; 5];
        ctrl[k] = u;
        let mut tau = [0.0];
        model
            .actuator_forces(
                (&q, &v),
                (&ctrl, &[]),
                &TendonKinematics::default(),
                &mut tau,
            )
            .unwrap();
        tau[0]
    };
    // motor: g f with u clamped to 1
    assert_eq!(one(0, 5.0) - one(0, 0.0), 2.0);
    // position: k_p (u − q) − k_v q̇, u clamped to 2, plus the zero controls' biases of the others
    let others = one(1, 0.0) - (10.0 * (0.0 - 0.5) - 2.0 * 0.25);
    assert!((one(1, 9.0) - others - (10.0 * (2.0 - 0.5) - 2.0 * 0.25)).abs() < 1e-14);
    // general: (1 + 2 l + 3 l̇) u + (4 + 5 l + 6 l̇)
    let general = (1.0 + 2.0 * 0.5 + 3.0 * 0.25) * 2.0;
    assert!((one(3, 2.0) - one(3, 0.0) - general).abs() < 1e-14);
    assert!(model
        .actuator_forces(
            (&q, &v),
            (&[0.0; 2], &[]),
            &TendonKinematics::default(),
            &mut tau
        )
        .is_err());
}

#[test]
fn a_tendons_actuators_are_scaled_together_into_its_force_range() {
    // two motors on L = 2 q: forces 3 u₀ (gear 1) and u₁, their sum held in [−1, 2]; the second
    // motor's own forcerange clamps it after the scaling
    let text = r#"<mujoco>
      <worldbody><body><joint name="j" axis="0 1 0"/><geom size="0.1"/></body></worldbody>
      <tendon><fixed name="t" actuatorfrcrange="-1 2"><joint joint="j" coef="2"/></fixed></tendon>
      <actuator>
        <general tendon="t" gainprm="3"/>
        <motor tendon="t" gear="4" forcerange="-0.25 0.25"/>
      </actuator>
    </mujoco>"#;
    let model = load_mjcf_str(text, "bounded.xml").unwrap();
    assert_eq!(model.tendons[0].actuator_force_range, Some((-1.0, 2.0)));
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let (q, v) = ([0.3], [0.0]);
    let tendons = TendonKinematics::at(&model, &mut Data::new(&model), &q).unwrap();
    let forces = |ctrl: [f64; 2]| -> Vec<f64> {
        let states = model.actuator_scalar_forces((&q, &v), (&ctrl, &[]), &tendons);
        states.map(|(_, out)| out.force).collect()
    };
    // inside the range: as they are (but the motor's clamp)
    assert_eq!(forces([0.25, 0.3]), vec![0.75, 0.25]);
    // saturated: the motor on its forcerange; both where the tendon's forces are scaled
    let saturated = |ctrl: [f64; 2]| -> Vec<bool> {
        let states = model.actuator_scalar_forces((&q, &v), (&ctrl, &[]), &tendons);
        states.map(|(_, out)| out.saturated).collect()
    };
    assert_eq!(saturated([0.25, 0.1]), vec![false, false]);
    assert_eq!(saturated([0.25, 0.3]), vec![false, true]);
    assert_eq!(saturated([1.0, 0.1]), vec![true, true]);
    // F = 3 + 1 = 4 > 2: each halved, then the motor's 0.5 clamped to 0.25
    assert_eq!(forces([1.0, 1.0]), vec![1.5, 0.25]);
    // F = −6 + 2 = −4 < −1: each times 1/4
    assert_eq!(forces([-2.0, 2.0]), vec![-1.5, 0.25]);
    // τ = Σ gear J f = 2 (1.5 + 4 · 0.25)
    let mut tau = [0.0];
    model
        .actuator_forces((&q, &v), (&[1.0, 1.0], &[]), &tendons, &mut tau)
        .unwrap();
    assert!((tau[0] - 2.0 * (1.5 + 4.0 * 0.25)).abs() < 1e-14);
}

const SCENE: &str = r#"<mujoco model="scene">
  <option timestep="0.005" integrator="RK4" cone="elliptic">
    <flag gravity="disable" filterparent="disable" energy="enable"/>
  </option>
  <default>
    <geom friction="0.5 0.01"/>
    <default class="bumper"><geom friction="0.9" contype="2" conaffinity="2"/></default>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="cart" pos="0 0 0.2">
      <joint name="rail" type="slide" axis="1 0 0" range="-1 1" solreflimit="0.05" margin="0.01"/>
      <geom name="cart" type="box" size="0.2 0.1 0.05" class="bumper"/>
      <body name="pole">
        <joint name="hinge" axis="0 1 0"/>
        <geom name="pole" type="capsule" fromto="0 0 0 0 0 0.5" size="0.02" conaffinity="3"/>
      </body>
    </body>
  </worldbody>
  <contact><pair geom1="floor" geom2="pole"/></contact>
</mujoco>"#;

#[test]
fn scene_geoms_options_and_the_pairs_checked() {
    let model = load_mjcf_str(SCENE, "scene").unwrap();
    let options = &model.options;
    assert_eq!(options.timestep, 0.005);
    assert_eq!(options.integrator, robodyn::model::Integrator::Rk4);
    assert_eq!(options.cone, robodyn::model::FrictionCone::Elliptic);
    assert!(!options.flag("gravity") && !options.flag("filterparent") && options.flag("energy"));
    // a disabled gravity flag leaves the model without gravity
    assert_eq!(model.gravity, robodyn::spatial::Vec3::zeros());
    // a class's leading friction keeps the default class's torsional term
    let cart = &model.geoms[1];
    assert_eq!((cart.name.as_str(), cart.contype), ("cart", 2));
    assert_eq!(cart.friction, [0.9, 0.01, 0.0001]);
    let rail = &model.joint_softness[1];
    assert_eq!((rail.limit.solref, rail.margin), ([0.05, 1.0], 0.01));
    // the floor and the cart share no bit; the cart and its child pole touch because filterparent
    // is disabled; the floor and the pole are an explicit pair, not a dynamic one
    assert_eq!(robodyn::collision::candidate_pairs(&model), vec![(1, 2)]);
    let pair = &model.contact_pairs[0];
    assert_eq!((pair.geoms, pair.contact.condim), ((0, 2), 3));
}

#[test]
fn disabled_actuator_groups_are_named() {
    let text = r#"<mujoco>
      <option actuatorgroupdisable="2 5"/>
      <default><default class="off"><motor group="5"/></default></default>
      <worldbody><body><joint name="j" axis="0 1 0"/><geom size="0.1"/></body></worldbody>
      <actuator>
        <motor name="on" joint="j"/>
        <motor name="grouped" joint="j" group="2"/>
        <motor name="by_class" joint="j" class="off"/>
        <position name="other" joint="j" group="3"/>
      </actuator>
    </mujoco>"#;
    let model = load_mjcf_str(text, "groups.xml").unwrap();
    let warning = model
        .warnings
        .iter()
        .find(|w| w.contains("actuatorgroupdisable"))
        .expect("a warning");
    assert!(warning.contains("'grouped', 'by_class'"), "{warning}");
    assert!(!warning.contains("'on'") && !warning.contains("'other'"));
}
