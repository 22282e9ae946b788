//! Kinematics: frame poses, Jacobians and their derivatives, frame velocities and accelerations,
//! the centre of mass, manipulability, workspace sampling and inverse kinematics.

use crate::args::*;
use crate::model::*;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rand::{rngs::StdRng, SeedableRng};
use robodyn::algo::{self, BatchAlgorithm};
use robodyn::Error;

impl PyModel {
    /// One of the two measures of `algo::manipulability`, per state.
    pub(crate) fn manipulability_measure<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        task: Option<&Bound<'py, PyAny>>,
        measure: fn((f64, f64)) -> f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        let rows = task.map_or_else(|| Ok((0..6).collect()), parse_task)?;
        self.evaluate(py, &[self.q_arg("q", q)?], &[], &|m, w, i, out| {
            out[0] = measure(algo::manipulability(m, &mut w.data, i[0], frame, &rows)?);
            Ok(())
        })
    }
}

#[pymethods]
impl PyModel {
    /// Pose of a frame (name or index) in the world: 4x4 homogeneous matrix. `out` as in
    /// `inverse_dynamics`.
    #[pyo3(signature = (q, frame, out=None))]
    fn frame_pose<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        let kernel: &Kernel = &|m, w, i, out| {
            algo::frame_pose(m, &mut w.data, i[0], frame)?.write_homogeneous(out);
            Ok(())
        };
        let lanes = Some(BatchAlgorithm::FramePose { frame });
        self.evaluate_into(py, &[self.q_arg("q", q)?], &[4, 4], out, kernel, lanes)
    }

    /// The pose in the world of every body, the world first: (nbodies, 4, 4) homogeneous
    /// matrices, in the order of `["world"] + body_names`. What a viewer needs for each frame.
    fn body_poses<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let bodies = self.model.nbodies();
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[bodies, 4, 4],
            &|m, w, i, out| {
                let placements = algo::forward_kinematics(m, &mut w.data, i[0])?;
                for (placement, pose) in placements.iter().zip(out.chunks_exact_mut(16)) {
                    placement.write_homogeneous(pose);
                }
                Ok(())
            },
        )
    }

    /// Jacobian of a frame, (6, nv), rows [linear; angular]. `reference`: "world" (velocity of the
    /// frame's origin and angular velocity in world axes: the geometric Jacobian), "local" (the
    /// same in the frame's axes) or "spatial" (spatial velocity in world coordinates). `out` as
    /// in `inverse_dynamics`.
    #[pyo3(signature = (q, frame, reference=algo::Reference::World, out=None), text_signature = "($self, q, frame, reference='world', out=None)")]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::reference)] reference: algo::Reference,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        self.evaluate_into(
            py,
            &[self.q_arg("q", q)?],
            &[6, self.model.nv],
            out,
            &|m, w, i, out| {
                // row-major (6, nv): only the columns of the frame's support are not zero
                out.fill(0.0);
                let column = |c, linear: &_, angular: &_| {
                    algo::write_jacobian_column(out, m.nv, c, linear, angular)
                };
                algo::jacobian_columns(m, &mut w.data, i[0], frame, reference, column)?;
                Ok(())
            },
            Some(BatchAlgorithm::Jacobian { frame, reference }),
        )
    }

    /// Time derivative J̇(q, v) of a frame's Jacobian, (6, nv), same references as `jacobian`;
    /// J̇ v equals `frame_acceleration(q, v, 0, frame, reference)`.
    #[pyo3(signature = (q, v, frame, reference=algo::Reference::World), text_signature = "($self, q, v, frame, reference='world')")]
    fn jacobian_time_variation<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::reference)] reference: algo::Reference,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[6, self.model.nv],
            &|m, w, i, out| {
                write_row_major(
                    algo::jacobian_time_variation(m, &mut w.data, i[0], i[1], frame, reference)?,
                    6,
                    out,
                );
                Ok(())
            },
        )
    }

    /// Derivatives of a frame's velocity (`frame_velocity`, same `reference`): dict of `dv_dq`
    /// (tangent space, right perturbations q ⊕ δ) and `dv_dv` (= J), each (6, nv).
    #[pyo3(signature = (q, v, frame, reference=algo::Reference::World), text_signature = "($self, q, v, frame, reference='world')")]
    fn frame_velocity_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::reference)] reference: algo::Reference,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        let zeros = vec![0.0; self.model.nv];
        let arguments = [self.q_arg("q", q)?, self.v_arg("v", v)?];
        let stack = self.evaluate(py, &arguments, &[2, 6, self.model.nv], &|m, w, i, out| {
            let data = &mut w.data;
            algo::frame_motion_derivatives(m, data, i[0], i[1], &zeros, frame, reference)?;
            write_stack(&[&data.frame_velocity_dq, &data.jacobian], 6, out);
            Ok(())
        })?;
        split_stack(py, &stack, &keys!(py, "dv_dq", "dv_dv"))
    }

    /// Derivatives of a frame's velocity and classical acceleration (`frame_acceleration`, same
    /// `reference`): dict of `dv_dq`, `dv_dv` (= J), `da_dq`, `da_dv`, `da_da` (= J), each
    /// (6, nv), q in the tangent space.
    #[pyo3(signature = (q, v, a, frame, reference=algo::Reference::World), text_signature = "($self, q, v, a, frame, reference='world')")]
    fn frame_acceleration_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::reference)] reference: algo::Reference,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        let stack = self.with_dynamics_arguments((q, v, ("a", a)), None, |arguments| {
            self.evaluate(py, arguments, &[5, 6, self.model.nv], &|m, w, i, out| {
                let data = &mut w.data;
                algo::frame_motion_derivatives(m, data, i[0], i[1], i[2], frame, reference)?;
                let matrices = [
                    &data.frame_velocity_dq,
                    &data.jacobian,
                    &data.frame_acceleration_dq,
                    &data.frame_acceleration_dv,
                    &data.jacobian,
                ];
                write_stack(&matrices, 6, out);
                Ok(())
            })
        })?;
        split_stack(
            py,
            &stack,
            &keys!(py, "dv_dq", "dv_dv", "da_dq", "da_dv", "da_da"),
        )
    }

    /// Derivatives of the centre of mass's velocity ċ = J_com v (world axes): dict of `dv_dq`
    /// (tangent space) and `dv_dv` (= J_com), each (3, nv).
    fn center_of_mass_velocity_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let arguments = [self.q_arg("q", q)?, self.v_arg("v", v)?];
        let stack = self.evaluate(py, &arguments, &[2, 3, self.model.nv], &|m, w, i, out| {
            let data = &mut w.data;
            algo::center_of_mass_velocity_derivatives(m, data, i[0], i[1])?;
            // J_com: the first three rows of `data.jacobian`
            write_stack(&[&data.com_velocity_dq, &data.jacobian], 3, out);
            Ok(())
        })?;
        split_stack(py, &stack, &keys!(py, "dv_dq", "dv_dv"))
    }

    /// Velocity of a frame, (6,) [linear; angular] = J(q) v: "world" (its origin's velocity and
    /// angular velocity in world axes), "local" (the same in its axes) or "spatial".
    #[pyo3(signature = (q, v, frame, reference=algo::Reference::World), text_signature = "($self, q, v, frame, reference='world')")]
    fn frame_velocity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::reference)] reference: algo::Reference,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        self.evaluate(
            py,
            &[self.q_arg("q", q)?, self.v_arg("v", v)?],
            &[6],
            &|m, w, i, out| {
                out.copy_from_slice(&algo::frame_velocity(
                    m,
                    &mut w.data,
                    i[0],
                    i[1],
                    frame,
                    reference,
                )?);
                Ok(())
            },
        )
    }

    /// Acceleration of a frame, (6,) [linear; angular] = J(q) a + J̇(q, v) v: "world" (the
    /// classical acceleration of its origin and its angular acceleration, world axes), "local"
    /// (the same in its axes) or "spatial" (Featherstone's spatial acceleration, world
    /// coordinates). With a = 0 it is J̇ v.
    #[pyo3(signature = (q, v, a, frame, reference=algo::Reference::World), text_signature = "($self, q, v, a, frame, reference='world')")]
    fn frame_acceleration<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        a: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::reference)] reference: algo::Reference,
    ) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.frame_index(frame)?;
        self.with_dynamics_arguments((q, v, ("a", a)), None, |arguments| {
            self.evaluate(py, arguments, &[6], &|m, w, i, out| {
                let data = &mut w.data;
                let acceleration =
                    algo::frame_acceleration(m, data, i[0], i[1], i[2], frame, reference)?;
                out.copy_from_slice(&acceleration);
                Ok(())
            })
        })
    }

    /// Centre of mass of the robot in world coordinates. (3,).
    fn center_of_mass<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(py, &[self.q_arg("q", q)?], &[3], &|m, w, i, out| {
            out.copy_from_slice(algo::center_of_mass(m, &mut w.data, i[0])?.as_slice());
            Ok(())
        })
    }

    /// Jacobian of the centre of mass, (3, nv) in world axes: ċ = J_com v.
    fn center_of_mass_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.matrix_of_q(py, q, 3, algo::center_of_mass_jacobian)
    }

    /// Velocity of the centre of mass ċ = J_com(q) v, (3,), world axes.
    fn center_of_mass_velocity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.matrix_of_q_times_v(py, q, v, 3, algo::center_of_mass_jacobian)
    }

    /// Yoshikawa's manipulability √det(J Jᵀ) of a frame for a task: "full" (6 rows), "position",
    /// "orientation" or a list of rows of [vx, vy, vz, ωx, ωy, ωz]. Zero at a singularity.
    #[pyo3(signature = (q, frame, task=None))]
    fn manipulability<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        task: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.manipulability_measure(py, q, frame, task, |(w, _)| w)
    }

    /// σ_min / σ_max of a frame's task Jacobian (see `manipulability`): 1 when isotropic, 0 at a
    /// singularity.
    #[pyo3(signature = (q, frame, task=None))]
    fn inverse_condition_number<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &Bound<'py, PyAny>,
        task: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.manipulability_measure(py, q, frame, task, |(_, inverse_condition)| {
            inverse_condition
        })
    }

    /// Workspace sampling: the world positions (n, 3) of a frame's origin over n random
    /// configurations (see `random_configuration`), computed on all cores.
    #[pyo3(signature = (frame, n=10_000, seed=None))]
    fn workspace<'py>(
        &self,
        py: Python<'py>,
        frame: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = named::n)] n: usize,
        #[pyo3(from_py_with = named::optional_seed)] seed: Option<u64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let states = self.random_configuration(py, Some(n), seed)?;
        let poses = self.frame_pose(py, &states, frame, None)?;
        // the translation column of each pose
        let slicing = (
            pyo3::types::PySlice::full(py),
            pyo3::types::PySlice::new(py, 0, 3, 1),
            3,
        );
        poses.get_item(slicing)?.call_method0("copy")
    }

    /// Inverse kinematics: a configuration placing `frame` at `target`, a 4x4 pose (or N poses,
    /// solved in parallel), by damped least squares from `q0` (default: neutral) and then from up
    /// to `restarts` random configurations. `position_only` matches only the target's position.
    /// Returns a dict: "q" (nq,), "success" (bool), "iterations" (int), "residual" (the error
    /// norm, m and rad), with a leading N for a batch. Results do not depend on batch position.
    #[pyo3(signature = (frame, target, q0=None, position_only=false, tolerance=1e-10, max_iterations=200, restarts=20, damping=1e-6, seed=0))]
    #[allow(clippy::too_many_arguments)]
    fn inverse_kinematics<'py>(
        &self,
        py: Python<'py>,
        frame: &Bound<'py, PyAny>,
        target: &Bound<'py, PyAny>,
        q0: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = named::position_only)] position_only: bool,
        #[pyo3(from_py_with = named::tolerance)] tolerance: f64,
        #[pyo3(from_py_with = named::max_iterations)] max_iterations: usize,
        #[pyo3(from_py_with = named::restarts)] restarts: usize,
        #[pyo3(from_py_with = named::damping)] damping: f64,
        #[pyo3(from_py_with = named::seed)] seed: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let frame = self.frame_index(frame)?;
        let options = algo::IkOptions {
            position_only,
            tolerance,
            max_iterations,
            restarts,
            damping,
        };
        let target = Argument::new("target", target, SampleShape::matrix(4, 4))?;
        let q0 = match q0 {
            Some(q0) => self.q_arg("q0", q0)?,
            None => {
                // the neutral configuration, once per target
                let neutral = self.model.neutral();
                let starts = match target.batch()? {
                    None => PyArray1::from_slice(py, neutral.as_slice()).into_any(),
                    Some(n) => {
                        let repeated: Vec<f64> =
                            (0..n).flat_map(|_| neutral.iter().copied()).collect();
                        PyArray1::from_vec(py, repeated)
                            .reshape([n, self.model.nq])?
                            .into_any()
                    }
                };
                self.q_arg("q0", &starts)?
            }
        };
        let nq = self.model.nq;
        let packed = self.evaluate(py, &[target, q0], &[nq + 3], &|m, w, i, out| {
            let pose = i[0];
            let rotation = nalgebra::Matrix3::new(
                pose[0], pose[1], pose[2], pose[4], pose[5], pose[6], pose[8], pose[9], pose[10],
            );
            let orthonormal =
                (rotation.transpose() * rotation - nalgebra::Matrix3::identity()).norm() < 1e-6
                    && rotation.determinant() > 0.0
                    && pose[12..16] == [0.0, 0.0, 0.0, 1.0];
            if !orthonormal {
                return Err(Error::InvalidValue {
                    argument: "target".into(),
                    message: "expected a 4x4 homogeneous pose [R p; 0 0 0 1] with R a rotation"
                        .into(),
                });
            }
            let position = nalgebra::Vector3::new(pose[3], pose[7], pose[11]);
            let target = robodyn::spatial::Transform::from_pose(&rotation, &position);
            // the restarts' random states depend on the sample, never on its place in a batch
            let mut hasher = std::collections::hash_map::DefaultHasher::new();
            std::hash::Hash::hash(&seed, &mut hasher);
            for value in pose.iter().chain(i[1]) {
                std::hash::Hash::hash(&value.to_bits(), &mut hasher);
            }
            let mut rng = StdRng::seed_from_u64(std::hash::Hasher::finish(&hasher));
            let solution =
                algo::inverse_kinematics(m, &mut w.data, frame, &target, i[1], &options, &mut rng)?;
            out[..m.nq].copy_from_slice(solution.q.as_slice());
            out[m.nq] = f64::from(u8::from(solution.success));
            out[m.nq + 1] = solution.iterations as f64;
            out[m.nq + 2] = solution.residual;
            Ok(())
        })?;
        search_result(py, &packed, nq)
    }
}

/// The dict of a configuration search (inverse kinematics, closing constraints) from its
/// results packed as `[q (nq), success, iterations, residual]` along the last axis: "q",
/// "success" (bool), "iterations" (int) and "residual", each with the batch's leading axis.
pub(crate) fn search_result<'py>(
    py: Python<'py>,
    packed: &Bound<'py, PyAny>,
    nq: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let result = PyDict::new(py);
    let ellipsis = py.Ellipsis().into_bound(py);
    let column = |k: usize| (ellipsis.clone(), k);
    let configurations = (
        ellipsis.clone(),
        pyo3::types::PySlice::new(py, 0, nq as isize, 1),
    );
    result.set_item("q", packed.get_item(configurations)?.call_method0("copy")?)?;
    result.set_item(
        "success",
        packed
            .get_item(column(nq))?
            .call_method1("astype", ("bool",))?,
    )?;
    result.set_item(
        "iterations",
        packed
            .get_item(column(nq + 1))?
            .call_method1("astype", ("int64",))?,
    )?;
    result.set_item("residual", packed.get_item(column(nq + 2))?)?;
    Ok(result)
}
