//! Integration on the configuration's Lie group.
//!
//! A step from q₀ writes the configuration as q = q₀ ⊕ ξ with ξ in the tangent space (one entry
//! per velocity coordinate) and integrates ξ, which lives in a vector space, with an ordinary
//! Runge–Kutta scheme: the Runge–Kutta–Munthe-Kaas method (Munthe-Kaas, *High order Runge–Kutta
//! methods on manifolds*, Appl. Numer. Math. 29, 1999). With body velocities v the tangent
//! coordinates move as ξ̇ = dexp⁻¹_{-ξ}(v) ([`Joint::tangent_rate`](crate::Joint::tangent_rate));
//! on revolute and prismatic joints this is ξ̇ = v and the scheme is the textbook one.

use crate::model::Model;

/// ξ̇ = dexp⁻¹_{-ξ}(v) for every joint: the rate of the tangent coordinates `xi` (nv) of
/// q = q₀ ⊕ ξ when the body velocities are `v` (nv). Writes `out` (nv).
pub fn tangent_rate(model: &Model, xi: &[f64], v: &[f64], out: &mut [f64]) {
    for i in 1..model.nbodies() {
        let dofs = model.v_range(i);
        model.joints[i].tangent_rate(&xi[dofs.clone()], &v[dofs.clone()], &mut out[dofs]);
    }
}
