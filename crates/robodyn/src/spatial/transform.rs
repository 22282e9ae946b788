//! Plücker coordinate transforms (Featherstone §2.8).

use super::turn::{
    for_rotation_of, with_axis_rotation, with_rotation, AnyRotation, Rotation, Turn, TurnAbout,
};
use super::{
    add_blocks, block, cross, matrix3, matrix6, rotate, rotate_back, skew, transposed, Force,
    ForceProduct, ForceStore, Inertia, Mat3, Mat6, Motion, Real, Vec3,
};
use nalgebra::{Matrix3, Matrix6, Vector3};
use std::marker::PhantomData;
use std::ops::Mul;

/// Featherstone's `X = B_X_A`: the coordinate transform from frame A to frame B, stored as the
/// rotation `E` (A axes to B axes) and `r`, the position of B's origin in A coordinates.
/// As a 6x6 matrix on `[angular; linear]` motion vectors, `X = [E 0; -E r× E]`.
///
/// The same object describes the pose of B in A: rotation `Eᵀ`, translation `r`
/// (see [`Transform::from_pose`] and [`Transform::to_homogeneous`]). `S` as for [`Motion`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "S: nalgebra::Scalar + serde::Serialize",
    deserialize = "S: nalgebra::Scalar + serde::Deserialize<'de>"
))]
pub struct Transform<S = f64> {
    /// `E`: rotates A coordinates into B coordinates.
    pub rotation: Matrix3<S>,
    /// `r`: B's origin expressed in A coordinates.
    pub translation: Vector3<S>,
}

impl Default for Transform {
    #[inline]
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    /// The identity: no rotation, no translation.
    pub const IDENTITY: Transform = Transform {
        rotation: Mat3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        translation: Vec3::new(0.0, 0.0, 0.0),
    };
}

impl<S: Real> Transform<S> {
    /// A constant transform (of the model) in every lane.
    #[inline(always)]
    pub fn splat(x: &Transform) -> Self {
        Transform {
            rotation: super::splat_matrix(&x.rotation),
            translation: super::splat_vector(&x.translation),
        }
    }

    /// The transform into a frame B whose axes are `rotation` (columns = B's axes in A) and whose
    /// origin is at `position`, both in A coordinates: `E = rotationᵀ`, `r = position`.
    #[inline(always)]
    pub fn from_pose(rotation: &Matrix3<S>, position: &Vector3<S>) -> Self {
        Transform {
            rotation: rotation.transpose(),
            translation: *position,
        }
    }

    /// Rotation about a unit `axis` by `angle` (a frame rotated by `angle`): by Rodrigues' formula
    /// `R = c 1 + s a× + (1 - c) a aᵀ`, and `E = Rᵀ`.
    #[inline(always)]
    pub fn from_axis_angle(axis: &Vec3, angle: S) -> Self {
        let (s, c) = super::trig::sin_cos(angle);
        Transform::from_axis_sin_cos(axis, s, c)
    }

    /// [`Transform::from_axis_angle`] given the angle's sine `s` and cosine `c`.
    #[inline(always)]
    pub fn from_axis_sin_cos(axis: &Vec3, s: S, c: S) -> Self {
        let t = S::one() - c;
        let a: Vector3<S> = super::splat_vector(axis);
        // E = c 1 - s a× + (1 - c) a aᵀ
        let rotation = Matrix3::new(
            c + t * a.x * a.x,
            t * a.x * a.y + s * a.z,
            t * a.x * a.z - s * a.y,
            t * a.x * a.y - s * a.z,
            c + t * a.y * a.y,
            t * a.y * a.z + s * a.x,
            t * a.x * a.z + s * a.y,
            t * a.y * a.z - s * a.x,
            c + t * a.z * a.z,
        );
        Transform {
            rotation,
            translation: super::zero_vector(),
        }
    }

