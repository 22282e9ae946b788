//! `simulate` and `step`: the binding of `robodyn::integrate`. Native controllers and constant
//! wrenches run with the GIL released (batches on all cores); Python callables are called back
//! with the GIL.
//!
//! Its parts: `arguments` (the call's arguments, read and checked once), `rollouts` (running
//! them), `callbacks` (Python controllers, wrenches and progress), `record` (the trajectories
//! as NumPy arrays).

mod arguments;
mod callbacks;
mod record;
mod rollouts;
mod scene;

pub use scene::{simulate_scene, step_scene};

use crate::constrained::made_for;
use crate::model::{write_row_major, PyModel};
use crate::to_py_err;
use arguments::{ConstrainedArguments, PassiveArguments, SimulateArguments, Simulation};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use record::stack;
use robodyn::integrate::simulator::DEFAULT_ACCURACY_RTOL;
use robodyn::integrate::{ForwardDynamics, Integrator, PassiveForces, StepWorkspace};
use robodyn::Model;

/// Simulates `model` from `q0`, `v0` (one state, or N of them: shape (N, nq), (N, nv)) over
/// [0, t_end], recording every `dt`. See `robodyn.simulate` for the arguments; `controller` is
/// None, a dict describing a native controller, or a callable `(t, q, v) -> tau`.
#[pyfunction]
#[pyo3(signature = (model, q0, v0, t_end, dt, integrator="rk4", rtol=1e-6, atol=1e-9, max_step=f64::INFINITY,
                    controller=None, wrenches=None, friction_velocity=1e-2, limits="report",
                    limit_stiffness=1e4, limit_damping=1e2, progress=None, accuracy_rtol=DEFAULT_ACCURACY_RTOL,
                    constraints=None, baumgarte=None, damping=0.0))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    model: &PyModel,
    q0: &Bound<'py, PyAny>,
    v0: &Bound<'py, PyAny>,
    t_end: f64,
    dt: f64,
    integrator: &str,
    rtol: f64,
    atol: f64,
    max_step: f64,
    controller: Option<&Bound<'py, PyAny>>,
    wrenches: Option<&Bound<'py, PyAny>>,
    friction_velocity: f64,
    limits: &str,
    limit_stiffness: f64,
    limit_damping: f64,
    progress: Option<&Bound<'py, PyAny>>,
    accuracy_rtol: f64,
    constraints: Option<&Bound<'py, PyAny>>,
    baumgarte: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = crate::args::named::damping)] damping: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let arguments = SimulateArguments {
        q0,
        v0,
        t_end,
        dt,
        integrator,
        rtol,
        atol,
        max_step,
        controller,
        wrenches,
        passive: PassiveArguments {
            friction_velocity,
            limits,
            limit_stiffness,
            limit_damping,
        },
        progress,
        accuracy_rtol,
        constrained: ConstrainedArguments {
            constraints,
            baumgarte,
            damping,
        },
    };
    let simulation = Simulation::read(model, &arguments)?;
    let runs = simulation.run(py)?;
    stack(py, &model.model, &runs, simulation.rollouts.batch.is_some())
}

/// One step of each state: per sample the flat [q₁, v₁] and, with `derivatives`, A (2nv × 2nv)
/// and B (2nv × nv) row-major after it. The Python `robodyn.step` splits them. With
/// `constraints`, the step integrates their constrained forward dynamics.
#[pyfunction]
#[pyo3(signature = (model, q, v, tau, dt, integrator, derivatives, friction_velocity, limits,
                    limit_stiffness, limit_damping, constraints=None, baumgarte=None, damping=0.0))]
#[allow(clippy::too_many_arguments)]
pub fn step<'py>(
    py: Python<'py>,
    model: &PyModel,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
    dt: f64,
    integrator: &str,
    derivatives: bool,
    friction_velocity: f64,
    limits: &str,
    limit_stiffness: f64,
    limit_damping: f64,
    constraints: Option<&Bound<'py, PyAny>>,
    baumgarte: Option<&Bound<'py, PyAny>>,
    damping: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let m = &model.model;
    let passive = PassiveArguments {
        friction_velocity,
        limits,
        limit_stiffness,
        limit_damping,
    }
    .read()?;
    let constrained = ConstrainedArguments {
        constraints,
        baumgarte,
        damping,
    }
    .read(model)?;
    let integrator = Integrator::from_name(integrator, 0.0, 0.0).map_err(to_py_err)?;
    let arguments = [
        model.q_arg("q", q)?,
        model.v_arg("v", v)?,
        model.v_arg("tau", tau)?,
    ];
    let (nq, nv) = (m.nq, m.nv);
    let size = nq + nv + if derivatives { 6 * nv * nv } else { 0 };
    let one_step = OneStep {
        dt,
        integrator,
        passive: &passive,
        derivatives,
    };
    model.evaluate(
        py,
        &arguments,
        &[size],
        &|m, w, i, out| match &constrained {
            None => {
                let stepper = w
                    .step
                    .get_or_insert_with(|| Box::new(StepWorkspace::new(m)));
                one_step.run(m, stepper, (i[0], i[1], i[2]), out)
            }
            Some(held) => {
                let stepper = made_for(
                    &mut w.constrained_step,
                    |s| s.forward_dynamics.is_for(held),
                    || StepWorkspace::with_forward_dynamics(m, held.clone()),
                );
                one_step.run(m, stepper, (i[0], i[1], i[2]), out)
            }
        },
    )
}

/// The options of one `step` call.
struct OneStep<'a> {
    dt: f64,
    integrator: Integrator,
    passive: &'a PassiveForces,
    derivatives: bool,
}

impl OneStep<'_> {
    /// The step from (q, v) under τ with `stepper`, written as [q₁, v₁, A, B] into `out`.
    fn run<F: ForwardDynamics>(
        &self,
        m: &Model,
        stepper: &mut StepWorkspace<F>,
        (q, v, tau): (&[f64], &[f64], &[f64]),
        out: &mut [f64],
    ) -> robodyn::Result<()> {
        let (nq, nv) = (m.nq, m.nv);
        let (dt, integrator, derivatives) = (self.dt, self.integrator, self.derivatives);
        stepper.step(m, q, v, tau, dt, integrator, self.passive, derivatives)?;
        let (state, jacobians) = out.split_at_mut(nq + nv);
        state[..nq].copy_from_slice(&stepper.q_end);
        state[nq..].copy_from_slice(&stepper.v_end);
        if derivatives {
            let (a, b) = jacobians.split_at_mut(4 * nv * nv);
            write_row_major(&stepper.a, 2 * nv, a);
            write_row_major(&stepper.b, 2 * nv, b);
        }
        Ok(())
    }
}
