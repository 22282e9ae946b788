//! Spatial algebra identities, as property tests over random transforms and vectors.

use nalgebra::Vector6;
use proptest::prelude::*;
use robodyn::spatial::{
    rotation_from_rpy, CoriolisFactor, Force, ForceProduct, ForceStore, Inertia, Mat3, Motion,
    Transform, Vec3,
};
use robodyn::Joint;
use simba::simd::{AutoF64x4, SimdValue};

const TOLERANCE: f64 = 1e-12;

fn vec3() -> impl Strategy<Value = Vec3> {
    (-2.0..2.0, -2.0..2.0, -2.0..2.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn transform() -> impl Strategy<Value = Transform> {
    (vec3(), vec3())
        .prop_map(|(rpy, p)| Transform::from_pose(&rotation_from_rpy(rpy.x, rpy.y, rpy.z), &p))
}

fn inertia() -> impl Strategy<Value = Inertia> {
    (0.1..5.0, vec3(), vec3(), vec3()).prop_map(|(m, c, d, rpy)| {
        let r = rotation_from_rpy(rpy.x, rpy.y, rpy.z);
        let principal = Mat3::from_diagonal(&(d.abs() + Vec3::repeat(0.1)));
        Inertia::from_com(m, &c, &(r * principal * r.transpose()))
    })
}

/// The `index`-th (mod 24) of the 24 rotations that are signed permutations: a permutation of
/// the axes (6) with signs (8), those of determinant +1.
fn quarter_turns(index: usize) -> Mat3 {
    let permutations = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let rotations: Vec<Mat3> = permutations
        .iter()
        .flat_map(|p| {
            (0..8).map(move |signs: usize| {
                Mat3::from_fn(|row, col| match col == p[row] {
                    true if signs >> row & 1 == 1 => -1.0,
                    true => 1.0,
                    false => 0.0,
                })
            })
        })
        .filter(|e| e.determinant() > 0.0)
        .collect();
    assert_eq!(rotations.len(), 24);
    rotations[index % 24]
}

/// A joint that turns about a coordinate axis after a tree transform of quarter turns: revolute
/// about ±e_k, or prismatic (along a general axis), with its transform at `angle` (or `angle` m).
fn turning_joint(
    k: usize,
    negative: bool,
    prismatic: bool,
    tree: &Transform,
    angle: f64,
) -> (Joint, Transform) {
    let mut axis = Vec3::zeros();
    axis[k] = if negative { -1.0 } else { 1.0 };
    let joint = match prismatic {
        true => Joint::Prismatic {
            axis: Vec3::new(0.6, 0.0, -0.8),
        },
        false => Joint::Revolute { axis },
    };
    (
        joint,
        joint.transform_after_turn(&[angle], angle.sin_cos(), tree),
    )
}

proptest! {
    /// A joint's transform that turns about a coordinate axis after a rotation that keeps one
    /// axis (a revolute joint about ±e_k or a prismatic joint, after a tree transform whose
    /// rotation is quarter turns, maybe then a turn about the joint's axis) gives the same
    /// products by the turned paths, which leave out the rotation's zeros, as by the general ones.
    #[test]
    fn turned_products_equal_the_general_ones(
        angle in -4.0f64..4.0, k in 0usize..3, negative in any::<bool>(), r in vec3(),
        quarter in 0usize..24, prismatic in any::<bool>(), twist in prop::option::of(-3.0f64..3.0),
        i in inertia(), j in inertia(), w in vec3(), v in vec3(), y in transform(),
    ) {
        // quarter turns, then (maybe) a turn about the joint's own axis: a tree rotation that
        // keeps that axis
        let axis = if prismatic { 2 } else { k };
        let quarters = Transform::from_pose(&quarter_turns(quarter), &r);
        let tree = twist.map_or(quarters, |t| quarters.rotated_about_axis(axis, t.sin(), t.cos()));
        let (joint, x) = turning_joint(k, negative, prismatic, &tree, angle);
        let turn = joint.turn(&tree);
        // a tree that turns the axis into its opposite is the one case left to the general path
        prop_assert_eq!(turn.is_none(), tree.rotation[(axis, axis)] == -1.0);
        // the joint's transform made knowing its turn (no axis test, no product by an identity)
        prop_assert_eq!(joint.transform_after_turn_of(&[angle], angle.sin_cos(), &tree, turn), x);
        let unrotated = Transform::from_translation(&r);
        prop_assert_eq!(
            joint.transform_after_turn_of(&[angle], angle.sin_cos(), &unrotated, joint.turn(&unrotated)),
            joint.transform_after_turn(&[angle], angle.sin_cos(), &unrotated)
        );
        prop_assume!(turn.is_some());
        let (m, f) = (Motion::new(w, v), Force::new(v, w));
        let u = nalgebra::Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z);
        let articulated = i.to_matrix() + j.to_matrix() - u * u.transpose() * 0.1;
        prop_assert_eq!(x.compose_turned(turn, &y), x * y);
        prop_assert_eq!(x.apply_motion_turned(turn, &m), x.apply_motion(&m));
        prop_assert_eq!(x.transpose_apply_force_turned(turn, &f), x.transpose_apply_force(&f));
        // added in place to a sum: the same sum, bit for bit, as the product added after
        let mut sum = articulated;
        x.add_transpose_apply_matrix_turned(turn, &articulated, &mut sum);
        prop_assert_eq!(sum, articulated + x.transpose_apply_matrix(&articulated));
        prop_assert_eq!(x.transpose_apply_inertia_turned(turn, &i), x.transpose_apply_inertia(&i));
        let mut forces = [f, Force::new(w, v)];
        x.transpose_apply_forces_turned(turn, &mut forces);
        prop_assert_eq!(forces, [x.transpose_apply_force(&f), x.transpose_apply_force(&Force::new(w, v))]);
    }

    /// Forces kept in another layout (here by component, a row per component) and carried in
    /// place through `ForceStore` equal each force carried alone, bit for bit, turned or not.
    #[test]
    fn forces_carried_in_any_layout_equal_each_carried_alone(
        angle in -4.0f64..4.0, k in 0usize..3, r in vec3(), y in transform(), turned in any::<bool>(),
        quarter in 0usize..24, values in prop::collection::vec(-2.0f64..2.0, 6 * 11), count in 0usize..12,
    ) {
        let tree = Transform::from_pose(&quarter_turns(quarter), &r);
        let (joint, turning) = turning_joint(k, false, false, &tree, angle);
        let (x, turn) = match turned {
            true => (turning, joint.turn(&tree)),
            false => (y, None),
        };
        let mut rows = ByComponent { rows: values[..6 * count].to_vec(), count };
        let carried: Vec<Force> = (0..count).map(|d| x.transpose_apply_force(&rows.load(d))).collect();
        x.transpose_apply_stored_forces_turned(turn, &mut rows);
        for (d, force) in carried.iter().enumerate() {
            prop_assert_eq!(&rows.load(d), force);
        }
    }

    #[test]
    fn transform_times_inverse_is_identity(x in transform(), w in vec3(), v in vec3()) {
        let m = Motion::new(w, v);
        let back = x.inverse().apply_motion(&x.apply_motion(&m));
        prop_assert!((back.to_vector() - m.to_vector()).norm() < TOLERANCE);
        let composed = x * x.inverse();
        prop_assert!((composed.to_matrix() - nalgebra::Matrix6::identity()).norm() < TOLERANCE);
        prop_assert!((x.inverse_apply_motion(&m).to_vector() - x.inverse().apply_motion(&m).to_vector()).norm() < TOLERANCE);
    }

    #[test]
    fn force_motion_duality_preserves_power(x in transform(), w in vec3(), v in vec3(), n in vec3(), f in vec3()) {
        // (X m) · (X* f) = m · f
        let (m, force) = (Motion::new(w, v), Force::new(n, f));
        prop_assert!((x.apply_motion(&m).dot(&x.apply_force(&force)) - m.dot(&force)).abs() < TOLERANCE * 100.0);
        // Xᵀ is the inverse of X*
        let back = x.transpose_apply_force(&x.apply_force(&force));
        prop_assert!((back.to_vector() - force.to_vector()).norm() < TOLERANCE * 100.0);
        // X* = X⁻ᵀ as matrices
        let star = x.apply_force(&force).to_vector();
        let expected = x.to_matrix().try_inverse().unwrap().transpose() * force.to_vector();
        prop_assert!((star - expected).norm() < 1e-10);
    }

    #[test]
    fn homogeneous_rows_are_the_homogeneous_matrix(x in transform()) {
        let mut rows = [0.0; 16];
        x.write_homogeneous(&mut rows);
        prop_assert_eq!(nalgebra::Matrix4::from_row_slice(&rows), x.to_homogeneous());
    }

    #[test]
    fn composition_matches_matrix_product(a in transform(), b in transform()) {
        prop_assert!(((a * b).to_matrix() - a.to_matrix() * b.to_matrix()).norm() < 1e-10);
    }

    #[test]
    fn an_inertia_splat_into_lanes_is_its_matrix_in_every_lane(i in inertia()) {
        let mut lanes = nalgebra::Matrix6::from_element(AutoF64x4::splat(f64::NAN));
        i.splat_matrix_into(&mut lanes);
        for lane in 0..4 {
            prop_assert_eq!(lanes.map(|x| x.extract(lane)), i.to_matrix());
        }
    }

    #[test]
    fn inertia_transform_is_congruence_and_symmetric(x in transform(), i in inertia(), w in vec3(), v in vec3()) {
        let moved = x.transpose_apply_inertia(&i).to_matrix();
        let expected = x.to_matrix().transpose() * i.to_matrix() * x.to_matrix();
        prop_assert!((moved - expected).norm() < 1e-9);
        prop_assert!((moved - moved.transpose()).norm() < 1e-12);
        let m = Motion::new(w, v);
        prop_assert!((i.mul_motion(&m).to_vector() - i.to_matrix() * m.to_vector()).norm() < 1e-12);
    }

    #[test]
    fn articulated_inertia_transform_is_the_congruence(x in transform(), i in inertia(), j in inertia(), w in vec3(), v in vec3()) {
        // an articulated inertia has no rigid body's structure: a rigid one less a rank-one term
        let u = nalgebra::Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z);
        let articulated = i.to_matrix() + j.to_matrix() - u * u.transpose() * 0.1;
        let moved = x.transpose_apply_matrix(&articulated);
        let expected = x.to_matrix().transpose() * articulated * x.to_matrix();
        prop_assert!((moved - expected).norm() < 1e-9 * expected.norm().max(1.0));
        // computed on one triangle and mirrored
        prop_assert_eq!(moved, moved.transpose());
    }

    #[test]
    fn cross_products_match_their_matrices(w in vec3(), v in vec3(), w2 in vec3(), v2 in vec3(), n in vec3(), f in vec3()) {
        let (m, other, force) = (Motion::new(w, v), Motion::new(w2, v2), Force::new(n, f));
        // (m ×* f) · other = -(m × other) · f
        prop_assert!((other.dot(&m.cross_force(&force)) + m.cross_motion(&other).dot(&force)).abs() < 1e-10);
    }

    #[test]
    fn an_inertia_times_a_unit_motion_is_its_column(i in inertia()) {
        // ±e_c in Plücker order, against the general product
        for c in 0..6 {
            for negative in [false, true] {
                let mut unit = [0.0; 6];
                unit[c] = if negative { -1.0 } else { 1.0 };
                let motion = Motion::new(
                    Vec3::new(unit[0], unit[1], unit[2]),
                    Vec3::new(unit[3], unit[4], unit[5]),
                );
                let column = i.mul_unit_motion(c, negative).plucker();
                prop_assert_eq!(column, i.mul_motion(&motion).plucker(), "c = {}, negative = {}", c, negative);
            }
        }
    }

    #[test]
    fn an_inertia_times_a_linear_motion_is_the_general_product(i in inertia(), v in vec3()) {
        let general = i.mul_motion(&Motion::new(Vec3::zeros(), v));
        prop_assert_eq!(i.mul_linear_motion(&v).plucker(), general.plucker());
    }

    #[test]
    fn a_motion_across_a_unit_motion_is_the_general_cross_product(w in vec3(), v in vec3(), s in -10.0..10.0f64) {
        // s e_c in Plücker order, against the general product and the general sum
        let m = Motion::new(w, v);
        for c in 0..6 {
            let mut unit = Vector6::zeros();
            unit[c] = s;
            let scaled_unit = Motion::new(unit.fixed_rows::<3>(0).into(), unit.fixed_rows::<3>(3).into());
            let across = m.cross_unit_motion(c, s).to_vector();
            prop_assert_eq!(across, m.cross_motion(&scaled_unit).to_vector(), "c = {}", c);
            let mut sum = m;
            sum.add_to_component(c, s);
            prop_assert_eq!(sum.to_vector(), (m + scaled_unit).to_vector(), "c = {}", c);
        }
    }

    #[test]
    fn factored_coriolis_is_twice_the_coriolis_factor(i in inertia(), w in vec3(), v in vec3(), w2 in vec3(), v2 in vec3(), j in inertia(), w3 in vec3(), v3 in vec3()) {
        let (velocity, s, other_velocity) = (Motion::new(w, v), Motion::new(w2, v2), Motion::new(w3, v3));
        // a subtree's H is the sum of its bodies'
        let mut factored = CoriolisFactor::new(&i, &velocity);
        factored += CoriolisFactor::new(&j, &other_velocity);
        let h = (i.coriolis_factor(&velocity) + j.coriolis_factor(&other_velocity)) * 2.0;
        prop_assert!((factored.mul_motion(&s).to_vector() - h * s.to_vector()).norm() < 1e-10);
        prop_assert!((factored.tr_mul_motion(&s).to_vector() - h.transpose() * s.to_vector()).norm() < 1e-10);
    }
}