    /// `X_J X` for `X_J` a rotation about coordinate axis `k` (0, 1, 2 for x, y, z) of this
    /// transform's target frame by the angle of sine `s` and cosine `c`: E' = E_J E turns the two
    /// rows of E other than k (E_J's rows are [c s; −s c] on them, as `from_axis_angle` gives),
    /// r' = r (X_J moves no origin).
    #[inline(always)]
    pub fn rotated_about_axis(&self, k: usize, s: S, c: S) -> Transform<S> {
        // the axis as a constant, so that the rows turned are registers, not indexed stores
        match k {
            0 => self.rotated_about::<0>(s, c),
            1 => self.rotated_about::<1>(s, c),
            _ => self.rotated_about::<2>(s, c),
        }
    }

    /// `E_J`, the rotation about coordinate axis `k` by the angle of sine `s` and cosine `c`, as
    /// [`Transform::rotated_about_axis`] turns by.
    #[inline(always)]
    pub fn rotation_about_axis(k: usize, s: S, c: S) -> Matrix3<S> {
        match k {
            0 => TurnAbout::<0, 0>::matrix(s, c),
            1 => TurnAbout::<1, 1>::matrix(s, c),
            _ => TurnAbout::<2, 2>::matrix(s, c),
        }
    }

    /// [`Transform::rotated_about_axis`] for the axis `K`, given the angle's sine and cosine.
    #[inline(always)]
    fn rotated_about<const K: usize>(&self, s: S, c: S) -> Transform<S> {
        Transform {
            rotation: TurnAbout::<K, K>::compose(&TurnAbout::<K, K>::matrix(s, c), &self.rotation),
            translation: self.translation,
        }
    }

    /// Pure translation: B's origin at `position` in A, axes parallel.
    #[inline(always)]
    pub fn from_translation(position: &Vector3<S>) -> Self {
        Transform {
            rotation: super::splat_matrix(&Mat3::identity()),
            translation: *position,
        }
    }

    /// `X⁻¹ = A_X_B`: `E' = Eᵀ`, `r' = -E r`.
    #[inline(always)]
    pub fn inverse(&self) -> Transform<S> {
        Transform {
            rotation: self.rotation.transpose(),
            translation: -rotate(&self.rotation, &self.translation),
        }
    }

    /// `X m`: `ω' = E ω`, `v' = E (v - r × ω)`.
    #[inline(always)]
    pub fn apply_motion(&self, m: &Motion<S>) -> Motion<S> {
        self.apply_motion_by::<AnyRotation>(m)
    }

    /// [`Transform::apply_motion`] for a rotation of the pattern `turn` (`None`: any; see
    /// [`crate::Model::turn`]): the same value, fewer products.
    #[inline(always)]
    pub fn apply_motion_turned(&self, turn: Option<Turn>, m: &Motion<S>) -> Motion<S> {
        with_rotation!(turn, self.apply_motion_by(m))
    }

    /// `E v`, for a rotation of the pattern `turn` as [`Transform::apply_motion_turned`].
    #[inline(always)]
    pub fn rotate_turned(&self, turn: Option<Turn>, v: &Vector3<S>) -> Vector3<S> {
        for_rotation_of!(turn, R => R::rotate(&self.rotation, v))
    }

    #[inline(always)]
    fn apply_motion_by<R: Rotation>(&self, m: &Motion<S>) -> Motion<S> {
        Motion {
            angular: R::rotate(&self.rotation, &m.angular),
            linear: R::rotate(
                &self.rotation,
                &(m.linear - cross(&self.translation, &m.angular)),
            ),
        }
    }

    /// `X⁻¹ m`: `ω = Eᵀ ω'`, `v = Eᵀ v' + r × ω`.
    #[inline(always)]
    pub fn inverse_apply_motion(&self, m: &Motion<S>) -> Motion<S> {
        let angular = rotate_back(&self.rotation, &m.angular);
        Motion {
            angular,
            linear: rotate_back(&self.rotation, &m.linear) + cross(&self.translation, &angular),
        }
    }

