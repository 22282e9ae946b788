//! How a model file asks to be simulated (MJCF `<option>` and its `<flag>`), and the parameters
//! of MuJoCo's soft constraint model that its elements carry (`solref`, `solimp`).
//!
//! Reference: MuJoCo's documentation, "XML Reference", §option, and "Computation", §Solver
//! parameters. The defaults are MuJoCo's.

/// MuJoCo's defaults of every `solref` (time constant, damping ratio).
pub const DEFAULT_SOLREF: [f64; 2] = [0.02, 1.0];
/// MuJoCo's defaults of every `solimp` (d₀, d_width, width, midpoint, power).
pub const DEFAULT_SOLIMP: [f64; 5] = [0.9, 0.95, 0.001, 0.5, 2.0];

/// How stiff and how damped a soft constraint is (MuJoCo's solver parameters).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolverParameters {
    /// `solref`: (time constant, damping ratio), or, both negative, (−stiffness, −damping).
    pub solref: [f64; 2],
    /// `solimp`: the impedance's (d₀, d_width, width, midpoint, power).
    pub solimp: [f64; 5],
}

impl Default for SolverParameters {
    fn default() -> Self {
        SolverParameters {
            solref: DEFAULT_SOLREF,
            solimp: DEFAULT_SOLIMP,
        }
    }
}

/// The numerical integrator (`<option integrator>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Integrator {
    /// Semi-implicit Euler, joint damping implicit (`Euler`).
    Euler,
    /// Fourth-order Runge–Kutta (`RK4`).
    Rk4,
    /// Implicit in velocity, every velocity-dependent force (`implicit`).
    Implicit,
    /// Implicit in velocity, the symmetric part of the force derivatives (`implicitfast`).
    ImplicitFast,
    /// MuJoCo's discrete-time variational integrator (`discrete`).
    Discrete,
}

impl Integrator {
    /// The MJCF keywords, in the enum's order.
    pub const KEYWORDS: [&'static str; 5] =
        ["Euler", "RK4", "implicit", "implicitfast", "discrete"];

    /// The integrator an MJCF keyword names.
    pub fn from_keyword(word: &str) -> Option<Self> {
        let all = [
            Integrator::Euler,
            Integrator::Rk4,
            Integrator::Implicit,
            Integrator::ImplicitFast,
            Integrator::Discrete,
        ];
        Self::KEYWORDS
            .iter()
            .position(|k| *k == word)
            .map(|index| all[index])
    }

    /// Its MJCF keyword.
    pub fn keyword(self) -> &'static str {
        Self::KEYWORDS[self as usize]
    }
}

/// The friction cone's shape (`<option cone>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FrictionCone {
    /// Linearised by the pyramid's edges (`pyramidal`).
    Pyramidal,
    /// Exact (`elliptic`).
    Elliptic,
}

/// The constraint solver's algorithm (`<option solver>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ConstraintSolver {
    /// Projected Gauss–Seidel on the dual (`PGS`).
    Pgs,
    /// Conjugate gradient on the primal (`CG`).
    Cg,
    /// Newton's method on the primal (`Newton`).
    Newton,
}

/// The `<option>` flags MuJoCo reads as "disable" bits (every one on by default), in its order.
pub const DISABLE_FLAGS: [&str; 20] = [
    "constraint",
    "equality",
    "frictionloss",
    "limit",
    "contact",
    "spring",
    "damper",
    "gravity",
    "clampctrl",
    "warmstart",
    "filterparent",
    "actuation",
    "refsafe",
    "sensor",
    "midphase",
    "eulerdamp",
    "autoreset",
    "nativeccd",
    "island",
    "multiccd",
];

/// The `<option>` flags MuJoCo reads as "enable" bits (every one off by default), in its order.
pub const ENABLE_FLAGS: [&str; 8] = [
    "override",
    "energy",
    "fwdinv",
    "invdiscrete",
    "sleep",
    "diagexact",
    "ipc",
    "speculative",
];

/// How the model file asks to be simulated (MJCF `<option>`; gravity is [`crate::Model::gravity`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimulationOptions {
    /// The time step (s).
    pub timestep: f64,
    /// The integrator.
    pub integrator: Integrator,
    /// The friction cone.
    pub cone: FrictionCone,
    /// The constraint solver.
    pub solver: ConstraintSolver,
    /// The ratio of frictional to normal impedance (elliptic cones).
    pub impratio: f64,
    /// The solver's relative improvement at which it stops.
    pub tolerance: f64,
    /// The solver's most iterations.
    pub iterations: usize,
    /// The line search's most iterations (CG and Newton).
    pub ls_iterations: usize,
    /// The line search's tolerance.
    pub ls_tolerance: f64,
    /// The no-slip solver's iterations (0: not run).
    pub noslip_iterations: usize,
    /// The no-slip solver's tolerance.
    pub noslip_tolerance: f64,
    /// The flags of [`DISABLE_FLAGS`] the file turns off.
    pub disabled: Vec<String>,
    /// The flags of [`ENABLE_FLAGS`] the file turns on.
    pub enabled: Vec<String>,
    /// The contact override's margin (`o_margin`; read when `override` is enabled).
    pub override_margin: f64,
    /// The contact override's solver parameters (`o_solref`, `o_solimp`).
    pub override_solver: SolverParameters,
    /// The contact override's friction (`o_friction`: sliding ×2, torsional, rolling ×2).
    pub override_friction: [f64; 5],
}

impl Default for SimulationOptions {
    fn default() -> Self {
        SimulationOptions {
            timestep: 0.002,
            integrator: Integrator::Euler,
            cone: FrictionCone::Pyramidal,
            solver: ConstraintSolver::Newton,
            impratio: 1.0,
            tolerance: 1e-8,
            iterations: 100,
            ls_iterations: 50,
            ls_tolerance: 0.01,
            noslip_iterations: 0,
            noslip_tolerance: 1e-6,
            disabled: Vec::new(),
            enabled: Vec::new(),
            override_margin: 0.0,
            override_solver: SolverParameters::default(),
            override_friction: [1.0, 1.0, 0.005, 0.0001, 0.0001],
        }
    }
}

impl SimulationOptions {
    /// Whether `flag` (one of [`DISABLE_FLAGS`] or [`ENABLE_FLAGS`]) is on.
    pub fn flag(&self, flag: &str) -> bool {
        if DISABLE_FLAGS.contains(&flag) {
            !self.disabled.iter().any(|f| f == flag)
        } else {
            self.enabled.iter().any(|f| f == flag)
        }
    }
}
