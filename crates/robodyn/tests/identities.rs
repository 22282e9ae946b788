//! Identities between the dynamics algorithms, on every test model (DESIGN.md, "How we know it is right" 4).

mod common;

use common::*;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use robodyn::algo::ltdl::{factor_mass_matrix, solve_rows};
use robodyn::algo::*;
use robodyn::Data;

#[test]
fn mass_matrix_columns_are_rnea_with_unit_accelerations() {
    let mut rng = rng();
    for (name, mut model) in test_models() {
        model.gravity.fill(0.0);
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        let m = crba(&model, &mut data, q.as_slice()).unwrap().clone();
        let zero = DVector::zeros(model.nv);
        for j in 0..model.nv {
            // M e_j = rnea(q, 0, e_j) with no gravity
            let e_j = DVector::from_fn(model.nv, |i, _| if i == j { 1.0 } else { 0.0 });
            let column = rnea(
                &model,
                &mut data,
                q.as_slice(),
                zero.as_slice(),
                e_j.as_slice(),
                None,
            )
            .unwrap();
            assert_close(
                &format!("{name}: M column {j}"),
                m.column(j).as_slice(),
                column.as_slice(),
                IDENTITY_TOLERANCE,
            );
        }
    }
}

#[test]
fn mass_matrix_is_symmetric_positive_definite() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        for _ in 0..5 {
            let q = model.random_configuration(&mut rng);
            let m = crba(&model, &mut data, q.as_slice()).unwrap().clone();
            assert_close(
                &format!("{name}: M symmetric"),
                m.as_slice(),
                m.transpose().as_slice(),
                0.0,
            );
            assert!(
                m.clone().cholesky().is_some(),
                "{name}: M not positive definite"
            );
        }
    }
}

#[test]
fn aba_inverts_rnea() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        for _ in 0..5 {
            let (q, v, a) = state(&model, &mut rng);
            let f_ext: Vec<_> = (1..model.nbodies())
                .map(|_| robodyn::spatial::Force::from_array(&[0.3, -0.2, 0.5, 0.1, 0.05, -0.1]))
                .collect();
            let tau = rnea(
                &model,
                &mut data,
                q.as_slice(),
                v.as_slice(),
                a.as_slice(),
                Some(&f_ext),
            )
            .unwrap()
            .clone();
            let qdd = aba(
                &model,
                &mut data,
                q.as_slice(),
                v.as_slice(),
                tau.as_slice(),
                Some(&f_ext),
            )
            .unwrap();
            assert_close(
                &format!("{name}: aba(rnea(a))"),
                qdd.as_slice(),
                a.as_slice(),
                IDENTITY_TOLERANCE,
            );
        }
    }
}

/// The tree-sparse solve with M's factors, on rows of every width its column blocks come in
/// (32, 16, 8, 4, 2 and 1 columns), gives X with M X = B.
#[test]
fn factored_solve_on_rows_solves_with_the_mass_matrix() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let (q, _, _) = state(&model, &mut rng);
        crba(&model, &mut data, q.as_slice()).unwrap();
        factor_mass_matrix(&model, &mut data).unwrap();
        for width in [1, 2, 3, 7, 15, 31, 63] {
            let b = DMatrix::from_fn(model.nv, width, |_, _| rng.random_range(-1.0..1.0));
            // row i of B, then of X, at i * width
            let mut rows: Vec<f64> = b.transpose().as_slice().to_vec();
            solve_rows(&model, &data, &mut rows);
            let x = DMatrix::from_row_slice(model.nv, width, &rows);
            assert_close(
                &format!("{name}, {width} columns: M X"),
                (&data.mass_matrix * x).as_slice(),
                b.as_slice(),
                IDENTITY_TOLERANCE,
            );
        }
    }
}

#[test]
fn forward_dynamics_solves_the_equation_of_motion() {
    // q̈ = M⁻¹ (τ - b) with b = C q̇ + g
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let (q, v, tau) = state(&model, &mut rng);
        let bias = bias_forces(&model, &mut data, q.as_slice(), v.as_slice())
            .unwrap()
            .clone();
        let m_inv = inverse_mass_matrix(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        let m = data.mass_matrix.clone();
        assert_close(
            &format!("{name}: M⁻¹ M"),
            (&m_inv * &m).as_slice(),
            DMatrix::identity(model.nv, model.nv).as_slice(),
            IDENTITY_TOLERANCE,
        );
        let expected = &m_inv * (&tau - &bias);
        let qdd = aba(
            &model,
            &mut data,
            q.as_slice(),
            v.as_slice(),
            tau.as_slice(),
            None,
        )
        .unwrap();
        assert_close(
            &format!("{name}: aba"),
            qdd.as_slice(),
            expected.as_slice(),
            IDENTITY_TOLERANCE,
        );
    }
}

