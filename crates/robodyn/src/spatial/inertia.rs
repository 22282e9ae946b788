//! Rigid-body spatial inertia (Featherstone §2.13).

use super::{
    cross, rotate, skew, splat_matrix, splat_vector, update_matrix6, Force, Mat3, Mat6, Motion,
    Real, Vec3,
};
use nalgebra::{Matrix3, Matrix6, Vector3};
use std::ops::{Add, AddAssign};

/// The spatial inertia of a rigid body about a frame's origin, stored as the mass `m`, the first
/// moment `h = m c` (c: centre of mass) and the rotational inertia `Ī_O` about the origin, all in
/// the frame's axes. As a 6x6 matrix on `[angular; linear]`: `I = [Ī_O  h×; h×ᵀ  m 1]`.
/// `S` as for [`Motion`]: a model's inertias are `f64`; composites that depend on q can be lanes.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "S: nalgebra::Scalar + serde::Serialize",
    deserialize = "S: nalgebra::Scalar + serde::Deserialize<'de>"
))]
pub struct Inertia<S = f64> {
    /// The body's mass `m` (kg).
    pub mass: S,
    /// `h = m c`.
    pub first_moment: Vector3<S>,
    /// `Ī_O = I_C + m (c·c 1 - c cᵀ)`, the rotational inertia about the frame's origin.
    pub rotational: Matrix3<S>,
}

impl<S: Real> Inertia<S> {
    /// A constant inertia (of the model) in every lane.
    #[inline(always)]
    pub fn splat(inertia: &Inertia) -> Self {
        Inertia {
            mass: S::splat(inertia.mass),
            first_moment: splat_vector(&inertia.first_moment),
            rotational: splat_matrix(&inertia.rotational),
        }
    }

    /// `f = I m`: `n = Ī_O ω + h × v`, `f = m v - h × ω`.
    #[inline(always)]
    pub fn mul_motion(&self, m: &Motion<S>) -> Force<S> {
        Force {
            angular: rotate(&self.rotational, &m.angular) + cross(&self.first_moment, &m.linear),
            linear: m.linear * self.mass - cross(&self.first_moment, &m.angular),
        }
    }

    /// `f = I [0; v]`, a motion with no angular part: `n = h × v`, `f = m v` (the value of
    /// [`Inertia::mul_motion`] without the products with the zeros).
    #[inline(always)]
    pub fn mul_linear_motion(&self, v: &Vector3<S>) -> Force<S> {
        Force {
            angular: cross(&self.first_moment, v),
            linear: v * self.mass,
        }
    }

    /// `f = I u` for `u` the unit motion ±e_c (c in [`Force::plucker`]'s order; `negative`: −):
    /// column c of the 6x6 matrix, read off without products. About axis c < 3:
    /// `n = Ī_O e_c`, `f = e_c × h`; along axis j = c − 3: `n = h × e_j`, `f = m e_j`.
    #[inline(always)]
    pub fn mul_unit_motion(&self, c: usize, negative: bool) -> Force<S> {
        let (h, zero) = (&self.first_moment, S::zero());
        // e_j × h
        let unit_cross = |j: usize| match j {
            0 => Vector3::new(zero, -h.z, h.y),
            1 => Vector3::new(h.z, zero, -h.x),
            _ => Vector3::new(-h.y, h.x, zero),
        };
        let force = if c < 3 {
            Force::new(self.rotational.column(c).into_owned(), unit_cross(c))
        } else {
            let mut linear = Vector3::from_element(zero);
            linear[c - 3] = self.mass;
            Force::new(-unit_cross(c - 3), linear)
        };
        if negative {
            -force
        } else {
            force
        }
    }
}

impl Default for Inertia {
    #[inline]
    fn default() -> Self {
        Inertia::ZERO
    }
}

impl Inertia {
    /// The inertia of nothing: zero mass, first moment and rotational inertia.
    pub const ZERO: Inertia = Inertia {
        mass: 0.0,
        first_moment: Vec3::new(0.0, 0.0, 0.0),
        rotational: Mat3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };

    /// From the mass, the centre of mass `com` and the rotational inertia `inertia_com` about the
    /// centre of mass (parallel-axis theorem: `Ī_O = I_C + m (c·c 1 - c cᵀ)`).
    #[inline]
    pub fn from_com(mass: f64, com: &Vec3, inertia_com: &Mat3) -> Self {
        Inertia {
            mass,
            first_moment: com * mass,
            rotational: inertia_com
                + (Mat3::identity() * com.norm_squared() - com * com.transpose()) * mass,
        }
    }

    /// The centre of mass `c = h / m` (the origin for a massless body).
    #[inline]
    pub fn com(&self) -> Vec3 {
        if self.mass > 0.0 {
            self.first_moment / self.mass
        } else {
            Vec3::zeros()
        }
    }

