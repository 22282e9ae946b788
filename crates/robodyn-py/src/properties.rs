//! Model properties (sizes, names, limits, settable gravity, armature and passive forces) and
//! configurations (neutral, random, integrate, difference).

use crate::args::*;
use crate::model::*;
use crate::to_py_err;
use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rand::{rngs::StdRng, SeedableRng};
use robodyn::integrate::lie_group::{difference_jacobians, integrate_jacobians};
use robodyn::Model;

#[pymethods]
impl PyModel {
    /// The model's name (URDF `<robot name>`).
    #[getter]
    fn name(&self) -> &str {
        &self.model.name
    }

    /// Number of configuration coordinates.
    #[getter]
    fn nq(&self) -> usize {
        self.model.nq
    }

    /// Number of velocity coordinates (degrees of freedom).
    #[getter]
    fn nv(&self) -> usize {
        self.model.nv
    }

    /// Names of the moving joints, in q/v order (depth-first, file order).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model.joint_names[1..].to_vec()
    }

    /// Kind of each moving joint: "revolute", "prismatic", "spherical" or "free".
    #[getter]
    fn joint_types(&self) -> Vec<&'static str> {
        self.model.joints()[1..].iter().map(|j| j.kind()).collect()
    }

    /// First index of each joint in q (aligned with joint_names).
    #[getter]
    fn joint_idx_q(&self) -> Vec<usize> {
        self.model.idx_q()[1..].to_vec()
    }

    /// First index of each joint in v (aligned with joint_names).
    #[getter]
    fn joint_idx_v(&self) -> Vec<usize> {
        self.model.idx_v()[1..].to_vec()
    }

    /// Names of the moving bodies (the child link of each joint, aligned with joint_names); the
    /// rows of `f_ext`.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.model.body_names[1..].to_vec()
    }

    /// Names of every frame: one per URDF link, moving or merged through a fixed joint.
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.model.frames.iter().map(|f| f.name.clone()).collect()
    }

    /// The parent of each moving body, aligned with body_names: -1 for the world, else an index
    /// into body_names.
    #[getter]
    fn body_parents(&self) -> Vec<isize> {
        self.model.parent()[1..]
            .iter()
            .map(|&p| p as isize - 1)
            .collect()
    }

    /// The body each frame is attached to, aligned with frame_names: -1 for the world, else an
    /// index into body_names.
    #[getter]
    fn frame_bodies(&self) -> Vec<isize> {
        self.model
            .frames
            .iter()
            .map(|f| f.body as isize - 1)
            .collect()
    }

    /// Gravity vector in world axes (m/s²), settable.
    #[getter]
    fn get_gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.gravity.as_slice())
    }

    #[setter]
    fn set_gravity(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        let values = read_property("gravity", value, 3)?;
        self.model.gravity = nalgebra::Vector3::from_row_slice(&values);
        Ok(())
    }

    /// Rotor inertia per velocity coordinate (kg m² or kg), settable: it adds to M's diagonal and
    /// to inverse and forward dynamics.
    #[getter]
    fn get_armature<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.armature.as_slice())
    }

    #[setter]
    fn set_armature(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        let armature = read_non_negative("armature", value, self.model.nv)?;
        self.model
            .check_armature(armature.as_slice())
            .map_err(to_py_err)?;
        self.model.armature = armature;
        Ok(())
    }

    /// Lower position limits, shape (nq,), -inf where none.
    #[getter]
    fn lower_position_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.lower_position_limit.as_slice())
    }

    /// Upper position limits, shape (nq,), inf where none.
    #[getter]
    fn upper_position_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.upper_position_limit.as_slice())
    }

    /// Velocity limits, shape (nv,), inf where none.
    #[getter]
    fn velocity_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.velocity_limit.as_slice())
    }

    /// Effort limits, shape (nv,), inf where none.
    #[getter]
    fn effort_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.effort_limit.as_slice())
    }

    /// Viscous damping per velocity coordinate (URDF `<dynamics damping>`, MJCF `damping`),
    /// settable. `simulate` applies it; the dynamics calls do not.
    #[getter]
    fn get_damping<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.damping.as_slice())
    }

    #[setter]
    fn set_damping(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        self.model.damping = read_non_negative("damping", value, self.model.nv)?;
        Ok(())
    }

    /// Coulomb friction per velocity coordinate (URDF `<dynamics friction>`, MJCF
    /// `frictionloss`), settable. `simulate` applies it smoothed; the dynamics calls do not.
    #[getter]
    fn get_friction<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.friction.as_slice())
    }

    #[setter]
    fn set_friction(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        self.model.friction = read_non_negative("friction", value, self.model.nv)?;
        Ok(())
    }

    /// Joint spring stiffness per velocity coordinate (MJCF `stiffness`), settable. `simulate`
    /// applies it; the dynamics calls do not.
    #[getter]
    fn get_stiffness<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.stiffness.as_slice())
    }

    #[setter]
    fn set_stiffness(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        self.model.stiffness = read_non_negative("stiffness", value, self.model.nv)?;
        Ok(())
    }

    /// The springs' higher coefficients (k₁, k₂) per velocity coordinate, shape (nv, 2) (MJCF
    /// `stiffness="k k₁ k₂"`): the spring's force is −(k + k₁ s + k₂ s²) d, s the signed
    /// displacement of a hinge or slide, the length of a ball's or either half of a free
    /// joint's. Settable (finite; one pair per ball and per half of a free joint).
    #[getter]
    fn get_stiffness_poly<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        pairs_array(py, &self.model.stiffness_poly)
    }

    #[setter]
    fn set_stiffness_poly(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        let pairs = read_pairs("stiffness_poly", value, self.model.nv)?;
        self.model.set_stiffness_poly(&pairs).map_err(to_py_err)
    }

    /// The dampers' higher coefficients (b₁, b₂) per velocity coordinate, shape (nv, 2) (MJCF
    /// `damping="b b₁ b₂"`): the damper's force is −(b + b₁ |q̇| + b₂ q̇²) q̇. Settable (finite).
    #[getter]
    fn get_damping_poly<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        pairs_array(py, &self.model.damping_poly)
    }

    #[setter]
    fn set_damping_poly(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        let pairs = read_pairs("damping_poly", value, self.model.nv)?;
        self.model.set_damping_poly(&pairs).map_err(to_py_err)
    }

    /// The configuration at which the joint springs are relaxed, shape (nq,) (MJCF `springref`;
    /// neutral for spherical and free joints), settable to any valid configuration.
    #[getter]
    fn get_spring_reference<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.spring_reference.as_slice())
    }

    #[setter]
    fn set_spring_reference(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        let values = read_property("spring_reference", value, self.model.nq)?;
        self.model
            .check_configuration(&values)
            .map_err(|e| to_py_err(e.for_argument("spring_reference")))?;
        self.model.spring_reference = DVector::from_vec(values);
        Ok(())
    }

    /// Each joint's spring yield (MJCF `springyield`, rad or m; 0: elastic), one per joint in
    /// `joint_names`' order: a spring stretched past it moves its reference (the plastic state,
    /// `plastic0`), in the scene's own dynamics.
    #[getter]
    fn spring_yield(&self) -> Vec<f64> {
        self.model.spring_yield[1..].to_vec()
    }

    /// The length of the plastic state (MuJoCo's `nplastic`): one reference per plastic hinge or
    /// slide, a quaternion (scalar last) per plastic ball, then a dead band [low, high] per
    /// plastic tendon.
    #[getter]
    fn nplastic(&self) -> usize {
        self.model.nplastic()
    }

    /// The plastic state before anything yields (nplastic,): the springs' own references.
    #[getter]
    fn plastic0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, &self.model.initial_plastic())
    }

    /// URDF mimic relations as (joint, mimicked joint, multiplier, offset):
    /// q[joint] = multiplier * q[mimicked] + offset. Those between two revolute or prismatic
    /// joints are also in `constraints` (as `JointCoupling`s), which `simulate` holds.
    #[getter]
    fn mimic_joints(&self) -> Vec<(String, String, f64, f64)> {
        self.model
            .mimics
            .iter()
            .map(|m| {
                (
                    self.model.joint_names[m.joint].clone(),
                    self.model.joint_names[m.mimicked].clone(),
                    m.multiplier,
                    m.offset,
                )
            })
            .collect()
    }

    /// What the loader accepted but you should know: ignored mimic tags, unchecked inertias.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.model.warnings.clone()
    }

    /// The constraints the model file declares and holds active (MJCF `<equality>` connect, weld
    /// and joint, anchors computed at the neutral configuration as MuJoCo's compiler does), as
    /// the `PointAnchor`, `FrameAnchor` and `JointCoupling` objects that state them; pass them
    /// to `constrained_forward_dynamics` or `simulate(..., constraints=m.constraints)`.
    #[getter]
    fn constraints(&self, py: Python) -> PyResult<Vec<Py<PyAny>>> {
        let active = self.model.constraints.iter().filter(|c| c.active);
        active
            .map(|c| crate::constraints::to_python(py, &self.model, &c.constraint))
            .collect()
    }

    /// The mass of each moving body (kg), aligned with body_names (fixed links merged in).
    #[getter]
    fn body_masses(&self) -> Vec<f64> {
        self.model.inertias[1..].iter().map(|i| i.mass).collect()
    }

    /// The ten standard inertial parameters of each moving body, shape (nbodies, 10), rows as
    /// body_names: [m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz], c the centre of
    /// mass and I the rotational inertia about the body's origin, in the body's axes (the
    /// regressor's order, as Pinocchio's dynamic parameters). Settable: every algorithm then
    /// uses the new values. Each row follows the rule for physical inertias, as a loaded file's
    /// do: m >= 0 and the inertia about the centre of mass positive semi-definite, else
    /// ValueError naming the row and body, and nothing changes; principal moments that break
    /// the triangle inequality are set with a ModelWarning naming them, so that
    /// `m.inertial_parameters = m.inertial_parameters` always holds.
    #[getter]
    fn get_inertial_parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows = self.model.nbodies() - 1;
        let flat: Vec<f64> = self
            .model
            .inertial_parameters()
            .into_iter()
            .flatten()
            .collect();
        Ok(PyArray1::from_vec(py, flat).reshape([rows, 10])?.into_any())
    }

    #[setter]
    fn set_inertial_parameters(&mut self, value: &Bound<PyAny>) -> PyResult<()> {
        self.forget_scene_step();
        let rows = self.model.nbodies() - 1;
        let flat = read_sample("inertial_parameters", value, SampleShape::matrix(rows, 10))?;
        let parameters: Vec<[f64; 10]> = flat
            .chunks_exact(10)
            .map(|row| <[f64; 10]>::try_from(row).expect("rows of ten"))
            .collect();
        let warnings = self
            .model
            .set_inertial_parameters(&parameters)
            .map_err(to_py_err)?;
        warn_model(value.py(), &warnings)
    }

    /// Total mass (kg).
    #[getter]
    fn total_mass(&self) -> f64 {
        self.model.total_mass()
    }

    fn __repr__(&self) -> String {
        format!(
            "robodyn.Model('{}', nq={}, nv={}, joints={}, frames={})",
            self.model.name,
            self.model.nq,
            self.model.nv,
            self.model.nbodies() - 1,
            self.model.frames.len()
        )
    }

    /// The neutral configuration, shape (nq,): zero angles and identity quaternions for URDF and
    /// DH models; MuJoCo's `qpos0` for an MJCF model (free joints at their bodies' poses in the
    /// file, hinges and slides at their `ref`).
    fn neutral<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_array(py, self.model.neutral().as_slice())
    }

    /// A random configuration within the position limits (angles in [-π, π] and translations in
    /// [-1, 1] m where a joint has none; uniform rotations). `n` gives a batch (n, nq); `seed`
    /// makes it reproducible.
    #[pyo3(signature = (n=None, seed=None))]
    pub(crate) fn random_configuration<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = named::optional_n)] n: Option<usize>,
        #[pyo3(from_py_with = named::optional_seed)] seed: Option<u64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let mut rng = match seed {
            Some(seed) => StdRng::seed_from_u64(seed),
            None => StdRng::from_os_rng(),
        };
        match n {
            None => Ok(
                vector_array(py, self.model.random_configuration(&mut rng).as_slice()).into_any(),
            ),
            Some(n) => {
                let mut values = Vec::with_capacity(n * self.model.nq);
                for _ in 0..n {
                    values.extend_from_slice(self.model.random_configuration(&mut rng).as_slice());
                }
                Ok(PyArray1::from_vec(py, values)
                    .reshape([n, self.model.nq])?
                    .into_any())
            }
        }
    }

    /// q ⊕ v dt: moves q with constant velocity v for dt seconds on each joint's Lie group.
    #[pyo3(signature = (q, v, dt=1.0))]
    fn integrate<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::dt)] dt: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        if !dt.is_finite() {
            return Err(PyValueError::new_err(format!(
                "argument 'dt': expected a finite number, got {dt}"
            )));
        }
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[self.model.nq],
            &|m, _, i, out| {
                robodyn::error::check_finite("v", i[1])?;
                let step: Vec<f64> = i[1].iter().map(|x| x * dt).collect();
                m.integrate(i[0], &step, out)
            },
        )
    }

    /// Jacobians of q ⊕ v in the tangent spaces (right perturbations q ⊕ δ, Pinocchio's
    /// `dIntegrate` convention): dict of `dq` = ∂(q ⊕ v)/∂q = Ad(exp(v))⁻¹ and `dv` =
    /// ∂(q ⊕ v)/∂v = J_r(v), each (nv, nv), block-diagonal by joint; identity blocks on revolute
    /// and prismatic joints.
    fn integrate_jacobians<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let arguments = [self.q_arg("q", q)?, self.v_arg("v", v)?];
        let pair = self.jacobian_pair(py, &arguments, integrate_jacobians)?;
        split_stack(py, &pair, &keys!(py, "dq", "dv"))
    }

    /// Jacobians of q1 ⊖ q0 in the tangent spaces: dict of `dq0` = −J_l(v)⁻¹ and `dq1` =
    /// J_r(v)⁻¹ with v = q1 ⊖ q0, each (nv, nv), block-diagonal by joint.
    fn difference_jacobians<'py>(
        &self,
        py: Python<'py>,
        q0: &Bound<'py, PyAny>,
        q1: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let arguments = [self.q_arg("q0", q0)?, self.q_arg("q1", q1)?];
        let pair = self.jacobian_pair(py, &arguments, difference_jacobians)?;
        split_stack(py, &pair, &keys!(py, "dq0", "dq1"))
    }

    /// q1 ⊖ q0: the velocity that moves q0 to q1 in unit time. (nv,).
    fn difference<'py>(
        &self,
        py: Python<'py>,
        q0: &Bound<'py, PyAny>,
        q1: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q0", q0)?, self.q_arg("q1", q1)?],
            &[self.model.nv],
            &|m, _, i, out| m.difference(i[0], i[1], out),
        )
    }
}

