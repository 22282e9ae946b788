//! Products with a rotation that turns about one coordinate axis after one that keeps an axis.
//!
//! A revolute joint about ±e_k whose tree transform `X_T` has a rotation `P` whose row k has one
//! nonzero ±1, in some column c, and whose column c has no other (no rotation; quarter turns,
//! what URDF `rpy` multiples of π/2 give, stored exactly by `ModelBuilder::add_body`; a rotation
//! about e_k itself) gives `X_up = X_J X_T` a rotation `E = E_J P` with row k equal to P's row
//! k: one entry ±1 in column c and two exact zeros; the other two rows mix only the other two
//! columns, and have exact zeros in column c ([`Turn`]). A product with such an
//! `E` needs only those entries: 5 products instead of 9 for a vector, 15 instead of 27 for a
//! matrix. Leaving out products with an exact zero leaves the value as it was (x + 0·y = x; two
//! terms add the same in either order, and ±1·x is exact), so a transform gives the same result
//! by either path.

use super::{compose, compose_transposed, rotate, rotate_back, Real};
use nalgebra::{Matrix3, Vector3};

/// How a transform's rotation is applied: any rotation, or one of a [`Turn`]'s pattern.
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

/// Where a transform's rotation `E` has its nonzeros when it turns about coordinate axis `axis`
/// after a rotation that keeps one axis (`spatial::turn`'s header): row `axis` has its one nonzero (±1) in column `column`; the other
/// two rows have theirs in the other two columns. Where `column == axis` that nonzero is +1
/// (no permutation, or one that keeps the axis: then row `axis` is the identity's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Turn {
    /// The joint's axis k: 0, 1, 2 for x, y, z.
    pub axis: usize,
    /// The column of row k's nonzero.
    pub column: usize,
    /// Whether a revolute joint's axis is −e_k (it then turns about e_k by −q).
    pub axis_negative: bool,
    /// Whether the tree transform rotates (else `E = E_J`, the joint's own turn).
    pub tree_rotates: bool,
}

/// A rotation whose row `K` has its one nonzero in column `C` and whose other two rows have
/// theirs in the other two columns ([`Turn`] with `axis = K`, `column = C`).
pub(crate) struct TurnAbout<const K: usize, const C: usize>;

impl<const K: usize, const C: usize> TurnAbout<K, C> {
    /// The two rows the turn mixes.
    const FIRST: usize = (K + 1) % 3;
    const SECOND: usize = (K + 2) % 3;
    /// The two columns they mix.
    const A: usize = (C + 1) % 3;
    const B: usize = (C + 2) % 3;

    /// `E_KC x`, the one nonzero of row K times `x`: `x` itself where `K == C` (a [`Turn`] with
    /// `column == axis` has `E_KK = 1`, so the row is copied, as it was, and a chain of
    /// placements does not wait on a product).
    #[inline(always)]
    fn scaled<S: Real>(e: &Matrix3<S>, x: S) -> S {
        if K == C {
            x
        } else {
            e[(K, C)] * x
        }
    }

    /// The turn by the angle of sine `s` and cosine `c` as a joint's `E_J` (`K == C`): rows
    /// `[c s; −s c]` on the two other coordinates (as `Transform::from_axis_angle` gives), 1 on
    /// axis K.
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

impl<const K: usize, const C: usize> Rotation for TurnAbout<K, C> {
    #[inline(always)]
    fn rotate<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
        let (f, s, a, b) = (Self::FIRST, Self::SECOND, Self::A, Self::B);
        let mut out = *v;
        out[K] = Self::scaled(e, v[C]);
        out[f] = e[(f, a)] * v[a] + e[(f, b)] * v[b];
        out[s] = e[(s, a)] * v[a] + e[(s, b)] * v[b];
        out
    }

    #[inline(always)]
    fn rotate_back<S: Real>(e: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
        // Eᵀ has row C's one nonzero in column K (the transpose is only other loads once inlined)
        TurnAbout::<C, K>::rotate(&e.transpose(), v)
    }

    #[inline(always)]
    fn rotated<S: Real>(e: &Matrix3<S>, m: &Matrix3<S>) -> Matrix3<S> {
        let (f, s, a, b) = (Self::FIRST, Self::SECOND, Self::A, Self::B);
        // M E: column C is column K of M scaled, columns a and b mix columns f and s (entry by
        // entry, not by a closure: a closure is not always inlined into a kernel compiled for
        // wider lanes)
        let mut m_e = *m;
        for row in 0..3 {
            m_e[(row, C)] = Self::scaled(e, m[(row, K)]);
            m_e[(row, a)] = m[(row, f)] * e[(f, a)] + m[(row, s)] * e[(s, a)];
            m_e[(row, b)] = m[(row, f)] * e[(f, b)] + m[(row, s)] * e[(s, b)];
        }
        // then Eᵀ (M E): row C is row K scaled, rows a and b mix rows f and s
        let mut out = m_e;
        for col in 0..3 {
            out[(C, col)] = Self::scaled(e, m_e[(K, col)]);
            out[(a, col)] = e[(f, a)] * m_e[(f, col)] + e[(s, a)] * m_e[(s, col)];
            out[(b, col)] = e[(f, b)] * m_e[(f, col)] + e[(s, b)] * m_e[(s, col)];
        }
        out
    }

