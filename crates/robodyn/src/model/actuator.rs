//! Actuators (MJCF `<actuator>`): the generalised forces a control vector produces.
//!
//! Reference: MuJoCo's documentation, "Computation", §Actuation model. An actuator with a joint
//! transmission of gear g on a hinge or slide has length `l = g q_j` and velocity `l̇ = g q̇_j`;
//! with control u (clamped to `ctrlrange` when limited, unless the `clampctrl` flag is
//! disabled) its scalar force is
//! ```text
//!   f = (a₀ + a₁ l + a₂ l̇) u + (b₀ + b₁ l + b₂ l̇)        (gain a, bias b: MuJoCo's
//!                                                             gainprm and biasprm, affine)
//! ```
//! clamped to `forcerange` when limited, and it adds `g f` to the joint's generalised force, whose
//! total is clamped to the joint's `actuatorfrcrange` where it has one. The actuators on a
//! tendon with an `actuatorfrcrange` [f₋, f₊] are scaled together first, before each one's
//! `forcerange`: where the sum F = Σ f of their forces leaves the range, each f becomes
//! f f₊ / F (or f f₋ / F) (MuJoCo's `mj_fwdActuation`, in that order). On a tendon of length L
//! and Jacobian J (fixed or spatial, [`TendonKinematics`]) `l = g L`, `l̇ = g J q̇`, and it adds
//! `g Jᵀ f`: its moment arms are g J, which move with q on a spatial tendon. A `motor` has
//! a = (1, 0, 0), b = 0; a `position` a = (k_p, 0, 0), b = (0, −k_p, −k_v); a `velocity`
//! a = (k_v, 0, 0), b = (0, 0, −k_v). Inputs: q, q̇, the controls (nu), the activations (na).
//! Cost: O(nu).
//!
//! §Activation dynamics: an actuator with a `dyntype` other than none has a state w (MuJoCo's
//! `act`, one per such actuator, in the actuators' order) that replaces u in the force, and
//! evolves under the clamped control u:
//! ```text
//!   integrator     ẇ = u
//!   filter         ẇ = (u − w) / τ                         (τ = dynprm[0], at least 1e-15)
//!   filterexact    the same ẇ, integrated exactly over a step h:
//!                  w₁ = w + ẇ τ (1 − e^(−h/τ))              (else w₁ = w + h ẇ)
//! ```
//! w₁ clamped to `actrange` when limited. With `actearly` the force takes w₁ instead of w (the
//! force answers the control within the same step). With the `actuation` flag disabled the
//! actuators exert nothing and every ẇ is 0.

use super::Model;
use crate::error::{check_length, check_vector, Result};
use crate::soft::tendons::TendonKinematics;

/// One actuator's output ([`Model::actuator_scalar_forces`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorForce {
    /// What its gain multiplies ([`Actuator::input`]).
    pub input: f64,
    /// Its force f (MuJoCo's `actuator_force`).
    pub force: f64,
    /// Whether f sits on its `forcerange` or its tendon's forces were scaled into the tendon's
    /// `actuatorfrcrange`: f then does not answer a change of velocity, and MuJoCo's implicit
    /// integrators leave it out of ∂f/∂q̇ (MuJoCo 4.0, measured: `qDeriv`).
    pub saturated: bool,
}

/// A below-this time constant is taken as this (MuJoCo's `mjMINVAL`).
const MIN_TIME_CONSTANT: f64 = 1e-15;

/// How an actuator's activation w evolves under its control u (MJCF `dyntype`, `dynprm`).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ActivationDynamics {
    /// No activation: the force takes the control itself.
    #[default]
    None,
    /// ẇ = u.
    Integrator,
    /// ẇ = (u − w)/τ, integrated as any state.
    Filter {
        /// τ (s).
        time_constant: f64,
    },
    /// ẇ = (u − w)/τ, integrated exactly over each step.
    FilterExact {
        /// τ (s).
        time_constant: f64,
    },
    /// Activations robodyn does not model (a muscle's, a user's, a PID's): ẇ = 0, they keep
    /// their places among the activations.
    Held {
        /// How many (MuJoCo's `actdim`).
        states: usize,
    },
}

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
    /// The tendon ([`Model::tendons`], fixed or spatial) it pulls on instead of a joint (its
    /// length is `gear L`).
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
    /// Its activation dynamics (MJCF `dyntype`, `dynprm`).
    #[serde(default)]
    pub dynamics: ActivationDynamics,
    /// The activation's range where it is limited (MJCF `actrange` with `actlimited`).
    #[serde(default)]
    pub act_range: Option<(f64, f64)>,
    /// The force takes the activation at the end of the step (MJCF `actearly`).
    #[serde(default)]
    pub act_early: bool,
}

