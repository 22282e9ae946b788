//! The elements and attributes of URDF, as the specification lists them
//! (<http://wiki.ros.org/urdf/XML>: robot, link, joint and their children), and the common elements
//! that describe other things than the rigid-body tree (`<gazebo>`, `<transmission>`,
//! `<ros2_control>`, `<sensor>`; pybullet's `<contact>`), whose contents pass unchecked. Also
//! accepted because exporters write them and ROS's parser reads past them: `<material>` in a
//! `<collision>`, and SDFormat's `dont_collapse` on a joint.

use crate::io::schema::SchemaElement;

const fn element(
    name: &'static str,
    attributes: &'static [&'static str],
    children: &'static [usize],
) -> SchemaElement {
    SchemaElement {
        name,
        attributes: Some(attributes),
        children,
    }
}

const fn not_checked(name: &'static str) -> SchemaElement {
    SchemaElement {
        name,
        attributes: None,
        children: &[],
    }
}

/// Index 0 is `<robot>`.
pub(crate) const URDF_SCHEMA: &[SchemaElement] = &[
    /* 0 */ element("robot", &["name", "version"], &[1, 9, 19, 27, 28, 29, 30]),
    /* 1 */ element("link", &["name", "type"], &[2, 6, 16, 31]),
    /* 2 */ element("inertial", &[], &[3, 4, 5]),
    /* 3 */ element("origin", &["xyz", "rpy"], &[]),
    /* 4 */ element("mass", &["value"], &[]),
    /* 5 */ element("inertia", &["ixx", "ixy", "ixz", "iyy", "iyz", "izz"], &[]),
    /* 6 */ element("visual", &["name"], &[3, 7, 19]),
    /* 7 */ element("geometry", &[], &[8, 22, 23, 24, 25]),
    /* 8 */ element("box", &["size"], &[]),
    /* 9 */
    element(
        "joint",
        &["name", "type", "dont_collapse"],
        &[3, 10, 11, 12, 13, 14, 15, 17, 18],
    ),
    /* 10 */ element("parent", &["link"], &[]),
    /* 11 */ element("child", &["link"], &[]),
    /* 12 */ element("axis", &["xyz"], &[]),
    /* 13 */
    element(
        "calibration",
        &["rising", "falling", "reference_position"],
        &[],
    ),
    /* 14 */ element("dynamics", &["damping", "friction"], &[]),
    /* 15 */ element("limit", &["lower", "upper", "effort", "velocity"], &[]),
    /* 16 */ element("collision", &["name"], &[3, 7, 19, 26]),
    /* 17 */ element("mimic", &["joint", "multiplier", "offset"], &[]),
    /* 18 */
    element(
        "safety_controller",
        &[
            "soft_lower_limit",
            "soft_upper_limit",
            "k_position",
            "k_velocity",
        ],
        &[],
    ),
    /* 19 */ element("material", &["name"], &[20, 21]),
    /* 20 */ element("color", &["rgba"], &[]),
    /* 21 */ element("texture", &["filename"], &[]),
    /* 22 */ element("cylinder", &["radius", "length"], &[]),
    /* 23 */ element("sphere", &["radius"], &[]),
    /* 24 */ element("mesh", &["filename", "scale"], &[]),
    /* 25 */ element("capsule", &["radius", "length"], &[]),
    /* 26 */ not_checked("verbose"),
    /* 27 */ not_checked("transmission"),
    /* 28 */ not_checked("gazebo"),
    /* 29 */ not_checked("ros2_control"),
    /* 30 */ not_checked("sensor"),
    /* 31 */ not_checked("contact"),
];
