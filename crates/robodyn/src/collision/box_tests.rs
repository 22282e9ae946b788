//! The box colliders against contacts worked out by hand and against MuJoCo 4.0.0's.

use super::super::box_box::box_box;
use super::*;
use crate::collision::Collider;
use crate::spatial::Mat3;
use nalgebra::{Quaternion, UnitQuaternion};

/// Agreement with contacts worked out by hand (a few roundings of numbers near 1).
const CLOSED_FORM: f64 = 1e-12;
/// Agreement with MuJoCo's contacts: the same arithmetic on rotations that differ from
/// MuJoCo's by rounding (built here from the quaternions).
const MUJOCO_AGREEMENT: f64 = 1e-9;

fn cuboid(x: f64, y: f64, z: f64) -> Shape {
    Shape::Box {
        half_extents: Vec3::new(x, y, z),
    }
}

fn placed(shape: &Shape, rotation: Mat3, position: Vec3) -> Placed<'_> {
    Placed {
        shape,
        rotation,
        position,
    }
}

fn collide(collider: Collider, first: &Placed, second: &Placed, margin: f64) -> Vec<Touch> {
    let mut touches = Vec::new();
    collider(first, second, margin, &mut touches);
    touches
}

fn assert_touch(touch: &Touch, distance: f64, position: Vec3, normal: Vec3, tolerance: f64) {
    let error = (touch.distance - distance)
        .abs()
        .max((touch.position - position).amax())
        .max((touch.normal - normal).amax());
    assert!(
        error < tolerance,
        "{touch:?} is not ({distance}, {position:?}, {normal:?})"
    );
}

/// 90° about z: the box's x along world y.
fn quarter_turn_z() -> Mat3 {
    Mat3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
}

#[test]
fn sphere_on_a_face_an_edge_and_a_corner() {
    // the box spans x ∈ [0, 2], y ∈ [0, 4], z ∈ [2.5, 3.5] in the world
    let block = cuboid(2.0, 1.0, 0.5);
    let boxed = placed(&block, quarter_turn_z(), Vec3::new(1.0, 2.0, 3.0));
    let ball = |radius| Shape::Sphere { radius };
    let at = |shape, x, y, z| placed(shape, Mat3::identity(), Vec3::new(x, y, z));
    // 0.1 into the top face
    let face = ball(0.5);
    let touches = collide(sphere_box, &at(&face, 1.2, 2.3, 3.9), &boxed, 0.0);
    let down = Vec3::new(0.0, 0.0, -1.0);
    assert_touch(
        &touches[0],
        -0.1,
        Vec3::new(1.2, 2.3, 3.45),
        down,
        CLOSED_FORM,
    );
    // 0.5 from the edge x = 2, z = 3.5 along (0.6, 0, 0.8), radius 0.6
    let edge = ball(0.6);
    let touches = collide(sphere_box, &at(&edge, 2.3, 2.3, 3.9), &boxed, 0.0);
    let normal = Vec3::new(-0.6, 0.0, -0.8);
    assert_touch(
        &touches[0],
        -0.1,
        Vec3::new(1.97, 2.3, 3.46),
        normal,
        CLOSED_FORM,
    );
    // 0.3 from the corner (2, 4, 3.5) along (1, 2, 2)/3, radius 0.25: 0.05 apart
    let corner = ball(0.25);
    let sphere = at(&corner, 2.1, 4.2, 3.7);
    let touches = collide(sphere_box, &sphere, &boxed, 0.1);
    let outward = Vec3::new(1.0, 2.0, 2.0) / 3.0;
    let midway = Vec3::new(2.0, 4.0, 3.5) + outward * 0.025;
    assert_touch(&touches[0], 0.05, midway, -outward, CLOSED_FORM);
    assert!(collide(sphere_box, &sphere, &boxed, 0.04).is_empty());
}