impl ActivationDynamics {
    /// Its MJCF `dyntype`.
    pub fn keyword(&self) -> &'static str {
        match self {
            ActivationDynamics::None => "none",
            ActivationDynamics::Integrator => "integrator",
            ActivationDynamics::Filter { .. } => "filter",
            ActivationDynamics::FilterExact { .. } => "filterexact",
            ActivationDynamics::Held { .. } => "muscle, user or pid",
        }
    }
}

impl Actuator {
    /// u clamped to the control's range where it is limited.
    pub fn clamp_control(&self, u: f64) -> f64 {
        self.ctrl_range.map_or(u, |(low, high)| u.clamp(low, high))
    }

    /// Whether it has an activation state w.
    pub fn has_activation(&self) -> bool {
        self.dynamics != ActivationDynamics::None
    }

    /// How many activations it has (MuJoCo's `actuator_actnum`): 1 with modelled dynamics.
    pub fn activation_count(&self) -> usize {
        match self.dynamics {
            ActivationDynamics::None => 0,
            ActivationDynamics::Held { states } => states,
            _ => 1,
        }
    }

    /// ẇ at activation `w` under the control `u` (already clamped); 0 without activation.
    pub fn activation_rate(&self, u: f64, w: f64) -> f64 {
        match self.dynamics {
            ActivationDynamics::None | ActivationDynamics::Held { .. } => 0.0,
            ActivationDynamics::Integrator => u,
            // ẇ = (u − w)/τ
            ActivationDynamics::Filter { time_constant }
            | ActivationDynamics::FilterExact { time_constant } => {
                (u - w) / time_constant.max(MIN_TIME_CONSTANT)
            }
        }
    }

    /// w₁: the activation after a step `h` from `w` at the rate `rate`, clamped to its range
    /// (held where robodyn does not model it).
    pub fn next_activation(&self, w: f64, rate: f64, h: f64) -> f64 {
        let next = match self.dynamics {
            ActivationDynamics::Held { .. } => return w,
            // w₁ = w + ẇ τ (1 − e^(−h/τ))
            ActivationDynamics::FilterExact { time_constant } => {
                let tau = time_constant.max(MIN_TIME_CONSTANT);
                w + rate * tau * (1.0 - (-h / tau).exp())
            }
            _ => w + rate * h,
        };
        self.act_range
            .map_or(next, |(low, high)| next.clamp(low, high))
    }

    /// What the force's gain multiplies: the control `u` (as the model takes it,
    /// [`Model::control`]) without activation, else the activation `w` (or, with `actearly`,
    /// the next one, after a step `h`).
    pub fn input(&self, u: f64, w: f64, h: f64) -> f64 {
        match (self.has_activation(), self.act_early) {
            (false, _) => u,
            (true, false) => w,
            (true, true) => self.next_activation(w, self.activation_rate(u, w), h),
        }
    }

    /// f at its length l and rate l̇ for the gain's input `input` ([`Self::input`]), before
    /// any range: `(a₀ + a₁ l + a₂ l̇) input + (b₀ + b₁ l + b₂ l̇)`.
    pub fn unlimited_force_at(&self, l: f64, l_dot: f64, input: f64) -> f64 {
        let (a, b) = (&self.gain, &self.bias);
        (a[0] + a[1] * l + a[2] * l_dot) * input + (b[0] + b[1] * l + b[2] * l_dot)
    }

    /// A force clamped to `forcerange` where limited.
    pub fn clamp_force(&self, f: f64) -> f64 {
        self.force_range.map_or(f, |(low, high)| f.clamp(low, high))
    }
}

