//! Integration on the configuration's Lie group.
//!
//! A step from q₀ writes the configuration as q = q₀ ⊕ ξ with ξ in the tangent space (one entry
//! per velocity coordinate) and integrates ξ, which lives in a vector space, with an ordinary
//! Runge–Kutta scheme: the Runge–Kutta–Munthe-Kaas method (Munthe-Kaas, *High order Runge–Kutta
//! methods on manifolds*, Appl. Numer. Math. 29, 1999). With body velocities v the tangent
//! coordinates move as ξ̇ = dexp⁻¹_{-ξ}(v) ([`Joint::tangent_rate`](crate::Joint::tangent_rate));
//! on revolute and prismatic joints this is ξ̇ = v and the scheme is the textbook one.
//! The Jacobians of ⊕ and ⊖ (for derivatives of a step and of anything written on q) are here too.

use crate::error::{check_length, check_vector, Result};
use crate::model::Model;
use crate::spatial::Mat6;
use nalgebra::DMatrix;

/// ξ̇ = dexp⁻¹_{-ξ}(v) for every joint: the rate of the tangent coordinates `xi` (nv) of
/// q = q₀ ⊕ ξ when the body velocities are `v` (nv). Writes `out` (nv).
pub fn tangent_rate(model: &Model, xi: &[f64], v: &[f64], out: &mut [f64]) {
    for i in 1..model.nbodies() {
        let dofs = model.v_range(i);
        model.joints[i].tangent_rate(&xi[dofs.clone()], &v[dofs.clone()], &mut out[dofs]);
    }
}

/// ∂(q ⊕ v)/∂q and ∂(q ⊕ v)/∂v (nv × nv each, block-diagonal: one block per joint), tangent
/// space to tangent space with right perturbations (see [`Joint::integrate_jacobians`]).
///
/// [`Joint::integrate_jacobians`]: crate::Joint::integrate_jacobians
pub fn integrate_jacobians(
    model: &Model,
    q: &[f64],
    v: &[f64],
    d_q: &mut DMatrix<f64>,
    d_v: &mut DMatrix<f64>,
) -> Result<()> {
    model.check_configuration(q)?;
    check_vector("v", v, model.nv)?;
    joint_blocks(model, d_q, d_v, |i, a, b| {
        model.joints[i].integrate_jacobians(&v[model.v_range(i)], a, b)
    })
}

/// ∂(q₁ ⊖ q₀)/∂q₀ and ∂(q₁ ⊖ q₀)/∂q₁ (nv × nv each, block-diagonal), tangent to tangent (see
/// [`Joint::difference_jacobians`]).
///
/// [`Joint::difference_jacobians`]: crate::Joint::difference_jacobians
pub fn difference_jacobians(
    model: &Model,
    q0: &[f64],
    q1: &[f64],
    d_q0: &mut DMatrix<f64>,
    d_q1: &mut DMatrix<f64>,
) -> Result<()> {
    model.check_configuration(q0)?;
    model.check_configuration(q1)?;
    joint_blocks(model, d_q0, d_q1, |i, a, b| {
        model.joints[i].difference_jacobians(&q0[model.q_range(i)], &q1[model.q_range(i)], a, b)
    })
}

/// ∂ξ̇/∂ξ and ∂ξ̇/∂v of [`tangent_rate`] (nv × nv each, block-diagonal), for the derivatives of
/// a Runge–Kutta–Munthe-Kaas step.
pub fn tangent_rate_jacobians(
    model: &Model,
    xi: &[f64],
    v: &[f64],
    d_xi: &mut DMatrix<f64>,
    d_v: &mut DMatrix<f64>,
) -> Result<()> {
    check_vector("xi", xi, model.nv)?;
    check_vector("v", v, model.nv)?;
    joint_blocks(model, d_xi, d_v, |i, a, b| {
        let dofs = model.v_range(i);
        model.joints[i].tangent_rate_jacobians(&xi[dofs.clone()], &v[dofs], a, b)
    })
}

/// Fills two block-diagonal nv × nv matrices from each joint's pair of blocks.
fn joint_blocks(
    model: &Model,
    first: &mut DMatrix<f64>,
    second: &mut DMatrix<f64>,
    blocks: impl Fn(usize, &mut Mat6, &mut Mat6),
) -> Result<()> {
    check_length("out", first.nrows() * first.ncols(), model.nv * model.nv)?;
    check_length("out", second.nrows() * second.ncols(), model.nv * model.nv)?;
    first.as_mut_slice().fill(0.0);
    second.as_mut_slice().fill(0.0);
    for i in 1..model.nbodies() {
        let (mut a, mut b) = (Mat6::zeros(), Mat6::zeros());
        blocks(i, &mut a, &mut b);
        let (start, n) = (model.idx_v[i], model.joints[i].nv());
        first
            .view_mut((start, start), (n, n))
            .copy_from(&a.view((0, 0), (n, n)));
        second
            .view_mut((start, start), (n, n))
            .copy_from(&b.view((0, 0), (n, n)));
    }
    Ok(())
}