#[test]
fn sphere_inside_a_box_leaves_through_the_nearest_face() {
    let block = cuboid(2.0, 1.0, 0.5);
    let boxed = placed(&block, quarter_turn_z(), Vec3::new(1.0, 2.0, 3.0));
    let ball = Shape::Sphere { radius: 0.3 };
    // 0.1 below the top face, further from every other
    let sphere = placed(&ball, Mat3::identity(), Vec3::new(1.2, 2.3, 3.4));
    let touches = collide(sphere_box, &sphere, &boxed, 0.0);
    let down = Vec3::new(0.0, 0.0, -1.0);
    assert_touch(
        &touches[0],
        -0.4,
        Vec3::new(1.2, 2.3, 3.3),
        down,
        CLOSED_FORM,
    );
}

#[test]
fn capsule_lying_on_a_face_touches_at_both_ends() {
    let block = cuboid(1.0, 1.0, 0.5);
    let boxed = placed(&block, Mat3::identity(), Vec3::zeros());
    let rod = Shape::Capsule {
        radius: 0.1,
        half_length: 0.4,
    };
    // its axis along x, 0.02 into the top face
    let along_x = Mat3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0);
    let capsule = placed(&rod, along_x, Vec3::new(0.2, 0.1, 0.58));
    let touches = collide(capsule_box, &capsule, &boxed, 0.0);
    let down = Vec3::new(0.0, 0.0, -1.0);
    assert_eq!(touches.len(), 2);
    assert_touch(
        &touches[0],
        -0.02,
        Vec3::new(-0.2, 0.1, 0.49),
        down,
        CLOSED_FORM,
    );
    assert_touch(
        &touches[1],
        -0.02,
        Vec3::new(0.6, 0.1, 0.49),
        down,
        CLOSED_FORM,
    );
    // standing on its lower end: the upper end is far above the face
    let upright = placed(&rod, Mat3::identity(), Vec3::new(0.3, 0.2, 0.98));
    let touches = collide(capsule_box, &upright, &boxed, 0.0);
    assert_eq!(touches.len(), 1);
    assert_touch(
        &touches[0],
        -0.02,
        Vec3::new(0.3, 0.2, 0.49),
        down,
        CLOSED_FORM,
    );
}

#[test]
fn capsule_along_an_edge_beyond_it_touches_at_both_ends() {
    // the nearest edge is parallel to the segment; the far edges along y and z at x = −5
    // find the corner, nearer than MuJoCo 4.0.0's bound (m + 2 (r + l + Σ h))² (its
    // `mjc_CapsuleBox` gives these two contacts; with the bound not squared, none)
    let block = cuboid(5.0, 0.5, 1.0);
    let boxed = placed(&block, Mat3::identity(), Vec3::zeros());
    let rod = Shape::Capsule {
        radius: 1.0,
        half_length: 0.3,
    };
    // 1.05 from the edge y = −0.5, z = 1 along (0, −0.6, 0.8)
    let along_x = Mat3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0);
    let capsule = placed(&rod, along_x, Vec3::new(-0.5, -1.13, 1.84));
    let touches = collide(capsule_box, &capsule, &boxed, 0.1);
    let normal = Vec3::new(0.0, 0.6, -0.8);
    assert_eq!(touches.len(), 2);
    for (touch, x) in touches.iter().zip([-0.8, -0.2]) {
        assert_touch(touch, 0.05, Vec3::new(x, -0.515, 1.02), normal, CLOSED_FORM);
    }
}

