//! URDF loading: structure, conventions, and every kind of bad input giving a clear error.

use robodyn::io::{bundled_model, bundled_names, load_urdf_file, load_urdf_str, LoadOptions};
use robodyn::{Error, Joint};

fn error_of(text: &str) -> String {
    load_urdf_str(text, "bad.urdf", LoadOptions::default())
        .expect_err("must fail")
        .to_string()
}

fn robot(body: &str) -> String {
    format!("<robot name='r'>{body}</robot>")
}

const LINK_A: &str = "<link name='a'/>";
const LINK_B: &str = "<link name='b'/>";

/// Quarter turns in `rpy` (π/2 rounded to a double: cos = 6e-17, not 0) are stored as the exact
/// signed permutations they stand for, so that the joints after them take the turned products;
/// an angle that is not a quarter turn, even a near one, is kept as written.
#[test]
fn quarter_turns_in_rpy_are_stored_exactly() {
    let joint = |name: &str, parent: &str, child: &str, rpy: &str, axis: &str| {
        format!(
            "<joint name='{name}' type='revolute'><parent link='{parent}'/><child link='{child}'/>\
             <origin rpy='{rpy}' xyz='0 0.1 0.2'/><axis xyz='{axis}'/>\
             <limit lower='-3' upper='3' effort='1' velocity='1'/></joint>"
        )
    };
    let link = |name: &str| {
        format!(
            "<link name='{name}'><inertial><mass value='1'/>\
             <inertia ixx='0.1' iyy='0.1' izz='0.1' ixy='0' ixz='0' iyz='0'/></inertial></link>"
        )
    };
    let text = robot(&format!(
        "{}{}{}{}{}{}{}",
        link("base"),
        link("a"),
        link("b"),
        link("c"),
        joint("j1", "base", "a", "-1.5707963267948966 0 0", "0 0 1"),
        joint(
            "j2",
            "a",
            "b",
            "0 3.141592653589793 1.5707963267948966",
            "0 1 0"
        ),
        joint("j3", "b", "c", "1.5708 0 0", "0 0 1"),
    ));
    let model = load_urdf_str(&text, "quarter.urdf", LoadOptions::default()).unwrap();
    for i in [1, 2] {
        let rotation = model.x_tree()[i].rotation;
        assert!(
            rotation.iter().all(|x| [0.0, 1.0, -1.0].contains(x)),
            "{rotation}"
        );
        assert!((rotation.determinant() - 1.0).abs() == 0.0);
    }
    // about x by −π/2: row z of the tree rotation is e_y
    let turn = model
        .turn(1)
        .expect("a z joint after a quarter turn about x");
    assert_eq!((turn.axis, turn.column, turn.tree_rotates), (2, 1, true));
    assert!(model.turn(2).is_some());
    assert!(model.x_tree()[3]
        .rotation
        .iter()
        .any(|x| x.abs() > 0.0 && x.abs() < 1.0));
    assert_eq!(model.turn(3), None);
}

#[test]
fn bundled_models_load_with_their_gravity() {
    assert_eq!(bundled_names(), vec!["ur5", "planar2", "pendulum"]);
    let ur5 = bundled_model("ur5", false).unwrap();
    assert_eq!((ur5.nq, ur5.nv, ur5.nbodies()), (6, 6, 7));
    assert_eq!(ur5.joint_names[1], "shoulder_pan_joint");
    assert!(ur5.frame_index("tool0").is_ok());
    assert_eq!(
        bundled_model("planar2", false).unwrap().gravity.y,
        -robodyn::model::STANDARD_GRAVITY
    );
    let floating = bundled_model("ur5", true).unwrap();
    assert_eq!((floating.nq, floating.nv), (13, 12));
    assert_eq!(floating.joint_names[1], "root_joint");
    assert!(matches!(floating.joints()[1], Joint::Free));
    assert!(bundled_model("nope", false)
        .unwrap_err()
        .to_string()
        .contains("'nope'"));
}

