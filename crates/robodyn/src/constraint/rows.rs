//! The rows of each constraint at a state: its Jacobian J, drift γ = J̇ q̇ and position error φ.
//!
//! Reference: Featherstone, *Rigid Body Dynamics Algorithms* (2008), §8.1 (loop constraints as
//! rows `K q̈ = k`) and §2.11 (classical acceleration); the ECE 470 notes' geometric Jacobian.
//! A point p fixed in body b, whose spatial velocity in world coordinates is `(ω, v_O)` and
//! acceleration `(ω̇, a_O)` (here with q̈ = 0, so that they give J̇ q̇), moves with
//! ```text
//!   ṗ = v_O + ω × p                  (its velocity: the rows J q̇)
//!   p̈ = a_O + ω̇ × p + ω × ṗ          (its classical acceleration: the drift γ)
//! ```
//! and column k of joint j of J is the joint's subspace column in world coordinates taken at p.
//! A constraint between two attachments has the first's rows minus the second's; in local axes
//! each row is turned by the first's rotation `E` (world to constraint frame).
//! Inputs: the placements `x_world`, velocities `v` and bias accelerations `a` of every body
//! (body coordinates), q and q̇. Cost: O(depth) per point.

use super::{Attachment, ConstraintKind, ConstraintReference, ConstraintSet};
use crate::model::Model;
use crate::spatial::{
    compose, cross, dot, log_rotation, rotate, rotate_back, transposed, Motion, Real, Transform,
};
use nalgebra::{DMatrix, Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Where the rows of a constraint set are written: J (rows × nv), γ and φ (rows each); in `f64`
/// or in lanes ([`crate::algo::lanes`]).
pub(crate) struct ConstraintRows<'a, S = f64> {
    /// J: the rows' velocity is `J q̇`.
    pub jacobian: &'a mut DMatrix<S>,
    /// γ = J̇ q̇: the rows' acceleration is `J q̈ + γ`.
    pub drift: &'a mut [S],
    /// φ: how far each row is from holding (zero where a point is held where it is).
    pub error: &'a mut [S],
}

/// The bodies' motion that the rows are made from: placements `X_{i←0}`, velocities and
/// accelerations with q̈ = 0, in body coordinates.
pub(crate) struct BodyMotion<'a, S = f64> {
    /// `X_{i←0}` of every body.
    pub x_world: &'a [Transform<S>],
    /// Spatial velocity of every body, in its own coordinates.
    pub v: &'a [Motion<S>],
    /// Spatial acceleration of every body with q̈ = 0 (no gravity), in its own coordinates.
    pub a: &'a [Motion<S>],
}

/// The motion of a constraint frame: its placement, and its origin's velocity and classical
/// acceleration (with q̈ = 0), all in world coordinates.
struct FrameMotion<S> {
    /// `E`: world to constraint-frame axes.
    rotation: Matrix3<S>,
    /// p: the origin.
    position: Vector3<S>,
    /// ṗ.
    velocity: Vector3<S>,
    /// p̈ with q̈ = 0.
    acceleration: Vector3<S>,
    /// ω̇ with q̈ = 0.
    angular_acceleration: Vector3<S>,
    /// The body the frame is fixed in (0: the world).
    body: usize,
}

/// Writes J, γ and φ of every constraint of `set` (J's rows zeroed first).
#[inline(always)]
pub(crate) fn evaluate<S: Real>(
    model: &Model,
    set: &ConstraintSet,
    bodies: &BodyMotion<S>,
    (q, v): (&[S], &[S]),
    mut rows: ConstraintRows<S>,
) {
    // a slice's fill: the matrix's own goes entry by entry through an iterator
    rows.jacobian.as_mut_slice().fill(S::zero());
    for (k, constraint) in set.constraints().iter().enumerate() {
        let row = set.offset(k);
        let local = constraint.reference == ConstraintReference::Local;
        match &constraint.kind {
            ConstraintKind::Point { first, second } => {
                let mask = [true, true, true, false, false, false];
                let held = Held::new(model, bodies, first, second.as_ref());
                held.write(model, bodies, row, &mask, local, &mut rows);
            }
            ConstraintKind::Frame {
                first,
                second,
                mask,
            } => {
                let held = Held::new(model, bodies, first, second.as_ref());
                held.write(model, bodies, row, mask, local, &mut rows);
            }
            ConstraintKind::Distance {
                first,
                second,
                length,
            } => {
                let (one, other) = (
                    frame_motion(model, bodies, first),
                    frame_motion(model, bodies, second),
                );
                write_distance(model, bodies, (&one, &other), *length, row, &mut rows);
            }
            ConstraintKind::Coupling {
                follower,
                leader,
                polynomial,
                references,
            } => {
                let f = model.idx_v[*follower];
                let follower_q = q[model.idx_q[*follower]] - S::splat(references.0);
                rows.jacobian[(row, f)] += S::one();
                rows.error[row] = follower_q - S::splat(polynomial[0]);
                rows.drift[row] = S::zero();
                if let Some(leader) = leader {
                    let l = model.idx_v[*leader];
                    let x = q[model.idx_q[*leader]] - S::splat(references.1);
                    let [p, dp, ddp, _] = polynomial_at(polynomial, x);
                    // φ = (q_f − q_f,ref) − p(x);  J = e_f − p'(x) e_l;  γ = −p''(x) q̇_l²
                    rows.error[row] = follower_q - p;
                    rows.jacobian[(row, l)] -= dp;
                    rows.drift[row] = -ddp * v[l] * v[l];
                }
            }
        }
    }
}