#[test]
fn box_on_a_box_face_touches_at_four_corners() {
    let (slab, block) = (cuboid(1.0, 1.0, 0.5), cuboid(0.3, 0.3, 0.5));
    let below = placed(&slab, Mat3::identity(), Vec3::zeros());
    let above = placed(&block, Mat3::identity(), Vec3::new(0.1, 0.05, 0.98));
    // the incident face's corners, in MuJoCo's winding, 0.02 into the top face
    let touches = collide(box_box, &below, &above, 0.0);
    let corners = [(0.4, 0.35), (-0.2, 0.35), (-0.2, -0.25), (0.4, -0.25)];
    assert_eq!(touches.len(), 4);
    for (touch, (x, y)) in touches.iter().zip(corners) {
        let up = Vec3::new(0.0, 0.0, 1.0);
        assert_touch(touch, -0.02, Vec3::new(x, y, 0.49), up, CLOSED_FORM);
    }
    // the other way round: the normal still points from the first to the second
    let touches = collide(box_box, &above, &below, 0.0);
    assert_eq!(touches.len(), 4);
    for touch in &touches {
        assert!((touch.normal - Vec3::new(0.0, 0.0, -1.0)).amax() < CLOSED_FORM);
        assert!((touch.distance + 0.02).abs() < CLOSED_FORM);
    }
    // lifted 0.05 clear: only within a margin above that
    let lifted = placed(&block, Mat3::identity(), Vec3::new(0.1, 0.05, 1.05));
    assert!(collide(box_box, &below, &lifted, 0.04).is_empty());
    assert_eq!(collide(box_box, &below, &lifted, 0.06).len(), 4);
}

#[test]
fn crossed_edges_touch_once_midway() {
    // cubes turned 45° about y and about x: a top edge along y under a bottom edge along x
    let (c, s) = (
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
    );
    let about_y = Mat3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c);
    let about_x = Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c);
    let cube = cuboid(1.0, 1.0, 1.0);
    let lower = placed(&cube, about_y, Vec3::zeros());
    let height = 2.0 * std::f64::consts::SQRT_2 - 0.1;
    let upper = placed(&cube, about_x, Vec3::new(0.0, 0.0, height));
    let touches = collide(box_box, &lower, &upper, 0.0);
    assert_eq!(touches.len(), 1);
    let midway = Vec3::new(0.0, 0.0, height / 2.0);
    let up = Vec3::new(0.0, 0.0, 1.0);
    assert_touch(&touches[0], -0.1, midway, up, CLOSED_FORM);
}

/// Reference cases: MuJoCo 4.0.0's `mj_collision` output for two geoms on free bodies (the
/// first of `kind`, the second a box), the pair given as a `<contact><pair>` of the given
/// margin, `qpos` set to the two poses, after `mj_kinematics`. Per case: the first's sizes,
/// the box's half extents, the margin; each pose (position, quaternion w x y z); the number
/// of contacts; each contact's distance and position, then its normal (`frame` row 0).
/// Lines starting with `#` say what the case is.
const SPHERE_BOX: &str = "
# 0.09 off a face: within the margin
0.17   0.88 0.04 0.93   0.19
-0.67 -1.47 -1.28   -0.13 -0.59 -0.35 0.71
-0.69 -0.33 -0.56   -0.71 0 0 0.71
1
0.09000000000000011   -0.67 -1.2550000000000003 -1.2800000000000002
    0.0 1.0 0.0
# centre inside the box
0.16   0.79 0.79 0.79   0.09
-1.01 0.26 1.4   0.36 0.11 -0.93 -0.03
-0.99 0.06 1.34   1 0 0 0
1
-0.7500000000000001   -1.01 0.47500000000000003 1.4
    0.0 -1.0 0.0
# into a corner
0.44   0.06 0.23 0.71   0
0.09 1.17 -1.35   0.03 -0.67 0.04 0.74
-0.03 0.88 -0.58   1 0 0 0
1
-0.3360769515458673   -0.0670170592217176 1.0129829407782824 -1.1929829407782822
    -0.5773502691896255 -0.5773502691896247 0.5773502691896271
# off a face, beyond the margin
0.07   0.59 0.41 0.44   0
0.44 0.67 -1.85   -0.9 -0.14 -0.4 0.07
-0.01 0.58 -1.29   -0.02 0.52 -0.26 0.81
0
# into a corner of a turned box
0.22   0.03 0.6 0.33   0
-0.62 0.25 -0.16   -0.06 -0 -0.61 0.79
-1.04 0.51 -0.68   0.04 0.8 0.55 0.22
1
-0.183655441230618   -0.6959291242070088 0.23457184438640893 -0.2621022688983292
    -0.5923989537481683 -0.1203704552002674 -0.7966018033578359
