//! The tendons' inertia (`armature`): a mass a moving with each tendon's length L, as MuJoCo's
//! `mj_makeM` and `mj_rne` add it to the soft model.
//!
//! Reference: MuJoCo's documentation, "Computation", §Tendons (tendon armature), and its XML
//! reference (`<tendon armature>`). The kinetic energy ½ a L̇², L̇ = J q̇, adds to the equations
//! of motion
//! ```text
//!   M' = M + a JᵀJ            MuJoCo keeps only M's own sparsity: the terms J_k J_l of two
//!                             coordinates on one branch of the tree
//!                             ([`Model::dofs_on_one_branch`])
//!   bias += a Jᵀ (J̇ ν)        J̇ ν = L̈ at ν̇ = 0, in MuJoCo's velocities ν
//! ```
//! (the term ∂T/∂q cancels J̇ᵀ's part, J being the gradient of L). A fixed tendon's J is
//! constant; a spatial one's segment d = p₂ − p₁ between sites on two bodies (u = d / |d|, each
//! branch after a pulley divided by its divisor) has
//! ```text
//!   L̈ = u·(p̈₂ − p̈₁) + (|ḋ|² − (u·ḋ)²) / |d|
//! ```
//! with p̈ the sites' accelerations at q̈ = 0 (robodyn's velocity products). MuJoCo's J̇ ν is
//! that at ν̇ = 0, i.e. at q̈ = −w (w = (ω × v, 0) on free joints): `L̈(q̈ = 0) − J w`.

use super::tendons::TendonKinematics;
use super::weights::world_point;
use super::TINY;
use crate::algo::{crba, forward_kinematics, inverse_mass_matrix};
use crate::error::{Error, Result};
use crate::model::{Model, Tendon};
use crate::spatial::{Motion, Transform, Vec3};
use crate::Data;
use nalgebra::DMatrix;

/// Whether some tendon of `model` has an inertia.
pub fn has_tendon_inertia(model: &Model) -> bool {
    model.tendons.iter().any(|t| t.armature != 0.0)
}

/// M += Σ a JᵀJ over the tendons with an inertia, on M's tree pattern only (see the module's
/// header).
pub fn add_tendon_inertia(model: &Model, tendons: &TendonKinematics, mass: &mut DMatrix<f64>) {
    for (t, tendon) in model.tendons.iter().enumerate() {
        if tendon.armature == 0.0 {
            continue;
        }
        let j = tendons.jacobian.row(t);
        let columns = (0..model.nv).filter(|k| j[*k] != 0.0);
        for k in columns {
            for l in (0..model.nv).filter(|l| j[*l] != 0.0) {
                if model.dofs_on_one_branch(k, l) {
                    mass[(k, l)] += tendon.armature * j[k] * j[l];
                }
            }
        }
    }
}

/// M' at q (the module's header) and its inverse: what the weights at qpos0 and a damping
/// ratio's reflected inertia read.
pub fn inverse_inertia(model: &Model, data: &mut Data, q: &[f64]) -> Result<DMatrix<f64>> {
    if !has_tendon_inertia(model) {
        return Ok(inverse_mass_matrix(model, data, q)?.clone());
    }
    let mut mass = crba(model, data, q)?.clone();
    let x_world = forward_kinematics(model, data, q)?.to_vec();
    let mut tendons = TendonKinematics::default();
    tendons.update(model, q, &x_world);
    add_tendon_inertia(model, &tendons, &mut mass);
    mass.cholesky()
        .map(|factor| factor.inverse())
        .ok_or_else(|| Error::InvalidValue {
            argument: "model".into(),
            message: "its mass matrix with the tendons' armature is not positive definite".into(),
        })
}

/// The bodies' placements `X_{body←0}`, velocities and velocity products (their accelerations at
/// q̈ = 0, no gravity), the last two in the bodies' own coordinates
/// (`crate::algo::kinematics::update_velocity_products`).
pub type BodyMotions<'a> = (&'a [Transform], &'a [Motion], &'a [Motion]);

/// Σ a Jᵀ (J̇ ν) of the tendons with an inertia, added to `bias` (nv, robodyn's forces), with
/// `w` the free joints' term at the velocity (see the module's header).
pub fn add_tendon_inertia_bias(
    model: &Model,
    tendons: &TendonKinematics,
    bodies: BodyMotions,
    w: &[f64],
    bias: &mut [f64],
) {
    for (t, tendon) in model.tendons.iter().enumerate() {
        if tendon.armature != 0.0 {
            // J̇ ν = L̈(q̈ = 0) − J w
            let rate = velocity_product(tendon, bodies) - tendons.rate(t, w);
            tendons.add_to_row(t, tendon.armature * rate, bias);
        }
    }
}

/// L̈ of `tendon` at q̈ = 0 (robodyn's accelerations): 0 for a fixed tendon, the sum over a
/// spatial one's segments between two bodies (the module's header).
pub fn velocity_product(tendon: &Tendon, (x_world, velocity, product): BodyMotions) -> f64 {
    let mut rate = 0.0;
    let mut previous: Option<(usize, SiteMotion)> = None;
    // no site is wrapped where an inertia is (refused: MuJoCo's J̇ does not follow a wrap)
    for site in tendon.path_sites() {
        let p = world_point(&x_world[site.body], &site.point);
        let here = site_motion(
            &x_world[site.body],
            &velocity[site.body],
            &product[site.body],
            &p,
        );
        if let (false, Some((from_body, from))) = (site.starts_branch, &previous) {
            if *from_body != site.body {
                rate += segment_acceleration(from, &here) / site.divisor;
            }
        }
        previous = Some((site.body, here));
    }
    rate
}

