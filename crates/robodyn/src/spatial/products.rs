//! The scalar the spatial algebra computes in ([`Real`]: `f64`, or lanes of a batch) and the small
//! products its kernels use, written out and always inlined so that a batch kernel compiled for
//! wider vector instructions (`algo::lanes`) runs them with those instructions too (nalgebra's
//! generic products, called out of line, would not).

use super::{Force, Mat3, Mat6, Motion, Vec3};
use nalgebra::{Matrix3, Matrix6, SVector, SimdRealField, Vector3};

/// A number the spatial algebra computes in: `f64` for one state, or a lane type holding one
/// `f64` per state of a batch (`simba`'s `AutoSimd<[f64; N]>`), so that one kernel serves both
/// and the same operations run in every lane. Model constants enter by
/// [`simba::simd::SimdValue::splat`].
pub trait Real: SimdRealField<Element = f64> + Copy {
    /// The lanes `(f(0), f(1), ...)`, built in registers (replacing lanes one by one goes
    /// through memory).
    fn from_lanes(f: impl Fn(usize) -> f64) -> Self;

    /// `out[k] = (sin, cos)` of `q[indices[k]]` by [`super::trig::sin_cos`], the same digits
    /// however it is evaluated: `f64` takes four values per evaluation in AVX2 lanes where the CPU
    /// has them ([`super::trig::sin_cos_at`]); lanes, already one value per state, one at a time.
    fn sin_cos_at(q: &[Self], indices: &[usize], out: &mut [(Self, Self)]);
}

impl Real for f64 {
    #[inline(always)]
    fn from_lanes(f: impl Fn(usize) -> f64) -> Self {
        f(0)
    }

    #[inline(always)]
    fn sin_cos_at(q: &[f64], indices: &[usize], out: &mut [(f64, f64)]) {
        super::trig::sin_cos_at(q, indices, out);
    }
}

impl<const N: usize> Real for simba::simd::AutoSimd<[f64; N]>
where
    simba::simd::AutoSimd<[f64; N]>: SimdRealField<Element = f64> + Copy,
{
    #[inline(always)]
    fn from_lanes(f: impl Fn(usize) -> f64) -> Self {
        simba::simd::AutoSimd(std::array::from_fn(f))
    }

    #[inline(always)]
    fn sin_cos_at(q: &[Self], indices: &[usize], out: &mut [(Self, Self)]) {
        super::trig::sin_cos_one_by_one(q, indices, out);
    }
}

/// `−x` where `negative`, else `x`: a component along the unit motion ±e_c (exact).
#[inline(always)]
pub(crate) fn signed<S: Real>(x: S, negative: bool) -> S {
    if negative {
        -x
    } else {
        x
    }
}

/// The skew-symmetric matrix `v×` with `(v×) w = v × w`.
#[inline(always)]
pub fn skew<S: Real>(v: &Vector3<S>) -> Matrix3<S> {
    let zero = S::zero();
    Matrix3::new(zero, -v.z, v.y, v.z, zero, -v.x, -v.y, v.x, zero)
}

/// A constant vector in every lane.
#[inline(always)]
pub fn splat_vector<S: Real>(v: &Vec3) -> Vector3<S> {
    Vector3::new(S::splat(v.x), S::splat(v.y), S::splat(v.z))
}

/// A constant matrix in every lane.
#[inline(always)]
pub fn splat_matrix<S: Real>(m: &Mat3) -> Matrix3<S> {
    matrix3(|r, c| S::splat(m[(r, c)]))
}

/// The 3x3 matrix of `entry(row, column)`.
#[inline(always)]
pub fn matrix3<S: Real>(entry: impl Fn(usize, usize) -> S) -> Matrix3<S> {
    Matrix3::new(
        entry(0, 0),
        entry(0, 1),
        entry(0, 2),
        entry(1, 0),
        entry(1, 1),
        entry(1, 2),
        entry(2, 0),
        entry(2, 1),
        entry(2, 2),
    )
}

/// The zero vector, entry by entry (nalgebra's generic `zeros` compiles poorly for wide lanes).
#[inline(always)]
pub fn zero_vector<S: Real>() -> Vector3<S> {
    let zero = S::splat(0.0);
    Vector3::new(zero, zero, zero)
}

/// `a × b`.
#[inline(always)]
pub fn cross<S: Real>(a: &Vector3<S>, b: &Vector3<S>) -> Vector3<S> {
    Vector3::new(
        a.y * b.z - a.z * b.y,
        a.z * b.x - a.x * b.z,
        a.x * b.y - a.y * b.x,
    )
}

