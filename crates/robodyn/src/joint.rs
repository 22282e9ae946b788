//! Joints: the only place in robodyn that matches on the joint type.
//!
//! Each joint answers Featherstone's `jcalc` (*Rigid Body Dynamics Algorithms*, §4.4, Table 4.1):
//! the joint transform `X_J(q)`, the motion subspace `S` (one [`Motion`] column per velocity
//! coordinate, in the child body's frame) and the joint velocity `v_J = S q̇`. Every joint here has a
//! constant `S` in the child frame, so the bias `c_J = Ṡ q̇` is zero. Configuration integration and
//! differences act on the joint's Lie group (quaternions for the spherical and free joints), so
//! `difference(q, integrate(q, v)) = v`.

use crate::spatial::trig::sin_cos;
use crate::spatial::turn::lone_column;
use crate::spatial::{
    cross, rotate_back, skew, splat_vector, zero_vector, Force, Mat3, Motion, Real, Transform,
    Turn, Vec3,
};
use nalgebra::{Matrix3, Matrix6, Quaternion, UnitQuaternion, Vector3};

mod configuration;
mod jacobians;
mod subspace;

pub(crate) use subspace::{ArticulatedTerms, MotionSubspace};

/// Below this rotation angle the SE(3)/SO(3) exponential and logarithm use their Taylor series.
const SMALL_ANGLE: f64 = 1e-6;

/// A unit vector that is exactly a coordinate axis or its opposite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct CoordinateAxis {
    /// 0, 1, 2 for x, y, z.
    index: usize,
    /// Whether it points the negative way.
    negative: bool,
}

impl CoordinateAxis {
    /// `x`, or `−x` for an axis that points the negative way.
    #[inline(always)]
    fn signed<T: std::ops::Neg<Output = T>>(self, x: T) -> T {
        if self.negative {
            -x
        } else {
            x
        }
    }
}

/// Which coordinate axis a unit vector is exactly, or its opposite, if any. Asked for every joint
/// of every call: which two components are zero first, then the third (a search over the three
/// axes had cost a tenth of a Jacobian).
#[inline(always)]
fn coordinate_axis(axis: &Vec3) -> Option<CoordinateAxis> {
    let (index, value) = match (axis.x == 0.0, axis.y == 0.0, axis.z == 0.0) {
        (true, true, false) => (2, axis.z),
        (true, false, true) => (1, axis.y),
        (false, true, true) => (0, axis.x),
        _ => return None,
    };
    let negative = value == -1.0;
    (value == 1.0 || negative).then_some(CoordinateAxis { index, negative })
}

/// A joint between a body and its parent.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Joint {
    /// No motion: nq = nv = 0. Only the world (body 0) carries it; the loaders merge fixed joints
    /// into the parent body and keep the child link as a frame.
    Fixed,
    /// Rotation about a unit `axis` of the joint frame. q = `[angle]` (rad), v = `[angular rate]`
    /// (rad/s). A URDF `continuous` joint is a revolute joint without position limits.
    Revolute {
        /// The unit rotation axis, in joint-frame coordinates.
        axis: Vec3,
    },
    /// Translation along a unit `axis` of the joint frame. q = `[displacement]` (m),
    /// v = `[rate]` (m/s).
    Prismatic {
        /// The unit translation axis, in joint-frame coordinates.
        axis: Vec3,
    },
    /// Ball joint. q = [qx, qy, qz, qw], the unit quaternion (scalar last) of the child's rotation
    /// relative to the joint frame; v = [ωx, ωy, ωz], the child's angular velocity in child axes.
    Spherical,
    /// Floating base. q = [x, y, z, qx, qy, qz, qw]: the child's origin in the parent frame and its
    /// orientation (unit quaternion, scalar last); v = [vx, vy, vz, ωx, ωy, ωz]: the linear
    /// velocity of the child's origin and its angular velocity, both in the child's own axes.
    Free,
}

impl Joint {
    /// Number of configuration coordinates.
    #[inline]
    pub fn nq(&self) -> usize {
        match self {
            Joint::Fixed => 0,
            Joint::Revolute { .. } | Joint::Prismatic { .. } => 1,
            Joint::Spherical => 4,
            Joint::Free => 7,
        }
    }

    /// Number of velocity coordinates (degrees of freedom).
    #[inline]
    pub fn nv(&self) -> usize {
        match self {
            Joint::Fixed => 0,
            Joint::Revolute { .. } | Joint::Prismatic { .. } => 1,
            Joint::Spherical => 3,
            Joint::Free => 6,
        }
    }

