//! The integration schemes: explicit and semi-implicit Euler, RK4 and Dormand–Prince RK5(4),
//! all on the configuration's Lie group.
//!
//! An explicit Runge–Kutta scheme with Butcher tableau (a, b, c) becomes a Runge–Kutta–Munthe-Kaas
//! step ([`super::lie_group`]) on the state (ξ, v), ξ the tangent coordinates of q = q₀ ⊕ ξ:
//!
//! ```text
//! stage s:  ξ_s = h Σ_j a_sj Ξ_j,   v_s = v₀ + h Σ_j a_sj A_j,   q_s = q₀ ⊕ ξ_s
//!           A_s = q̈(t + c_s h, q_s, v_s),   Ξ_s = dexp⁻¹_{-ξ_s}(v_s)
//! step:     ξ₁ = h Σ_s b_s Ξ_s,   v₁ = v₀ + h Σ_s b_s A_s,   q₁ = q₀ ⊕ ξ₁
//! ```
//!
//! On revolute and prismatic joints this is the textbook scheme. Tableaus: Euler (order 1), the
//! classical RK4 (Butcher, *Numerical Methods for ODEs*, 2016, §235), Dormand & Prince, *A family
//! of embedded Runge–Kutta formulae*, J. Comp. Appl. Math. 6 (1980), order 5 with an embedded
//! order-4 error estimate, with the order-4 dense output of Hairer, Nørsett & Wanner, *Solving
//! Ordinary Differential Equations I* (1993), §II.6. Semi-implicit (symplectic) Euler updates the
//! velocity first and moves the configuration with the new velocity.

use crate::error::{Error, Result};
use crate::integrate::lie_group::tangent_rate;
use crate::model::Model;

/// Which scheme integrates the equations of motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    /// q₁ = q₀ ⊕ h v₀, v₁ = v₀ + h q̈₀. Order 1; gains energy on oscillators.
    ExplicitEuler,
    /// v₁ = v₀ + h q̈₀, q₁ = q₀ ⊕ h v₁. Order 1, symplectic: its energy error stays bounded.
    SemiImplicitEuler,
    /// The classical fourth-order Runge–Kutta scheme, fixed step.
    Rk4,
    /// Dormand–Prince 5(4): adaptive steps that keep the local error below
    /// `atol + rtol·|x|` per state component, with dense output at the recording times.
    Rk45 {
        /// Relative tolerance on the local error, > 0.
        rtol: f64,
        /// Absolute tolerance on the local error, > 0 (in each state component's unit).
        atol: f64,
    },
}

impl Integrator {
    /// The names the Python API and the CLI use.
    pub const NAMES: [&'static str; 4] = ["euler", "semi_implicit_euler", "rk4", "rk45"];

    /// The scheme called `name` (one of [`Integrator::NAMES`]); `rtol` and `atol` are used by
    /// `"rk45"` only.
    pub fn from_name(name: &str, rtol: f64, atol: f64) -> Result<Self> {
        match name {
            "euler" => Ok(Integrator::ExplicitEuler),
            "semi_implicit_euler" => Ok(Integrator::SemiImplicitEuler),
            "rk4" => Ok(Integrator::Rk4),
            "rk45" => Ok(Integrator::Rk45 { rtol, atol }),
            _ => Err(Error::InvalidValue {
                argument: "integrator".into(),
                message: format!("expected one of {:?}, got '{name}'", Integrator::NAMES),
            }),
        }
    }

    /// The order p of the scheme: its local error per step grows as h^(p+1), its global error
    /// over a fixed time as h^p.
    pub fn order(&self) -> i32 {
        match self {
            Integrator::ExplicitEuler | Integrator::SemiImplicitEuler => 1,
            Integrator::Rk4 => 4,
            Integrator::Rk45 { .. } => 5,
        }
    }

    /// The Butcher tableau of the Runge–Kutta schemes (semi-implicit Euler has none).
    pub(crate) fn tableau(&self) -> Option<&'static Tableau> {
        match self {
            Integrator::ExplicitEuler => Some(&EULER),
            Integrator::SemiImplicitEuler => None,
            Integrator::Rk4 => Some(&RK4),
            Integrator::Rk45 { .. } => Some(&DORMAND_PRINCE),
        }
    }
}

/// An explicit Butcher tableau: `a` row s holds a_sj for j < s.
pub(crate) struct Tableau {
    pub a: &'static [&'static [f64]],
    pub b: &'static [f64],
    pub c: &'static [f64],
    /// b − b̂, the weights of the embedded error estimate (empty without one).
    pub error: &'static [f64],
}

const EULER: Tableau = Tableau {
    a: &[&[]],
    b: &[1.0],
    c: &[0.0],
    error: &[],
};

const RK4: Tableau = Tableau {
    a: &[&[], &[0.5], &[0.0, 0.5], &[0.0, 0.0, 1.0]],
    b: &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
    c: &[0.0, 0.5, 0.5, 1.0],
    error: &[],
};