    /// [`Inertia::to_matrix`] in every lane of `out`, written in place (no matrix built beside
    /// `out` and copied: at eight lanes a 6x6 matrix is 2304 bytes).
    #[inline(always)]
    pub fn splat_matrix_into<S: Real>(&self, out: &mut Matrix6<S>) {
        let h = skew(&self.first_moment);
        update_matrix6(out, |row, col, _| {
            S::splat(match (row < 3, col < 3) {
                (true, true) => self.rotational[(row, col)],
                (true, false) => h[(row, col - 3)],
                (false, true) => h[(col, row - 3)],
                (false, false) if row == col => self.mass,
                (false, false) => 0.0,
            })
        })
    }

    /// The 6x6 matrix on `[angular; linear]`: `[Ī_O  h×; h×ᵀ  m 1]`.
    #[inline]
    pub fn to_matrix(&self) -> Mat6 {
        let mut i = Mat6::zeros();
        self.splat_matrix_into(&mut i);
        i
    }
}

impl Inertia {
    /// The ten standard inertial parameters π = [m, h_x, h_y, h_z, Ī_xx, Ī_xy, Ī_yy, Ī_xz, Ī_yz,
    /// Ī_zz] (h = m c, Ī about the frame's origin), the order of Atkeson, An and Hollerbach (1986)
    /// that Pinocchio's dynamic parameters also use.
    pub fn to_parameters(&self) -> [f64; 10] {
        let (h, i) = (&self.first_moment, &self.rotational);
        [
            self.mass,
            h.x,
            h.y,
            h.z,
            i[(0, 0)],
            i[(0, 1)],
            i[(1, 1)],
            i[(0, 2)],
            i[(1, 2)],
            i[(2, 2)],
        ]
    }

    /// The inertia of the ten standard parameters (see [`Inertia::to_parameters`]).
    pub fn from_parameters(p: &[f64; 10]) -> Self {
        Inertia {
            mass: p[0],
            first_moment: Vec3::new(p[1], p[2], p[3]),
            rotational: Mat3::new(p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9]),
        }
    }

    /// The columns of f = I a + v ×* I v as a linear map of the ten parameters: f = Σ_k π_k
    /// F_k(v, a). With v = (ω, u), a = (ω̇, u̇) on `[angular; linear]` (Atkeson, An and
    /// Hollerbach 1986, with the Jacobi identity `[u]×[ω]× − [ω]×[u]× = [u × ω]×`):
    /// - m: `n = 0`, `f = u̇ + ω × u`;
    /// - h: `n = −[u̇ + ω × u]× h`, `f = ([ω̇]× + [ω]×[ω]×) h`;
    /// - Ī: `n = L(ω̇) + [ω]× L(ω)`, `f = 0`, with
    ///   `Ī w = L(w) [Ī_xx, Ī_xy, Ī_yy, Ī_xz, Ī_yz, Ī_zz]`.
    pub fn force_regressor(v: &Motion, a: &Motion) -> [Force; 10] {
        let (w, u) = (&v.angular, &v.linear);
        let linear_acceleration = a.linear + w.cross(u);
        let mut columns = [Force::ZERO; 10];
        columns[0].linear = linear_acceleration;
        for (k, e) in [Vec3::x(), Vec3::y(), Vec3::z()].iter().enumerate() {
            columns[1 + k] = Force {
                angular: -linear_acceleration.cross(e),
                linear: a.angular.cross(e) + w.cross(&w.cross(e)),
            };
        }
        // L(w) column by column: the unit tensors of Ī_xx, Ī_xy, Ī_yy, Ī_xz, Ī_yz, Ī_zz
        for (k, (r, c)) in [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)]
            .into_iter()
            .enumerate()
        {
            let mut unit = Mat3::zeros();
            unit[(r, c)] = 1.0;
            unit[(c, r)] = 1.0;
            columns[4 + k].angular = unit * a.angular + w.cross(&(unit * w));
        }
        columns
    }
}

impl Inertia {
    /// The body's Coriolis factor `B(I, v) = ½[(v×*) I + (I v)×̄ − I (v×)]` (Echeandia & Wensing
    /// 2021, eq. 19) on `[angular; linear]`: `B v = v ×* I v` gives the body's velocity-product
    /// force, and `İ − 2B = −(I v)×̄` is skew-symmetric, so the joint-space C it assembles makes
    /// `Ṁ − 2C` skew-symmetric. `v` and `self` in the same coordinates.
    pub fn coriolis_factor(&self, v: &Motion) -> Mat6 {
        let inertia = self.to_matrix();
        let v_cross = v.cross_matrix();
        // v×* = −(v×)ᵀ
        let force_cross = -v_cross.transpose();
        (force_cross * inertia + self.mul_motion(v).bar_cross_matrix() - inertia * v_cross) * 0.5
    }
}

