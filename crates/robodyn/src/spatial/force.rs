//! Spatial force vectors (wrenches, momenta).

use super::Vec3;
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

/// A spatial force `f = (n_O, f)`: the moment about the frame's origin and the linear force, both
/// in the frame's axes (Featherstone §2.4).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Force {
    pub angular: Vec3,
    pub linear: Vec3,
}

impl Force {
    pub const ZERO: Force = Force {
        angular: Vec3::new(0.0, 0.0, 0.0),
        linear: Vec3::new(0.0, 0.0, 0.0),
    };

    pub fn new(angular: Vec3, linear: Vec3) -> Self {
        Force { angular, linear }
    }

    /// The 6x6 matrix `f ×̄` on `[angular; linear]` motions with `(f ×̄) m = m ×* f`
    /// (Echeandia & Wensing 2021): `[-n× -f×; -f× 0]` for `f = (n, f)`.
    #[inline]
    pub fn bar_cross_matrix(&self) -> super::Mat6 {
        let (n, f) = (super::skew(&self.angular), super::skew(&self.linear));
        let mut x = super::Mat6::zeros();
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-n));
        x.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-f));
        x.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-f));
        x
    }

    /// The Plücker 6-vector `[angular; linear]` (moment; force).
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

    /// Inverse of [`Force::to_vector`].
    #[inline]
    pub fn from_vector(f: &nalgebra::Vector6<f64>) -> Self {
        Force::new(Vec3::new(f[0], f[1], f[2]), Vec3::new(f[3], f[4], f[5]))
    }

    /// Flattened `[linear; angular]` (force; moment), robodyn's public order.
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

    /// Inverse of [`Force::to_array`].
    #[inline]
    pub fn from_array(values: &[f64; 6]) -> Self {
        Force {
            linear: Vec3::new(values[0], values[1], values[2]),
            angular: Vec3::new(values[3], values[4], values[5]),
        }
    }
}

impl Add for Force {
    type Output = Force;
    #[inline]
    fn add(self, rhs: Force) -> Force {
        Force::new(self.angular + rhs.angular, self.linear + rhs.linear)
    }
}

impl AddAssign for Force {
    #[inline]
    fn add_assign(&mut self, rhs: Force) {
        self.angular += rhs.angular;
        self.linear += rhs.linear;
    }
}

impl Sub for Force {
    type Output = Force;
    #[inline]
    fn sub(self, rhs: Force) -> Force {
        Force::new(self.angular - rhs.angular, self.linear - rhs.linear)
    }
}

impl SubAssign for Force {
    #[inline]
    fn sub_assign(&mut self, rhs: Force) {
        self.angular -= rhs.angular;
        self.linear -= rhs.linear;
    }
}

impl Neg for Force {
    type Output = Force;
    #[inline]
    fn neg(self) -> Force {
        Force::new(-self.angular, -self.linear)
    }
}

impl Mul<f64> for Force {
    type Output = Force;
    #[inline]
    fn mul(self, s: f64) -> Force {
        Force::new(self.angular * s, self.linear * s)
    }
}
