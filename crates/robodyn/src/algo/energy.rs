//! Energies and the centre of mass.
//!
//! Kinetic energy `T = Σ ½ v_iᵀ I_i v_i + ½ Σ armature_k q̇_k²` (Featherstone §2.13 and the TUM notes'
//! `k_i = ½ m_i v_cᵀ v_c + ½ ωᵀ I ω`), equal to `½ q̇ᵀ M q̇`. Potential energy
//! `V = -Σ m_i gᵀ c_i` (the TUM notes), c_i the body's centre of mass in world coordinates.
//! The centre-of-mass Jacobian `J_com = Σ m_i J_{c_i} / m` (the TU Berlin notes' COM Jacobians, summed) is
//! computed per joint from the mass `m_j` and first moment `h_j` of the subtree it carries:
//! column k is `(m_j v_O + ω × h_j) / m` for the world-coordinates motion `(ω, v_O)` of its axis.
//! Writes `data.x_up`, and `data.v` (kinetic) or `data.x_world` (potential, centre of mass, its
//! Jacobian, which also writes `data.i_c` (subtree mass and first moment) and `data.jacobian`).
//! Cost: O(n).

use crate::algo::kinematics::{update_body_placements, update_joint_transforms};
use crate::error::{check_vector, Result};
use crate::model::Model;
use crate::spatial::{Inertia, Motion, Vec3};
use crate::Data;
use nalgebra::DMatrix;

/// Kinetic energy `T(q, q̇)`.
pub fn kinetic_energy(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> Result<f64> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    update_joint_transforms(model, data, q);
    data.v[0] = Motion::ZERO;
    let mut energy = 0.0;
    for i in 1..model.nbodies() {
        // v_i = X_i v_λ(i) + S_i q̇_i;  T += ½ v_iᵀ I_i v_i
        let v_i = data.x_up[i].apply_motion(&data.v[model.parent[i]])
            + model.joints[i].motion(&v[model.v_range(i)]);
        energy += 0.5 * v_i.dot(&model.inertias[i].mul_motion(&v_i));
        data.v[i] = v_i;
    }
    // rotor energy ½ armature q̇²
    energy += 0.5
        * model
            .armature
            .iter()
            .zip(v)
            .map(|(r, w)| r * w * w)
            .sum::<f64>();
    Ok(energy)
}

/// Potential energy `V(q) = -Σ m_i gᵀ c_i`.
pub fn potential_energy(model: &Model, data: &mut Data, q: &[f64]) -> Result<f64> {
    let (_, first_moment) = mass_and_first_moment(model, data, q)?;
    Ok(-model.gravity.dot(&first_moment))
}

/// Centre of mass of the whole robot in world coordinates (the world origin for a massless model).
pub fn center_of_mass(model: &Model, data: &mut Data, q: &[f64]) -> Result<Vec3> {
    let (mass, first_moment) = mass_and_first_moment(model, data, q)?;
    Ok(if mass > 0.0 {
        first_moment / mass
    } else {
        Vec3::zeros()
    })
}

/// Total mass and `Σ m_i c_i` in world coordinates.
fn mass_and_first_moment(model: &Model, data: &mut Data, q: &[f64]) -> Result<(f64, Vec3)> {
    model.check_configuration(q)?;
    update_body_placements(model, data, q);
    let mut mass = 0.0;
    let mut first_moment = Vec3::zeros();
    for i in 1..model.nbodies() {
        let inertia = &model.inertias[i];
        // c_i (world) = E_iᵀ c_i (body) + r_i
        let pose = &data.x_world[i];
        let com = pose.rotation.tr_mul(&inertia.com()) + pose.translation;
        mass += inertia.mass;
        first_moment += com * inertia.mass;
    }
    Ok((mass, first_moment))
}

/// The Jacobian of the centre of mass, 3 x nv in world axes (`ċ = J_com q̇`), written into the
/// first three rows of `data.jacobian` (the last three are zero).
pub fn center_of_mass_jacobian<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DMatrix<f64>> {
    model.check_configuration(q)?;
    update_body_placements(model, data, q);
    // subtree masses and first moments in world coordinates, leaves to root
    for i in 1..model.nbodies() {
        let inertia = &model.inertias[i];
        let pose = &data.x_world[i];
        // h_i = m_i c_i with c_i = E_iᵀ c + r_i
        let first_moment =
            pose.rotation.tr_mul(&inertia.first_moment) + pose.translation * inertia.mass;
        data.i_c[i] = Inertia {
            mass: inertia.mass,
            first_moment,
            rotational: Default::default(),
        };
    }
    for i in (1..model.nbodies()).rev() {
        let parent = model.parent[i];
        if parent != 0 {
            let subtree = data.i_c[i];
            data.i_c[parent].mass += subtree.mass;
            data.i_c[parent].first_moment += subtree.first_moment;
        }
    }
    let total = model.total_mass();
    data.jacobian.as_mut_slice().fill(0.0);
    if total <= 0.0 {
        return Ok(&data.jacobian);
    }
    for i in 1..model.nbodies() {
        let subtree = data.i_c[i];
        for (k, column) in model.v_range(i).enumerate() {
            // (ω, v_O) = X_{i←0}⁻¹ S_k;  J_com[:, k] = (m_sub v_O + ω × h_sub) / m
            let s = model.joints[i].subspace_column_from(k, &data.x_world[i]);
            let column_value =
                (s.linear * subtree.mass + s.angular.cross(&subtree.first_moment)) / total;
            data.jacobian
                .fixed_view_mut::<3, 1>(0, column)
                .copy_from(&column_value);
        }
    }
    Ok(&data.jacobian)
}
