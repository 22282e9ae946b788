//! Convex contacts: closed forms and MuJoCo 4.0.0's own numbers.

use super::*;

/// The largest deviation from MuJoCo 4.0.0 measured on identical inputs (103,500 random
/// cases over all pair types, shallow, deep, within the margin, near-parallel and grid-aligned
/// faces): counts, positions and distances identical to the bit, normals within 5e-16 (MuJoCo
/// renormalises the normal when it builds the contact frame).
const MUJOCO_AGREEMENT: f64 = 1e-15;

/// Rounding in a closed-form case.
const ROUNDING: f64 = 1e-15;

/// EPA's stopping tolerance (MuJoCo's `ccd_tolerance`) bounds the error of a depth on a curved
/// surface; the normal is then known to `√(2 tol / r)`, 2.6e-3 on a cylinder's side of
/// radius 0.3 (MuJoCo's own answer for the case below is 1.3e-3 off the exact normal).
const CURVED_DEPTH: f64 = TOLERANCE;
const CURVED_NORMAL: f64 = 2.6e-3;

fn placed(shape: &Shape, position: [f64; 3], rotation: Mat3) -> Placed<'_> {
    Placed {
        shape,
        rotation,
        position: Vec3::from(position),
    }
}

fn collide(first: &Placed, second: &Placed, margin: f64) -> Vec<Touch> {
    let mut touches = Vec::new();
    if matches!(first.shape, Shape::Plane { .. }) {
        plane_convex(first, second, margin, &mut touches);
    } else {
        convex_convex(first, second, margin, &mut touches);
    }
    touches
}

#[test]
fn ellipsoid_resting_on_a_plane_touches_at_its_lowest_point() {
    // radii (0.3, 0.2, 0.1) with its centre 0.08 above the plane: 0.02 deep
    let plane = Shape::Plane {
        half_extents: [0.0, 0.0],
    };
    let ellipsoid = Shape::Ellipsoid {
        radii: Vec3::new(0.3, 0.2, 0.1),
    };
    let touches = collide(
        &placed(&plane, [0.0; 3], Mat3::identity()),
        &placed(&ellipsoid, [0.1, -0.2, 0.08], Mat3::identity()),
        0.0,
    );
    assert_eq!(touches.len(), 1);
    assert!((touches[0].distance + 0.02).abs() < ROUNDING);
    assert!((touches[0].position - Vec3::new(0.1, -0.2, -0.01)).norm() < ROUNDING);
    assert_eq!(touches[0].normal, Vec3::z());
}

#[test]
fn sphere_pressed_into_an_ellipsoid_along_its_axis() {
    // sphere r = 0.2 at the origin, ellipsoid radii (0.5, 0.3, 0.4) at x = 0.6: the surfaces
    // at x = 0.2 and x = 0.1, 0.1 deep, midway at x = 0.15
    let sphere = Shape::Sphere { radius: 0.2 };
    let ellipsoid = Shape::Ellipsoid {
        radii: Vec3::new(0.5, 0.3, 0.4),
    };
    let touches = collide(
        &placed(&sphere, [0.0; 3], Mat3::identity()),
        &placed(&ellipsoid, [0.6, 0.0, 0.0], Mat3::identity()),
        0.0,
    );
    assert_eq!(touches.len(), 1);
    assert!((touches[0].distance + 0.1).abs() < ROUNDING);
    assert!((touches[0].position - Vec3::new(0.15, 0.0, 0.0)).norm() < ROUNDING);
    assert!((touches[0].normal - Vec3::x()).norm() < ROUNDING);
}

#[test]
fn cylinders_side_by_side_touch_once_along_their_sides() {
    // r = 0.3, axes along z, centres 0.59 apart along x: 0.01 deep, the contact on the line
    // x = 0.295, y = 0
    let cylinder = Shape::Cylinder {
        radius: 0.3,
        half_length: 0.4,
    };
    let touches = collide(
        &placed(&cylinder, [0.0; 3], Mat3::identity()),
        &placed(&cylinder, [0.59, 0.0, 0.0], Mat3::identity()),
        0.0,
    );
    assert_eq!(touches.len(), 1);
    let touch = touches[0];
    assert!((touch.distance + 0.01).abs() < CURVED_DEPTH);
    assert!((touch.position.x - 0.295).abs() < CURVED_DEPTH);
    assert!(touch.position.y.abs() < CURVED_NORMAL * 0.3);
    assert!(touch.position.z.abs() <= 0.4);
    assert!((touch.normal - Vec3::x()).norm() < CURVED_NORMAL);
}