/// `a · b`, summed in order (the same operations in `f64` and in lanes, inlined where a lane
/// kernel is compiled).
#[inline(always)]
pub fn dot<S: Real, const N: usize>(a: &SVector<S, N>, b: &SVector<S, N>) -> S {
    let mut sum = a[0] * b[0];
    for k in 1..N {
        sum += a[k] * b[k];
    }
    sum
}

/// `E v`.
#[inline(always)]
pub fn rotate<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
    let row = |r: usize| e[(r, 0)] * v.x + e[(r, 1)] * v.y + e[(r, 2)] * v.z;
    Vector3::new(row(0), row(1), row(2))
}

/// `Eᵀ v`.
#[inline(always)]
pub fn rotate_back<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
    let column = |c: usize| e[(0, c)] * v.x + e[(1, c)] * v.y + e[(2, c)] * v.z;
    Vector3::new(column(0), column(1), column(2))
}

/// `A B`.
#[inline(always)]
pub fn compose<S: Real>(a: &Matrix3<S>, b: &Matrix3<S>) -> Matrix3<S> {
    matrix3(|r, c| a[(r, 0)] * b[(0, c)] + a[(r, 1)] * b[(1, c)] + a[(r, 2)] * b[(2, c)])
}

/// `Aᵀ B`.
#[inline(always)]
pub fn compose_transposed<S: Real>(a: &Matrix3<S>, b: &Matrix3<S>) -> Matrix3<S> {
    matrix3(|r, c| a[(0, r)] * b[(0, c)] + a[(1, r)] * b[(1, c)] + a[(2, r)] * b[(2, c)])
}

/// `Aᵀ`.
#[inline(always)]
pub fn transposed<S: Real>(a: &Matrix3<S>) -> Matrix3<S> {
    matrix3(|r, c| a[(c, r)])
}

/// The 3x3 block of `m` from (`row`, `col`).
#[inline(always)]
pub fn block<S: Real>(m: &Matrix6<S>, row: usize, col: usize) -> Matrix3<S> {
    matrix3(|r, c| m[(row + r, col + c)])
}

/// `sum += [a b; c d]`, entry by entry in place (no 6x6 matrix built beside `sum` and copied).
#[inline(always)]
pub fn add_blocks<S: Real>(sum: &mut Matrix6<S>, [a, b, c, d]: [&Matrix3<S>; 4]) {
    update_matrix6(sum, |row, col, old| {
        old + match (row < 3, col < 3) {
            (true, true) => a[(row, col)],
            (true, false) => b[(row, col - 3)],
            (false, true) => c[(row - 3, col)],
            (false, false) => d[(row - 3, col - 3)],
        }
    })
}

/// A constant 6x6 matrix in every lane.
#[inline(always)]
pub fn splat_matrix6<S: Real>(m: &Mat6) -> Matrix6<S> {
    matrix6(|r, c| S::splat(m[(r, c)]))
}

/// Each entry of `m` replaced by `entry(row, column, its value)`, column by column in place.
#[inline(always)]
pub fn update_matrix6<S: Real>(m: &mut Matrix6<S>, entry: impl Fn(usize, usize, S) -> S) {
    for col in 0..6 {
        for row in 0..6 {
            m[(row, col)] = entry(row, col, m[(row, col)]);
        }
    }
}

/// The 6x6 matrix of `entry(row, column)`, built column by column in place.
#[inline(always)]
pub fn matrix6<S: Real>(entry: impl Fn(usize, usize) -> S) -> Matrix6<S> {
    let columns: [[S; 6]; 6] = std::array::from_fn(|c| std::array::from_fn(|r| entry(r, c)));
    Matrix6::from_data(nalgebra::ArrayStorage(columns))
}

/// `f = I m` for a general (articulated-body) 6x6 inertia on `[angular; linear]`.
#[inline(always)]
pub fn mat6_mul_motion<S: Real>(inertia: &Matrix6<S>, m: &Motion<S>) -> Force<S> {
    let x = [
        m.angular.x,
        m.angular.y,
        m.angular.z,
        m.linear.x,
        m.linear.y,
        m.linear.z,
    ];
    let mut rows = [S::splat(0.0); 6];
    for (r, row) in rows.iter_mut().enumerate() {
        *row = inertia[(r, 0)] * x[0]
            + inertia[(r, 1)] * x[1]
            + inertia[(r, 2)] * x[2]
            + inertia[(r, 3)] * x[3]
            + inertia[(r, 4)] * x[4]
            + inertia[(r, 5)] * x[5];
    }
    Force::from_plucker(rows)
}
