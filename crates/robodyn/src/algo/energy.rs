//! Energies and the centre of mass.
//!
//! Kinetic energy `T = Σ ½ v_iᵀ I_i v_i + ½ Σ armature_k q̇_k²` (Featherstone §2.13 and seed 002's
//! `k_i = ½ m_i v_cᵀ v_c + ½ ωᵀ I ω`), equal to `½ q̇ᵀ M q̇`. Potential energy
//! `V = -Σ m_i gᵀ c_i` (seed 002), c_i the body's centre of mass in world coordinates.
//! Writes `data.x_up`, and `data.v` (kinetic) or `data.x_world` (potential, centre of mass).
//! Cost: O(n).

use crate::algo::kinematics::{update_body_placements, update_joint_transforms};
use crate::error::{check_vector, Result};
use crate::model::Model;
use crate::spatial::{Motion, Vec3};
use crate::Data;

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