#[test]
fn cylinder_standing_on_a_box_touches_at_four_rim_points() {
    // r = 0.3, h = 0.4 at (0.1, 0.2, 0.89) on a box of half-sides (1, 1, 0.5): the bottom cap
    // 0.01 into the top face, contacts at every other vertex of the cap's 16-gon, midway at
    // z = 0.495, normal from the cylinder down into the box
    let cylinder = Shape::Cylinder {
        radius: 0.3,
        half_length: 0.4,
    };
    let cuboid = Shape::Box {
        half_extents: Vec3::new(1.0, 1.0, 0.5),
    };
    let touches = collide(
        &placed(&cylinder, [0.1, 0.2, 0.89], Mat3::identity()),
        &placed(&cuboid, [0.0; 3], Mat3::identity()),
        0.0,
    );
    assert_eq!(touches.len(), 4);
    // the largest quadrilateral of the 16-gon, in MuJoCo's order
    for (touch, degrees) in touches.iter().zip([157.5_f64, 67.5, -22.5, -112.5]) {
        let rim = Vec3::new(degrees.to_radians().cos(), degrees.to_radians().sin(), 0.0);
        let expected = Vec3::new(0.1, 0.2, 0.495) + rim * 0.3;
        assert!((touch.distance + 0.01).abs() < ROUNDING);
        assert!((touch.position - expected).norm() < ROUNDING);
        assert_eq!(touch.normal, -Vec3::z());
    }
}