    /// `X* f`: `n' = E (n - r × f)`, `f' = E f`.
    #[inline(always)]
    pub fn apply_force(&self, f: &Force<S>) -> Force<S> {
        Force {
            angular: rotate(
                &self.rotation,
                &(f.angular - cross(&self.translation, &f.linear)),
            ),
            linear: rotate(&self.rotation, &f.linear),
        }
    }

    /// `Xᵀ f` (B forces to A): `f = Eᵀ f'`, `n = Eᵀ n' + r × f`.
    #[inline(always)]
    pub fn transpose_apply_force(&self, f: &Force<S>) -> Force<S> {
        self.transpose_apply_force_by::<AnyRotation>(f)
    }

    /// [`Transform::transpose_apply_force`] for a rotation of the pattern `turn`, as
    /// [`Transform::apply_motion_turned`].
    #[inline(always)]
    pub fn transpose_apply_force_turned(&self, turn: Option<Turn>, f: &Force<S>) -> Force<S> {
        with_rotation!(turn, self.transpose_apply_force_by(f))
    }

    /// [`Transform::transpose_apply_force_turned`] of every force of `forces`, in place.
    #[inline(always)]
    pub fn transpose_apply_forces_turned(&self, turn: Option<Turn>, forces: &mut [Force<S>]) {
        with_rotation!(turn, self.transpose_apply_stored_forces_by(forces))
    }

    #[inline(always)]
    fn transpose_apply_stored_forces_by<R: Rotation>(
        &self,
        forces: &mut (impl ForceStore<S> + ?Sized),
    ) {
        forces.replace_each(&TransposeBy::<S, R>(self, PhantomData));
    }

    #[inline(always)]
    fn transpose_apply_force_by<R: Rotation>(&self, f: &Force<S>) -> Force<S> {
        let linear = R::rotate_back(&self.rotation, &f.linear);
        Force {
            angular: R::rotate_back(&self.rotation, &f.angular) + cross(&self.translation, &linear),
            linear,
        }
    }

    /// `Xᵀ I X` for a symmetric 6x6 inertia on `[angular; linear]` (an articulated-body
    /// inertia, which has no rigid body's structure), by 3x3 blocks instead of two 6x6 products.
    /// With `I = [A B; Bᵀ C]` and `X = diag(E, E) [1 0; -r× 1]`: rotate, `Â = Eᵀ A E`,
    /// `B̂ = Eᵀ B E`, `Ĉ = Eᵀ C E`; then shift, `C' = Ĉ`, `B' = B̂ + r× Ĉ`,
    /// `A' = Â - B̂ r× + r× B̂ᵀ - r× Ĉ r× = Â + P + Pᵀ + r× (r× Ĉ)ᵀ` with `P = r× B̂ᵀ` (as
    /// `(r×)ᵀ = -r×`). `A`, `C` are read from their upper triangles; `A'`, `C'` are computed on
    /// theirs and mirrored, so the result is exactly symmetric.
    #[inline(always)]
    pub fn transpose_apply_matrix(&self, inertia: &Matrix6<S>) -> Matrix6<S> {
        let mut moved = matrix6(|_, _| S::zero());
        self.add_transpose_apply_matrix_by::<AnyRotation>(inertia, &mut moved);
        moved
    }

    /// `sum += Xᵀ I X` ([`Transform::transpose_apply_matrix`]) in place, for a rotation of the
    /// pattern `turn` as [`Transform::apply_motion_turned`]: the articulated inertia a body adds
    /// to its parent's, without a 6x6 matrix built beside the sum and copied.
    #[inline(always)]
    pub fn add_transpose_apply_matrix_turned(
        &self,
        turn: Option<Turn>,
        inertia: &Matrix6<S>,
        sum: &mut Matrix6<S>,
    ) {
        with_rotation!(turn, self.add_transpose_apply_matrix_by(inertia, sum))
    }

