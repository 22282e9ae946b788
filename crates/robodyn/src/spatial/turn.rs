//! Products with a rotation that turns about one coordinate axis only.
//!
//! A revolute joint about ±e_k whose tree transform `X_T` does not rotate gives
//! `X_up = X_J X_T` a rotation `E` with `E_kk = 1` and the rest of row and column k zero (exactly:
//! `Transform::rotated_about_axis` writes them from the identity's). A product with such an `E`
//! needs only the 2x2 block on the other two coordinates: 4 products instead of 9 for a vector,
//! 12 instead of 27 for a matrix. Leaving out products with an exact zero leaves the value as it
//! was (x + 0·y = x; two terms add the same in either order), so a transform gives the same
//! result by either path.

use super::{compose, compose_transposed, rotate, rotate_back, Real};
use nalgebra::{Matrix3, Vector3};

/// How a transform's rotation is applied: any rotation, or one about a coordinate axis only.
pub(crate) trait Rotation {
    /// `E v`.
    fn rotate<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S>;
    /// `Eᵀ v`.
    fn rotate_back<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S>;
    /// `Eᵀ M E`.
    fn rotated<S: Real>(e: &Matrix3<S>, m: &Matrix3<S>) -> Matrix3<S>;
    /// `E M`.
    fn compose<S: Real>(e: &Matrix3<S>, m: &Matrix3<S>) -> Matrix3<S>;
}

/// Any rotation.
pub(crate) struct AnyRotation;

impl Rotation for AnyRotation {
    #[inline(always)]
    fn rotate<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
        rotate(e, v)
    }

    #[inline(always)]
    fn rotate_back<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
        rotate_back(e, v)
    }

    #[inline(always)]
    fn rotated<S: Real>(e: &Matrix3<S>, m: &Matrix3<S>) -> Matrix3<S> {
        compose_transposed(e, &compose(m, e))
    }

    #[inline(always)]
    fn compose<S: Real>(e: &Matrix3<S>, m: &Matrix3<S>) -> Matrix3<S> {
        compose(e, m)
    }
}

/// A rotation about coordinate axis `K` only.
pub(crate) struct TurnAbout<const K: usize>;

impl<const K: usize> TurnAbout<K> {
    /// The two coordinates the turn mixes.
    const FIRST: usize = (K + 1) % 3;
    const SECOND: usize = (K + 2) % 3;

    /// The turn by the angle of sine `s` and cosine `c` as a joint's `E_J`: rows `[c s; −s c]`
    /// on the two other coordinates (as `Transform::from_axis_angle` gives), 1 on axis K.
    #[inline(always)]
    pub(crate) fn matrix<S: Real>(s: S, c: S) -> Matrix3<S> {
        let (f, second) = (Self::FIRST, Self::SECOND);
        super::matrix3(|row, col| match (row, col) {
            (r, k) if r == K && k == K => S::one(),
            (r, k) if r == f && k == f => c,
            (r, k) if r == f && k == second => s,
            (r, k) if r == second && k == f => -s,
            (r, k) if r == second && k == second => c,
            _ => S::zero(),
        })
    }
}

impl<const K: usize> Rotation for TurnAbout<K> {
    #[inline(always)]
    fn rotate<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
        let (f, s) = (Self::FIRST, Self::SECOND);
        // (E v)_K = v_K
        let mut out = *v;
        out[f] = e[(f, f)] * v[f] + e[(f, s)] * v[s];
        out[s] = e[(s, f)] * v[f] + e[(s, s)] * v[s];
        out
    }

    #[inline(always)]
    fn rotate_back<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
        // Eᵀ turns about the same axis (the transpose is only other loads once inlined)
        Self::rotate(&e.transpose(), v)
    }

    #[inline(always)]
    fn rotated<S: Real>(e: &Matrix3<S>, m: &Matrix3<S>) -> Matrix3<S> {
        let (f, s) = (Self::FIRST, Self::SECOND);
        // M E: columns f and s turn, column K stays (entry by entry, not by a closure: a
        // closure is not always inlined into a kernel compiled for wider lanes)
        let mut m_e = *m;
        for row in 0..3 {
            m_e[(row, f)] = m[(row, f)] * e[(f, f)] + m[(row, s)] * e[(s, f)];
            m_e[(row, s)] = m[(row, f)] * e[(f, s)] + m[(row, s)] * e[(s, s)];
        }
        // then Eᵀ (M E): rows f and s turn
        let mut out = m_e;
        for col in 0..3 {
            out[(f, col)] = e[(f, f)] * m_e[(f, col)] + e[(s, f)] * m_e[(s, col)];
            out[(s, col)] = e[(f, s)] * m_e[(f, col)] + e[(s, s)] * m_e[(s, col)];
        }
        out
    }

    #[inline(always)]
    fn compose<S: Real>(e: &Matrix3<S>, m: &Matrix3<S>) -> Matrix3<S> {
        let (f, s) = (Self::FIRST, Self::SECOND);
        // row K of M stays, rows f and s turn (entry by entry, as in `rotated`)
        let mut out = *m;
        for col in 0..3 {
            out[(f, col)] = e[(f, f)] * m[(f, col)] + e[(f, s)] * m[(s, col)];
            out[(s, col)] = e[(s, f)] * m[(f, col)] + e[(s, s)] * m[(s, col)];
        }
        out
    }
}

/// `$receiver.$method::<R>(arguments)` with `R` the [`Rotation`] of `turn` (`Some(k)`: about
/// coordinate axis k only; `None`: any).
macro_rules! with_rotation {
    ($turn:expr, $receiver:ident . $method:ident ($($argument:expr),*)) => {{
        use $crate::spatial::turn::{AnyRotation, TurnAbout};
        match $turn {
            Some(0) => $receiver.$method::<TurnAbout<0>>($($argument),*),
            Some(1) => $receiver.$method::<TurnAbout<1>>($($argument),*),
            Some(2) => $receiver.$method::<TurnAbout<2>>($($argument),*),
            _ => $receiver.$method::<AnyRotation>($($argument),*),
        }
    }};
}
pub(crate) use with_rotation;
