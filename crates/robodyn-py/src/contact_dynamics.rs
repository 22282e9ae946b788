//! Forward dynamics with MuJoCo's soft contacts, limits and dry friction:
//! `Model.contact_forward_dynamics`.

use crate::args::{read_sample, SampleShape};
use crate::errors::to_py_err;
use crate::model::PyModel;
use crate::scene::contact_dicts;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::soft::dynamics::{ContactDynamics, ContactForward};

#[pymethods]
impl PyModel {
    /// The accelerations and constraint forces of MuJoCo's soft constraint model at (q, v) and
    /// the actuators' activations `act` (na; None: zero) and the plastic springs' references
    /// `plastic` (nplastic; None: `plastic0`) under the applied generalised forces
    /// `tau` (nv, MuJoCo's `qfrc_applied`; None: zero) and the controls `ctrl` (nu; None:
    /// zero), as MuJoCo's `mj_forward` computes them with its solver
    /// run to convergence: the contacts (`collide`), the rows of every active constraint (the
    /// model's equality constraints, dry friction of the joints and the tendons, their limits,
    /// the contacts, in MuJoCo's order), and the solution of the soft model. A dict: `qdd` (nv,),
    /// `forces` (one per row: MuJoCo's `efc_force`), `row_types` (MuJoCo's constraint types:
    /// "equality", "friction_dof", "friction_tendon", "limit_joint", "limit_tendon",
    /// "contact_frictionless", "contact_pyramidal", "contact_elliptic"), `row_ids` (the equality's
    /// place among the file's equalities, the degree of freedom, the tendon, the joint or the
    /// contact of each row), `jacobian` (rows, nv), `R` and `aref`
    /// (each row's regulariser and reference acceleration), `contacts` (as `collide` lists them,
    /// each with `dim`, its condim, `first_row`, −1 when it has no rows, and `force`: the normal,
    /// tangent, spin and roll forces in its frame, MuJoCo's `mj_contactForce`), `tau_actuator` and
    /// `tau_constraint` (nv,: MuJoCo's `qfrc_actuator` and `qfrc_constraint`), `act_dot` (na,:
    /// the activations' rates).
    #[pyo3(signature = (q, v, tau=None, ctrl=None, act=None, plastic=None))]
    #[allow(clippy::too_many_arguments)]
    fn contact_forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: Option<&Bound<'py, PyAny>>,
        ctrl: Option<&Bound<'py, PyAny>>,
        act: Option<&Bound<'py, PyAny>>,
        plastic: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let model = &self.model;
        let (nv, nu, na) = (model.nv, model.nu(), model.na());
        let q = read_sample("q", q, SampleShape::vector(model.nq))?;
        let v = read_sample("v", v, SampleShape::vector(nv))?;
        let tau = match tau {
            Some(tau) => read_sample("tau", tau, SampleShape::vector(nv))?,
            None => vec![0.0; nv],
        };
        let ctrl = match ctrl {
            Some(ctrl) => read_sample("ctrl", ctrl, SampleShape::vector(nu))?,
            None => vec![0.0; nu],
        };
        let act = match act {
            Some(act) => read_sample("act", act, SampleShape::vector(na))?,
            None => vec![0.0; na],
        };
        let plastic = match plastic {
            Some(p) => read_sample("plastic", p, SampleShape::vector(model.nplastic()))?,
            None => model.initial_plastic(),
        };
        let mut out = ContactForward::default();
        py.detach(|| {
            let state = (&q[..], &v[..], &act[..], &plastic[..]);
            ContactDynamics::new(model)?.forward(model, state, &tau, &ctrl, &mut out)
        })
        .map_err(to_py_err)?;
        let rows = &out.rows;
        let result = PyDict::new(py);
        result.set_item(
            "qdd",
            PyArray1::from_slice(py, out.solution.acceleration.as_slice()),
        )?;
        result.set_item("forces", PyArray1::from_slice(py, &out.solution.forces))?;
        let types: Vec<&str> = rows.kind.iter().map(|k| k.name()).collect();
        result.set_item("row_types", types)?;
        let ids: Vec<i64> = rows.id.iter().map(|&i| i as i64).collect();
        result.set_item("row_ids", PyArray1::from_slice(py, &ids))?;
        let jacobian =
            numpy::ndarray::Array2::from_shape_vec((rows.len(), nv), rows.jacobian.clone())
                .expect("rows × nv");
        result.set_item("jacobian", PyArray2::from_owned_array(py, jacobian))?;
        result.set_item("R", PyArray1::from_slice(py, &rows.regulariser))?;
        result.set_item("aref", PyArray1::from_slice(py, &rows.reference))?;
        let contacts = contact_dicts(py, model, &out.contacts)?;
        for (contact, item) in out.contacts.iter().zip(&contacts) {
            let condim =
                robodyn::soft::contact_parameters(model, contact.geoms.0, contact.geoms.1).condim;
            item.set_item("dim", condim)?;
        }
        for (c, (first, item)) in rows.contact_rows.iter().zip(&contacts).enumerate() {
            item.set_item("first_row", first.map_or(-1, |f| f as i64))?;
            let force = rows.contact_force(&out.solution.forces, c);
            item.set_item("force", PyArray1::from_slice(py, &force))?;
        }
        result.set_item("contacts", contacts)?;
        result.set_item(
            "tau_actuator",
            PyArray1::from_slice(py, out.actuator.as_slice()),
        )?;
        result.set_item(
            "tau_constraint",
            PyArray1::from_slice(py, out.constraint.as_slice()),
        )?;
        result.set_item(
            "act_dot",
            PyArray1::from_slice(py, out.activation_rate.as_slice()),
        )?;
        Ok(result)
    }
}
