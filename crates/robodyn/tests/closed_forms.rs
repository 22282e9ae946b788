//! Closed forms from the lecture notes (cited by course; `docs/guide/dynamics.md` lists them).

mod common;

use common::*;
use robodyn::algo::*;
use robodyn::io::bundled_model;
use robodyn::Data;

const G: f64 = robodyn::model::STANDARD_GRAVITY;

/// The UR5 dynamics notes, "The pendulum": m l² q̈ + m g l sin q = τ with m = 1 kg, l = 1 m.
#[test]
fn pendulum_equation_of_motion() {
    let model = bundled_model("pendulum", false).unwrap();
    let mut data = Data::new(&model);
    let (m, l) = (1.0, 1.0);
    for (q, v, a) in [
        (0.3, 0.0, 0.0),
        (-1.2, 2.0, 0.5),
        (2.9, -1.0, -3.0),
        (0.0, 5.0, 1.0),
    ] {
        let tau = rnea(&model, &mut data, &[q], &[v], &[a], None).unwrap()[0];
        let expected = m * l * l * a + m * G * l * f64::sin(q);
        assert_close("pendulum τ", &[tau], &[expected], CLOSED_FORM_TOLERANCE);
        let qdd = aba(&model, &mut data, &[q], &[v], &[0.0], None).unwrap()[0];
        assert_close(
            "pendulum q̈",
            &[qdd],
            &[-G / l * f64::sin(q)],
            CLOSED_FORM_TOLERANCE,
        );
    }
}

/// The ECE 470 notes "Dynamic Equation" and the TUM notes eq. 6.58: the 2-link planar arm with point masses at
/// the link ends, τ = M(θ) θ̈ + V(θ, θ̇) + G(θ), gravity along -y.
#[test]
fn planar_two_link_arm_m_v_g() {
    let model = bundled_model("planar2", false).unwrap();
    let mut data = Data::new(&model);
    let (m1, m2, l1, l2) = (2.0, 1.0, 1.0, 0.5);
    let states: [([f64; 2], [f64; 2], [f64; 2]); 4] = [
        ([0.3, -0.7], [0.5, 1.5], [0.2, -0.4]),
        ([1.2, 2.1], [-2.0, 0.3], [1.0, 1.0]),
        ([-2.5, 0.4], [0.0, -1.0], [-0.5, 2.0]),
        ([0.0, 0.0], [1.0, 1.0], [0.0, 0.0]),
    ];
    for (q, v, a) in states {
        let (c1, c2, s2, c12) = (q[0].cos(), q[1].cos(), q[1].sin(), (q[0] + q[1]).cos());
        let mass_matrix = [
            [
                l2 * l2 * m2 + 2.0 * l1 * l2 * m2 * c2 + l1 * l1 * (m1 + m2),
                l2 * l2 * m2 + l1 * l2 * m2 * c2,
            ],
            [l2 * l2 * m2 + l1 * l2 * m2 * c2, l2 * l2 * m2],
        ];
        let coriolis = [
            -m2 * l1 * l2 * s2 * v[1] * v[1] - 2.0 * m2 * l1 * l2 * s2 * v[0] * v[1],
            m2 * l1 * l2 * s2 * v[0] * v[0],
        ];
        let gravity = [
            m2 * l2 * G * c12 + (m1 + m2) * l1 * G * c1,
            m2 * l2 * G * c12,
        ];

        let m = crba(&model, &mut data, &q).unwrap();
        assert_close(
            "planar2 M",
            m.as_slice(),
            &[
                mass_matrix[0][0],
                mass_matrix[1][0],
                mass_matrix[0][1],
                mass_matrix[1][1],
            ],
            CLOSED_FORM_TOLERANCE,
        );
        let g = generalized_gravity(&model, &mut data, &q).unwrap().clone();
        assert_close("planar2 G", g.as_slice(), &gravity, CLOSED_FORM_TOLERANCE);
        let b = bias_forces(&model, &mut data, &q, &v).unwrap();
        let expected_bias = [coriolis[0] + gravity[0], coriolis[1] + gravity[1]];
        assert_close(
            "planar2 V + G",
            b.as_slice(),
            &expected_bias,
            CLOSED_FORM_TOLERANCE,
        );
        // the TUM notes, eq. 6.58, τ written out
        let tau = rnea(&model, &mut data, &q, &v, &a, None).unwrap();
        let tau_2 = m2 * l1 * l2 * c2 * a[0]
            + m2 * l1 * l2 * s2 * v[0] * v[0]
            + m2 * l2 * G * c12
            + m2 * l2 * l2 * (a[0] + a[1]);
        let tau_1 = m2 * l2 * l2 * (a[0] + a[1])
            + m2 * l1 * l2 * c2 * (2.0 * a[0] + a[1])
            + (m1 + m2) * l1 * l1 * a[0]
            - m2 * l1 * l2 * s2 * v[1] * v[1]
            - 2.0 * m2 * l1 * l2 * s2 * v[0] * v[1]
            + m2 * l2 * G * c12
            + (m1 + m2) * l1 * G * c1;
        assert_close(
            "planar2 τ (6.58)",
            tau.as_slice(),
            &[tau_1, tau_2],
            CLOSED_FORM_TOLERANCE,
        );
    }
}