/// A point or frame constraint at this state: the first attachment's motion and the second's
/// (the world where the first is, when there is none).
struct Held<S> {
    first: FrameMotion<S>,
    second: Option<FrameMotion<S>>,
}

impl<S: Real> Held<S> {
    #[inline(always)]
    fn new(
        model: &Model,
        bodies: &BodyMotion<S>,
        first: &Attachment,
        second: Option<&Attachment>,
    ) -> Self {
        Held {
            first: frame_motion(model, bodies, first),
            second: second.map(|s| frame_motion(model, bodies, s)),
        }
    }

    /// Writes the `mask`ed rows `[linear; angular]` from row `row` on.
    #[inline(always)]
    fn write(
        &self,
        model: &Model,
        bodies: &BodyMotion<S>,
        row: usize,
        mask: &[bool; 6],
        local: bool,
        rows: &mut ConstraintRows<S>,
    ) {
        let first = &self.first;
        // the rows' axes: world, or the first frame's (E)
        let axes = if local {
            first.rotation
        } else {
            Matrix3::identity()
        };
        // J: the first point's columns minus the second's (world axes: no turn), each column's
        // kept entries written straight into J's storage (column-major, m rows)
        let turned = |x: &Vector3<S>| if local { rotate(&axes, x) } else { *x };
        let (kept_entries, count) = kept_indices(mask);
        let m = rows.jacobian.nrows();
        let jacobian = rows.jacobian.as_mut_slice();
        for (motion, first) in [(Some(first), true), (self.second.as_ref(), false)] {
            let Some(motion) = motion else { continue };
            point_columns(model, bodies, motion, |column, linear, angular| {
                let full = six(&turned(linear), &turned(angular));
                let entries = &mut jacobian[column * m + row..column * m + row + count];
                for (entry, &k) in entries.iter_mut().zip(&kept_entries[..count]) {
                    *entry = if first {
                        *entry + full[k]
                    } else {
                        *entry - full[k]
                    };
                }
            });
        }

        // γ = p̈_1 − p̈_2 and ω̇_1 − ω̇_2 with q̈ = 0;  φ = p_1 − p_2 and R_2 log(R_2ᵀ R_1)
        let (mut acceleration, mut angular_acceleration) =
            (first.acceleration, first.angular_acceleration);
        let (mut offset, mut turn) = (Vector3::zeros(), Vector3::zeros());
        if let Some(second) = &self.second {
            acceleration -= second.acceleration;
            angular_acceleration -= second.angular_acceleration;
            offset = first.position - second.position;
            // R = Eᵀ, so R_2ᵀ R_1 = E_2 E_1ᵀ
            let relative = compose(&second.rotation, &transposed(&first.rotation));
            turn = rotate_back(&second.rotation, &relative_turn(&relative));
        }
        let turned = |x: &Vector3<S>| rotate(&axes, x);
        let drift = six(&turned(&acceleration), &turned(&angular_acceleration));
        let error = six(&turned(&offset), &turned(&turn));
        for ((r, gamma), (_, phi)) in kept(mask, &drift).zip(kept(mask, &error)) {
            rows.drift[row + r] = gamma;
            rows.error[row + r] = phi;
        }
    }
}

/// The distance row: with n = (p_1 − p_2)/d, `J = nᵀ (J_1 − J_2)`,
/// `γ = nᵀ (p̈_1 − p̈_2) + (|ṗ_1 − ṗ_2|² − (nᵀ (ṗ_1 − ṗ_2))²)/d`, φ = d − length.
#[inline(always)]
fn write_distance<S: Real>(
    model: &Model,
    bodies: &BodyMotion<S>,
    (one, other): (&FrameMotion<S>, &FrameMotion<S>),
    length: f64,
    row: usize,
    rows: &mut ConstraintRows<S>,
) {
    let offset = one.position - other.position;
    let distance = dot(&offset, &offset)
        .simd_sqrt()
        .simd_max(S::splat(f64::MIN_POSITIVE));
    let n = offset / distance;
    for (motion, first) in [(one, true), (other, false)] {
        point_columns(model, bodies, motion, |column, linear, _| {
            let entry = &mut rows.jacobian[(row, column)];
            *entry = if first {
                *entry + dot(&n, linear)
            } else {
                *entry - dot(&n, linear)
            };
        });
    }
    let relative_velocity = one.velocity - other.velocity;
    let along = dot(&n, &relative_velocity);
    let gamma = dot(&n, &(one.acceleration - other.acceleration))
        + (dot(&relative_velocity, &relative_velocity) - along * along) / distance;
    rows.drift[row] = gamma;
    rows.error[row] = distance - S::splat(length);
}