/// A site's position p, velocity ṗ and acceleration p̈ at q̈ = 0, world axes.
struct SiteMotion {
    position: Vec3,
    velocity: Vec3,
    acceleration: Vec3,
}

/// The motion of the world point p moving with a body placed at `x` (`X_{body←0}`), its
/// velocity and velocity product in its own coordinates: ṗ = v_O + ω × p,
/// p̈ = a_O + ω̇ × p + ω × ṗ (world coordinates).
fn site_motion(x: &Transform, velocity: &Motion, product: &Motion, p: &Vec3) -> SiteMotion {
    let velocity = x.inverse_apply_motion(velocity);
    let product = x.inverse_apply_motion(product);
    let point_velocity = velocity.linear + velocity.angular.cross(p);
    SiteMotion {
        position: *p,
        velocity: point_velocity,
        acceleration: product.linear
            + product.angular.cross(p)
            + velocity.angular.cross(&point_velocity),
    }
}

/// L̈ of the straight segment from `one` to `other` at q̈ = 0 (the module's header); a vanishing
/// one takes the x axis for u and no curvature term, as MuJoCo.
fn segment_acceleration(one: &SiteMotion, other: &SiteMotion) -> f64 {
    let d = other.position - one.position;
    let norm = d.norm();
    let u = if norm < TINY { Vec3::x() } else { d / norm };
    let rate = other.velocity - one.velocity;
    let along = u.dot(&rate);
    let bend = if norm < TINY {
        0.0
    } else {
        (rate.norm_squared() - along * along) / norm
    };
    u.dot(&(other.acceleration - one.acceleration)) + bend
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algo::kinematics::{update_body_placements, update_velocity_products};
    use crate::io::load_mjcf_str;
    use crate::soft::tendons::tests::CORDS;

    #[test]
    fn the_velocity_product_is_the_lengths_second_rate_at_rest() {
        let model = load_mjcf_str(CORDS, "cords.xml").unwrap();
        let mut data = Data::new(&model);
        let mut q = vec![0.0; model.nq];
        let turn: Vec<f64> = (0..model.nv).map(|k| 0.2 - 0.07 * k as f64).collect();
        let start = model.neutral_configuration.clone();
        model.integrate(start.as_slice(), &turn, &mut q).unwrap();
        let v: Vec<f64> = (0..model.nv).map(|k| 0.5 - 0.15 * k as f64).collect();
        update_body_placements(&model, &mut data, &q);
        update_velocity_products(&model, &mut data, &v);
        let bodies = (&data.x_world[..], &data.v[..], &data.a[..]);
        let product = velocity_product(&model.tendons[0], bodies);
        assert_eq!(velocity_product(&model.tendons[1], bodies), 0.0);
        // q̈ = 0 is q(t) = q ⊕ t v: L̈ = (L(ε) − 2 L(0) + L(−ε)) / ε²
        let epsilon = 1e-4;
        let mut length = |t: f64| {
            let step: Vec<f64> = v.iter().map(|x| t * x).collect();
            let mut moved = vec![0.0; model.nq];
            model.integrate(&q, &step, &mut moved).unwrap();
            TendonKinematics::at(&model, &mut data, &moved)
                .unwrap()
                .lengths[0]
        };
        let second = (length(epsilon) - 2.0 * length(0.0) + length(-epsilon)) / epsilon.powi(2);
        assert!((product - second).abs() < 1e-6, "{product} vs {second}");
        assert!(
            product.abs() > 0.1,
            "a state that bends the cord: {product}"
        );
    }

    #[test]
    fn the_inertia_adds_a_jtj_along_one_branch_only() {
        let model = load_mjcf_str(CORDS, "cords.xml").unwrap();
        let mut data = Data::new(&model);
        let q = model.neutral_configuration.clone();
        let tendons = TendonKinematics::at(&model, &mut data, q.as_slice()).unwrap();
        let rigid = crba(&model, &mut data, q.as_slice()).unwrap().clone();
        let mut mass = rigid.clone();
        add_tendon_inertia(&model, &tendons, &mut mass);
        let added = &mass - &rigid;
        let (j, a) = (&tendons.jacobian, [0.4, 0.7]);
        for k in 0..model.nv {
            for l in 0..model.nv {
                let full: f64 = (0..2).map(|t| a[t] * j[(t, k)] * j[(t, l)]).sum();
                let expected = if model.dofs_on_one_branch(k, l) {
                    full
                } else {
                    0.0
                };
                assert!((added[(k, l)] - expected).abs() < 1e-15, "({k}, {l})");
            }
        }
        // the shoulder and the swing: two trees, coupled by the fixed tendon, left apart
        let (shoulder, swing) = (0, model.nv - 1);
        assert!(j[(1, shoulder)] * j[(1, swing)] != 0.0);
        assert_eq!(added[(shoulder, swing)], 0.0);
    }
}