#[test]
fn bias_and_gravity_are_rnea_special_cases() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let (q, v, _) = state(&model, &mut rng);
        let zero = DVector::zeros(model.nv);
        let bias = bias_forces(&model, &mut data, q.as_slice(), v.as_slice())
            .unwrap()
            .clone();
        let expected = rnea(
            &model,
            &mut data,
            q.as_slice(),
            v.as_slice(),
            zero.as_slice(),
            None,
        )
        .unwrap()
        .clone();
        assert_close(
            &format!("{name}: bias"),
            bias.as_slice(),
            expected.as_slice(),
            0.0,
        );
        let gravity = generalized_gravity(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        let expected = rnea(
            &model,
            &mut data,
            q.as_slice(),
            zero.as_slice(),
            zero.as_slice(),
            None,
        )
        .unwrap();
        assert_close(
            &format!("{name}: gravity"),
            gravity.as_slice(),
            expected.as_slice(),
            0.0,
        );
    }
}

#[test]
fn kinetic_energy_is_half_v_m_v() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let (q, v, _) = state(&model, &mut rng);
        let energy = kinetic_energy(&model, &mut data, q.as_slice(), v.as_slice()).unwrap();
        let m = crba(&model, &mut data, q.as_slice()).unwrap();
        let expected = 0.5 * v.dot(&(m * &v));
        assert_close(
            &format!("{name}: KE"),
            &[energy],
            &[expected],
            IDENTITY_TOLERANCE,
        );
    }
}

#[test]
fn gravity_is_the_gradient_of_potential_energy() {
    // g(q) = ∂V/∂q, by central differences along each velocity coordinate on the Lie group
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        let gravity = generalized_gravity(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        for k in 0..model.nv {
            let energy_at = |h: f64, data: &mut Data| {
                let moved = displaced(&model, &q, &unit_step(model.nv, k, h));
                potential_energy(&model, data, moved.as_slice()).unwrap()
            };
            let derivative =
                (energy_at(FD_STEP, &mut data) - energy_at(-FD_STEP, &mut data)) / (2.0 * FD_STEP);
            assert_close(
                &format!("{name}: dV/dq {k}"),
                &[gravity[k]],
                &[derivative],
                FD_TOLERANCE,
            );
        }
    }
}

#[test]
fn coriolis_matrix_gives_the_velocity_terms_and_a_skew_m_dot_minus_two_c() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let (q, v, _) = state(&model, &mut rng);
        let c = coriolis_matrix(&model, &mut data, q.as_slice(), v.as_slice())
            .unwrap()
            .clone();
        // C v = bias − g
        let bias = bias_forces(&model, &mut data, q.as_slice(), v.as_slice())
            .unwrap()
            .clone();
        let gravity = generalized_gravity(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        let velocity_terms = bias - gravity;
        assert_close(
            &format!("{name} C v"),
            (&c * &v).as_slice(),
            velocity_terms.as_slice(),
            IDENTITY_TOLERANCE,
        );
        // Ṁ along v by central differences; Ṁ − 2C + (Ṁ − 2C)ᵀ = 0
        let forward = displaced(&model, &q, &(&v * FD_STEP));
        let backward = displaced(&model, &q, &(&v * -FD_STEP));
        let m_plus = crba(&model, &mut data, forward.as_slice()).unwrap().clone();
        let m_minus = crba(&model, &mut data, backward.as_slice())
            .unwrap()
            .clone();
        let m_dot = (m_plus - m_minus) / (2.0 * FD_STEP);
        let n = &m_dot - &c * 2.0;
        let symmetric_part = &n + n.transpose();
        assert_close(
            &format!("{name} Ṁ − 2C skew"),
            symmetric_part.as_slice(),
            &vec![0.0; model.nv * model.nv],
            FD_TOLERANCE * m_dot.amax().max(1.0),
        );
    }
}