/// The TU Berlin and TUM notes: the 2-link arm's Coriolis matrix, Christoffel symbols and Craig's split, and
/// its M and G computed the notes' ways. With h = −m₂ l₁ l₂ sin q₂:
/// C(q, q̇) = [[h q̇₂, h (q̇₁ + q̇₂)], [−h q̇₁, 0]], Γ_112 = Γ_121 = Γ_122 = h, Γ_211 = −h, others 0.
#[test]
fn planar_two_link_arm_coriolis_matrix_and_christoffel_symbols() {
    let model = bundled_model("planar2", false).unwrap();
    let mut data = Data::new(&model);
    let (m2, l1, l2) = (1.0, 1.0, 0.5);
    let states: [([f64; 2], [f64; 2]); 2] = [([0.3, -0.7], [0.5, 1.5]), ([1.2, 2.1], [-2.0, 0.3])];
    for (q, v) in states {
        let h = -m2 * l1 * l2 * q[1].sin();
        let c = coriolis_matrix(&model, &mut data, &q, &v).unwrap();
        // column-major: C11, C21, C12, C22
        let expected = [h * v[1], -h * v[0], h * (v[0] + v[1]), 0.0];
        assert_close("planar2 C", c.as_slice(), &expected, CLOSED_FORM_TOLERANCE);
        let mut gamma = [0.0; 8];
        christoffel_symbols(&model, &mut data, &q, &mut gamma).unwrap();
        // Γ_ijk at (i, j, k) row-major: 111 112 121 122 211 212 221 222
        let expected = [0.0, h, h, h, -h, 0.0, 0.0, 0.0];
        assert_close("planar2 Γ", &gamma, &expected, CLOSED_FORM_TOLERANCE);
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let by_jacobians = mass_matrix_by_jacobians(&model, &mut data, &q).unwrap();
        assert_close(
            "planar2 M by Jacobians",
            by_jacobians.as_slice(),
            m.as_slice(),
            CLOSED_FORM_TOLERANCE,
        );
    }
}