    /// A short lowercase name: "revolute", "prismatic", "spherical", "free", "fixed".
    pub fn kind(&self) -> &'static str {
        match self {
            Joint::Fixed => "fixed",
            Joint::Revolute { .. } => "revolute",
            Joint::Prismatic { .. } => "prismatic",
            Joint::Spherical => "spherical",
            Joint::Free => "free",
        }
    }

    /// Where the unit quaternion sits inside this joint's q, if it has one.
    #[inline]
    pub fn quaternion_offset(&self) -> Option<usize> {
        match self {
            Joint::Spherical => Some(0),
            Joint::Free => Some(3),
            _ => None,
        }
    }

    /// The joint transform `X_J(q)` from the joint frame to the child body frame.
    /// `q` is this joint's slice of the configuration (`f64`, or lanes of a batch).
    #[inline(always)]
    pub fn transform<S: Real>(&self, q: &[S]) -> Transform<S> {
        match self {
            Joint::Fixed => Transform::splat(&Transform::IDENTITY),
            Joint::Revolute { axis } => Transform::from_axis_angle(axis, q[0]),
            Joint::Prismatic { axis } => {
                Transform::from_translation(&(splat_vector::<S>(axis) * q[0]))
            }
            Joint::Spherical => Transform::from_pose(&rotation_of(&q[0..4]), &zero_vector()),
            Joint::Free => {
                Transform::from_pose(&rotation_of(&q[3..7]), &Vector3::new(q[0], q[1], q[2]))
            }
        }
    }

    /// `X_J(q) X_T`: this joint's transform after the constant `x_tree` (parent frame to joint
    /// frame), the body's `X_{i←λ(i)}`. A revolute joint about a coordinate axis of its frame (most
    /// joints: URDF and MJCF axes are mostly x, y or z) turns two rows of X_T's rotation and keeps
    /// its translation; a prismatic joint moves the translation only.
    #[inline(always)]
    pub fn transform_after<S: Real>(&self, q: &[S], x_tree: &Transform) -> Transform<S> {
        // the sine and cosine of a revolute joint's angle; the other joints take none
        let turn = match self {
            Joint::Revolute { .. } => sin_cos(q[0]),
            _ => (S::zero(), S::one()),
        };
        self.transform_after_turn(q, turn, x_tree)
    }

    /// [`Joint::transform_after`] given `(sin, cos)` of `q[0]` (used by a revolute joint only),
    /// computed beforehand: forward kinematics evaluates several joints' at once.
    #[inline(always)]
    pub fn transform_after_turn<S: Real>(
        &self,
        q: &[S],
        (s, c): (S, S),
        x_tree: &Transform,
    ) -> Transform<S> {
        let x_tree = Transform::splat(x_tree);
        match self {
            Joint::Fixed => x_tree,
            Joint::Revolute { axis } => match coordinate_axis(axis) {
                // about −e_k by θ is about e_k by −θ
                Some(k) => x_tree.rotated_about_axis(k.index, k.signed(s), c),
                None => Transform::from_axis_sin_cos(axis, s, c) * x_tree,
            },
            Joint::Prismatic { axis } => Transform {
                rotation: x_tree.rotation,
                // r = r_T + E_Tᵀ (axis q)
                translation: x_tree.translation
                    + rotate_back(&x_tree.rotation, &(splat_vector::<S>(axis) * q[0])),
            },
            Joint::Spherical | Joint::Free => self.transform(q) * x_tree,
        }
    }

    /// The pattern of `X_J(q) X_T`'s rotation when it turns about one coordinate axis after a
    /// rotation that keeps one axis, for this `X_T`: a revolute joint about ±e_k, or a prismatic
    /// joint (whose X_J does not turn; k = 2), after an `X_T` whose rotation's row k is exactly
    /// ±e_c with nothing else in column c (none, quarter turns, a rotation about e_k itself), and
    /// does not turn e_k into −e_k. Transforms by it can then leave out the products
    /// with the rotation's zeros (`Transform::apply_motion_turned` and the like).
    #[inline(always)]
    pub fn turn(&self, x_tree: &Transform) -> Option<Turn> {
        let (axis, axis_negative) = match self {
            Joint::Revolute { axis } => {
                let k = coordinate_axis(axis)?;
                (k.index, k.negative)
            }
            Joint::Prismatic { .. } => (2, false),
            _ => return None,
        };
        let column = lone_column(&x_tree.rotation, axis)?;
        // row k of E = E_J E_T is E_T's: where it is −e_k, the general products
        let keeps_axis = column != axis || x_tree.rotation[(axis, axis)] == 1.0;
        keeps_axis.then_some(Turn {
            axis,
            column,
            axis_negative,
            tree_rotates: x_tree.rotation != Mat3::identity(),
        })
    }

    /// [`Joint::transform_after_turn`] given the body's [`Turn`] (`Model::turn`, found once per
    /// model): a revolute joint needs no test of its axis, and after a tree transform that does
    /// not rotate its rotation is its own turn `E_J`, with no product by X_T's identity (the same
    /// values: c·1 + s·0 = c).
    #[inline(always)]
    pub fn transform_after_turn_of<S: Real>(
        &self,
        q: &[S],
        (s, c): (S, S),
        x_tree: &Transform,
        turn: Option<Turn>,
    ) -> Transform<S> {
        match (self, turn) {
            (Joint::Revolute { .. }, Some(turn)) => {
                // about −e_k by θ is about e_k by −θ
                let s = if turn.axis_negative { -s } else { s };
                match turn.tree_rotates {
                    true => Transform::splat(x_tree).rotated_about_axis(turn.axis, s, c),
                    false => Transform {
                        rotation: Transform::rotation_about_axis(turn.axis, s, c),
                        translation: splat_vector(&x_tree.translation),
                    },
                }
            }
            _ => self.transform_after_turn(q, (s, c), x_tree),
        }
    }

    /// Column `k` of the motion subspace `S`, in the child frame.
    #[inline(always)]
    pub fn subspace_column(&self, k: usize) -> Motion {
        let unit = |i: usize| Vec3::ith(i % 3, 1.0);
        match self {
            Joint::Fixed => Motion::ZERO,
            Joint::Revolute { axis } => Motion::new(*axis, Vec3::zeros()),
            Joint::Prismatic { axis } => Motion::new(Vec3::zeros(), *axis),
            Joint::Spherical => Motion::new(unit(k), Vec3::zeros()),
            Joint::Free if k < 3 => Motion::new(Vec3::zeros(), unit(k)),
            Joint::Free => Motion::new(unit(k), Vec3::zeros()),
        }
    }

    /// Column `k` of `S` in the coordinates `x` maps from (the world's, for `x = X_{i←0}`):
    /// `X⁻¹ S_k = (Eᵀ ω_k, Eᵀ v_k + r × Eᵀ ω_k)`. About or along coordinate axis c of the joint
    /// frame, `Eᵀ e_c` is row c of E: a joint turns about it (v = r × ω) or slides along it —
    /// no rotation product. Spherical and free joints' columns are all such axes.
    #[inline(always)]
    pub fn subspace_column_from<S: Real>(&self, k: usize, x: &Transform<S>) -> Motion<S> {
        // turning about ω through r: v = r × ω
        self.subspace_column_with(k, x, |angular| cross(&x.translation, angular))
    }

    /// [`Joint::subspace_column_from`] with its linear part the velocity of the body point at
    /// `point` (in the same coordinates) instead of the one at the origin: turning about ω
    /// through r, that point moves at `ω × (point − r)`; sliding, every point moves alike.
    #[inline(always)]
    pub fn subspace_column_at<S: Real>(
        &self,
        k: usize,
        x: &Transform<S>,
        point: &Vector3<S>,
    ) -> Motion<S> {
        let arm = point - x.translation;
        self.subspace_column_with(k, x, |angular| cross(angular, &arm))
    }

    /// Column `k` of `S` in the coordinates `x` maps from, its axis `Eᵀ a` and, where the joint
    /// turns about it, its linear part `turning_velocity(Eᵀ a)`.
    #[inline(always)]
    fn subspace_column_with<S: Real>(
        &self,
        k: usize,
        x: &Transform<S>,
        turning_velocity: impl Fn(&Vector3<S>) -> Vector3<S>,
    ) -> Motion<S> {
        let e = &x.rotation;
        let row = |c: usize| Vector3::new(e[(c, 0)], e[(c, 1)], e[(c, 2)]);
        // Eᵀ a, a row of E (or its opposite) when a is a coordinate axis (or its opposite)
        let back = |a: &Vec3| match coordinate_axis(a) {
            Some(k) => k.signed(row(k.index)),
            None => rotate_back(e, &splat_vector(a)),
        };
        let turning = |angular: Vector3<S>| Motion {
            linear: turning_velocity(&angular),
            angular,
        };
        let sliding = |linear: Vector3<S>| Motion {
            angular: zero_vector(),
            linear,
        };
        match self {
            Joint::Fixed => Motion::zeros(),
            Joint::Revolute { axis } => turning(back(axis)),
            Joint::Prismatic { axis } => sliding(back(axis)),
            Joint::Spherical => turning(row(k)),
            Joint::Free if k < 3 => sliding(row(k)),
            Joint::Free => turning(row(k - 3)),
        }
    }

    /// `I S_k` for a 6x6 inertia `I` on `[angular; linear]` (an articulated one, say) and this
    /// joint's subspace column k: one column of I, or its angular (revolute) or linear
    /// (prismatic) half times the axis — not a full 6x6 product.
    #[inline(always)]
    pub fn inertia_times_subspace<S: Real>(&self, inertia: &Matrix6<S>, k: usize) -> Force<S> {
        match self {
            Joint::Fixed => Force::new(zero_vector(), zero_vector()),
            Joint::Revolute { axis } => match coordinate_axis(axis) {
                Some(c) => c.signed(inertia_column(inertia, c.index)),
                None => inertia_times_axis(inertia, 0, axis),
            },
            Joint::Prismatic { axis } => match coordinate_axis(axis) {
                Some(c) => c.signed(inertia_column(inertia, 3 + c.index)),
                None => inertia_times_axis(inertia, 3, axis),
            },
            Joint::Spherical => inertia_column(inertia, k),
            Joint::Free if k < 3 => inertia_column(inertia, 3 + k),
            Joint::Free => inertia_column(inertia, k - 3),
        }
    }

    /// Where column `k` of `S` is a coordinate axis of `[angular; linear]` or its opposite (every
    /// column of a spherical or free joint; a revolute or prismatic joint about ±e_c): its index
    /// in `[angular; linear]` and whether it is the opposite. `S_kᵀ f` is then that component of
    /// `f` (negated), the same value as [`Joint::project_force`] without the products by zero.
    #[inline(always)]
    pub fn subspace_component(&self, k: usize) -> Option<(usize, bool)> {
        let signed = |offset: usize, axis: &Vec3| {
            coordinate_axis(axis).map(|c| (offset + c.index, c.negative))
        };
        match self {
            Joint::Fixed => None,
            Joint::Revolute { axis } => signed(0, axis),
            Joint::Prismatic { axis } => signed(3, axis),
            Joint::Spherical => Some((k, false)),
            Joint::Free if k < 3 => Some((3 + k, false)),
            Joint::Free => Some((k - 3, false)),
        }
    }

    /// `S_kᵀ f`: the component of force `f` (child frame) along velocity coordinate `k`.
    #[inline(always)]
    pub fn project_force<S: Real>(&self, k: usize, f: &Force<S>) -> S {
        match self {
            Joint::Fixed => S::zero(),
            Joint::Revolute { axis } => splat_vector::<S>(axis).dot(&f.angular),
            Joint::Prismatic { axis } => splat_vector::<S>(axis).dot(&f.linear),
            Joint::Spherical => f.angular[k % 3],
            Joint::Free if k < 3 => f.linear[k],
            Joint::Free => f.angular[k % 3],
        }
    }

    /// Entry (r, c) of the velocity-dependent part of the rotor (armature) force, `K(v)` with
    /// `τ_rotor = A (q̈ + K(v) q̇)`, for this joint's slice `v`. Zero except on a free joint, whose
    /// armature acts, as in MuJoCo, on the world-frame linear velocity R v_lin: its rate in body
    /// axes is v̇_lin + ω × v_lin, so K's linear block is [ω×] (skew-symmetric, so Ṁ − 2C stays
    /// skew and the rotor does no work). Needs the same armature on the three linear coordinates.
    #[inline(always)]
    pub fn rotor_velocity_term<S: Real>(&self, r: usize, c: usize, v: &[S]) -> S {
        match self {
            Joint::Free if r < 3 && c < 3 => skew(&Vector3::new(v[3], v[4], v[5]))[(r, c)],
            _ => S::zero(),
        }
    }

    /// Entry (r, c) of ∂(K(v) v)/∂v, the derivative of the rotor's velocity term above: on a free
    /// joint (K v)_lin = ω × v_lin, so ∂/∂v_lin = [ω×] and ∂/∂ω = −[v_lin×].
    #[inline(always)]
    pub fn rotor_velocity_jacobian<S: Real>(&self, r: usize, c: usize, v: &[S]) -> S {
        match self {
            Joint::Free if r < 3 && c < 3 => skew(&Vector3::new(v[3], v[4], v[5]))[(r, c)],
            Joint::Free if r < 3 => -skew(&Vector3::new(v[0], v[1], v[2]))[(r, c - 3)],
            _ => S::splat(0.0),
        }
    }

    /// Checks the armature of this joint's velocity coordinates: a free joint's acts on its
    /// world-frame linear velocity, so it must be the same along the three linear coordinates.
    pub fn check_armature(&self, armature: &[f64]) -> Result<(), String> {
        match self {
            Joint::Free if armature[0] != armature[1] || armature[0] != armature[2] => Err(format!(
                "a free joint's armature acts on its world-frame linear velocity (as in MuJoCo) and \
                 must be the same on its three linear coordinates, got {:?}",
                &armature[..3]
            )),
            _ => Ok(()),
        }
    }

    /// The joint velocity `v_J = S q̇` for this joint's slice `v` of the velocity.
    #[inline(always)]
    pub fn motion<S: Real>(&self, v: &[S]) -> Motion<S> {
        let mut sum = Motion::zeros();
        for (k, v_k) in v.iter().enumerate().take(self.nv()) {
            sum += Motion::splat(&self.subspace_column(k)) * *v_k;
        }
        sum
    }
}

