//! Dynamics: RNEA, ABA, M three ways, bias forces, gravity, the Coriolis matrix and Christoffel
//! symbols, Craig's split, energies and centroidal momentum.

use crate::args::*;
use crate::model::*;
use nalgebra::DVector;
use pyo3::prelude::*;
use pyo3::types::PyString;
use robodyn::algo::{self, BatchAlgorithm};
use robodyn::spatial::Force;
use robodyn::{Data, Model};

impl PyModel {
    /// `then` on the arguments (q, v, x[, f_ext]) of a dynamics algorithm with optional external
    /// forces. Each argument is made in its place in an array of three or four on this frame:
    /// moved after it was made (into a vector returned to the caller), a freshly written
    /// argument was read back in wider pieces than it was stored in, and each such read waited
    /// for the stores (a tenth of a small call's fixed cost).
    #[inline(always)]
    pub(crate) fn with_dynamics_arguments<'py, R>(
        &self,
        (q, v, x): (
            &Bound<'py, PyAny>,
            &Bound<'py, PyAny>,
            (&'static str, &Bound<'py, PyAny>),
        ),
        f_ext: Option<&Bound<'py, PyAny>>,
        then: impl FnOnce(&[Argument<'py>]) -> PyResult<R>,
    ) -> PyResult<R> {
        let (q, v, x) = (
            self.q_arg("q", q)?,
            self.v_arg("v", v)?,
            self.v_arg(x.0, x.1)?,
        );
        match f_ext {
            None => then(&[q, v, x]),
            Some(f) => {
                let shape = SampleShape::matrix(self.model.nbodies() - 1, 6);
                then(&[q, v, x, Argument::new("f_ext", f, shape)?])
            }
        }
    }

    /// Dynamics with optional external forces: `algorithm(q, v, x, f_ext)` on the arguments of
    /// [`Self::with_dynamics_arguments`], into `out` when given; a batch without external forces
    /// runs `lanes` (the algorithm in lanes) when given.
    pub(crate) fn with_external_forces<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        out: Option<&Bound<'py, PyAny>>,
        algorithm: DynamicsAlgorithm,
        lanes: Option<BatchAlgorithm>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate_into(
            py,
            arguments,
            &[self.model.nv],
            out,
            &|m, w, i, out| {
                let Workspace { data, forces, .. } = w;
                let forces = i.get(3).map(|flat| external_forces(forces, flat));
                out.copy_from_slice(algorithm(m, data, i[0], i[1], i[2], forces)?.as_slice());
                Ok(())
            },
            lanes.filter(|_| arguments.len() < 4),
        )
    }

    /// The three nv × nv derivatives of a dynamics algorithm with optional external forces, as a
    /// dict of (…, nv, nv) arrays named `names`.
    fn dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        names: [&Bound<'py, PyString>; 3],
        derivatives: DerivativesAlgorithm,
        lanes: Option<BatchAlgorithm>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        let kernel: &Kernel = &|m, w, i, out| {
            let Workspace { data, forces, .. } = w;
            let forces = i.get(3).map(|flat| external_forces(forces, flat));
            let into = algo::DerivativesInto::Stacked(out);
            derivatives(m, data, i[0], i[1], i[2], forces, into)
        };
        let lanes = lanes.filter(|_| arguments.len() < 4);
        let lanes = lanes.map(LaneRun::Algorithm);
        let stack = self.evaluate_to(py, arguments, &[3, nv, nv], Target::Zeros, kernel, lanes)?;
        split_stack(py, &stack, &names)
    }
}

/// A derivatives algorithm `(q, v, x, f_ext)` writing its three nv × nv results where it is told.
type DerivativesAlgorithm = fn(
    &Model,
    &mut Data,
    &[f64],
    &[f64],
    &[f64],
    Option<&[Force]>,
    algo::DerivativesInto,
) -> robodyn::Result<()>;

/// `forces` filled from the flat (nbodies − 1) × 6 rows of an `f_ext` argument.
fn external_forces<'w>(forces: &'w mut [Force], flat: &[f64]) -> &'w [Force] {
    fill_forces(forces, flat);
    forces
}