/// A case for [`contacts_match_mujoco`]: shapes, MuJoCo sizes, margin, each geom's
/// `geom_xpos` and `geom_xmat` (row-major), and the contacts (distance, position, normal).
struct Reference {
    shapes: [&'static str; 2],
    sizes: [[f64; 3]; 2],
    margin: f64,
    poses: [[f64; 12]; 2],
    contacts: &'static [[f64; 7]],
}

/// MuJoCo 4.0.0 `mj_collision` output, default options: each case two free bodies with one
/// geom each (a plane is a world geom), placed through `qpos` by a position and a rotation
/// about an axis (see each label); the poses are MuJoCo's `geom_xpos`, `geom_xmat`, the
/// contacts its `dist`, `pos` and `frame[0..3]`.
#[rustfmt::skip]
const REFERENCES: &[Reference] = &[
    // plane, tilted ellipsoid
    Reference {
        shapes: ["plane", "ellipsoid"],
        sizes: [[0.0, 0.0, 1.0], [0.3, 0.2, 0.1]],
        margin: 0.0,
        poses: [
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            [0.1, -0.2, 0.12, 0.8213938048432696, 0.17860619515673035, 0.5416752204197018,
             0.17860619515673035, 0.8213938048432696, -0.5416752204197018, -0.5416752204197018,
             0.5416752204197018, 0.6427876096865393],
        ],
        contacts: &[
            [-0.0856096420060124, 0.2589998251071177, -0.2272756474044344, -0.0428048210030062,
             0.0, 0.0, 1.0],
        ],
    },
    // sphere, ellipsoid: shallow
    Reference {
        shapes: ["sphere", "ellipsoid"],
        sizes: [[0.2, 0.0, 0.0], [0.3, 0.2, 0.4]],
        margin: 0.0,
        poses: [
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            [0.25, 0.3, 0.1, 0.7827555543247654, -0.4819544221406551, 0.3937177633188482,
             0.5487988669638042, 0.8328888879421272, -0.07152554761601951,
             -0.29345109608412456, 0.2720588820854669, 0.9164444439710636],
        ],
        contacts: &[
            [-0.08869935458784348, 0.061080973157473815, 0.1407752313257007,
             0.02604749358072147, 0.3924243271426803, 0.9044326338566808, 0.1673462227888095],
        ],
    },
    // sphere, ellipsoid: deep
    Reference {
        shapes: ["sphere", "ellipsoid"],
        sizes: [[0.2, 0.0, 0.0], [0.3, 0.2, 0.4]],
        margin: 0.0,
        poses: [
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            [0.05, 0.1, 0.05, 0.7827555543247654, -0.4819544221406551, 0.3937177633188482,
             0.5487988669638042, 0.8328888879421272, -0.07152554761601951,
             -0.29345109608412456, 0.2720588820854669, 0.9164444439710636],
        ],
        contacts: &[
            [-0.3147179352386688, -0.009487856260522672, 0.04001371375747491,
             0.011286073803720407, -0.23750381359314676, 0.9318516407096528,
             0.2743072332904112],
        ],
    },
    // capsule, ellipsoid
    Reference {
        shapes: ["capsule", "ellipsoid"],
        sizes: [[0.1, 0.3, 0.0], [0.3, 0.2, 0.4]],
        margin: 0.0,
        poses: [
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.8660254037844387, -0.49999999999999994, 0.0,
             0.49999999999999994, 0.8660254037844387],
            [0.2, 0.1, 0.3, 0.34202014332566877, -0.6644630243886747, 0.6644630243886747,
             0.6644630243886747, 0.6710100716628343, 0.32898992833716556, -0.6644630243886747,
             0.32898992833716556, 0.6710100716628343],
        ],
        contacts: &[
            [-0.16053107798410707, 0.0029816027155903715, -0.05348214559729694,
             0.13164955590710173, 0.14854456198506077, 0.8564174711136139,
             0.49445285748595796],
        ],
    },
    // capsule lying on a cylinder's cap: two contacts
    Reference {
        shapes: ["capsule", "cylinder"],
        sizes: [[0.1, 0.3, 0.0], [0.4, 0.2, 0.0]],
        margin: 0.0,
        poses: [
            [0.05, 0.0, 0.29, 1.721713049906981e-16, -0.01999600119960014, 0.999800059980007,
             0.01999600119960014, 0.9996001599360257, 0.01999200319872051, -0.999800059980007,
             0.01999200319872051, 0.0003998400639745824],
            [0.0, 0.0, 0.0, 0.9848077530122081, -0.17364817766693033, 0.0, 0.17364817766693033,
             0.9848077530122081, 0.0, 0.0, 0.0, 1.0],
        ],
        contacts: &[
            [-0.010119936031984772, -0.24990004198200763, -0.005996801599232369,
             0.1949400319840076, 0.0, 0.0, -1.0],
            [-0.00988003199360002, 0.34997999400599655, 0.005998400319999937,
             0.19505998400320002, 0.0, 0.0, -1.0],
        ],
    },
    // ellipsoid, ellipsoid
    Reference {
        shapes: ["ellipsoid", "ellipsoid"],
        sizes: [[0.3, 0.2, 0.1], [0.2, 0.3, 0.4]],
        margin: 0.0,
        poses: [
            [0.0, 0.0, 0.0, 0.9999999999999999, 0.0, 0.0, 0.0, 0.9396926207859083,
             -0.34202014332566866, 0.0, 0.34202014332566866, 0.9396926207859083],
            [0.3, 0.2, 0.2, 0.7500000000000002, 0.2499999999999999, 0.6123724356957945,
             0.2499999999999999, 0.75, -0.6123724356957945, -0.6123724356957945,
             0.6123724356957945, 0.5000000000000002],
        ],
        contacts: &[
            [-0.1294131962263757, 0.1750254716949321, 0.0862404644279057, 0.02474863716522594,
             0.52247942175063, 0.646360315345989, 0.5560877597942263],
        ],
    },
    // ellipsoid, cylinder
    Reference {
        shapes: ["ellipsoid", "cylinder"],
        sizes: [[0.3, 0.2, 0.1], [0.2, 0.3, 0.0]],
        margin: 0.0,
        poses: [
            [0.0, 0.0, 0.0, 0.9396926207859083, 0.0, 0.34202014332566866, 0.0,
             0.9999999999999999, 0.0, -0.34202014332566866, 0.0, 0.9396926207859083],
            [0.35, 0.1, 0.1, 0.8213938048432696, -0.5416752204197018, 0.17860619515673035,
             0.5416752204197018, 0.6427876096865393, -0.5416752204197018, 0.17860619515673035,
             0.5416752204197018, 0.8213938048432696],
        ],
        contacts: &[
            [-0.0802617691277806, 0.2039606634836004, 0.08612371828577328,
             -0.07206125010496987, 0.7351107955465446, 0.6283530050829657, 0.2545282288354927],
        ],
    },
    // ellipsoid, box
    Reference {
        shapes: ["ellipsoid", "box"],
        sizes: [[0.3, 0.2, 0.1], [0.2, 0.3, 0.25]],
        margin: 0.0,
        poses: [
            [0.0, 0.0, 0.0, 0.8191520442889919, 0.0, 0.573576436351046, 0.0, 1.0, 0.0,
             -0.573576436351046, 0.0, 0.8191520442889919],
            [0.3, 0.2, -0.2, 0.9148252609424091, -0.10187177862327826, 0.3907900749274256,
             0.15297662205783283, 0.9829650521884818, -0.10187177862327826,
             -0.37375512711590747, 0.15297662205783283, 0.9148252609424091],
        ],
        contacts: &[
            [-0.11176812693947966, 0.19686877680250148, 0.01244061711370397,
             -0.14360829859180688, 0.914825260910738, 0.1529766221932327,
             -0.37375512713800885],
        ],
    },
    // cylinder, cylinder: crossed
    Reference {
        shapes: ["cylinder", "cylinder"],
        sizes: [[0.2, 0.4, 0.0], [0.15, 0.3, 0.0]],
        margin: 0.0,
        poses: [
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 2.220446049250313e-16, -1.0, 0.0, 1.0,
             2.220446049250313e-16],
            [0.1, 0.05, 0.33, 2.220446049250313e-16, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0,
             2.220446049250313e-16],
        ],
        contacts: &[
            [-0.019999999830818894, -6.135767323903564e-07, 0.05000045288113499,
             0.18999999994647368, 1.2728193238811198e-10, 3.2123956544572017e-10, 1.0],
        ],
    },
    // cylinder on cylinder, caps nearly parallel: four contacts
    Reference {
        shapes: ["cylinder", "cylinder"],
        sizes: [[0.2, 0.3, 0.0], [0.3, 0.2, 0.0]],
        margin: 0.0,
        poses: [
            [0.05, 0.02, 0.49, 0.9993147673772869, 0.000685232622713063, 0.03700710955926801,
             0.000685232622713063, 0.9993147673772869, -0.03700710955926801,
             -0.03700710955926801, 0.03700710955926801, 0.9986295347545737],
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        ],
        contacts: &[
            [-0.019259284183824554, 0.22349471372104462, -0.04525549369180517,
             0.19037035790808773, 0.0, 0.0, -1.0],
            [-0.01699028233822575, 0.03876082060767698, -0.168760820607677,
             0.19150485883088714, 0.0, 0.0, -1.0],
            [-0.005583239752140368, -0.14580387032541672, -0.045508722649858654,
             0.19720838012392983, 0.0, 0.0, -1.0],
            [-0.0021874385145185526, 0.03903491365676219, 0.23096508634323776,
             0.19890628074274075, 0.0, 0.0, -1.0],
        ],
    },
    // cylinder on a box face, tilted: four contacts
    Reference {
        shapes: ["cylinder", "box"],
        sizes: [[0.2, 0.3, 0.0], [0.5, 0.4, 0.1]],
        margin: 0.0,
        poses: [
            [0.1, -0.1, 0.395, 0.9980512402078595, -0.0009743798960703008,
             -0.06239208686501738, -0.0009743798960703008, 0.9995128100519649,
             -0.03119604343250869, 0.06239208686501738, 0.03119604343250869,
             0.9975640502598243],
            [0.0, 0.0, 0.0, 0.9659258262890682, -0.25881904510252074, 0.0, 0.25881904510252074,
             0.9659258262890682, 0.0, 0.0, 0.0, 1.0],
        ],
        contacts: &[
            [-0.018185411282391012, -0.06562362077699313, -0.16696054361038581,
             0.0909072943588045, 0.0, 0.0, -1.0],
            [-0.013410127691605878, -0.06577277239421542, -0.013961746472960973,
             0.09329493615419707, 0.0, 0.0, -1.0],
            [-0.0032802214642068256, 0.04215004927513551, 0.0941192743763341,
             0.0983598892678966, 0.0, 0.0, -1.0],
            [-0.005258208691687721, 0.19528520284387488, -0.27540164831682895,
             0.09737089565415614, 0.0, 0.0, -1.0],
        ],
    },
    // cylinder's side on a box edge: two contacts
    Reference {
        shapes: ["cylinder", "box"],
        sizes: [[0.2, 0.3, 0.0], [0.5, 0.4, 0.1]],
        margin: 0.0,
        poses: [
            [0.1, 0.05, 0.29, 1.0, 0.0, 0.0, 0.0, 2.220446049250313e-16, -1.0, 0.0, 1.0,
             2.220446049250313e-16],
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        ],
        contacts: &[
            [-0.009999999989313835, 0.09999793252377623, -0.25000000000000006,
             0.09500000000534309, 0.0, 0.0, -1.0],
            [-0.009999999989313973, 0.09999793252377623, 0.3499999999999999,
             0.09500000000534302, 0.0, 0.0, -1.0],
        ],
    },
    // cylinder, box within the margin only
    Reference {
        shapes: ["cylinder", "box"],
        sizes: [[0.2, 0.3, 0.0], [0.5, 0.4, 0.1]],
        margin: 0.05,
        poses: [
            [0.1, -0.1, 0.42, 0.9980512402078595, -0.0009743798960703008, -0.06239208686501738,
             -0.0009743798960703008, 0.9995128100519649, -0.03119604343250869,
             0.06239208686501738, 0.03119604343250869, 0.9975640502598243],
            [0.0, 0.0, 0.0, 0.9659258262890682, -0.25881904510252074, 0.0, 0.25881904510252074,
             0.9659258262890682, 0.0, 0.0, 0.0, 1.0],
        ],
        contacts: &[
            [0.006814588717608955, -0.06562362077699313, -0.16696054361038584,
             0.10340729435880448, 0.0, 0.0, -1.0],
            [0.02171977853579314, 0.042150049275135444, 0.09411927437633412,
             0.11085988926789657, 0.0, 0.0, -1.0],
            [0.03396614523644287, 0.2597255879176369, 0.050573472077473064,
             0.11698307261822144, 0.0, 0.0, -1.0],
            [0.02514257169351608, 0.26000118417042206, -0.2321314422707533,
             0.11257128584675805, 0.0, 0.0, -1.0],
        ],
    },
];