#[test]
fn fixed_joints_merge_and_order_is_depth_first() {
    let text = robot(
        "<link name='base'/>
         <joint name='j1' type='revolute'><parent link='base'/><child link='l1'/><axis xyz='0 0 2'/>
           <limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
         <joint name='j3' type='prismatic'><parent link='base'/><child link='l3'/><axis xyz='1 0 0'/>
           <limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
         <link name='l1'><inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/></inertial></link>
         <link name='l3'/>
         <joint name='j2' type='continuous'><parent link='l1'/><child link='l2'/></joint>
         <link name='l2'/>
         <joint name='f' type='fixed'><parent link='l2'/><child link='tip'/><origin xyz='0 0 1'/></joint>
         <link name='tip'><inertial><mass value='2'/></inertial></link>
         <joint name='m' type='revolute'><parent link='l3'/><child link='l4'/><mimic joint='j1' multiplier='2' offset='0.5'/>
           <limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
         <link name='l4'/>",
    );
    let model = load_urdf_str(&text, "t.urdf", LoadOptions::default()).unwrap();
    assert_eq!(model.joint_names, vec!["universe", "j1", "j2", "j3", "m"]);
    assert_eq!(model.parent(), vec![0, 0, 1, 0, 3]);
    assert_eq!(
        model.joints()[1],
        Joint::Revolute {
            axis: nalgebra::Vector3::z()
        }
    );
    // the fixed link's mass is merged into l2's body, 1 m up its z axis
    assert_eq!(model.inertias[2].mass, 2.0);
    assert_eq!(
        model.inertias[2].first_moment,
        nalgebra::Vector3::new(0.0, 0.0, 2.0)
    );
    assert_eq!(model.frames[model.frame_index("tip").unwrap()].body, 2);
    assert_eq!(
        model.lower_position_limit.as_slice(),
        &[-1.0, f64::NEG_INFINITY, -1.0, -1.0]
    );
    assert_eq!(model.mimics.len(), 1);
    assert_eq!(
        (
            model.mimics[0].joint,
            model.mimics[0].mimicked,
            model.mimics[0].multiplier
        ),
        (4, 1, 2.0)
    );
}

#[test]
fn errors_name_the_element_and_what_is_wrong() {
    let cases: Vec<(String, &str)> = vec![
        ("<robot><link".into(), "malformed XML"),
        ("<notrobot/>".into(), "expected the root element <robot>"),
        (robot(&format!("{LINK_A}{LINK_B}<joint name='j' type='screw'><parent link='a'/><child link='b'/></joint>")), "unknown joint type 'screw'"),
        (robot(&format!("{LINK_A}<joint name='j' type='fixed'><parent link='a'/><child link='ghost'/></joint>")), "<child link='ghost'>: no link of that name"),
        (robot(&format!("{LINK_A}{LINK_B}")), "expected one root link"),
        (robot(&format!("{LINK_A}{LINK_B}<joint name='j1' type='fixed'><parent link='a'/><child link='b'/></joint><joint name='j2' type='fixed'><parent link='b'/><child link='a'/></joint>")), "cycle"),
        (robot(&format!("<link name='r'/>{LINK_A}{LINK_B}<joint name='j0' type='fixed'><parent link='r'/><child link='a'/></joint><joint name='j1' type='fixed'><parent link='a'/><child link='b'/></joint><joint name='j2' type='fixed'><parent link='b'/><child link='a'/></joint>")), "already has the parent joint"),
        (robot("<link name='a'><inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='-1' ixy='0' ixz='0' iyz='0'/></inertial></link>"), "positive semi-definite"),
        (robot("<link name='a'><inertial><mass value='-1'/></inertial></link>"), "mass >= 0"),
        (robot("<link name='a'><inertial><mass value='nan'/></inertial></link>"), "expected finite numbers"),
        (robot(&format!("{LINK_A}{LINK_B}<joint name='j' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 0'/></joint>")), "non-zero vector"),
        (robot(&format!("{LINK_A}{LINK_B}<joint name='j' type='revolute'><parent link='a'/><child link='b'/><origin xyz='1 2'/></joint>")), "expected 3 numbers"),
        (robot(&format!("{LINK_A}{LINK_B}<joint type='revolute'><parent link='a'/><child link='b'/></joint>")), "missing attribute 'name'"),
        (robot(""), "expected at least one <link>"),
    ];
    for (text, expected) in cases {
        let message = error_of(&text);
        assert!(
            message.contains(expected),
            "for {text}\n got: {message}\n expected it to contain: {expected}"
        );
        assert!(
            message.starts_with("bad.urdf"),
            "message must name the file: {message}"
        );
    }
    // the element and the line are named
    let message = error_of(&robot(&format!("{LINK_A}{LINK_B}\n<joint name='j' type='screw'><parent link='a'/><child link='b'/></joint>")));
    assert!(message.contains("<joint name='j'> (line 2)"), "{message}");
    let message = error_of(&robot(
        "<link name='a'>\n<inertial><mass value='-1'/></inertial></link>",
    ));
    assert!(
        message.contains("<link name='a'>/<inertial> (line 2)"),
        "{message}"
    );
}