    #[inline(always)]
    fn add_transpose_apply_matrix_by<R: Rotation>(
        &self,
        inertia: &Matrix6<S>,
        sum: &mut Matrix6<S>,
    ) {
        let (e, r) = (&self.rotation, &self.translation);
        // Â, Ĉ from the upper triangles of A, C, kept on theirs
        let rotated_symmetric = |m: &Matrix3<S>| upper_mirrored(&R::rotated(e, &upper_mirrored(m)));
        let a = rotated_symmetric(&block(inertia, 0, 0));
        let b = R::rotated(e, &block(inertia, 0, 3));
        let c = rotated_symmetric(&block(inertia, 3, 3));
        let r_c = cross_columns(r, &c);
        let coupling = b + r_c;
        let p = cross_columns(r, &transposed(&b));
        let q = cross_columns(r, &transposed(&r_c));
        let angular =
            symmetric3(|row, col| a[(row, col)] + p[(row, col)] + p[(col, row)] + q[(row, col)]);
        add_blocks(sum, [&angular, &coupling, &transposed(&coupling), &c]);
    }

    /// `Xᵀ I X`: a rigid-body inertia given in B coordinates, expressed in A coordinates.
    #[inline(always)]
    pub fn transpose_apply_inertia(&self, inertia: &Inertia<S>) -> Inertia<S> {
        self.transpose_apply_inertia_by::<AnyRotation>(inertia)
    }

    /// [`Transform::transpose_apply_inertia`] for a rotation of the pattern `turn`, as
    /// [`Transform::apply_motion_turned`].
    #[inline(always)]
    pub fn transpose_apply_inertia_turned(
        &self,
        turn: Option<Turn>,
        inertia: &Inertia<S>,
    ) -> Inertia<S> {
        with_rotation!(turn, self.transpose_apply_inertia_by(inertia))
    }

    #[inline(always)]
    fn transpose_apply_inertia_by<R: Rotation>(&self, inertia: &Inertia<S>) -> Inertia<S> {
        let (e, r, m) = (&self.rotation, &self.translation, inertia.mass);
        // h' = Eᵀ h_B (the first moment in A's axes, about B's origin)
        let h = R::rotate_back(e, &inertia.first_moment);
        // Ī_A = Eᵀ Ī_B E + (2 r·h' + m|r|²) 1 - (r h'ᵀ + h' rᵀ + m r rᵀ)
        //     = Eᵀ Ī_B E + 2 (r·u) 1 - (r uᵀ + u rᵀ)   with u = h' + (m/2) r,
        // symmetric: the upper triangle is computed and mirrored
        let rotated = R::rotated(e, &inertia.rotational);
        let u = h + r * (m * S::splat(0.5));
        let diagonal = S::splat(2.0) * (r.x * u.x + r.y * u.y + r.z * u.z);
        let mut rotational = rotated;
        for row in 0..3 {
            for col in row..3 {
                let shift = r[row] * u[col] + u[row] * r[col];
                let mut value = rotated[(row, col)] - shift;
                if row == col {
                    value += diagonal;
                }
                rotational[(row, col)] = value;
                rotational[(col, row)] = value;
            }
        }
        Inertia {
            mass: m,
            first_moment: h + r * m,
            rotational,
        }
    }
}

impl<S: Real> Transform<S> {
    /// [`Transform::to_homogeneous`] written row by row into `out` (16 values), in `f64` or lanes.
    #[inline(always)]
    pub fn write_homogeneous(&self, out: &mut [S]) {
        let (e, r) = (&self.rotation, &self.translation);
        let (zero, one) = (S::zero(), S::one());
        out[..16].copy_from_slice(&[
            e[(0, 0)],
            e[(1, 0)],
            e[(2, 0)],
            r.x, //
            e[(0, 1)],
            e[(1, 1)],
            e[(2, 1)],
            r.y, //
            e[(0, 2)],
            e[(1, 2)],
            e[(2, 2)],
            r.z, //
            zero,
            zero,
            zero,
            one,
        ]);
    }
}