";

const CAPSULE_BOX: &str = "
# at a corner, then across a face
0.31 0.88   0.23 0.6 0.09   0
-2.12 -1.5 -0.38   0.33 -0.91 0.04 -0.23
-1.62 -2.12 0.25   0 0.71 0.71 0
2
-0.09295124348261644   -2.1801332737399397 -1.89333631095928 0.18365368010964817
    0.8577986644689942 -0.07178625770410241 0.5089481156660766
-0.015042864346948515   -2.2124785678265257 -2.0167281896116993 0.2127907211296015
    1.0 0.0 0.0
# across an edge, then over a face
0.17 0.64   0.39 0.65 0.87   0
-0.61 -1.28 0.44   -0.03 -0.62 0.78 0.07
-1 -0.4 -0.43   -0.03 -0.14 -0.68 -0.72
2
-0.11588581371517231   -0.7618827972607382 -1.2299258234129389 0.12995331087478373
    -0.9609632793036379 0.2342894324063068 0.14716670035279453
-0.11168125198507697   -0.8051087898907486 -1.2072223906973536 -0.1742325973809415
    -0.9590532307999602 0.2332967142714472 0.1605912313991811
# an end over a face, the segment along it
0.35 0.51   0.06 0.23 0.71   0
-0.05 1.37 -1.43   1 0 0 -0
-0.03 0.88 -0.58   1 0 0 0
2
-0.08999999999999986   -0.05 1.065 -0.9199999999999999
    0.0 -1.0 0.0
-0.08999999999999986   -0.05 1.065 -1.29
    0.0 -1.0 4.2700885562506e-16
# an end inside the box
0.17 0.82   0.55 0.88 0.38   0.03
-1.17 0.04 0.53   0.96 0.06 -0.28 0.04
-1.03 -0.08 0.04   -0 -0 -0 1
1
-0.3537843215280544   -0.7353641066454437 0.15224830879426976 -0.1631078392359728
    0.0 0.0 1.0
# across an edge, pointing away (no second point)
0.17 0.92   0.47 0.47 0.47   0.18
-0.5 -0.62 0.88   -0.01 -0.61 -0.1 0.79
-0.12 -1 1.12   0 0 0 1
1
-0.12201977496119273   0.2797260895553746 -0.5910098874805965 0.6837308314812266
    0.0 -1.0 0.0
";

const BOX_BOX: &str = "
# on a face of the first, tilted
0.22 0.11 0.44   0.16 0.16 0.16   0.13
-0.21 -0.63 -2.06   0.51 0.5 0.5 -0.5
-0.21 -0.63 -1.76   0 1 0 0
4
-0.08269999999999995   -0.10018870658821152 -0.7895906345906346 -1.8786540936540936
    -0.009999009999010045 0.009900009900009943 0.999900999901
-0.08049999999999993   -0.32019948985543045 -0.7896015246015247 -1.8797539847539848
    -0.009999009999010045 0.009900009900009943 0.999900999901
-0.07729999999999994   -0.32338349143943207 -0.4696173646173646 -1.8813538263538263
    -0.009999009999010045 0.009900009900009943 0.999900999901
-0.07949999999999996   -0.10337270817221313 -0.46960647460647453 -1.8802539352539354
    -0.009999009999010045 0.009900009900009943 0.999900999901
# on a face of the second
0.28 0.66 0.41   0.45 0.84 0.84   0.01
-1.54 -0.98 2.03   0 -0.71 0 0.71
-1.51 -0.98 1.39   -0.71 -0 -0.71 0
4
-0.09000000000000014   -1.9500000000000002 -1.6400000000000006 1.795
    0.0 0.0 -1.0
-0.09000000000000014   -1.9500000000000002 -0.3199999999999995 1.795
    0.0 0.0 -1.0