/// The motion of an attachment's constraint frame (fixed in the world when it has no frame).
#[inline(always)]
fn frame_motion<S: Real>(
    model: &Model,
    bodies: &BodyMotion<S>,
    attachment: &Attachment,
) -> FrameMotion<S> {
    let Some(frame) = attachment.frame else {
        let placement = Transform::<S>::splat(&attachment.placement);
        return FrameMotion {
            rotation: placement.rotation,
            position: placement.translation,
            velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
            body: 0,
        };
    };
    let body = model.frames[frame].body;
    // X_{c←0} = X_{c←frame} X_{frame←body} X_{body←0}
    let (attached, framed) = (&attachment.placement, &model.frames[frame].placement);
    let placement =
        Transform::<S>::splat(attached) * (Transform::splat(framed) * bodies.x_world[body]);
    let p = placement.translation;
    // (ω, v_O) and (ω̇, a_O) of the body in world coordinates
    let velocity = bodies.x_world[body].inverse_apply_motion(&bodies.v[body]);
    let acceleration = bodies.x_world[body].inverse_apply_motion(&bodies.a[body]);
    // ṗ = v_O + ω × p;  p̈ = a_O + ω̇ × p + ω × ṗ
    let point_velocity = velocity.linear + cross(&velocity.angular, &p);
    let point_acceleration = acceleration.linear
        + cross(&acceleration.angular, &p)
        + cross(&velocity.angular, &point_velocity);
    FrameMotion {
        rotation: placement.rotation,
        position: p,
        velocity: point_velocity,
        acceleration: point_acceleration,
        angular_acceleration: acceleration.angular,
        body,
    }
}

/// The columns of the point's Jacobian that are not zero, world axes, each handed to
/// `column(index, linear, angular)`: the subspace columns of the joints between the point's
/// body and the world, taken at the point.
#[inline(always)]
fn point_columns<S: Real>(
    model: &Model,
    bodies: &BodyMotion<S>,
    motion: &FrameMotion<S>,
    mut column: impl FnMut(usize, &Vector3<S>, &Vector3<S>),
) {
    let mut j = motion.body;
    while j != 0 {
        let joint = &model.joints[j];
        for (k, index) in model.v_range(j).enumerate() {
            let s = joint.subspace_column_at(k, &bodies.x_world[j], &motion.position);
            column(index, &s.linear, &s.angular);
        }
        j = model.parent[j];
    }
}

/// `[linear; angular]` as six numbers.
#[inline(always)]
pub(super) fn six<S: Real>(linear: &Vector3<S>, angular: &Vector3<S>) -> [S; 6] {
    [
        linear.x, linear.y, linear.z, angular.x, angular.y, angular.z,
    ]
}

/// The entries of `full` that `mask` keeps, numbered from 0 in order.
#[inline(always)]
pub(super) fn kept<'a, S: Real>(
    mask: &'a [bool; 6],
    full: &'a [S; 6],
) -> impl Iterator<Item = (usize, S)> + 'a {
    full.iter()
        .zip(mask)
        .filter(|(_, &keep)| keep)
        .map(|(&value, _)| value)
        .enumerate()
}

/// The indices of the entries `mask` keeps, in order, and how many there are.
#[inline(always)]
fn kept_indices(mask: &[bool; 6]) -> ([usize; 6], usize) {
    let (mut indices, mut count) = ([0; 6], 0);
    for (k, _) in mask.iter().enumerate().filter(|(_, &keep)| keep) {
        indices[count] = k;
        count += 1;
    }
    (indices, count)
}

/// p(x) = Σ c_k x^k and its first three derivatives, by Horner's rule.
#[inline(always)]
pub(crate) fn polynomial_at<S: Real>(c: &[f64; 5], x: S) -> [S; 4] {
    let [mut p, mut dp, mut ddp, mut dddp] = [S::zero(); 4];
    let (two, three) = (S::splat(2.0), S::splat(3.0));
    for &coefficient in c.iter().rev() {
        dddp = dddp * x + three * ddp;
        ddp = ddp * x + two * dp;
        dp = dp * x + p;
        p = p * x + S::splat(coefficient);
    }
    [p, dp, ddp, dddp]
}

/// `log(R_2ᵀ R_1)` of `relative` = R_2ᵀ R_1, each lane alone (its branches differ by lane)
/// through a unit quaternion: the angle from the trace alone is NaN when rounding puts the
/// trace of a closed weld above 3.
fn relative_turn<S: Real>(relative: &Matrix3<S>) -> Vector3<S> {
    let logs: [[f64; 3]; 8] = std::array::from_fn(|lane| {
        if lane >= S::LANES {
            return [0.0; 3];
        }
        let matrix = Matrix3::from_fn(|r, c| relative[(r, c)].extract(lane));
        let turned = Rotation3::from_matrix_unchecked(matrix);
        log_rotation(&UnitQuaternion::from_rotation_matrix(&turned)).into()
    });
    Vector3::from_fn(|k, _| S::from_lanes(|lane| logs[lane][k]))
}
