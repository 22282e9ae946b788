//! Spatial motion vectors (velocities, accelerations, motion subspace columns).

use super::{Force, Vec3};
use std::ops::{Add, AddAssign, Mul, Neg, Sub};

/// A spatial motion vector `m = (ω, v_O)`: angular part and the linear velocity of the point at
/// the frame's origin, both in the frame's axes (Featherstone §2.3).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Motion {
    pub angular: Vec3,
    pub linear: Vec3,
}

impl Motion {
    pub const ZERO: Motion = Motion {
        angular: Vec3::new(0.0, 0.0, 0.0),
        linear: Vec3::new(0.0, 0.0, 0.0),
    };

    pub fn new(angular: Vec3, linear: Vec3) -> Self {
        Motion { angular, linear }
    }

    /// `m × n`: the motion cross product (Featherstone eq. 2.31).
    #[inline]
    pub fn cross_motion(&self, other: &Motion) -> Motion {
        Motion {
            angular: self.angular.cross(&other.angular),
            linear: self.angular.cross(&other.linear) + self.linear.cross(&other.angular),
        }
    }

    /// `m ×* f`: the force cross product (Featherstone eq. 2.32).
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force {
            angular: self.angular.cross(&f.angular) + self.linear.cross(&f.linear),
            linear: self.angular.cross(&f.linear),
        }
    }

    /// The 6x6 matrix of `m ×` on `[angular; linear]`: `[ω× 0; v× ω×]` (Featherstone eq. 2.31).
    #[inline]
    pub fn cross_matrix(&self) -> super::Mat6 {
        let (w, v) = (super::skew(&self.angular), super::skew(&self.linear));
        let mut x = super::Mat6::zeros();
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&w);
        x.fixed_view_mut::<3, 3>(3, 0).copy_from(&v);
        x.fixed_view_mut::<3, 3>(3, 3).copy_from(&w);
        x
    }

    /// The scalar product `m · f` (power).
    #[inline]
    pub fn dot(&self, f: &Force) -> f64 {
        self.angular.dot(&f.angular) + self.linear.dot(&f.linear)
    }

    /// The Plücker 6-vector `[angular; linear]` that [`super::Transform::to_matrix`] and
    /// [`super::Inertia::to_matrix`] act on.
    #[inline]
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
    #[inline]
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
    #[inline]
    pub fn from_array(values: &[f64; 6]) -> Self {
        Motion {
            linear: Vec3::new(values[0], values[1], values[2]),
            angular: Vec3::new(values[3], values[4], values[5]),
        }
    }
}

impl Add for Motion {
    type Output = Motion;
    #[inline]
    fn add(self, rhs: Motion) -> Motion {
        Motion::new(self.angular + rhs.angular, self.linear + rhs.linear)
    }
}

impl AddAssign for Motion {
    #[inline]
    fn add_assign(&mut self, rhs: Motion) {
        self.angular += rhs.angular;
        self.linear += rhs.linear;
    }
}

impl Sub for Motion {
    type Output = Motion;
    #[inline]
    fn sub(self, rhs: Motion) -> Motion {
        Motion::new(self.angular - rhs.angular, self.linear - rhs.linear)
    }
}

impl Neg for Motion {
    type Output = Motion;
    #[inline]
    fn neg(self) -> Motion {
        Motion::new(-self.angular, -self.linear)
    }
}

impl Mul<f64> for Motion {
    type Output = Motion;
    #[inline]
    fn mul(self, s: f64) -> Motion {
        Motion::new(self.angular * s, self.linear * s)
    }
}