-0.09000000000000014   -1.13 -0.3199999999999995 1.795
    0.0 0.0 -1.0
-0.09000000000000014   -1.13 -1.6400000000000006 1.795
    0.0 0.0 -1.0
# crossed edges, within the margin
0.72 0.86 0.7   0.09 0.09 0.09   0.17
-0.78 -2.4 -0.06   0.59 -0.03 -0.37 -0.72
-0.78 -1.17 -0.06   0.71 0 0 0.71
1
0.14927771754987526   -0.8837660878594444 -1.334154993331522 0.04901439309326949
    0.039313470504378056 0.9992269266972851 0.0
# a face of the second clipped to six vertices
0.03 0.03 0.03   0.01 0.03 0.04   0.01
0.92 0.21 0.37   0.65 0.27 0.66 0.27
0.96 0.19 0.37   -0.5 0.5 0.5 -0.5
6
-0.030458015267175648   0.9352290076335877 0.19819338422391858 0.4
    1.0 -0.0 -0.0
-0.030320089849782468   0.9351600449248912 0.18 0.3819317703214937
    1.0 -0.0 -0.0
-0.030000000000000072   0.935 0.18 0.35740458015267174
    1.0 -0.0 -0.0
-0.029679865206402766   0.9348399326032013 0.19728727885425443 0.33999999999999997
    1.0 -0.0 -0.0
-0.029665271966527268   0.9348326359832636 0.2 0.33999999999999997
    1.0 -0.0 -0.0
-0.03044829647340115   0.9352241482367005 0.2 0.4
    1.0 -0.0 -0.0
# apart
0.31 0.29 0.47   0.79 0.79 0.79   0.09
-1 -1.62 0.88   -0 -0.71 -0.71 0
-1 0 1.38   1 0 0 0
0
";

fn matches_mujoco(collider: Collider, sizes: usize, cases: &str) {
    let numbers: Vec<f64> = cases
        .lines()
        .filter(|line| !line.trim_start().starts_with('#'))
        .flat_map(str::split_whitespace)
        .map(|n| n.parse().unwrap())
        .collect();
    let mut numbers = numbers.into_iter();
    let mut take = |n: usize| -> Vec<f64> { numbers.by_ref().take(n).collect() };
    let vector = |v: &[f64]| Vec3::new(v[0], v[1], v[2]);
    let mut count = 0;
    loop {
        let size = take(sizes);
        if size.is_empty() {
            break;
        }
        let first_shape = match sizes {
            1 => Shape::Sphere { radius: size[0] },
            2 => Shape::Capsule {
                radius: size[0],
                half_length: size[1],
            },
            _ => cuboid(size[0], size[1], size[2]),
        };
        let half = take(3);
        let second_shape = cuboid(half[0], half[1], half[2]);
        let margin = take(1)[0];
        let mut pose = |shape| {
            let p = take(7);
            let turn = Quaternion::new(p[3], p[4], p[5], p[6]);
            let rotation = UnitQuaternion::from_quaternion(turn).to_rotation_matrix();
            placed(shape, rotation.into_inner(), vector(&p))
        };
        let (first, second) = (pose(&first_shape), pose(&second_shape));
        let touches = collide(collider, &first, &second, margin);
        assert_eq!(touches.len(), take(1)[0] as usize, "case {count}");
        for touch in &touches {
            let (at, normal) = (take(4), take(3));
            let position = vector(&at[1..]);
            assert_touch(touch, at[0], position, vector(&normal), MUJOCO_AGREEMENT);
        }
        count += 1;
    }
    assert_eq!(count, 5);
}

#[test]
fn sphere_box_matches_mujoco() {
    matches_mujoco(sphere_box, 1, SPHERE_BOX);
}

#[test]
fn capsule_box_matches_mujoco() {
    matches_mujoco(capsule_box, 2, CAPSULE_BOX);
}

#[test]
fn box_box_matches_mujoco() {
    matches_mujoco(box_box, 3, BOX_BOX);
}