/// Column `c` of a 6x6 inertia, as a force.
#[inline(always)]
fn inertia_column<S: Real>(inertia: &Matrix6<S>, c: usize) -> Force<S> {
    let entry = |r: usize| inertia[(r, c)];
    Force::from_plucker([entry(0), entry(1), entry(2), entry(3), entry(4), entry(5)])
}

/// Columns `first..first + 3` of a 6x6 inertia times `axis`, as a force.
#[inline(always)]
fn inertia_times_axis<S: Real>(inertia: &Matrix6<S>, first: usize, axis: &Vec3) -> Force<S> {
    let a = splat_vector::<S>(axis);
    let mut rows = [S::splat(0.0); 6];
    for (r, row) in rows.iter_mut().enumerate() {
        *row = inertia[(r, first)] * a.x
            + inertia[(r, first + 1)] * a.y
            + inertia[(r, first + 2)] * a.z;
    }
    Force::from_plucker(rows)
}

/// The unit quaternion of `[qx, qy, qz, qw]` (normalised).
pub(crate) fn quaternion_of<S: Real>(q: &[S]) -> UnitQuaternion<S> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]))
}

/// The rotation matrix of `[qx, qy, qz, qw]`, normalised on the way: with s = 2 / |q|²,
/// R = 1 − s [y²+z², ...] (the quaternion's rotation formula, written out so that it inlines
/// into the batch kernels).
#[inline(always)]
pub(crate) fn rotation_of<S: Real>(q: &[S]) -> Matrix3<S> {
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    let s = S::splat(2.0) / (x * x + y * y + z * z + w * w);
    let one = S::one();
    Matrix3::new(
        one - s * (y * y + z * z),
        s * (x * y - w * z),
        s * (x * z + w * y),
        s * (x * y + w * z),
        one - s * (x * x + z * z),
        s * (y * z - w * x),
        s * (x * z - w * y),
        s * (y * z + w * x),
        one - s * (x * x + y * y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinate_axes_are_exactly_the_unit_vectors() {
        let axis = |index, negative| Some(CoordinateAxis { index, negative });
        let cases = [
            (Vec3::new(1.0, 0.0, 0.0), axis(0, false)),
            (Vec3::new(0.0, 1.0, 0.0), axis(1, false)),
            (Vec3::new(0.0, 0.0, 1.0), axis(2, false)),
            (Vec3::new(-0.0, 0.0, 1.0), axis(2, false)),
            (Vec3::new(0.0, -0.0, 1.0), axis(2, false)),
            (Vec3::new(0.0, 0.0, -1.0), axis(2, true)),
            (Vec3::new(-1.0, -0.0, 0.0), axis(0, true)),
            (Vec3::new(0.0, 1.0, 1e-300), None),
            (Vec3::new(1.0 - f64::EPSILON, 0.0, 0.0), None),
            (Vec3::new(0.0, -1.0 - f64::EPSILON, 0.0), None),
            (Vec3::new(0.6, 0.0, 0.8), None),
            (Vec3::new(f64::NAN, 0.0, 1.0), None),
            (Vec3::new(0.0, 0.0, 0.0), None),
        ];
        for (vector, expected) in cases {
            assert_eq!(coordinate_axis(&vector), expected, "{vector:?}");
        }
    }
}