#[test]
fn christoffel_symbols_are_the_derivatives_of_the_mass_matrix() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        let n = model.nv;
        let mut gamma = vec![0.0; n * n * n];
        christoffel_symbols(&model, &mut data, q.as_slice(), &mut gamma).unwrap();
        // C(q, v) = Σ_k Γ_··k v_k for every model
        let v = random_vector(&mut rng, n);
        let c = coriolis_matrix(&model, &mut data, q.as_slice(), v.as_slice())
            .unwrap()
            .clone();
        let contracted: Vec<f64> = (0..n * n)
            .map(|index| {
                let (i, j) = (index % n, index / n);
                (0..n).map(|k| gamma[(i * n + j) * n + k] * v[k]).sum()
            })
            .collect();
        assert_close(
            &format!("{name} Σ Γ v"),
            &contracted,
            c.as_slice(),
            IDENTITY_TOLERANCE,
        );
        // the coordinate formula needs velocities that are coordinate rates: no quaternion joints
        if model
            .joints()
            .iter()
            .any(|j| j.quaternion_offset().is_some())
        {
            continue;
        }
        // ∂M/∂q_k by central differences
        let derivatives: Vec<DMatrix<f64>> = (0..n)
            .map(|k| {
                let plus = displaced(&model, &q, &unit_step(n, k, FD_STEP));
                let minus = displaced(&model, &q, &unit_step(n, k, -FD_STEP));
                let m_plus = crba(&model, &mut data, plus.as_slice()).unwrap().clone();
                let m_minus = crba(&model, &mut data, minus.as_slice()).unwrap().clone();
                (m_plus - m_minus) / (2.0 * FD_STEP)
            })
            .collect();
        // Γ_ijk = ½ (∂_k M_ij + ∂_j M_ik − ∂_i M_jk)
        let expected: Vec<f64> = (0..n * n * n)
            .map(|index| {
                let (i, j, k) = (index / (n * n), (index / n) % n, index % n);
                0.5 * (derivatives[k][(i, j)] + derivatives[j][(i, k)] - derivatives[i][(j, k)])
            })
            .collect();
        assert_close(&format!("{name} Γ"), &gamma, &expected, FD_TOLERANCE);
    }
}

#[test]
fn mass_matrix_and_gravity_the_notes_ways_equal_crba_and_rnea() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        let m = crba(&model, &mut data, q.as_slice()).unwrap().clone();
        let by_rnea = mass_matrix_by_rnea(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        let by_jacobians = mass_matrix_by_jacobians(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        for (method, other) in [("rnea", by_rnea), ("jacobians", by_jacobians)] {
            assert_close(
                &format!("{name} M by {method}"),
                other.as_slice(),
                m.as_slice(),
                CLOSED_FORM_TOLERANCE,
            );
        }
        let g = generalized_gravity(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        let g_jacobians = generalized_gravity_by_jacobians(&model, &mut data, q.as_slice())
            .unwrap()
            .clone();
        assert_close(
            &format!("{name} g by Jacobians"),
            g_jacobians.as_slice(),
            g.as_slice(),
            CLOSED_FORM_TOLERANCE,
        );
    }
}

#[test]
fn crba_into_writes_crba_s_matrix_which_is_exactly_symmetric() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let mut data = Data::new(&model);
        let q = model.random_configuration(&mut rng);
        let mut out = vec![f64::NAN; model.nv * model.nv];
        crba_into(&model, &mut data, q.as_slice(), &mut out).unwrap();
        let m = crba(&model, &mut data, q.as_slice()).unwrap();
        assert_eq!(out, m.as_slice(), "{name}");
        // handed on as row-major, which is right only for an exactly symmetric matrix
        assert_eq!(m, &m.transpose(), "{name}");
        let error = crba_into(&model, &mut data, q.as_slice(), &mut out[1..])
            .unwrap_err()
            .to_string();
        assert!(error.contains("out"), "{error}");
    }
}