fn shape(kind: &str, size: [f64; 3]) -> Shape {
    match kind {
        "sphere" => Shape::Sphere { radius: size[0] },
        "capsule" => Shape::Capsule {
            radius: size[0],
            half_length: size[1],
        },
        "ellipsoid" => Shape::Ellipsoid {
            radii: Vec3::from(size),
        },
        "cylinder" => Shape::Cylinder {
            radius: size[0],
            half_length: size[1],
        },
        "box" => Shape::Box {
            half_extents: Vec3::from(size),
        },
        _ => Shape::Plane {
            half_extents: [0.0, 0.0],
        },
    }
}

#[test]
fn contacts_match_mujoco() {
    for (index, case) in REFERENCES.iter().enumerate() {
        let shapes = [0, 1].map(|i| shape(case.shapes[i], case.sizes[i]));
        let [first, second] = [0, 1].map(|i| {
            let pose = &case.poses[i];
            placed(
                &shapes[i],
                [pose[0], pose[1], pose[2]],
                Mat3::from_row_slice(&pose[3..]),
            )
        });
        let touches = collide(&first, &second, case.margin);
        assert_eq!(touches.len(), case.contacts.len(), "case {index}");
        for (touch, expected) in touches.iter().zip(case.contacts) {
            let position = Vec3::new(expected[1], expected[2], expected[3]);
            let normal = Vec3::new(expected[4], expected[5], expected[6]);
            assert!(
                (touch.distance - expected[0]).abs() <= MUJOCO_AGREEMENT,
                "case {index}"
            );
            assert!(
                (touch.position - position).norm() <= MUJOCO_AGREEMENT,
                "case {index}"
            );
            assert!(
                (touch.normal - normal).norm() <= MUJOCO_AGREEMENT,
                "case {index}"
            );
        }
    }
}

