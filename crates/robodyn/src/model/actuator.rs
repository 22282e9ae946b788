//! Actuators (MJCF `<actuator>`): the generalised forces a control vector produces.
//!
//! Reference: MuJoCo's documentation, "Computation", §Actuation model. An actuator with a joint
//! transmission of gear g on a hinge or slide has length `l = g q_j` and velocity `l̇ = g q̇_j`;
//! with control u (clamped to `ctrlrange` when limited) its scalar force is
//! ```text
//!   f = (a₀ + a₁ l + a₂ l̇) u + (b₀ + b₁ l + b₂ l̇)        (gain a, bias b: MuJoCo's
//!                                                             gainprm and biasprm, affine)
//! ```
//! clamped to `forcerange` when limited, and it adds `g f` to the joint's generalised force, whose
//! total is clamped to the joint's `actuatorfrcrange` where it has one. A
//! `motor` has a = (1, 0, 0), b = 0; a `position` a = (k_p, 0, 0), b = (0, −k_p, −k_v); a `velocity`
//! a = (k_v, 0, 0), b = (0, 0, −k_v). Inputs: q, q̇, the controls (nu). Cost: O(nu).

use super::Model;
use crate::error::{check_vector, Result};

/// One actuator: a joint transmission, an affine gain and bias, optional ranges.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Actuator {
    /// The actuator's name (MJCF `name`; `actuator<k>` when the file gives none).
    pub name: String,
    /// The velocity coordinate of the hinge or slide it drives; `None` for an actuator robodyn
    /// does not model (its loader says which and why), which exerts no force.
    pub coordinate: Option<usize>,
    /// The coordinate of the same joint in q (its length is `gear q`).
    pub position: usize,
    /// The fixed tendon ([`Model::tendons`]) it pulls on instead of a joint (its length is
    /// `gear L`).
    #[serde(default)]
    pub tendon: Option<usize>,
    /// g: the moment arm, the length's scale (MJCF `gear[0]`).
    pub gear: f64,
    /// a: the gain's constant, length and velocity terms (MJCF `gainprm[0..3]`).
    pub gain: [f64; 3],
    /// b: the bias's constant, length and velocity terms (MJCF `biasprm[0..3]`).
    pub bias: [f64; 3],
    /// The control's range where it is limited (MJCF `ctrlrange` with `ctrllimited`).
    pub ctrl_range: Option<(f64, f64)>,
    /// The force's range where it is limited (MJCF `forcerange` with `forcelimited`).
    pub force_range: Option<(f64, f64)>,
}

impl Actuator {
    /// f: the actuator's scalar force at joint position `q_j` and velocity `v_j` under control
    /// `u`.
    pub fn force(&self, q_j: f64, v_j: f64, u: f64) -> f64 {
        // l = g q_j, l̇ = g q̇_j
        self.force_at(self.gear * q_j, self.gear * v_j, u)
    }

    /// f at its length l and rate l̇ under control `u`.
    pub fn force_at(&self, l: f64, l_dot: f64, u: f64) -> f64 {
        let (a, b) = (&self.gain, &self.bias);
        let u = self.ctrl_range.map_or(u, |(low, high)| u.clamp(low, high));
        // f = (a₀ + a₁ l + a₂ l̇) u + (b₀ + b₁ l + b₂ l̇)
        let f = (a[0] + a[1] * l + a[2] * l_dot) * u + (b[0] + b[1] * l + b[2] * l_dot);
        self.force_range.map_or(f, |(low, high)| f.clamp(low, high))
    }
}

impl Model {
    /// The moment arms of `actuator`: (velocity coordinate, configuration coordinate, ∂l/∂q̇)
    /// with its length `l = Σ arm q` and `τ = Σ arm f e_k`: `gear` on its joint, `gear c_k` on
    /// each joint of its tendon; none for an actuator robodyn does not model.
    pub fn actuator_arms<'a>(
        &'a self,
        actuator: &'a Actuator,
    ) -> impl Iterator<Item = (usize, usize, f64)> + 'a {
        let joint = actuator
            .coordinate
            .map(|c| (c, actuator.position, actuator.gear));
        let tendon = actuator.tendon.map(|t| &self.tendons[t]);
        let tendon_arms = tendon
            .into_iter()
            .flat_map(move |t| t.entries(self))
            .map(move |(k, p, c)| (k, p, actuator.gear * c));
        joint.into_iter().chain(tendon_arms)
    }

    /// `actuator`'s length l = Σ arm q and its rate l̇ = Σ arm q̇ at (q, q̇).
    pub fn actuator_length_and_rate(
        &self,
        actuator: &Actuator,
        q: &[f64],
        v: &[f64],
    ) -> (f64, f64) {
        self.actuator_arms(actuator)
            .fold((0.0, 0.0), |(l, rate), (k, p, arm)| {
                (l + arm * q[p], rate + arm * v[k])
            })
    }

    /// nu: the number of actuators (of the controls).
    pub fn nu(&self) -> usize {
        self.actuators.len()
    }

    /// The generalised forces (nv) the actuators exert under controls `ctrl` (nu, in the
    /// order of [`Model::actuators`]) at (q, q̇), into `tau`: MuJoCo's `qfrc_actuator`.
    pub fn actuator_forces(
        &self,
        q: &[f64],
        v: &[f64],
        ctrl: &[f64],
        tau: &mut [f64],
    ) -> Result<()> {
        self.check_configuration(q)?;
        check_vector("v", v, self.nv)?;
        check_vector("ctrl", ctrl, self.nu())?;
        tau.fill(0.0);
        for (actuator, &u) in self.actuators.iter().zip(ctrl) {
            // τ += arm f(l, l̇, u)
            let (length, rate) = self.actuator_length_and_rate(actuator, q, v);
            let force = actuator.force_at(length, rate, u);
            for (k, _, arm) in self.actuator_arms(actuator) {
                tau[k] += arm * force;
            }
        }
        // a hinge's or slide's total actuator force is clamped to its range
        for (body, range) in self.actuator_force_range.iter().enumerate() {
            if let (Some((low, high)), 1) = (range, self.joints[body].nv()) {
                let c = self.idx_v[body];
                tau[c] = tau[c].clamp(*low, *high);
            }
        }
        Ok(())
    }
}