/// `H(I, v) = 2 B(I, v)` of one body, or summed over a subtree, in the fifteen numbers it takes.
/// With `A = (v×*) I`, `2B = A + Aᵀ + (I v)×̄`; writing `v = (ω, u)` and `h = m c` (same axes),
/// ```text
///   A + Aᵀ = [S  p×; −p×  0],   S = ω×Ī − Īω× − (h uᵀ + u hᵀ) + 2 (u·h) 1,   p = ω × h + m u
/// ```
/// (the block algebra of Featherstone §2.13 with `a×b× = b aᵀ − (a·b) 1` and
/// `ω×h× − h×ω× = (ω × h)×`), so `H s = (A + Aᵀ) s + s ×* I v` and, `(I v)×̄` being skew,
/// `Hᵀ s = (A + Aᵀ) s − s ×* I v`. Every part is linear in the body, so a subtree's H is the sum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoriolisFactor<S = f64> {
    /// `S`, symmetric.
    pub rotational: Matrix3<S>,
    /// `p = ω × h + m u`.
    pub coupling: Vector3<S>,
    /// `I v`, the momentum.
    pub momentum: Force<S>,
}

impl CoriolisFactor {
    /// The factor of a zero inertia or a body at rest: all parts zero.
    pub const ZERO: CoriolisFactor = CoriolisFactor {
        rotational: Mat3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        coupling: Vec3::new(0.0, 0.0, 0.0),
        momentum: Force::ZERO,
    };
}

impl<S: Real> CoriolisFactor<S> {
    /// A constant factor in every lane.
    #[inline(always)]
    pub fn splat(factor: &CoriolisFactor) -> Self {
        CoriolisFactor {
            rotational: splat_matrix(&factor.rotational),
            coupling: splat_vector(&factor.coupling),
            momentum: Force::splat(&factor.momentum),
        }
    }

    /// `H(I, v)` of a body of inertia `inertia` moving with `v` (both in the same coordinates).
    #[inline(always)]
    pub fn new(inertia: &Inertia<S>, v: &Motion<S>) -> Self {
        let (w, u, h) = (&v.angular, &v.linear, &inertia.first_moment);
        // ω×Ī column by column, C; ω×Ī − Īω× = C + Cᵀ
        let i = &inertia.rotational;
        let columns = [
            cross(w, &Vector3::new(i[(0, 0)], i[(1, 0)], i[(2, 0)])),
            cross(w, &Vector3::new(i[(0, 1)], i[(1, 1)], i[(2, 1)])),
            cross(w, &Vector3::new(i[(0, 2)], i[(1, 2)], i[(2, 2)])),
        ];
        let diagonal = S::splat(2.0) * (u.x * h.x + u.y * h.y + u.z * h.z);
        // symmetric: the upper triangle, mirrored
        let mut rotational = *i;
        for r in 0..3 {
            for c in r..3 {
                let mut value = columns[c][r] + columns[r][c] - (h[r] * u[c] + u[r] * h[c]);
                if r == c {
                    value += diagonal;
                }
                rotational[(r, c)] = value;
                rotational[(c, r)] = value;
            }
        }
        CoriolisFactor {
            rotational,
            coupling: cross(w, h) + u * inertia.mass,
            momentum: inertia.mul_motion(v),
        }
    }

    /// `(A + Aᵀ) s = [S s_ω + p × s_u; −p × s_ω]`.
    #[inline(always)]
    fn symmetric_mul_motion(&self, s: &Motion<S>) -> Force<S> {
        Force {
            angular: rotate(&self.rotational, &s.angular) + cross(&self.coupling, &s.linear),
            linear: cross(&s.angular, &self.coupling),
        }
    }

    /// `H s`.
    #[inline(always)]
    pub fn mul_motion(&self, s: &Motion<S>) -> Force<S> {
        self.symmetric_mul_motion(s) + s.cross_force(&self.momentum)
    }

    /// `Hᵀ s`.
    #[inline(always)]
    pub fn tr_mul_motion(&self, s: &Motion<S>) -> Force<S> {
        self.symmetric_mul_motion(s) - s.cross_force(&self.momentum)
    }
}

impl<S: Real> AddAssign for CoriolisFactor<S> {
    #[inline(always)]
    fn add_assign(&mut self, rhs: CoriolisFactor<S>) {
        self.rotational += rhs.rotational;
        self.coupling += rhs.coupling;
        self.momentum += rhs.momentum;
    }
}

impl<S: Real> Add for Inertia<S> {
    type Output = Inertia<S>;
    #[inline(always)]
    fn add(self, rhs: Inertia<S>) -> Inertia<S> {
        Inertia {
            mass: self.mass + rhs.mass,
            first_moment: self.first_moment + rhs.first_moment,
            rotational: self.rotational + rhs.rotational,
        }
    }
}

impl<S: Real> AddAssign for Inertia<S> {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Inertia<S>) {
        *self = *self + rhs;
    }
}