impl Model {
    /// The moment arms of `actuator`: (velocity coordinate, ∂l/∂q̇) with `τ = Σ arm f e_k`:
    /// `gear` on its joint, `gear J_k` on its tendon (J from `tendons`, the tendons at the
    /// state's q); none for an actuator robodyn does not model.
    pub fn actuator_arms<'a>(
        &'a self,
        actuator: &'a Actuator,
        tendons: &'a TendonKinematics,
    ) -> impl Iterator<Item = (usize, f64)> + 'a {
        let joint = actuator.coordinate.map(|c| (c, actuator.gear));
        let tendon_arms = actuator.tendon.into_iter().flat_map(move |t| {
            (0..self.nv)
                .map(move |k| (k, actuator.gear * tendons.jacobian[(t, k)]))
                .filter(|&(_, arm)| arm != 0.0)
        });
        joint.into_iter().chain(tendon_arms)
    }

    /// `actuator`'s length l and its rate l̇ at (q, q̇): `gear q_j` and `gear q̇_j` on a joint,
    /// `gear L` and `gear J q̇` on a tendon (`tendons` at q).
    pub fn actuator_length_and_rate(
        &self,
        actuator: &Actuator,
        (q, v): (&[f64], &[f64]),
        tendons: &TendonKinematics,
    ) -> (f64, f64) {
        let g = actuator.gear;
        match (actuator.coordinate, actuator.tendon) {
            (Some(c), _) => (g * q[actuator.position], g * v[c]),
            (None, Some(t)) => (g * tendons.lengths[t], g * tendons.rate(t, v)),
            (None, None) => (0.0, 0.0),
        }
    }

    /// nu: the number of actuators (of the controls).
    pub fn nu(&self) -> usize {
        self.actuators.len()
    }

    /// na: the number of activations (MuJoCo's `act`), in the actuators' order.
    pub fn na(&self) -> usize {
        self.actuators.iter().map(Actuator::activation_count).sum()
    }

    /// Each actuator with the first of its activations in `act` (na).
    fn activation_slots(&self) -> impl Iterator<Item = (&Actuator, usize)> + '_ {
        self.actuators.iter().scan(0, |first, actuator| {
            let slot = *first;
            *first += actuator.activation_count();
            Some((actuator, slot))
        })
    }

    /// The control `u` as `actuator` takes it: clamped to its range, unless the `clampctrl`
    /// flag is disabled.
    pub fn control(&self, actuator: &Actuator, u: f64) -> f64 {
        match self.options.flag("clampctrl") {
            true => actuator.clamp_control(u),
            false => u,
        }
    }

    /// Each actuator with its control u ([`Model::control`]) and its activation w (its last; 0
    /// for one without): the actuators zipped with `ctrl` (nu) and `act` (na) in order.
    pub fn actuator_states<'a>(
        &'a self,
        ctrl: &'a [f64],
        act: &'a [f64],
    ) -> impl Iterator<Item = (&'a Actuator, f64, f64)> + 'a {
        self.activation_slots()
            .zip(ctrl)
            .map(move |((actuator, slot), &u)| {
                let w = match actuator.activation_count() {
                    0 => 0.0,
                    count => act[slot + count - 1],
                };
                (actuator, self.control(actuator, u), w)
            })
    }

    /// ẇ (na) at the controls `ctrl` (nu) and activations `act` (na), into `rates`: MuJoCo's
    /// `act_dot` (0 for the activations robodyn holds, and all 0 with the `actuation` flag
    /// disabled).
    pub fn activation_rates(&self, ctrl: &[f64], act: &[f64], rates: &mut [f64]) -> Result<()> {
        check_vector("ctrl", ctrl, self.nu())?;
        check_vector("act", act, self.na())?;
        rates.fill(0.0);
        if !self.options.flag("actuation") {
            return Ok(());
        }
        for ((actuator, slot), &u) in self.activation_slots().zip(ctrl) {
            if actuator.activation_count() == 1 {
                rates[slot] = actuator.activation_rate(self.control(actuator, u), act[slot]);
            }
        }
        Ok(())
    }

    /// w₁ = w ⊞ h ẇ for each activation in `act` at the rates `rates` (na), clamped to their
    /// ranges (MuJoCo's `mj_advance` on `act`).
    pub fn advance_activations(&self, act: &mut [f64], rates: &[f64], h: f64) {
        for (actuator, slot) in self.activation_slots() {
            for k in slot..slot + actuator.activation_count() {
                act[k] = actuator.next_activation(act[k], rates[k], h);
            }
        }
    }

    /// The generalised forces (nv) the actuators exert under controls `ctrl` (nu, in the
    /// order of [`Model::actuators`]) and activations `act` (na) at (q, q̇), the tendons at q
    /// `tendons` ([`TendonKinematics::update`]), into `tau`: MuJoCo's `qfrc_actuator` (without
    /// the gravity compensation of `actuatorgravcomp` joints, which the scene's dynamics adds
    /// before [`Model::clamp_joint_actuator_forces`]).
    pub fn actuator_forces(
        &self,
        state: (&[f64], &[f64]),
        inputs: (&[f64], &[f64]),
        tendons: &TendonKinematics,
        tau: &mut [f64],
    ) -> Result<()> {
        self.unclamped_actuator_forces(state, inputs, tendons, tau)?;
        self.clamp_joint_actuator_forces(tau);
        Ok(())
    }

    /// [`Model::actuator_forces`] before each joint's total is clamped to its range (zero with
    /// the `actuation` flag disabled).
    pub fn unclamped_actuator_forces(
        &self,
        (q, v): (&[f64], &[f64]),
        (ctrl, act): (&[f64], &[f64]),
        tendons: &TendonKinematics,
        tau: &mut [f64],
    ) -> Result<()> {
        self.check_configuration(q)?;
        check_vector("v", v, self.nv)?;
        check_vector("ctrl", ctrl, self.nu())?;
        check_vector("act", act, self.na())?;
        check_length("tendons", tendons.lengths.len(), self.tendons.len())?;
        tau.fill(0.0);
        if !self.options.flag("actuation") {
            return Ok(());
        }
        for (actuator, out) in self.actuator_scalar_forces((q, v), (ctrl, act), tendons) {
            // τ += arm f
            for (k, arm) in self.actuator_arms(actuator, tendons) {
                tau[k] += arm * out.force;
            }
        }
        Ok(())
    }

    /// Clamps a hinge's or slide's total actuator force in `tau` (nv) to its range
    /// (`actuatorfrcrange`).
    pub fn clamp_joint_actuator_forces(&self, tau: &mut [f64]) {
        for (body, range) in self.actuator_force_range.iter().enumerate() {
            if let (Some((low, high)), 1) = (range, self.joints[body].nv()) {
                let c = self.idx_v[body];
                tau[c] = tau[c].clamp(*low, *high);
            }
        }
    }

    /// Each actuator with its force at (q, q̇) under `ctrl` (nu) and `act` (na), the tendons at
    /// q `tendons`: f of the module's header, scaled with the other forces on its tendon into
    /// the tendon's `actuatorfrcrange`, then clamped to its own `forcerange`. Expects checked
    /// arguments ([`Model::actuator_forces`] checks them).
    pub fn actuator_scalar_forces<'a>(
        &'a self,
        (q, v): (&'a [f64], &'a [f64]),
        (ctrl, act): (&'a [f64], &'a [f64]),
        tendons: &'a TendonKinematics,
    ) -> impl Iterator<Item = (&'a Actuator, ActuatorForce)> + 'a {
        let h = self.options.timestep;
        // each actuator's force before any range
        let unlimited = move |(actuator, u, w): (&'a Actuator, f64, f64)| {
            let (length, rate) = self.actuator_length_and_rate(actuator, (q, v), tendons);
            let input = actuator.input(u, w, h);
            (
                actuator,
                input,
                actuator.unlimited_force_at(length, rate, input),
            )
        };
        // tendon t's factor: f₊ / F or f₋ / F where the sum F of its actuators' forces leaves
        // its range [f₋, f₊], else 1
        let tendon_scale = move |t: usize| {
            let Some((low, high)) = self.tendons[t].actuator_force_range else {
                return 1.0;
            };
            let total: f64 = self
                .actuator_states(ctrl, act)
                .filter(|(actuator, ..)| actuator.tendon == Some(t))
                .map(|state| unlimited(state).2)
                .sum();
            match total {
                _ if total < low => low / total,
                _ if total > high => high / total,
                _ => 1.0,
            }
        };
        self.actuator_states(ctrl, act).map(move |state| {
            let (actuator, input, force) = unlimited(state);
            let scale = actuator.tendon.map_or(1.0, tendon_scale);
            let force = actuator.clamp_force(force * scale);
            let clamped = actuator
                .force_range
                .is_some_and(|(low, high)| force <= low || force >= high);
            let saturated = clamped || scale != 1.0;
            (
                actuator,
                ActuatorForce {
                    input,
                    force,
                    saturated,
                },
            )
        })
    }
}