/// The Christoffel symbols at q, row-major (i, j, k), in a new buffer.
pub(crate) fn christoffel_of(
    model: &Model,
    worker: &mut Workspace,
    q: &[f64],
) -> robodyn::Result<Vec<f64>> {
    let mut gamma = vec![0.0; model.nv.pow(3)];
    algo::christoffel_symbols(model, &mut worker.data, q, &mut gamma)?;
    Ok(gamma)
}

#[pymethods]
impl PyModel {
    /// Inverse dynamics by RNEA: τ = M(q) a + C(q, v) v + g(q) - Σ J_iᵀ f_ext_i.
    /// `f_ext`: optional (nbodies, 6) wrenches [force; torque] on each body (rows as body_names),
    /// in the body's frame, at its origin. `out`: optional float64 array of the result's shape
    /// to write into and return (reused by a loop; not one of the inputs).
    #[pyo3(signature = (q, v, a, f_ext=None, out=None))]
    fn inverse_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        f_ext: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.with_dynamics_arguments((q, v, ("a", a)), f_ext, |arguments| {
            let lanes = Some(BatchAlgorithm::NewtonEuler);
            self.with_external_forces(py, arguments, out, algo::rnea, lanes)
        })
    }

    /// The joint-torque regressor Y(q, v, a), shape (nv, 10 nbodies): τ = Y π with π =
    /// `inertial_parameters.ravel()` (each body's ten parameters in turn). Armature adds
    /// armature · a (and the ball joints' rotor terms) to τ; it is not a body's parameter.
    fn torque_regressor<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let columns = 10 * (self.model.nbodies() - 1);
        self.with_dynamics_arguments((q, v, ("a", a)), None, |arguments| {
            self.evaluate(py, arguments, &[self.model.nv, columns], &|m, w, i, out| {
                let y = algo::torque_regressor(m, &mut w.data, i[0], i[1], i[2])?;
                write_row_major(y, m.nv, out);
                Ok(())
            })
        })
    }

    /// Forward dynamics by ABA: a = M(q)⁻¹ (τ - C(q, v) v - g(q) + Σ J_iᵀ f_ext_i).
    /// `out` as in `inverse_dynamics`.
    #[pyo3(signature = (q, v, tau, f_ext=None, out=None))]
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        f_ext: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.with_dynamics_arguments((q, v, ("tau", tau)), f_ext, |arguments| {
            let lanes = Some(BatchAlgorithm::ArticulatedBody);
            self.with_external_forces(py, arguments, out, algo::aba, lanes)
        })
    }

    /// Derivatives of inverse dynamics τ = ID(q, v, a, f_ext): dict of `dtau_dq`, `dtau_dv` and
    /// `dtau_da` (= M(q)), each (nv, nv). ∂/∂q is taken in the tangent space along right
    /// perturbations q ⊕ δ (δ a velocity, in each joint's child frame: Pinocchio's convention);
    /// on revolute and prismatic joints it is the ordinary partial derivative. `f_ext` as in
    /// `inverse_dynamics`, held fixed in each body's frame.
    #[pyo3(signature = (q, v, a, f_ext=None))]
    fn inverse_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        f_ext: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let names = keys!(py, "dtau_dq", "dtau_dv", "dtau_da");
        self.with_dynamics_arguments((q, v, ("a", a)), f_ext, |arguments| {
            let lanes = Some(BatchAlgorithm::RneaDerivatives);
            self.dynamics_derivatives(py, arguments, names, algo::rnea_derivatives, lanes)
        })
    }

    /// Derivatives of forward dynamics a = FD(q, v, tau, f_ext): dict of `dqdd_dq`, `dqdd_dv`
    /// and `dqdd_dtau` (= M(q)⁻¹), each (nv, nv); ∂/∂q as in `inverse_dynamics_derivatives`.
    /// Computed as −M⁻¹ ∂τ/∂x at a = FD(q, v, tau).
    #[pyo3(signature = (q, v, tau, f_ext=None))]
    fn forward_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        f_ext: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let names = keys!(py, "dqdd_dq", "dqdd_dv", "dqdd_dtau");
        self.with_dynamics_arguments((q, v, ("tau", tau)), f_ext, |arguments| {
            let lanes = Some(BatchAlgorithm::AbaDerivatives);
            self.dynamics_derivatives(py, arguments, names, algo::aba_derivatives, lanes)
        })
    }

    /// Joint-space inertia matrix M(q), full and symmetric, armature included. (nv, nv).
    /// `method`: "crba" (Featherstone's composite-rigid-body algorithm, the fastest), "rnea"
    /// (column k = τ(q, 0, e_k) − g(q), n RNEA calls: the UR5 dynamics notes) or "jacobians"
    /// (Σ m J_vᵀ J_v + J_ωᵀ I J_ω over the bodies: the TU Berlin and UR5 dynamics notes).
    /// `out` as in `inverse_dynamics`.
    #[pyo3(signature = (q, method=MethodName::Crba, out=None), text_signature = "($self, q, method='crba', out=None)")]
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::method)] method: MethodName,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let algorithm: MatrixOfQ = match method {
            MethodName::Crba => {
                // straight into the result: CRBA mirrors M, so it is exactly symmetric
                let (shape, arguments) = ([self.model.nv; 2], [self.q_arg("q", q)?]);
                let kernel: &Kernel = &|m, w, i, out| algo::crba_into(m, &mut w.data, i[0], out);
                let lanes = Some(BatchAlgorithm::CompositeRigidBody);
                return self.evaluate_into(py, &arguments, &shape, out, kernel, lanes);
            }
            MethodName::Rnea => algo::mass_matrix_by_rnea,
            MethodName::Jacobians => algo::mass_matrix_by_jacobians,
            other => return Err(unknown_method(other.as_str(), "crba, rnea or jacobians")),
        };
        self.matrix_of_q_into(py, q, self.model.nv, out, algorithm)
    }

    /// M(q)⁻¹. (nv, nv).
    fn inverse_mass_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.matrix_of_q(py, q, self.model.nv, algo::inverse_mass_matrix)
    }

    /// Bias forces C(q, v) v + g(q) (RNEA with a = 0). (nv,). `out` as in `inverse_dynamics`.
    #[pyo3(signature = (q, v, out=None))]
    fn bias_forces<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate_into(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[self.model.nv],
            out,
            &|m, w, i, out| {
                out.copy_from_slice(algo::bias_forces(m, &mut w.data, i[0], i[1])?.as_slice());
                Ok(())
            },
            Some(BatchAlgorithm::NewtonEuler),
        )
    }

    /// Coriolis matrix C(q, v) (nv, nv), from the Christoffel symbols of the first kind:
    /// C(q, v) v = bias_forces(q, v) − generalized_gravity(q), and Ṁ − 2C is skew-symmetric
    /// (the TU Berlin notes). A recursive O(n²) algorithm (Echeandia & Wensing 2021), no RNEA calls.
    fn coriolis_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[nv, nv],
            &|m, w, i, out| {
                write_row_major(
                    algo::coriolis_matrix(m, &mut w.data, i[0], i[1])?,
                    m.nv,
                    out,
                );
                Ok(())
            },
        )
    }

    /// Generalized gravity g(q). (nv,). `method`: "rnea" (RNEA with v = a = 0) or "jacobians"
    /// (−Σ J_cᵀ m g over the bodies' centres of mass: the TU Berlin notes "Gravity"). `out` as in
    /// `inverse_dynamics`.
    #[pyo3(signature = (q, method=MethodName::Rnea, out=None), text_signature = "($self, q, method='rnea', out=None)")]
    fn generalized_gravity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::method)] method: MethodName,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        type Method = for<'d> fn(&Model, &'d mut Data, &[f64]) -> robodyn::Result<&'d DVector<f64>>;
        let (algorithm, lanes): (Method, Option<BatchAlgorithm>) = match method {
            MethodName::Rnea => (algo::generalized_gravity, Some(BatchAlgorithm::NewtonEuler)),
            MethodName::Jacobians => (algo::generalized_gravity_by_jacobians, None),
            other => return Err(unknown_method(other.as_str(), "rnea or jacobians")),
        };
        self.evaluate_into(
            py,
            &[self.q_arg("q", q)?],
            &[self.model.nv],
            out,
            &|m, w, i, out| {
                out.copy_from_slice(algorithm(m, &mut w.data, i[0])?.as_slice());
                Ok(())
            },
            lanes,
        )
    }

    /// Christoffel symbols of the first kind, (nv, nv, nv):
    /// Γ[i, j, k] = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i), so that C(q, v)_ij = Σ_k Γ[i, j, k] v_k
    /// (the TU Berlin notes). Exact: Γ[:, :, k] = C(q, e_k) by the recursive Coriolis algorithm. With
    /// spherical or free joints (velocities that are not coordinate rates) the coordinate formula
    /// has no meaning; Γ[:, :, k] = C(q, e_k) still holds.
    fn christoffel<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[nv, nv, nv],
            &|m, w, i, out| {
                algo::christoffel_symbols(m, &mut w.data, i[0], out)?;
                Ok(())
            },
        )
    }

    /// Craig's centrifugal matrix C(q), (nv, nv) (the TU Berlin notes, "Centrifugal and Coriolis
    /// Computation"): the velocity terms are C(q) [q̇₁², …, q̇ₙ²] + B(q) [q̇₁q̇₂, q̇₁q̇₃, …];
    /// C(q)_ij = Γ_ijj.
    fn centrifugal_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        self.evaluate(py, &[self.q_arg("q", q)?], &[nv, nv], &|m, w, i, out| {
            let gamma = christoffel_of(m, w, i[0])?;
            for (row, j) in (0..nv).flat_map(|row| (0..nv).map(move |j| (row, j))) {
                out[row * nv + j] = gamma[(row * nv + j) * nv + j];
            }
            Ok(())
        })
    }

    /// Craig's Coriolis matrix B(q), (nv, nv(nv−1)/2) (the TU Berlin notes): multiplies the products
    /// [q̇₁q̇₂, q̇₁q̇₃, …, q̇₁q̇ₙ, q̇₂q̇₃, …] (pairs j < k in that order); B(q)_i,(jk) = 2 Γ_ijk.
    fn coriolis_pairs_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nv = self.model.nv;
        let pairs = nv * nv.saturating_sub(1) / 2;
        self.evaluate(py, &[self.q_arg("q", q)?], &[nv, pairs], &|m, w, i, out| {
            let gamma = christoffel_of(m, w, i[0])?;
            for row in 0..nv {
                let mut column = 0;
                for j in 0..nv {
                    for k in j + 1..nv {
                        out[row * pairs + column] = 2.0 * gamma[(row * nv + j) * nv + k];
                        column += 1;
                    }
                }
            }
            Ok(())
        })
    }

    /// Kinetic energy ½ vᵀ M(q) v (J), rotor energy included.
    fn kinetic_energy<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[],
            &|m, w, i, out| {
                out[0] = algo::kinetic_energy(m, &mut w.data, i[0], i[1])?;
                Ok(())
            },
        )
    }

    /// The Lagrangian L = T − V (J): kinetic minus potential energy.
    fn lagrangian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[],
            &|m, w, i, out| {
                let kinetic = algo::kinetic_energy(m, &mut w.data, i[0], i[1])?;
                out[0] = kinetic - algo::potential_energy(m, &mut w.data, i[0])?;
                Ok(())
            },
        )
    }

    /// Potential energy -Σ m_i gᵀ c_i (J), zero at the world origin.
    fn potential_energy<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(py, &[self.q_arg("q", q)?], &[], &|m, w, i, out| {
            out[0] = algo::potential_energy(m, &mut w.data, i[0])?;
            Ok(())
        })
    }

    /// The joint springs' energy (J) at q: Σ (k d²/2 + k₁ s³/3 + k₂ s⁴/4) over d = q ⊖
    /// `spring_reference`, s the signed displacement of a hinge or slide, the length of a ball's
    /// or of either half of a free joint's (the potential of the springs `simulate` applies);
    /// zero where every spring is relaxed. A batch (N, nq) gives (N,).
    fn spring_energy<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(py, &[self.q_arg("q", q)?], &[], &|m, w, i, out| {
            let scratch = w.data.tau.as_mut_slice();
            out[0] = robodyn::integrate::forces::spring_energy(m, i[0], scratch);
            Ok(())
        })
    }

    /// Centroidal momentum matrix A_G(q), (6, nv): h_G = A_G v, rows [linear momentum; angular
    /// momentum about the centre of mass], world axes (Orin, Goswami & Lee 2013).
    fn centroidal_momentum_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.matrix_of_q(py, q, 6, algo::centroidal_momentum_matrix)
    }

    /// Centroidal momentum h_G = A_G(q) v, (6,): [linear momentum m ċ; angular momentum about the
    /// centre of mass], world axes.
    fn centroidal_momentum<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.matrix_of_q_times_v(py, q, v, 6, algo::centroidal_momentum_matrix)
    }
}