/// A cuboid of half-sides `h` as a mesh: its eight corners' hull.
fn cuboid_mesh(h: Vec3) -> Shape {
    use crate::collision::hull::ConvexHull;
    let corners: Vec<Vec3> = (0..8)
        .map(|k| {
            let sign = |bit: usize| if k >> bit & 1 == 1 { -1.0 } else { 1.0 };
            Vec3::new(sign(0) * h.x, sign(1) * h.y, sign(2) * h.z)
        })
        .collect();
    Shape::Mesh {
        source: crate::visual::MeshSource::Missing(String::new()),
        file_to_visual: nalgebra::Matrix4::identity(),
        hull: Some(std::sync::Arc::new(
            ConvexHull::new(&crate::io::mesh::TriangleMesh {
                vertices: corners,
                faces: Vec::new(),
            })
            .unwrap(),
        )),
    }
}

/// A rotation by `angle` about the unit `axis`.
fn turned(axis: Vec3, angle: f64) -> Mat3 {
    nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).into_inner()
}

#[test]
fn a_mesh_is_collided_as_the_box_of_its_corners() {
    // the same support points, faces and edges: every convex partner finds the same contacts
    let h = Vec3::new(0.05, 0.07, 0.1);
    let (mesh, cuboid) = (cuboid_mesh(h), Shape::Box { half_extents: h });
    let partners = [
        Shape::Cylinder {
            radius: 0.06,
            half_length: 0.05,
        },
        Shape::Ellipsoid {
            radii: Vec3::new(0.08, 0.06, 0.04),
        },
    ];
    let rotation = turned(Vec3::new(0.3, -0.5, 0.8), 0.9);
    for partner in &partners {
        let first = placed(partner, [0.0; 3], Mat3::identity());
        for (k, offset) in [[0.02, -0.03, 0.12], [0.1, 0.05, 0.02], [0.0, 0.0, 0.16]]
            .iter()
            .enumerate()
        {
            for margin in [0.0, 0.01] {
                let as_mesh = collide(&first, &placed(&mesh, *offset, rotation), margin);
                let as_box = collide(&first, &placed(&cuboid, *offset, rotation), margin);
                assert!(
                    !as_box.is_empty() || k == 2,
                    "{partner:?} at {offset:?}: no contact"
                );
                assert_eq!(as_mesh.len(), as_box.len(), "{partner:?} at {offset:?}");
                for touch in &as_box {
                    assert!(as_mesh
                        .iter()
                        .any(|t| (t.position - touch.position).norm() < ROUNDING
                            && (t.distance - touch.distance).abs() < ROUNDING
                            && (t.normal - touch.normal).norm() < ROUNDING));
                }
            }
        }
    }
}

