//! Spatial force vectors (wrenches, momenta).

use super::{Real, Vec3};
use nalgebra::Vector3;
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

/// A spatial force `f = (n_O, f)`: the moment about the frame's origin and the linear force, both
/// in the frame's axes (Featherstone §2.4). `S` as for [`super::Motion`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Force<S = f64> {
    /// The moment `n_O` about the frame's origin.
    pub angular: Vector3<S>,
    /// The linear force `f`.
    pub linear: Vector3<S>,
}

impl<S: Real> Force<S> {
    /// The force with moment `angular` and linear force `linear`.
    #[inline(always)]
    pub fn new(angular: Vector3<S>, linear: Vector3<S>) -> Self {
        Force { angular, linear }
    }

    /// The Plücker coordinates `[angular; linear]` (moment; force).
    #[inline(always)]
    pub fn plucker(&self) -> [S; 6] {
        let (n, f) = (&self.angular, &self.linear);
        [n.x, n.y, n.z, f.x, f.y, f.z]
    }

    /// Inverse of [`Force::plucker`]: the force of Plücker coordinates `[angular; linear]`.
    #[inline(always)]
    pub fn from_plucker(values: [S; 6]) -> Self {
        let [nx, ny, nz, fx, fy, fz] = values;
        Force::new(Vector3::new(nx, ny, nz), Vector3::new(fx, fy, fz))
    }

    /// Component `index` of [`Force::plucker`].
    #[inline(always)]
    pub fn component(&self, index: usize) -> S {
        match index {
            0..3 => self.angular[index],
            _ => self.linear[index - 3],
        }
    }

    /// A constant force in every lane.
    #[inline(always)]
    pub fn splat(f: &Force) -> Self {
        Force::new(
            super::splat_vector(&f.angular),
            super::splat_vector(&f.linear),
        )
    }
}

impl Default for Force {
    #[inline(always)]
    fn default() -> Self {
        Force::ZERO
    }
}

impl Force {
    /// The zero force.
    pub const ZERO: Force = Force {
        angular: Vec3::new(0.0, 0.0, 0.0),
        linear: Vec3::new(0.0, 0.0, 0.0),
    };

    /// The 6x6 matrix `f ×̄` on `[angular; linear]` motions with `(f ×̄) m = m ×* f`
    /// (Echeandia & Wensing 2021): `[-n× -f×; -f× 0]` for `f = (n, f)`.
    #[inline(always)]
    pub fn bar_cross_matrix(&self) -> super::Mat6 {
        let (n, f) = (super::skew(&self.angular), super::skew(&self.linear));
        let mut x = super::Mat6::zeros();
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-n));
        x.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-f));
        x.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-f));
        x
    }

    /// The Plücker 6-vector `[angular; linear]` (moment; force).
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

    /// Inverse of [`Force::to_vector`].
    #[inline(always)]
    pub fn from_vector(f: &nalgebra::Vector6<f64>) -> Self {
        Force::from_plucker([f[0], f[1], f[2], f[3], f[4], f[5]])
    }

    /// Flattened `[linear; angular]` (force; moment), robodyn's public order.
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

    /// Inverse of [`Force::to_array`].
    #[inline(always)]
    pub fn from_array(values: &[f64; 6]) -> Self {
        Force {
            linear: Vec3::new(values[0], values[1], values[2]),
            angular: Vec3::new(values[3], values[4], values[5]),
        }
    }
}

impl<S: Real> Add for Force<S> {
    type Output = Force<S>;
    #[inline(always)]
    fn add(self, rhs: Force<S>) -> Force<S> {
        Force::new(self.angular + rhs.angular, self.linear + rhs.linear)
    }
}

impl<S: Real> AddAssign for Force<S> {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Force<S>) {
        self.angular += rhs.angular;
        self.linear += rhs.linear;
    }
}

impl<S: Real> Sub for Force<S> {
    type Output = Force<S>;
    #[inline(always)]
    fn sub(self, rhs: Force<S>) -> Force<S> {
        Force::new(self.angular - rhs.angular, self.linear - rhs.linear)
    }
}

impl<S: Real> SubAssign for Force<S> {
    #[inline(always)]
    fn sub_assign(&mut self, rhs: Force<S>) {
        self.angular -= rhs.angular;
        self.linear -= rhs.linear;
    }
}

impl<S: Real> Neg for Force<S> {
    type Output = Force<S>;
    #[inline(always)]
    fn neg(self) -> Force<S> {
        Force::new(-self.angular, -self.linear)
    }
}

impl<S: Real> Mul<S> for Force<S> {
    type Output = Force<S>;
    #[inline(always)]
    fn mul(self, s: S) -> Force<S> {
        Force::new(self.angular * s, self.linear * s)
    }
}

/// Forces kept in any layout, each replaced by a product of it in place: what
/// [`super::Transform::transpose_apply_stored_forces_turned`] carries.
pub trait ForceStore<S> {
    /// Every force `f` replaced by `product.of(f)`.
    fn replace_each(&mut self, product: &impl ForceProduct<S>);
}

/// A product that takes a force to a force (`Xᵀ f`, say), applied by [`ForceStore::replace_each`].
pub trait ForceProduct<S> {
    /// The product of `f`.
    fn of(&self, f: &Force<S>) -> Force<S>;
}

impl<S: Real> ForceStore<S> for [Force<S>] {
    #[inline(always)]
    fn replace_each(&mut self, product: &impl ForceProduct<S>) {
        for f in self {
            *f = product.of(f);
        }
    }
}