/// Dormand–Prince 5(4). Its last stage is evaluated at the step's result ("first same as last"),
/// so an accepted step's A₇ is the next step's A₁.
const DORMAND_PRINCE: Tableau = Tableau {
    a: &[
        &[],
        &[1.0 / 5.0],
        &[3.0 / 40.0, 9.0 / 40.0],
        &[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
        &[
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
        ],
        &[
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
        ],
        &[
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
        ],
    ],
    b: &[
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
        0.0,
    ],
    c: &[0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0],
    error: &[
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ],
};

/// The weights d_s of Dormand–Prince's dense output (Hairer, Nørsett & Wanner, §II.6).
const DENSE_OUTPUT: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// The state at one instant: time, configuration, velocity and acceleration q̈(t, q, v).
#[derive(Debug, Clone)]
pub(crate) struct State {
    pub t: f64,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
}

impl State {
    pub fn new(model: &Model) -> Self {
        State {
            t: 0.0,
            q: vec![0.0; model.nq],
            v: vec![0.0; model.nv],
            a: vec![0.0; model.nv],
        }
    }
}

/// The stages of one step and its result, allocated once.
pub(crate) struct Stepper {
    nv: usize,
    /// Ξ_s, stage after stage (stages × nv).
    tangent_rates: Vec<f64>,
    /// A_s, stage after stage (stages × nv).
    accelerations: Vec<f64>,
    xi: Vec<f64>,
    stage_q: Vec<f64>,
    stage_v: Vec<f64>,
    /// The step's result: tangent step ξ₁, q₁, v₁.
    pub xi_end: Vec<f64>,
    pub q_end: Vec<f64>,
    pub v_end: Vec<f64>,
    /// Scratch for the error scale: the tangent coordinates of q₀ and q₁ about the neutral
    /// configuration.
    neutral: Vec<f64>,
    coordinates_start: Vec<f64>,
    coordinates_end: Vec<f64>,
}

impl Stepper {
    pub fn new(model: &Model) -> Self {
        let (nq, nv) = (model.nq, model.nv);
        let stages = DORMAND_PRINCE.b.len();
        Stepper {
            nv,
            tangent_rates: vec![0.0; stages * nv],
            accelerations: vec![0.0; stages * nv],
            xi: vec![0.0; nv],
            stage_q: vec![0.0; nq],
            stage_v: vec![0.0; nv],
            xi_end: vec![0.0; nv],
            q_end: vec![0.0; nq],
            v_end: vec![0.0; nv],
            neutral: model.neutral().as_slice().to_vec(),
            coordinates_start: vec![0.0; nv],
            coordinates_end: vec![0.0; nv],
        }
    }

    /// A_s of the last step's stage `s`.
    pub fn stage_acceleration(&self, s: usize) -> &[f64] {
        &self.accelerations[s * self.nv..(s + 1) * self.nv]
    }

    /// One Runge–Kutta–Munthe-Kaas step of size `h` from `start` (whose `a` is known), with
    /// `acceleration(t, q, v, a)` the equations of motion. Writes ξ₁, q₁, v₁ and the stages.
    pub fn runge_kutta<F>(
        &mut self,
        model: &Model,
        tableau: &Tableau,
        start: &State,
        h: f64,
        acceleration: &mut F,
    ) -> Result<()>
    where
        F: FnMut(f64, &[f64], &[f64], &mut [f64]) -> Result<()>,
    {
        self.first_stage(start);
        for s in 1..tableau.a.len() {
            let t = self.stage_state(model, tableau, start, h, s)?;
            let (q, v, a) = self.stage_evaluation(s);
            acceleration(t, q, v, a)?;
            self.stage_rate(model, s);
        }
        self.step_result(model, tableau, start, h)
    }

    /// Stage 1 of a Runge–Kutta step from `start`: ξ = 0, so Ξ₁ = v₀ and A₁ = a₀.
    pub fn first_stage(&mut self, start: &State) {
        let nv = self.nv;
        self.tangent_rates[..nv].copy_from_slice(&start.v);
        self.accelerations[..nv].copy_from_slice(&start.a);
    }

    /// The state of stage `s` ≥ 1 (in [`Self::stage_evaluation`]) and its time:
    /// ξ_s = h Σ a_sj Ξ_j, v_s = v₀ + h Σ a_sj A_j, q_s = q₀ ⊕ ξ_s.
    pub fn stage_state(
        &mut self,
        model: &Model,
        tableau: &Tableau,
        start: &State,
        h: f64,
        s: usize,
    ) -> Result<f64> {
        self.weighted_sums(tableau.a[s], h, &start.v);
        model.integrate(&start.q, &self.xi, &mut self.stage_q)?;
        Ok(start.t + tableau.c[s] * h)
    }

    /// Stage `s`'s q_s and v_s, and where its acceleration A_s goes.
    pub fn stage_evaluation(&mut self, s: usize) -> (&[f64], &[f64], &mut [f64]) {
        let nv = self.nv;
        let a_s = &mut self.accelerations[s * nv..(s + 1) * nv];
        (&self.stage_q, &self.stage_v, a_s)
    }

    /// Ξ_s = dexp⁻¹_{-ξ_s}(v_s), once A_s is in.
    pub fn stage_rate(&mut self, model: &Model, s: usize) {
        let nv = self.nv;
        tangent_rate(
            model,
            &self.xi,
            &self.stage_v,
            &mut self.tangent_rates[s * nv..(s + 1) * nv],
        );
    }

    /// The step's result once every stage is in: ξ₁ = h Σ b_s Ξ_s, v₁ = v₀ + h Σ b_s A_s,
    /// q₁ = q₀ ⊕ ξ₁.
    pub fn step_result(
        &mut self,
        model: &Model,
        tableau: &Tableau,
        start: &State,
        h: f64,
    ) -> Result<()> {
        self.weighted_sums(tableau.b, h, &start.v);
        self.xi_end.copy_from_slice(&self.xi);
        self.v_end.copy_from_slice(&self.stage_v);
        model.integrate(&start.q, &self.xi_end, &mut self.q_end)
    }

    /// Semi-implicit Euler: v₁ = v₀ + h a₀, q₁ = q₀ ⊕ h v₁.
    pub fn semi_implicit_euler(&mut self, model: &Model, start: &State, h: f64) -> Result<()> {
        for j in 0..self.nv {
            self.v_end[j] = start.v[j] + h * start.a[j];
            self.xi_end[j] = h * self.v_end[j];
        }
        model.integrate(&start.q, &self.xi_end, &mut self.q_end)
    }

    /// ξ = h Σ w_s Ξ_s and v = v₀ + h Σ w_s A_s into `xi` and `stage_v`.
    fn weighted_sums(&mut self, weights: &[f64], h: f64, v_start: &[f64]) {
        let nv = self.nv;
        self.xi.fill(0.0);
        self.stage_v.copy_from_slice(v_start);
        for (s, &weight) in weights.iter().enumerate().filter(|(_, w)| **w != 0.0) {
            let rates = &self.tangent_rates[s * nv..(s + 1) * nv];
            let accelerations = &self.accelerations[s * nv..(s + 1) * nv];
            for j in 0..nv {
                self.xi[j] += h * weight * rates[j];
                self.stage_v[j] += h * weight * accelerations[j];
            }
        }
    }

    /// The embedded error estimate of the last step, as the root mean square over the state's
    /// components of e_i / (atol + rtol·max(|x₀,i|, |x₁,i|)), with x the velocity and, for the
    /// configuration, its tangent coordinates about the neutral configuration. A step is
    /// accepted when this is at most 1.
    pub fn error_norm(
        &mut self,
        model: &Model,
        tableau: &Tableau,
        start: &State,
        h: f64,
        tolerances: (f64, f64),
    ) -> Result<f64> {
        let (rtol, atol) = tolerances;
        let nv = self.nv;
        model.difference(&self.neutral, &start.q, &mut self.coordinates_start)?;
        model.difference(&self.neutral, &self.q_end, &mut self.coordinates_end)?;
        let mut sum = 0.0;
        for j in 0..nv {
            let (mut error_xi, mut error_v) = (0.0, 0.0);
            for (s, weight) in tableau.error.iter().enumerate() {
                error_xi += h * weight * self.tangent_rates[s * nv + j];
                error_v += h * weight * self.accelerations[s * nv + j];
            }
            let scale_xi = atol
                + rtol
                    * self.coordinates_start[j]
                        .abs()
                        .max(self.coordinates_end[j].abs());
            let scale_v = atol + rtol * start.v[j].abs().max(self.v_end[j].abs());
            sum += (error_xi / scale_xi).powi(2) + (error_v / scale_v).powi(2);
        }
        Ok((sum / (2 * nv).max(1) as f64).sqrt())
    }

    /// Dormand–Prince's dense output at t₀ + θh inside the last step, into (q, v):
    /// y(θ) = y₀ + θ (Δ + (1 − θ) (B + θ (Δ − h k₇ − B + (1 − θ) h Σ d_s k_s))), B = h k₁ − Δ,
    /// with y = (ξ, v), Δ = y₁ − y₀ and k_s = (Ξ_s, A_s); then q = q₀ ⊕ ξ(θ).
    pub fn dense_output(
        &mut self,
        model: &Model,
        start: &State,
        h: f64,
        theta: f64,
        q: &mut [f64],
        v: &mut [f64],
    ) -> Result<()> {
        let nv = self.nv;
        let last = DENSE_OUTPUT.len() - 1;
        let interpolate = |y0: f64, y1: f64, stages: &[f64], j: usize| {
            let delta = y1 - y0;
            let b = h * stages[j] - delta;
            let tail: f64 = DENSE_OUTPUT
                .iter()
                .enumerate()
                .map(|(s, d)| h * d * stages[s * nv + j])
                .sum();
            let fourth = delta - h * stages[last * nv + j] - b;
            y0 + theta * (delta + (1.0 - theta) * (b + theta * (fourth + (1.0 - theta) * tail)))
        };
        for (j, velocity) in v.iter_mut().enumerate() {
            self.xi[j] = interpolate(0.0, self.xi_end[j], &self.tangent_rates, j);
            *velocity = interpolate(start.v[j], self.v_end[j], &self.accelerations, j);
        }
        model.integrate(&start.q, &self.xi, q)
    }
}
