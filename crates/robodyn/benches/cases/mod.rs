//! What the benchmarks time: the robots (the bundled UR5 and, when the `example-robot-data`
//! URDFs are found (`ROBODYN_ROBOTS_DIR` or the test virtual environment), its UR5, Panda and
//! Talos, the robots `benchmarks/pinocchio_native.sh` times with Pinocchio) and the algorithms,
//! shared by the criterion benchmarks and the instruction counts.

use rand::{rngs::StdRng, SeedableRng};
use robodyn::algo::{
    aba, aba_derivatives, centroidal_momentum_matrix, coriolis_matrix, crba, forward_kinematics,
    frame_pose, generalized_gravity, jacobian, rnea, rnea_derivatives, DerivativesInto, Reference,
};
use robodyn::io::{bundled_model, load_urdf_file, LoadOptions};
use robodyn::{Data, Model};
use std::hint::black_box;
use std::path::PathBuf;

/// The example-robot-data robots directory, if present.
pub fn robots_dir() -> Option<PathBuf> {
    let dir = std::env::var("ROBODYN_ROBOTS_DIR").map(PathBuf::from).unwrap_or_else(|_| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../.venv/lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data/robots")
    });
    dir.is_dir().then_some(dir)
}

/// (name, model, the frame whose Jacobian and pose are timed).
pub fn models() -> Vec<(&'static str, Model, &'static str)> {
    let mut models = vec![(
        "ur5 (bundled)",
        bundled_model("ur5", false).expect("bundled ur5"),
        "tool0",
    )];
    if let Some(dir) = robots_dir() {
        for (name, path, floating, frame) in [
            ("ur5", "ur_description/urdf/ur5_robot.urdf", false, "tool0"),
            (
                "panda",
                "panda_description/urdf/panda.urdf",
                false,
                "panda_hand_tcp",
            ),
            (
                "talos",
                "talos_data/robots/talos_full_v2.urdf",
                true,
                "gripper_left_fingertip_1_link",
            ),
        ] {
            if let Ok(model) = load_urdf_file(&dir.join(path), LoadOptions::floating(floating)) {
                models.push((name, model, frame));
            }
        }
    }
    models
}

/// The algorithms timed, by name.
pub const ALGORITHMS: [&str; 11] = [
    "forward_kinematics",
    "frame_pose",
    "jacobian",
    "rnea",
    "gravity",
    "crba",
    "coriolis_matrix",
    "centroidal_momentum_matrix",
    "aba",
    "rnea_derivatives",
    "aba_derivatives",
];

/// A model's workspace and the state every algorithm runs at.
pub struct Bench<'m> {
    model: &'m Model,
    data: Data,
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    frame: usize,
}

impl<'m> Bench<'m> {
    pub fn new(model: &'m Model, frame: &str) -> Self {
        let mut rng = StdRng::seed_from_u64(7);
        Bench {
            model,
            data: Data::new(model),
            q: model.random_configuration(&mut rng).as_slice().to_vec(),
            v: vec![0.5; model.nv],
            a: vec![0.25; model.nv],
            frame: model.frame_index(frame).expect("benchmark frame"),
        }
    }

    /// Runs `algorithm` (one of [`ALGORITHMS`]) once, returning a number of its result.
    pub fn run(&mut self, algorithm: &str) -> f64 {
        let (model, data, frame) = (self.model, &mut self.data, self.frame);
        let (q, v, a) = (black_box(&self.q[..]), &self.v[..], &self.a[..]);
        let result = match algorithm {
            "forward_kinematics" => forward_kinematics(model, data, q).map(|x| x[1].translation.x),
            "frame_pose" => frame_pose(model, data, q, frame).map(|x| x.translation.x),
            "jacobian" => jacobian(model, data, q, frame, Reference::World).map(|j| j[0]),
            "rnea" => rnea(model, data, q, v, a, None).map(|t| t[0]),
            "gravity" => generalized_gravity(model, data, q).map(|g| g[0]),
            "crba" => crba(model, data, q).map(|m| m[0]),
            "coriolis_matrix" => coriolis_matrix(model, data, q, v).map(|m| m[0]),
            "centroidal_momentum_matrix" => {
                centroidal_momentum_matrix(model, data, q).map(|m| m[0])
            }
            "aba" => aba(model, data, q, v, a, None).map(|t| t[0]),
            "rnea_derivatives" => {
                rnea_derivatives(model, data, q, v, a, None, DerivativesInto::Data)
                    .map(|()| data.dtau_dq[0])
            }
            "aba_derivatives" => aba_derivatives(model, data, q, v, a, None, DerivativesInto::Data)
                .map(|()| data.dqdd_dq[0]),
            other => panic!("unknown algorithm {other}; expected one of {ALGORITHMS:?}"),
        };
        result.expect("benchmark state")
    }
}
