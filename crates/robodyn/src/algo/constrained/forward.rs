//! Forward dynamics and impulses under rigid constraints.
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §8.3 (the constraint forces
//! from the constraint-space inverse inertia) and §11.6 (impulses); Pinocchio's
//! `constraintDynamics` and `impulseDynamics` compute the same quantities. See the module's
//! header for the equations; both run on the articulated-body algorithm's terms, M is never
//! formed (`articulated`). Inputs: q, q̇, τ (or only q, q̇), the constraint set. Writes
//! `constraints.qdd`, `constraints.forces` and everything on the way (J, γ, φ, Y, Λ⁻¹), and in
//! `data`: ABA's fields (`data.qdd` the free acceleration on the rows' support, zero elsewhere)
//! and the placements of the bodies the rows reach. Cost: ABA, O(d) per row (d: the bodies its
//! constraint reaches), O(m² d) for Λ⁻¹, O(m³) to solve it.

use super::articulated::{
    articulated_delassus, constrained_accelerations, constraint_response, free_motion_rows,
    AbaTerms, RouteBuffers,
};
use super::solve::largest;
use super::{product_scale, solve_forces, ConstraintData};
use crate::constraint::ConstraintSet;
use crate::dispatch::multiversion;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::{Force, Real};
use crate::Data;
use nalgebra::DMatrix;

/// How the constraint equations are solved.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ConstrainedOptions {
    /// Baumgarte's gains `(K_p, K_d)` (1/s², 1/s): the rows' acceleration is held to
    /// `−K_d J q̇ − K_p φ` instead of zero, pulling a drifting loop back. `None`: zero.
    pub baumgarte: Option<(f64, f64)>,
    /// μ ≥ 0: with μ > 0 the forces are found by proximal iterations on `Λ⁻¹ + μ 1`, which
    /// accept redundant rows (least-norm forces); with 0 a redundant row is an error naming it.
    pub damping: f64,
}

impl ConstrainedOptions {
    /// Refuses negative or non-finite gains and damping.
    pub fn check(&self) -> Result<()> {
        let (kp, kd) = self.baumgarte.unwrap_or((0.0, 0.0));
        for (name, value) in [
            ("baumgarte", kp),
            ("baumgarte", kd),
            ("damping", self.damping),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::InvalidValue {
                    argument: name.into(),
                    message: format!("expected a finite value ≥ 0, got {value}"),
                });
            }
        }
        Ok(())
    }
}

/// q̈ and λ under the constraints of `set`: `M q̈ + h = τ + Jᵀ λ`, `J q̈ + γ = −K_d J q̇ − K_p φ`.
/// `f_ext` as in [`crate::algo::rnea()`]. Results in `constraints.qdd` and `constraints.forces`.
#[allow(clippy::too_many_arguments)]
pub fn constrained_forward_dynamics(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
    options: &ConstrainedOptions,
) -> Result<()> {
    super::check_fits(model, constraints, set)?;
    options.check()?;
    forward_route(model, data, constraints, set, (q, v, tau), f_ext, options)
}

multiversion! {
    /// [`constrained_forward_dynamics`]' steps on checked inputs, built for AVX2 and FMA as well
    /// ([`crate::dispatch`]).
    #[inline(never)]
    fn forward_route(
        model: &Model,
        data: &mut Data,
        constraints: &mut ConstraintData,
        set: &ConstraintSet,
        state: (&[f64], &[f64], &[f64]),
        f_ext: Option<&[Force]>,
        options: &ConstrainedOptions,
    ) -> Result<()> {
        forward_route_avx2 for ["avx2", "fma"] => {
            forward_steps(model, data, constraints, set, state, f_ext, options)
        }
        baseline => { forward_steps(model, data, constraints, set, state, f_ext, options) }
    }
}

/// The steps of [`constrained_forward_dynamics`].
#[inline(always)]
fn forward_steps(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v, tau): (&[f64], &[f64], &[f64]),
    f_ext: Option<&[Force]>,
    options: &ConstrainedOptions,
) -> Result<()> {
    // a_f = ABA(q, q̇, τ, f_ext); J, φ, γ and the rows' acceleration J a_f + γ under it
    free_motion_rows(model, data, constraints, set, (q, v, tau), f_ext)?;
    // Y = K Jᵀ by each row's inward pass;  Λ⁻¹ = Σ_i Y_iᵀ D_i⁻¹ Y_i
    articulated_delassus(
        model,
        set,
        &AbaTerms::of(data),
        &mut RouteBuffers::of(constraints),
    );

    // Λ⁻¹ λ = −(J a_f + γ + K_d J q̇ + K_p φ)
    solve_accelerated_forces(model, set, constraints, (v, data.qdd.as_slice()), options)?;

    // q̈ = M⁻¹ (τ − h + Jᵀ λ): ABA's outward pass from u_i + Y_i λ
    let route = &mut RouteBuffers::of(constraints);
    constrained_accelerations(model, set, &AbaTerms::of(data), route);
    Ok(())
}