#[test]
fn a_mesh_on_a_plane_touches_at_its_lowest_faces_corners() {
    let h = Vec3::new(0.05, 0.07, 0.1);
    let mesh = cuboid_mesh(h);
    let plane = Shape::Plane {
        half_extents: [0.0, 0.0],
    };
    let floor = placed(&plane, [0.0; 3], Mat3::identity());
    let mut touches = Vec::new();
    // flat, 1 mm deep: the bottom face's four corners
    plane_mesh(
        &floor,
        &placed(&mesh, [0.0, 0.0, 0.099], Mat3::identity()),
        0.0,
        &mut touches,
    );
    assert_eq!(touches.len(), 4);
    for touch in &touches {
        assert!((touch.distance + 0.001).abs() < ROUNDING);
        assert!((touch.position.z + 0.0005).abs() < ROUNDING);
        assert!((touch.position.x.abs() - h.x).abs() < ROUNDING);
        assert!((touch.position.y.abs() - h.y).abs() < ROUNDING);
        assert_eq!(touch.normal, Vec3::z());
    }
    // turned 40° about x: only the lower edge's two corners are below the plane
    touches.clear();
    let tilted = placed(
        &mesh,
        [0.0, 0.0, 0.05],
        turned(Vec3::x(), 40f64.to_radians()),
    );
    plane_mesh(&floor, &tilted, 0.0, &mut touches);
    assert_eq!(touches.len(), 2);
    let depth = 0.05 - h.z * 40f64.to_radians().cos() - h.y * 40f64.to_radians().sin();
    for touch in &touches {
        assert!((touch.distance - depth).abs() < ROUNDING);
    }
    // lifted beyond the margin: none
    touches.clear();
    plane_mesh(
        &floor,
        &placed(&mesh, [0.0, 0.0, 0.2], Mat3::identity()),
        0.01,
        &mut touches,
    );
    assert!(touches.is_empty());
}