#[test]
fn missing_file_is_its_own_error() {
    let error = load_urdf_file(
        std::path::Path::new("/no/such/robot.urdf"),
        LoadOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        error,
        Error::FileNotFound {
            path: "/no/such/robot.urdf".into()
        }
    );
}

#[test]
fn bad_states_are_rejected_with_the_argument_named() {
    let model = bundled_model("ur5", true).unwrap();
    let mut data = robodyn::Data::new(&model);
    let q = model.neutral();
    let v = vec![0.0; model.nv];
    let short =
        robodyn::algo::rnea(&model, &mut data, &q.as_slice()[..5], &v, &v, None).unwrap_err();
    assert_eq!(
        short.to_string(),
        "argument 'q': expected length 13, got length 5"
    );
    let mut nan = v.clone();
    nan[3] = f64::NAN;
    let error = robodyn::algo::aba(&model, &mut data, q.as_slice(), &v, &nan, None).unwrap_err();
    assert_eq!(
        error.to_string(),
        "argument 'tau': expected finite values, got NaN at index 3"
    );
    let mut unnormalised = q.clone();
    unnormalised[6] = 2.0;
    let error = robodyn::algo::crba(&model, &mut data, unnormalised.as_slice()).unwrap_err();
    assert!(error.to_string().contains("unit quaternion"), "{error}");
    assert!(model
        .frame_index("nope")
        .unwrap_err()
        .to_string()
        .contains("unknown frame 'nope'"));
}

#[test]
fn questionable_input_loads_with_a_warning() {
    // a mimic naming a joint that does not exist, and a non-physical inertia with the check off
    let text = robot(&format!(
        "<link name='a'><inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='-1' ixy='0' ixz='0' iyz='0'/></inertial></link>{LINK_B}
         <joint name='j' type='revolute'><parent link='a'/><child link='b'/><mimic joint='zz'/></joint>"
    ));
    let options = LoadOptions {
        check_inertia: false,
        ..LoadOptions::default()
    };
    let model = load_urdf_str(&text, "odd.urdf", options).unwrap();
    assert!(model.mimics.is_empty());
    assert_eq!(model.warnings.len(), 2, "{:?}", model.warnings);
    assert!(
        model.warnings[0].contains("positive semi-definite")
            && model.warnings[0].contains("check_inertia is off")
    );
    assert!(
        model.warnings[1].contains("1 <mimic> tag(s) ignored")
            && model.warnings[1].contains("'j' (line ")
            && model.warnings[1].contains("mimics 'zz'"),
        "{}",
        model.warnings[1]
    );
    // with the check on (the default) the inertia is an error
    assert!(load_urdf_str(&text, "odd.urdf", LoadOptions::default()).is_err());
}

#[test]
fn singular_dynamics_is_refused() {
    // floating, the UR5's massless base link can spin without moving the arm: M is singular
    let model = bundled_model("ur5", true).unwrap();
    let mut data = robodyn::Data::new(&model);
    let q = model.neutral();
    let zero = vec![0.0; model.nv];
    let error =
        robodyn::algo::aba(&model, &mut data, q.as_slice(), &zero, &zero, None).unwrap_err();
    assert!(error.to_string().contains("singular"), "{error}");
    let error = robodyn::algo::inverse_mass_matrix(&model, &mut data, q.as_slice()).unwrap_err();
    assert!(error.to_string().contains("singular"), "{error}");
}

#[test]
fn floating_joint_becomes_free() {
    let text = robot(
        "<link name='world'/><link name='box'><inertial><mass value='1'/><inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/></inertial></link>
         <joint name='float' type='floating'><parent link='world'/><child link='box'/><origin xyz='0 0 1'/></joint>",
    );
    let model = load_urdf_str(&text, "f.urdf", LoadOptions::default()).unwrap();
    assert_eq!((model.nq, model.nv), (7, 6));
    assert_eq!(model.joints()[1], Joint::Free);
    assert_eq!(
        model.neutral().as_slice(),
        &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    );
}