impl Transform {
    /// [`Transform::transpose_apply_force_turned`] of every force of `forces`, kept in any
    /// layout ([`ForceStore`]) and in `f64` or lanes (a force of `f64x4` components is four
    /// forces, each carried by the same operations as alone), in place: the pattern chosen once
    /// for all of them, and X put in every lane after that choice.
    #[inline(always)]
    pub fn transpose_apply_stored_forces_turned<L: Real>(
        &self,
        turn: Option<Turn>,
        forces: &mut (impl ForceStore<L> + ?Sized),
    ) {
        for_rotation_of!(turn, R => Transform::<L>::splat(self).transpose_apply_stored_forces_by::<R>(forces))
    }
}

impl Transform {
    /// The pose of B in A as a 4x4 homogeneous matrix `[Eᵀ r; 0 1]` (maps B points to A points).
    #[inline]
    pub fn to_homogeneous(&self) -> nalgebra::Matrix4<f64> {
        let mut pose = nalgebra::Matrix4::identity();
        pose.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&self.rotation.transpose());
        pose.fixed_view_mut::<3, 1>(0, 3)
            .copy_from(&self.translation);
        pose
    }

    /// `X` as a 6x6 matrix on `[angular; linear]` motion vectors: `[E 0; -E r× E]`.
    #[inline]
    pub fn to_matrix(&self) -> Mat6 {
        let mut x = Mat6::zeros();
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rotation);
        x.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.rotation);
        x.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(-self.rotation * skew(&self.translation)));
        x
    }
}

/// Composition `C_X_A = C_X_B * B_X_A`: `E = E_cb E_ba`, `r = r_ba + E_baᵀ r_cb`.
impl<S: Real> Mul for Transform<S> {
    type Output = Transform<S>;
    #[inline(always)]
    fn mul(self, rhs: Transform<S>) -> Transform<S> {
        self.compose_by::<AnyRotation>(&rhs)
    }
}

impl<S: Real> Transform<S> {
    /// `self * rhs` for `self`'s rotation of the pattern `turn`, as
    /// [`Transform::apply_motion_turned`].
    #[inline(always)]
    pub fn compose_turned(&self, turn: Option<Turn>, rhs: &Transform<S>) -> Transform<S> {
        with_axis_rotation!(turn, self.compose_by(rhs))
    }

    #[inline(always)]
    fn compose_by<R: Rotation>(&self, rhs: &Transform<S>) -> Transform<S> {
        Transform {
            rotation: R::compose(&self.rotation, &rhs.rotation),
            translation: rhs.translation + rotate_back(&rhs.rotation, &self.translation),
        }
    }
}

/// A symmetric matrix from the upper triangle of `m`.
#[inline(always)]
fn upper_mirrored<S: Real>(m: &Matrix3<S>) -> Matrix3<S> {
    symmetric3(|row, col| m[(row, col)])
}

/// The symmetric 3x3 matrix of `entry(row, col)` evaluated on and above the diagonal.
#[inline(always)]
fn symmetric3<S: Real>(entry: impl Fn(usize, usize) -> S) -> Matrix3<S> {
    let (xx, xy, xz, yy, yz, zz) = (
        entry(0, 0),
        entry(0, 1),
        entry(0, 2),
        entry(1, 1),
        entry(1, 2),
        entry(2, 2),
    );
    Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
}

/// `r× M`, column by column: column j is `r × m_j`.
#[inline(always)]
fn cross_columns<S: Real>(r: &Vector3<S>, m: &Matrix3<S>) -> Matrix3<S> {
    matrix3(|row, col| {
        let (next, last) = ((row + 1) % 3, (row + 2) % 3);
        r[next] * m[(last, col)] - r[last] * m[(next, col)]
    })
}

/// `Xᵀ f` with X's rotation applied as `R`, as a [`ForceProduct`].
struct TransposeBy<'x, S, R>(&'x Transform<S>, PhantomData<R>);

impl<S: Real, R: Rotation> ForceProduct<S> for TransposeBy<'_, S, R> {
    #[inline(always)]
    fn of(&self, f: &Force<S>) -> Force<S> {
        self.0.transpose_apply_force_by::<R>(f)
    }
}
