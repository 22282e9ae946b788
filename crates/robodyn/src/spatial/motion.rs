//! Spatial motion vectors (velocities, accelerations, motion subspace columns).

use super::{cross, Force, Real, Vec3};
use nalgebra::Vector3;
use std::ops::{Add, AddAssign, Mul, Neg, Sub};

/// A spatial motion vector `m = (ω, v_O)`: angular part and the linear velocity of the point at
/// the frame's origin, both in the frame's axes (Featherstone §2.3). `S` is `f64`, or a lane
/// type for a batch of states (see [`Real`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion<S = f64> {
    /// The angular velocity `ω`.
    pub angular: Vector3<S>,
    /// The linear velocity `v_O` of the point at the frame's origin.
    pub linear: Vector3<S>,
}

impl Default for Motion {
    #[inline(always)]
    fn default() -> Self {
        Motion::ZERO
    }
}

impl Motion {
    /// The zero motion.
    pub const ZERO: Motion = Motion {
        angular: Vec3::new(0.0, 0.0, 0.0),
        linear: Vec3::new(0.0, 0.0, 0.0),
    };
}

impl<S: Real> Motion<S> {
    /// The motion with angular part `angular` and linear part `linear`.
    #[inline(always)]
    pub fn new(angular: Vector3<S>, linear: Vector3<S>) -> Self {
        Motion { angular, linear }
    }

    /// The zero motion.
    #[inline(always)]
    pub fn zeros() -> Self {
        Motion::new(super::zero_vector(), super::zero_vector())
    }

    /// Sets the motion to zero where it lies: `*m = Motion::zeros()` builds the zeros beside it
    /// and copies them, and at eight lanes the copy's loads wait on the stores just made.
    #[inline(always)]
    pub fn set_zero(&mut self) {
        self.angular.fill(S::zero());
        self.linear.fill(S::zero());
    }

    /// A constant motion (of the model) in every lane.
    #[inline(always)]
    pub fn splat(m: &Motion) -> Self {
        Motion::new(
            super::splat_vector(&m.angular),
            super::splat_vector(&m.linear),
        )
    }

    /// Adds `x` to component `index` of `[angular; linear]` (the order of
    /// [`super::Force::plucker`]); one branch per component, so that the motion can stay in
    /// registers.
    #[inline(always)]
    pub fn add_to_component(&mut self, index: usize, x: S) {
        match index {
            0 => self.angular.x += x,
            1 => self.angular.y += x,
            2 => self.angular.z += x,
            3 => self.linear.x += x,
            4 => self.linear.y += x,
            _ => self.linear.z += x,
        }
    }

    /// `m × (s u)` for `u` the unit motion e_c (c as in [`Motion::add_to_component`]): the value
    /// of [`Motion::cross_motion`] without the products with u's zeros. About axis c < 3:
    /// `[ω × s e_c; v × s e_c]`; along axis j = c − 3: `[0; ω × s e_j]`.
    #[inline(always)]
    pub fn cross_unit_motion(&self, c: usize, s: S) -> Motion<S> {
        if c < 3 {
            Motion::new(
                cross_unit(&self.angular, c, s),
                cross_unit(&self.linear, c, s),
            )
        } else {
            Motion::new(super::zero_vector(), cross_unit(&self.angular, c - 3, s))
        }
    }

    /// `m × n`: the motion cross product (Featherstone eq. 2.31).
    #[inline(always)]
    pub fn cross_motion(&self, other: &Motion<S>) -> Motion<S> {
        Motion {
            angular: cross(&self.angular, &other.angular),
            linear: cross(&self.angular, &other.linear) + cross(&self.linear, &other.angular),
        }
    }

    /// `m ×* f`: the force cross product (Featherstone eq. 2.32).
    #[inline(always)]
    pub fn cross_force(&self, f: &Force<S>) -> Force<S> {
        Force {
            angular: cross(&self.angular, &f.angular) + cross(&self.linear, &f.linear),
            linear: cross(&self.angular, &f.linear),
        }
    }

    /// The scalar product `m · f` (power).
    #[inline(always)]
    pub fn dot(&self, f: &Force<S>) -> S {
        self.angular.dot(&f.angular) + self.linear.dot(&f.linear)
    }
}

/// `x × s e_j`: two products (a function, not a closure, so that it is inlined into the lane
/// kernels too).
#[inline(always)]
fn cross_unit<S: Real>(x: &Vector3<S>, j: usize, s: S) -> Vector3<S> {
    match j {
        0 => Vector3::new(S::zero(), x.z * s, -(x.y * s)),
        1 => Vector3::new(-(x.z * s), S::zero(), x.x * s),
        _ => Vector3::new(x.y * s, -(x.x * s), S::zero()),
    }
}

impl Motion {
    /// The 6x6 matrix of `m ×` on `[angular; linear]`: `[ω× 0; v× ω×]` (Featherstone eq. 2.31).
    #[inline(always)]
    pub fn cross_matrix(&self) -> super::Mat6 {
        let (w, v) = (super::skew(&self.angular), super::skew(&self.linear));
        let mut x = super::Mat6::zeros();
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&w);
        x.fixed_view_mut::<3, 3>(3, 0).copy_from(&v);
        x.fixed_view_mut::<3, 3>(3, 3).copy_from(&w);
        x
    }

    /// The Plücker 6-vector `[angular; linear]` that [`super::Transform::to_matrix`] and
    /// [`super::Inertia::to_matrix`] act on.
    #[inline(always)]
    pub fn to_vector(&self) -> nalgebra::Vector6<f64> {
        nalgebra::Vector6::new(
            self.angular.x,
            self.angular.y,
            self.angular.z,
            self.linear.x,
            self.linear.y,
            self.linear.z,
        )
    }

    /// Flattened `[linear; angular]`, robodyn's public order.
    #[inline(always)]
    pub fn to_array(&self) -> [f64; 6] {
        [
            self.linear.x,
            self.linear.y,
            self.linear.z,
            self.angular.x,
            self.angular.y,
            self.angular.z,
        ]
    }

    /// Inverse of [`Motion::to_array`].
    #[inline(always)]
    pub fn from_array(values: &[f64; 6]) -> Self {
        Motion {
            linear: Vec3::new(values[0], values[1], values[2]),
            angular: Vec3::new(values[3], values[4], values[5]),
        }
    }
}

impl<S: Real> Add for Motion<S> {
    type Output = Motion<S>;
    #[inline(always)]
    fn add(self, rhs: Motion<S>) -> Motion<S> {
        Motion::new(self.angular + rhs.angular, self.linear + rhs.linear)
    }
}

impl<S: Real> AddAssign for Motion<S> {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Motion<S>) {
        self.angular += rhs.angular;
        self.linear += rhs.linear;
    }
}

impl<S: Real> Sub for Motion<S> {
    type Output = Motion<S>;
    #[inline(always)]
    fn sub(self, rhs: Motion<S>) -> Motion<S> {
        Motion::new(self.angular - rhs.angular, self.linear - rhs.linear)
    }
}

impl<S: Real> Neg for Motion<S> {
    type Output = Motion<S>;
    #[inline(always)]
    fn neg(self) -> Motion<S> {
        Motion::new(-self.angular, -self.linear)
    }
}

impl<S: Real> Mul<S> for Motion<S> {
    type Output = Motion<S>;
    #[inline(always)]
    fn mul(self, s: S) -> Motion<S> {
        Motion::new(self.angular * s, self.linear * s)
    }
}