/// The ECE 470 notes forward kinematics of the 2-link arm: the tool frame {3} at
/// (l1 c1 + l2 c12, l1 s1 + l2 s12), rotated by θ1 + θ2; and its geometric Jacobian.
#[test]
fn planar_two_link_arm_kinematics() {
    let model = bundled_model("planar2", false).unwrap();
    let mut data = Data::new(&model);
    let (l1, l2) = (1.0, 0.5);
    let q: [f64; 2] = [0.4, 0.9];
    let (s1, c1, s12, c12) = (
        q[0].sin(),
        q[0].cos(),
        (q[0] + q[1]).sin(),
        (q[0] + q[1]).cos(),
    );
    forward_kinematics(&model, &mut data, &q).unwrap();
    let tool = model.frame_index("tool").unwrap();
    let pose = frame_placement(&model, &data, tool).to_homogeneous();
    let expected = nalgebra::Matrix4::new(
        c12,
        -s12,
        0.0,
        l1 * c1 + l2 * c12,
        s12,
        c12,
        0.0,
        l1 * s1 + l2 * s12,
        0.0,
        0.0,
        1.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
    );
    assert_close(
        "tool pose",
        pose.as_slice(),
        expected.as_slice(),
        CLOSED_FORM_TOLERANCE,
    );
    let j = jacobian(&model, &mut data, &q, tool, Reference::World).unwrap();
    // columns [z × (p - p_i); z]
    let expected_j = [
        -l1 * s1 - l2 * s12,
        l1 * c1 + l2 * c12,
        0.0,
        0.0,
        0.0,
        1.0,
        -l2 * s12,
        l2 * c12,
        0.0,
        0.0,
        0.0,
        1.0,
    ];
    assert_close(
        "tool Jacobian",
        j.as_slice(),
        &expected_j,
        CLOSED_FORM_TOLERANCE,
    );
}

/// The TU Berlin notes "Gravity": g(q) = -Σ J_ciᵀ m_i g, with J_ci the Jacobian of link i's centre of mass.
#[test]
fn gravity_torques_from_com_jacobians() {
    let model = bundled_model("planar2", false).unwrap();
    let mut data = Data::new(&model);
    let q = [0.7, -1.1];
    let g = generalized_gravity(&model, &mut data, &q).unwrap().clone();
    // link 1's point mass sits at joint 2, the origin of frame "link2"; link 2's at "tool"
    let mut expected = nalgebra::DVector::zeros(2);
    for (frame, mass) in [("link2", 2.0), ("tool", 1.0)] {
        let j = jacobian(
            &model,
            &mut data,
            &q,
            model.frame_index(frame).unwrap(),
            Reference::World,
        )
        .unwrap();
        let linear = j.rows(0, 3);
        expected -= linear.transpose() * (model.gravity * mass);
    }
    assert_close(
        "g = -Σ J_cᵀ m g",
        g.as_slice(),
        expected.as_slice(),
        CLOSED_FORM_TOLERANCE,
    );
}

/// The ECE 470 notes, "Manipulability": for the 2-link arm's planar position task, √det(J Jᵀ) = l1 l2 |s2|,
/// zero at the stretched-out singularity.
#[test]
fn planar_two_link_arm_manipulability() {
    let model = bundled_model("planar2", false).unwrap();
    let mut data = Data::new(&model);
    let tool = model.frame_index("tool").unwrap();
    let (l1, l2) = (1.0, 0.5);
    for q in [[0.3_f64, -0.7], [1.2, 2.1], [-2.5, 0.4], [0.7, 0.0]] {
        let (w, inverse_condition) = manipulability(&model, &mut data, &q, tool, &[0, 1]).unwrap();
        assert_close(
            "w",
            &[w],
            &[l1 * l2 * q[1].sin().abs()],
            CLOSED_FORM_TOLERANCE,
        );
        assert!((0.0..=1.0).contains(&inverse_condition));
        assert_eq!(inverse_condition == 0.0, q[1] == 0.0);
    }
    // the full 6-row task of a 2-joint arm has no volume
    assert_eq!(
        manipulability(&model, &mut data, &[0.3, 0.4], tool, &[0, 1, 2, 3, 4, 5])
            .unwrap()
            .0,
        0.0
    );
    let error = manipulability(&model, &mut data, &[0.3, 0.4], tool, &[0, 0]).unwrap_err();
    assert!(error.to_string().contains("argument 'task'"), "{error}");
}