/// CRBA's two forms (`algo::crba`), in body coordinates for bodies in depth-first order (every
/// loader's) and in world coordinates otherwise, give the same M; `Model::subtree_dof_end`
/// lists each subtree's coordinates, and a snapshot derives it (and each joint's turn and motion
/// subspace components) again. The model without its joints' specialisations gets the same M
/// bit for bit.
#[test]
fn crba_in_body_and_world_coordinates_agree() {
    let mut rng = rng();
    for (name, model) in test_models() {
        let ends = model
            .subtree_dof_end()
            .expect("loaders add bodies depth first");
        let reloaded = robodyn::io::model_from_bytes(&robodyn::io::model_to_bytes(&model)).unwrap();
        assert_eq!(reloaded.subtree_dof_end(), Some(ends), "{name}");
        for i in 0..model.nbodies() {
            assert_eq!(reloaded.turn(i), model.turn(i), "{name}: body {i}");
            for k in 0..model.joints()[i].nv() {
                let (got, built) = (
                    reloaded.subspace_component(i, k),
                    model.subspace_component(i, k),
                );
                assert_eq!(got, built, "{name}: body {i}, coordinate {k}");
            }
        }
        for (i, &end) in ends.iter().enumerate().skip(1) {
            for j in 1..model.nbodies() {
                // body j is in body i's subtree when i is on j's path to the world
                let mut on_path = j;
                while on_path > i {
                    on_path = model.parent()[on_path];
                }
                let listed = model
                    .v_range(j)
                    .all(|d| (model.idx_v()[i]..end).contains(&d));
                assert_eq!(
                    listed,
                    on_path == i || model.v_range(j).is_empty(),
                    "{name}: {i}, {j}"
                );
            }
        }
        let world_form = not_depth_first(&model);
        let unbuilt = model.without_joint_specialisations();
        let (mut data, mut world_data) = (Data::new(&model), Data::new(&world_form));
        let mut unbuilt_data = Data::new(&unbuilt);
        for _ in 0..3 {
            let q = model.random_configuration(&mut rng);
            let m_unbuilt = crba(&unbuilt, &mut unbuilt_data, q.as_slice()).unwrap();
            let m = crba(&model, &mut data, q.as_slice()).unwrap();
            assert_eq!(
                m, m_unbuilt,
                "{name}: M without the joints' specialisations"
            );
            let m_world = crba(&world_form, &mut world_data, q.as_slice()).unwrap();
            let label = format!("{name}: M in body and world coordinates");
            assert_close(
                &label,
                m.as_slice(),
                m_world.as_slice(),
                CLOSED_FORM_TOLERANCE,
            );
            assert_eq!(m, &m.transpose(), "{name}");
        }
    }
}

/// A model built with its bodies breadth first (not depth first) has no `subtree_dof_end`, and
/// its M is the depth-first model's with the coordinates reordered.
#[test]
fn bodies_out_of_depth_first_order_take_the_world_form() {
    let tree = test_model("tree");
    let depth = |mut i: usize| {
        let mut depth = 0;
        while i != 0 {
            i = tree.parent()[i];
            depth += 1;
        }
        depth
    };
    let mut order: Vec<usize> = (1..tree.nbodies()).collect();
    order.sort_by_key(|&i| depth(i));
    let mut builder = robodyn::ModelBuilder::new("breadth first", "world");
    let (mut index, mut q_of, mut v_of) = (vec![0; tree.nbodies()], vec![], vec![]);
    for &i in &order {
        let body = robodyn::NewBody {
            parent: index[tree.parent()[i]],
            joint: tree.joints()[i],
            joint_name: &tree.joint_names[i],
            x_tree: tree.x_tree()[i],
            properties: Default::default(),
            name: &tree.body_names[i],
            inertia: tree.inertias[i],
        };
        index[i] = builder.add_body(body).unwrap();
        q_of.extend(tree.q_range(i));
        v_of.extend(tree.v_range(i));
    }
    let mut shuffled = builder.build();
    assert_eq!(shuffled.subtree_dof_end(), None);
    for (new, &old) in v_of.iter().enumerate() {
        shuffled.armature[new] = tree.armature[old];
    }
    let q = tree.random_configuration(&mut rng());
    let q_shuffled: Vec<f64> = q_of.iter().map(|&old| q[old]).collect();
    let m = crba(&tree, &mut Data::new(&tree), q.as_slice())
        .unwrap()
        .clone();
    let m_shuffled = crba(&shuffled, &mut Data::new(&shuffled), &q_shuffled)
        .unwrap()
        .clone();
    let reordered = DMatrix::from_fn(tree.nv, tree.nv, |r, c| m[(v_of[r], v_of[c])]);
    let label = "M of the tree built breadth first";
    assert_close(
        label,
        m_shuffled.as_slice(),
        reordered.as_slice(),
        CLOSED_FORM_TOLERANCE,
    );
}

/// `Model::ancestor_runs` lists a coordinate's path to the root (itself, its parent, …) as runs
/// of consecutive coordinates, nearest first, on every test model and after a snapshot.
#[test]
fn ancestor_runs_are_the_parent_chain() {
    for (name, model) in test_models() {
        let reloaded = robodyn::io::model_from_bytes(&robodyn::io::model_to_bytes(&model)).unwrap();
        assert_eq!(reloaded.dof_run_start(), model.dof_run_start(), "{name}");
        for top in 0..model.nv {
            let mut chain = vec![];
            let mut next = Some(top);
            while let Some(k) = next {
                chain.push(k);
                next = model.dof_parent()[k];
            }
            let runs: Vec<_> = model.ancestor_runs(top).collect();
            let walked: Vec<usize> = runs.iter().flat_map(|run| run.clone().rev()).collect();
            assert_eq!(walked, chain, "{name}, coordinate {top}");
            for run in &runs {
                assert!(!run.is_empty(), "{name}: empty run");
                for c in run.start + 1..run.end {
                    assert_eq!(
                        model.dof_parent()[c],
                        Some(c - 1),
                        "{name}: {run:?} is not a chain"
                    );
                }
            }
        }
    }
}