/// A pair of nv × nv Jacobians of two inputs.
type JacobianPair =
    fn(&Model, &[f64], &[f64], &mut DMatrix<f64>, &mut DMatrix<f64>) -> robodyn::Result<()>;

impl PyModel {
    /// `algorithm`'s two Jacobians per sample, as one (…, 2, nv, nv) array.
    fn jacobian_pair<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        algorithm: JacobianPair,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.evaluate(py, arguments, &[2, nv, nv], &|m, w, i, out| {
            let (first, second) = &mut w.jacobians;
            algorithm(m, i[0], i[1], first, second)?;
            let (top, bottom) = out.split_at_mut(nv * nv);
            write_row_major(first, nv, top);
            write_row_major(second, nv, bottom);
            Ok(())
        })
    }
}

/// Reports each message as a `robodyn.ModelWarning` (an error if warnings are turned into errors).
fn warn_model(py: Python<'_>, messages: &[String]) -> PyResult<()> {
    if messages.is_empty() {
        return Ok(());
    }
    let category = py.import("robodyn")?.getattr("ModelWarning")?;
    for message in messages {
        let text = std::ffi::CString::new(message.replace('\0', " "))?;
        PyErr::warn(py, &category, &text, 1)?;
    }
    Ok(())
}

/// Checks ten inertial parameters [m, m c, Ī_O] against the rule for physical inertias, the one
/// the loaders and the `inertial_parameters` setter apply; raises ValueError naming what breaks it.
#[pyfunction]
pub(crate) fn check_physical_parameters(parameters: [f64; 10]) -> PyResult<()> {
    robodyn::model::check_physical_parameters(&parameters)
        .map_err(|defect| PyValueError::new_err(defect.to_string()))
}

/// Pairs per velocity coordinate as an (n, 2) array.
fn pairs_array<'py>(py: Python<'py>, pairs: &[[f64; 2]]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = pairs.iter().flatten().copied().collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([pairs.len(), 2])?
        .into_any())
}

/// An (n, 2) array argument as pairs.
fn read_pairs(name: &'static str, value: &Bound<PyAny>, n: usize) -> PyResult<Vec<[f64; 2]>> {
    let flat = read_sample(name, value, SampleShape::matrix(n, 2))?;
    Ok(flat.chunks_exact(2).map(|p| [p[0], p[1]]).collect())
}
