//! Editing a built model through its public methods: what the algorithms derive from the edited
//! values follows, so the dynamics are those of a model built with the new values.

mod common;

use common::{rng, state};
use robodyn::algo::{aba, crba, rnea};
use robodyn::spatial::{Inertia, Mat3, Transform, Vec3};
use robodyn::{Data, Joint, Model, ModelBuilder, NewBody};

/// A chain of four bodies: revolute about z, x and −y and prismatic along y, each placed by
/// `x_tree[k]`.
fn chain(x_tree: &[Transform; 4]) -> Model {
    let joints = [
        Joint::Revolute { axis: Vec3::z() },
        Joint::Revolute { axis: Vec3::x() },
        Joint::Revolute { axis: -Vec3::y() },
        Joint::Prismatic { axis: Vec3::y() },
    ];
    let mut builder = ModelBuilder::new("chain", "world");
    for (k, (joint, x)) in joints.into_iter().zip(x_tree).enumerate() {
        let name = format!("body{k}");
        let inertia = Inertia::from_com(
            1.0 + 0.3 * k as f64,
            &Vec3::new(0.05, -0.02 * k as f64, 0.2),
            &Mat3::from_diagonal(&Vec3::new(0.02, 0.03, 0.01)),
        );
        let body = NewBody {
            parent: k,
            joint,
            joint_name: &name,
            x_tree: *x,
            properties: Default::default(),
            name: &name,
            inertia,
        };
        builder.add_body(body).unwrap();
    }
    builder.build()
}

/// A placement `translation` away, turned by `angle` about `axis`.
fn placement(axis: Vec3, angle: f64, translation: Vec3) -> Transform {
    let rotation =
        nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle);
    Transform::from_pose(rotation.matrix(), &translation)
}

/// Tree rotations set after building (one oblique, one a quarter turn with round-off, on joints
/// whose built placements did not rotate) give τ, q̈ and M bit for bit those of a model built
/// with them, and not those of the model before the edit.
#[test]
fn an_edited_tree_rotation_moves_the_dynamics() {
    let straight = |z: f64| placement(Vec3::z(), 0.0, Vec3::new(0.1, 0.0, z));
    let before = [straight(0.1), straight(0.3), straight(0.25), straight(0.2)];
    let mut edited = chain(&before);
    let unedited = edited.clone();
    let mut after = before;
    after[1] = placement(Vec3::new(1.0, 2.0, 0.5), 0.7, Vec3::new(0.1, 0.0, 0.3));
    after[2] = placement(
        Vec3::y(),
        std::f64::consts::FRAC_PI_2,
        Vec3::new(0.0, 0.1, 0.25),
    );
    for body in [2, 3] {
        edited.set_tree_transform(body, after[body - 1]).unwrap();
    }
    let built = chain(&after);
    assert_eq!(edited.x_tree(), built.x_tree());
    let mut rng = rng();
    let (mut data, mut built_data, mut unedited_data) =
        (Data::new(&edited), Data::new(&built), Data::new(&unedited));
    for _ in 0..3 {
        let (q, v, a) = state(&edited, &mut rng);
        let (q, v, a) = (q.as_slice(), v.as_slice(), a.as_slice());
        let tau = rnea(&edited, &mut data, q, v, a, None).unwrap();
        assert_eq!(
            tau,
            rnea(&built, &mut built_data, q, v, a, None).unwrap(),
            "τ"
        );
        assert_ne!(
            tau,
            rnea(&unedited, &mut unedited_data, q, v, a, None).unwrap(),
            "τ"
        );
        let qdd = aba(&edited, &mut data, q, v, a, None).unwrap();
        assert_eq!(
            qdd,
            aba(&built, &mut built_data, q, v, a, None).unwrap(),
            "q̈"
        );
        let m = crba(&edited, &mut data, q).unwrap();
        assert_eq!(m, crba(&built, &mut built_data, q).unwrap(), "M");
        assert_ne!(m, crba(&unedited, &mut unedited_data, q).unwrap(), "M");
    }
}

/// A tree transform that is not a placement, or for a body that has none, is refused with the
/// argument named, and the model is left as it was.
#[test]
fn a_tree_transform_that_is_not_a_placement_is_refused() {
    let straight = placement(Vec3::z(), 0.0, Vec3::new(0.0, 0.0, 0.1));
    let mut model = chain(&[straight; 4]);
    let mut skewed = straight;
    skewed.rotation[(0, 1)] = 0.2;
    let mut mirrored = straight;
    mirrored.rotation[(2, 2)] = -1.0;
    let mut infinite = straight;
    infinite.translation.x = f64::INFINITY;
    for (body, x) in [
        (1, skewed),
        (2, mirrored),
        (3, infinite),
        (0, straight),
        (5, straight),
    ] {
        let error = model.set_tree_transform(body, x).unwrap_err().to_string();
        assert!(error.contains("x_tree"), "{error}");
    }
    assert_eq!(model.x_tree(), chain(&[straight; 4]).x_tree());
}