/// q̇ after an impact that makes the constraints of `set` hold at velocity level:
/// `M (q̇⁺ − q̇) = Jᵀ Λ`, `J q̇⁺ = −e J q̇` (e: `restitution`, from 0, plastic, to 1, elastic).
/// Results: q̇⁺ in `constraints.qdd`, the impulses Λ in `constraints.forces`.
pub fn impulse_dynamics(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v): (&[f64], &[f64]),
    restitution: f64,
    damping: f64,
) -> Result<()> {
    super::check_fits(model, constraints, set)?;
    impulse_route(
        model,
        data,
        constraints,
        set,
        (q, v),
        (restitution, damping),
    )
}

multiversion! {
    /// [`impulse_dynamics`]' steps on checked inputs, built for AVX2 and FMA as well
    /// ([`crate::dispatch`]).
    #[inline(never)]
    fn impulse_route(
        model: &Model,
        data: &mut Data,
        constraints: &mut ConstraintData,
        set: &ConstraintSet,
        state: (&[f64], &[f64]),
        impact: (f64, f64),
    ) -> Result<()> {
        impulse_route_avx2 for ["avx2", "fma"] => {
            impulse_steps(model, data, constraints, set, state, impact)
        }
        baseline => { impulse_steps(model, data, constraints, set, state, impact) }
    }
}

/// The steps of [`impulse_dynamics`], `impact` its restitution and damping.
#[inline(always)]
fn impulse_steps(
    model: &Model,
    data: &mut Data,
    constraints: &mut ConstraintData,
    set: &ConstraintSet,
    (q, v): (&[f64], &[f64]),
    (restitution, damping): (f64, f64),
) -> Result<()> {
    // ABA's terms at (q, q̇, τ = 0) and J
    let mut zeros = std::mem::take(&mut constraints.joint_forces);
    zeros.fill(0.0);
    let rows = free_motion_rows(
        model,
        data,
        constraints,
        set,
        (q, v, zeros.as_slice()),
        None,
    );
    constraints.joint_forces = zeros;
    rows?;
    articulated_delassus(
        model,
        set,
        &AbaTerms::of(data),
        &mut RouteBuffers::of(constraints),
    );

    // Λ⁻¹ Λ = −(1 + e) J q̇
    solve_impulses(model, set, constraints, v, restitution, damping)?;

    // q̇⁺ = q̇ + M⁻¹ Jᵀ Λ
    let route = &mut RouteBuffers::of(constraints);
    constraint_response(model, set, &AbaTerms::of(data), route, v);
    Ok(())
}

/// λ from `Λ⁻¹ λ = −(J a_f + γ + K_d J q̇ + K_p φ)`, with `J a_f + γ` (a_f: the free
/// acceleration `free`) in `constraints.rhs` and J, φ and Λ⁻¹ in `constraints`.
#[inline(always)]
pub(super) fn solve_accelerated_forces(
    model: &Model,
    set: &ConstraintSet,
    constraints: &mut ConstraintData,
    (v, free): (&[f64], &[f64]),
    options: &ConstrainedOptions,
) -> Result<()> {
    let m = set.rows();
    let ConstraintData {
        jacobian,
        drift,
        error,
        rhs,
        step,
        ..
    } = constraints;
    accelerated_right_side(
        jacobian,
        error.as_slice(),
        &mut rhs[..m],
        v,
        options.baumgarte,
    );
    // the size of the terms the right side is made of, for the proximal iterations' accuracy
    // (a direct solve needs none)
    let mut scale = 1.0;
    if options.damping > 0.0 {
        let (kp, kd) = options.baumgarte.unwrap_or((0.0, 0.0));
        scale += product_scale(jacobian, free, step) + largest(drift.as_slice());
        scale += kd * product_scale(jacobian, v, step) + kp * largest(error.as_slice());
    }
    solve_forces(model, set, constraints, options.damping, scale)
}

/// `−(J a_f + γ + K_d J q̇ + K_p φ)` in place of `J a_f + γ` in `rhs` (m), with Baumgarte's
/// gains `(K_p, K_d)`.
#[inline(always)]
pub(crate) fn accelerated_right_side<S: Real>(
    jacobian: &DMatrix<S>,
    error: &[S],
    rhs: &mut [S],
    v: &[S],
    baumgarte: Option<(f64, f64)>,
) {
    for entry in rhs.iter_mut() {
        *entry = -*entry;
    }
    let (kp, kd) = baumgarte.unwrap_or((0.0, 0.0));
    if kd != 0.0 {
        // −K_d J q̇
        let (kd, m, j) = (S::splat(kd), rhs.len(), jacobian.as_slice());
        for (c, v_c) in v.iter().enumerate() {
            let scaled = kd * *v_c;
            for (entry, j_rc) in rhs.iter_mut().zip(&j[c * m..(c + 1) * m]) {
                *entry -= *j_rc * scaled;
            }
        }
    }
    if kp != 0.0 {
        // −K_p φ
        let kp = S::splat(kp);
        for (entry, phi) in rhs.iter_mut().zip(error) {
            *entry -= kp * *phi;
        }
    }
}