/// Every quaternion of a configuration is checked, the last joint's as well as the floating
/// base's (the check stops after the last quaternion joint).
#[test]
fn every_quaternion_is_checked() {
    let tree = test_model("tree");
    let quaternion_starts: Vec<(String, usize)> = (1..tree.nbodies())
        .filter_map(|i| {
            let offset = tree.joints()[i].quaternion_offset()?;
            Some((tree.joint_names[i].clone(), tree.idx_q()[i] + offset))
        })
        .collect();
    assert_eq!(
        quaternion_starts.len(),
        2,
        "a free base and a spherical joint"
    );
    for (joint, start) in quaternion_starts {
        let mut q = tree.neutral();
        q[start + 3] = 2.0;
        let error = tree
            .check_configuration(q.as_slice())
            .unwrap_err()
            .to_string();
        assert!(error.contains(&format!("joint '{joint}'")), "{error}");
    }
}

/// Joints along negative and linear coordinate axes, after quarter turns and after none.
const AXES_URDF: &str = r#"<robot name="axes">
  <link name="base"/>
  <joint name="turn" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 -1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="a"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0.2 0 0" rpy="1.5707963267948966 0 0"/><axis xyz="-1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="b"><inertial><origin xyz="0 0.1 0"/><mass value="0.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="lift" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="c"><inertial><origin xyz="0 0 0.05"/><mass value="0.2"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
</robot>"#;

/// The specialised paths, a joint's transform that turns about a coordinate axis
/// (`Model::turn`) and a motion subspace that is one unit motion (`Model::subspace_component`,
/// `Model::unit_axis`), give the values of the general products: the same model without either
/// gives the same τ (with and without external forces), bias forces, gravity, q̈ and M.
#[test]
fn the_specialised_joint_paths_give_the_general_products_values() {
    let mut rng = rng();
    let mut models = test_models();
    let options = robodyn::io::LoadOptions::floating(false);
    let axes = robodyn::io::load_urdf_str(AXES_URDF, "axes.urdf", options).unwrap();
    models.push(("axes", axes));
    for (name, model) in models {
        let unit_axes = (1..model.nbodies()).filter(|&i| model.unit_axis(i).is_some());
        assert!(unit_axes.count() > 0, "{name}: no joint along a unit axis");
        let general = model.without_joint_specialisations();
        assert!((1..model.nbodies()).all(|i| general.unit_axis(i).is_none()));
        let (mut data, mut general_data) = (Data::new(&model), Data::new(&general));
        for _ in 0..3 {
            let (q, v, a) = state(&model, &mut rng);
            let (q, v, a) = (q.as_slice(), v.as_slice(), a.as_slice());
            let f_ext: Vec<_> = (1..model.nbodies())
                .map(|_| robodyn::spatial::Force::from_array(&[0.3, -0.2, 0.5, 0.1, 0.05, -0.1]))
                .collect();
            for forces in [None, Some(&f_ext[..])] {
                let tau = rnea(&model, &mut data, q, v, a, forces).unwrap();
                let general_tau = rnea(&general, &mut general_data, q, v, a, forces).unwrap();
                assert_eq!(tau, general_tau, "{name}: τ");
                let qdd = aba(&model, &mut data, q, v, a, forces).unwrap();
                let general_qdd = aba(&general, &mut general_data, q, v, a, forces).unwrap();
                assert_eq!(qdd, general_qdd, "{name}: q̈");
            }
            let bias = bias_forces(&model, &mut data, q, v).unwrap();
            assert_eq!(
                bias,
                bias_forces(&general, &mut general_data, q, v).unwrap()
            );
            let g = generalized_gravity(&model, &mut data, q).unwrap();
            assert_eq!(
                g,
                generalized_gravity(&general, &mut general_data, q).unwrap()
            );
            let m = crba(&model, &mut data, q).unwrap();
            assert_eq!(
                m,
                crba(&general, &mut general_data, q).unwrap(),
                "{name}: M"
            );
        }
    }
}