#[test]
fn rotation_log_is_accurate_from_tiny_angles_to_pi() {
    use robodyn::spatial::log_rotation;
    let axis = nalgebra::Unit::new_normalize(Vec3::new(0.3, -0.5, 0.8));
    for angle in [1e-14, 1e-9, 1e-5, 0.3, 2.0, std::f64::consts::PI - 1e-9] {
        let rotation = nalgebra::UnitQuaternion::from_axis_angle(&axis, angle);
        let log = log_rotation(&rotation);
        assert!(
            (log - axis.into_inner() * angle).norm() <= 1e-15 + 1e-12 * angle,
            "angle {angle}: {log:?}"
        );
        // the negated quaternion is the same rotation
        let flipped = nalgebra::UnitQuaternion::new_unchecked(-rotation.into_inner());
        assert!((log_rotation(&flipped) - log).norm() <= 1e-15 + 1e-12 * angle);
    }
}

/// Forces kept by component: component c (`Force::plucker`'s order) of force d at
/// `rows[c * count + d]`.
struct ByComponent {
    rows: Vec<f64>,
    count: usize,
}

impl ByComponent {
    fn load(&self, d: usize) -> Force {
        Force::from_plucker(std::array::from_fn(|c| self.rows[c * self.count + d]))
    }
}

impl ForceStore<f64> for ByComponent {
    fn replace_each(&mut self, product: &impl ForceProduct<f64>) {
        for d in 0..self.count {
            let carried = product.of(&self.load(d));
            for (c, value) in carried.plucker().into_iter().enumerate() {
                self.rows[c * self.count + d] = value;
            }
        }
    }
}