/// The impulses Λ from `Λ⁻¹ Λ = −(1 + e) J q̇`, with J and Λ⁻¹ in `constraints`; a restitution
/// outside [0, 1] or a negative damping is refused.
#[inline(always)]
pub(super) fn solve_impulses(
    model: &Model,
    set: &ConstraintSet,
    constraints: &mut ConstraintData,
    v: &[f64],
    restitution: f64,
    damping: f64,
) -> Result<()> {
    check_impact(restitution, damping)?;
    let m = set.rows();
    let ConstraintData {
        jacobian,
        rhs,
        step,
        ..
    } = constraints;
    impact_right_side(jacobian, &mut rhs[..m], v, restitution);
    let scale = match damping > 0.0 {
        true => 1.0 + (1.0 + restitution) * product_scale(jacobian, v, step),
        false => 1.0,
    };
    solve_forces(model, set, constraints, damping, scale)
}

/// Refuses a restitution outside [0, 1] and a negative or non-finite damping.
pub(crate) fn check_impact(restitution: f64, damping: f64) -> Result<()> {
    if !(0.0..=1.0).contains(&restitution) {
        return Err(Error::InvalidValue {
            argument: "restitution".into(),
            message: format!("expected a value from 0 to 1, got {restitution}"),
        });
    }
    let options = ConstrainedOptions {
        baumgarte: None,
        damping,
    };
    options.check()
}

/// `−(1 + e) J q̇` into `rhs` (m), e the restitution.
#[inline(always)]
pub(crate) fn impact_right_side<S: Real>(
    jacobian: &DMatrix<S>,
    rhs: &mut [S],
    v: &[S],
    restitution: f64,
) {
    let (m, j) = (rhs.len(), jacobian.as_slice());
    rhs.fill(S::zero());
    for (c, v_c) in v.iter().enumerate() {
        for (entry, j_rc) in rhs.iter_mut().zip(&j[c * m..(c + 1) * m]) {
            *entry += *j_rc * *v_c;
        }
    }
    let scale = S::splat(-(1.0 + restitution));
    for entry in rhs.iter_mut() {
        *entry *= scale;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraint::{Attachment, Constraint, ConstraintKind, ConstraintReference};
    use crate::io::bundled::floating_ur5_state;
    use crate::spatial::Transform;

    /// The floating UR5 with its last frame held to the world where it is.
    fn held_ur5() -> (Model, ConstraintSet, Vec<f64>, Vec<f64>, Vec<f64>) {
        let (model, q, v, tau) = floating_ur5_state();
        let frame = model.frames.len() - 1;
        let held = Constraint {
            kind: ConstraintKind::Frame {
                first: Attachment {
                    frame: Some(frame),
                    placement: Transform::IDENTITY,
                },
                second: None,
                mask: [true; 6],
            },
            reference: ConstraintReference::World,
        };
        let set = ConstraintSet::new(&model, vec![held]).unwrap();
        (model, set, q, v, tau)
    }

    /// One call, built for AVX2 and FMA where the processor has them, equals the baseline build
    /// of the same steps bit for bit (the claim of `forward_route` and `impulse_route`).
    #[test]
    fn the_dispatched_routes_equal_the_baseline_build_bit_for_bit() {
        let (model, set, q, v, tau) = held_ur5();
        let options = ConstrainedOptions::default();
        let (mut data, mut constraints) = (Data::new(&model), ConstraintData::new(&model, &set));
        let state = (q.as_slice(), v.as_slice(), tau.as_slice());
        constrained_forward_dynamics(
            &model,
            &mut data,
            &mut constraints,
            &set,
            state,
            None,
            &options,
        )
        .unwrap();
        let (mut base_data, mut base) = (Data::new(&model), ConstraintData::new(&model, &set));
        forward_steps(
            &model,
            &mut base_data,
            &mut base,
            &set,
            state,
            None,
            &options,
        )
        .unwrap();
        assert_eq!(
            (&constraints.qdd, &constraints.forces),
            (&base.qdd, &base.forces)
        );

        let (q, v) = (q.as_slice(), v.as_slice());
        impulse_dynamics(&model, &mut data, &mut constraints, &set, (q, v), 0.5, 0.0).unwrap();
        impulse_steps(&model, &mut base_data, &mut base, &set, (q, v), (0.5, 0.0)).unwrap();
        assert_eq!(
            (&constraints.qdd, &constraints.forces),
            (&base.qdd, &base.forces)
        );
    }
}