    #[inline(always)]
    fn compose<S: Real>(e: &Matrix3<S>, m: &Matrix3<S>) -> Matrix3<S> {
        let (f, s, a, b) = (Self::FIRST, Self::SECOND, Self::A, Self::B);
        // row K is row C of M scaled, rows f and s mix rows a and b (entry by entry, as in
        // `rotated`)
        let mut out = *m;
        for col in 0..3 {
            out[(K, col)] = Self::scaled(e, m[(C, col)]);
            out[(f, col)] = e[(f, a)] * m[(a, col)] + e[(f, b)] * m[(b, col)];
            out[(s, col)] = e[(s, a)] * m[(a, col)] + e[(s, b)] * m[(b, col)];
        }
        out
    }
}

/// The column c of row `row`'s one nonzero (±1) when neither that row nor that column has another
/// nonzero, else `None`: a tree rotation `R` of that shape gives `E_J R` (`E_J` about axis `row`)
/// a [`Turn`]'s pattern. Every signed permutation has it, and so has any rotation about the
/// axis itself (row and column `row` the identity's).
pub(crate) fn lone_column(rotation: &Matrix3<f64>, row: usize) -> Option<usize> {
    let column = (0..3).find(|&c| rotation[(row, c)].abs() == 1.0)?;
    let row_alone = (0..3).all(|c| c == column || rotation[(row, c)] == 0.0);
    let column_alone = (0..3).all(|r| r == row || rotation[(r, column)] == 0.0);
    (row_alone && column_alone).then_some(column)
}

/// `rotation` with every entry rounded to 0 or ±1 when each is within
/// [`SIGNED_PERMUTATION_TOLERANCE`] of one and the result is a signed permutation (a URDF
/// `rpy` of quarter turns gives entries like cos(π/2) = 6e-17, the rounding of π/2, not 0).
pub(crate) fn snapped_signed_permutation(rotation: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let snapped = rotation.map(|x| {
        let rounded = x.round();
        if (x - rounded).abs() <= SIGNED_PERMUTATION_TOLERANCE {
            rounded
        } else {
            x
        }
    });
    // a signed permutation: every row's one ±1 alone in its row and column
    let signed_permutation = (0..3).all(|row| lone_column(&snapped, row).is_some());
    signed_permutation.then(|| snapped.map(|x| x + 0.0))
}

/// How far a rotation's entries may be from 0 and ±1 to be stored as a signed permutation: a few
/// roundings of a product of quarter turns (cos(π/2) in `f64` is 6.1e-17).
pub const SIGNED_PERMUTATION_TOLERANCE: f64 = 1e-14;

/// `match $key` whose arm `$value` runs `$body` with the type `$rotation` the [`Rotation`]
/// `$chosen`: the body compiled once per arm.
macro_rules! match_rotation {
    ($key:expr, $rotation:ident => $body:expr; $($value:pat => $chosen:ty),+ $(,)?) => {
        match $key {
            $($value => {
                type $rotation = $chosen;
                $body
            })+
        }
    };
}
pub(crate) use match_rotation;

/// `$body` with the type `$rotation` the [`Rotation`] of `turn` (`Some`: a [`Turn`]; `None`:
/// any): one choice, then the body compiled for each of the ten.
macro_rules! for_rotation_of {
    ($turn:expr, $rotation:ident => $body:expr) => {{
        use $crate::spatial::turn::{match_rotation, AnyRotation, TurnAbout};
        // one number for the pair, so that the choice is one jump, not a pair compared in turn
        match_rotation!($turn.map_or(9, |turn| 3 * turn.axis + turn.column), $rotation => $body;
            0 => TurnAbout<0, 0>,
            1 => TurnAbout<0, 1>,
            2 => TurnAbout<0, 2>,
            3 => TurnAbout<1, 0>,
            4 => TurnAbout<1, 1>,
            5 => TurnAbout<1, 2>,
            6 => TurnAbout<2, 0>,
            7 => TurnAbout<2, 1>,
            8 => TurnAbout<2, 2>,
            _ => AnyRotation,
        )
    }};
}
pub(crate) use for_rotation_of;

/// `$receiver.$method::<R>(arguments)` with `R` the [`Rotation`] of `turn` ([`for_rotation_of!`]).
macro_rules! with_rotation {
    ($turn:expr, $receiver:ident . $method:ident ($($argument:expr),*)) => {
        $crate::spatial::turn::for_rotation_of!($turn, R => $receiver.$method::<R>($($argument),*))
    };
}
pub(crate) use with_rotation;

/// [`with_rotation!`] for the turns that keep their axis (`column == axis`) only, the others by
/// the general products: for a short product in a chain (the placements'), where ten variants
/// cost more in code than their products save.
macro_rules! with_axis_rotation {
    ($turn:expr, $receiver:ident . $method:ident ($($argument:expr),*)) => {{
        use $crate::spatial::turn::{match_rotation, AnyRotation, TurnAbout};
        let axis = $turn.filter(|turn| turn.column == turn.axis).map(|turn| turn.axis);
        match_rotation!(axis, R => $receiver.$method::<R>($($argument),*);
            Some(0) => TurnAbout<0, 0>,
            Some(1) => TurnAbout<1, 1>,
            Some(2) => TurnAbout<2, 2>,
            _ => AnyRotation,
        )
    }};
}
pub(crate) use with_axis_rotation;
