//! The soft model's cost per group of constraint rows, its forces and its curvature.
//!
//! Reference: MuJoCo's documentation, "Computation", §Soft constraints; E. Todorov, "Convex and
//! analytically-invertible dynamics with contacts and constraints", ICRA 2014. Per group of
//! rows, with `D = 1/R` and `x = J q̈ − a_ref`:
//! ```text
//!   equality rows                             s = ½ D x²                      f = −D x
//!   limits, frictionless and pyramidal rows   s = ½ D x²  where x < 0          f = −D x  (or 0)
//!   friction loss (largest force φ)           Huber: ½ D x² for |x| < R φ,     f = ∓φ beyond
//!                                                    φ|x| − ½ R φ² beyond
//!   elliptic contact (μ, friction f_k)        u₀ = μ x₀, u_k = f_k x_k, N = u₀, T = |u_1…|
//!     N ≥ μ T            (in the cone)        s = 0
//!     μ N + T ≤ 0        (opposite)           s = ½ Σ D_k x_k²
//!     otherwise          (on its surface)     s = ½ D_m (N − μ T)²,  D_m = D₀ / (μ² (1 + μ²))
//! ```
//! The forces are `f = −∂s/∂x`, the curvature `H_s = ∂²s/∂x²` (block diagonal).

use super::rows::{Group, RowKind, Rows};

/// Where [`forces_at`] puts each group's curvature ∂²s/∂x²: stored for the Hessian
/// ([`Curvature`]), taken along one direction for the line search ([`Along`]), or dropped (`()`).
pub(super) trait CurvatureSink {
    /// Row `i`'s cost is its own, with ∂²s/∂x_i² = `d`.
    fn row(&mut self, i: usize, d: f64);
    /// An elliptic contact on its cone's surface.
    fn surface(&mut self, surface: &Surface);
}

impl CurvatureSink for () {
    fn row(&mut self, _: usize, _: f64) {}
    fn surface(&mut self, _: &Surface) {}
}

/// An elliptic contact on its cone's surface, s = ½ D_m h², h = N − μ T:
/// ```text
///   ∇²s = D_m (∇h ∇hᵀ − c diag(f) (I − û ûᵀ) diag(f)),   c = μ h / T,  û = u / T
/// ```
/// on its rows `first..first + len` (û and f on the friction rows 1..len).
#[derive(Debug, Clone, Copy)]
pub(super) struct Surface {
    first: usize,
    len: usize,
    dm: f64,
    gradient: [f64; 6],
    c: f64,
    friction: [f64; 5],
    direction: [f64; 6],
}

impl Surface {
    /// ∇²s as a dense block (its first `len` rows and columns).
    fn block(&self) -> [[f64; 6]; 6] {
        let (g, f, d) = (&self.gradient, &self.friction, &self.direction);
        let mut block = [[0.0; 6]; 6];
        for a in 0..self.len {
            for b in 0..self.len {
                let mut value = g[a] * g[b];
                if a > 0 && b > 0 {
                    let projector = f64::from(u8::from(a == b)) - d[a] * d[b];
                    value -= self.c * f[a - 1] * f[b - 1] * projector;
                }
                block[a][b] = self.dm * value;
            }
        }
        block
    }

    /// yᵀ ∇²s y for y over all rows: D_m ((∇h·y)² − c (|diag(f) y|² − (û·diag(f) y)²)).
    fn along(&self, y: &[f64]) -> f64 {
        let y = &y[self.first..self.first + self.len];
        let slope: f64 = self.gradient.iter().zip(y).map(|(g, y)| g * y).sum();
        let (mut scaled, mut projected) = (0.0, 0.0);
        let friction = self.friction.iter().zip(&self.direction[1..]);
        for ((f, direction), y) in friction.zip(&y[1..]) {
            let fy = f * y;
            scaled += fy * fy;
            projected += direction * fy;
        }
        self.dm * (slope * slope - self.c * (scaled - projected * projected))
    }
}

/// ∂²s/∂x²: one value per active row whose cost is its own, a dense block per elliptic contact
/// on its cone's surface (0 elsewhere).
#[derive(Debug, Clone, Default)]
pub(super) struct Curvature {
    /// (row, ∂²s/∂x_row²).
    pub(super) diagonal: Vec<(usize, f64)>,
    /// (first row, the block: zero past the contact's rows).
    pub(super) blocks: Vec<(usize, [[f64; 6]; 6])>,
}

impl Curvature {
    pub(super) fn clear(&mut self) {
        self.diagonal.clear();
        self.blocks.clear();
    }

    /// The rows that curve and the contacts on their cone's surface (`true`): where H_s is
    /// nonzero, which changes only where a row or a contact changes zone.
    pub(super) fn zones(&self) -> impl Iterator<Item = (usize, bool)> + '_ {
        let rows = self.diagonal.iter().map(|&(i, _)| (i, false));
        rows.chain(self.blocks.iter().map(|&(first, _)| (first, true)))
    }

    /// H_s as a dense matrix over `count` rows.
    #[cfg(test)]
    pub(super) fn dense(&self, count: usize) -> nalgebra::DMatrix<f64> {
        let mut dense = nalgebra::DMatrix::zeros(count, count);
        for &(i, d) in &self.diagonal {
            dense[(i, i)] = d;
        }
        for (first, block) in &self.blocks {
            for a in (0..6).filter(|a| first + a < count) {
                for b in (0..6).filter(|b| first + b < count) {
                    dense[(first + a, first + b)] += block[a][b];
                }
            }
        }
        dense
    }
}

impl CurvatureSink for Curvature {
    fn row(&mut self, i: usize, d: f64) {
        self.diagonal.push((i, d));
    }

    fn surface(&mut self, surface: &Surface) {
        self.blocks.push((surface.first, surface.block()));
    }
}

/// yᵀ H_s y summed over the groups, H_s the curvature where [`forces_at`] was asked.
#[derive(Debug)]
pub(super) struct Along<'a> {
    y: &'a [f64],
    /// The sum so far.
    pub(super) value: f64,
}

impl<'a> Along<'a> {
    pub(super) fn new(y: &'a [f64]) -> Self {
        Along { y, value: 0.0 }
    }
}

impl CurvatureSink for Along<'_> {
    fn row(&mut self, i: usize, d: f64) {
        self.value += d * self.y[i] * self.y[i];
    }

    fn surface(&mut self, surface: &Surface) {
        self.value += surface.along(self.y);
    }
}

/// The forces `f` of every row at `x = J q̈ − a_ref` (`x` per row), into `forces`; the cost `s`
/// is returned. Each group's ∂²s/∂x² goes to `curvature`.
pub(super) fn forces_at(
    rows: &Rows,
    x: &[f64],
    forces: &mut [f64],
    curvature: &mut impl CurvatureSink,
) -> f64 {
    let mut cost = 0.0;
    for group in &rows.groups {
        let range = group.first..group.first + group.len;
        match group.kind {
            RowKind::Equality => {
                for i in range {
                    let d = 1.0 / rows.regulariser[i];
                    forces[i] = -d * x[i];
                    cost += 0.5 * d * x[i] * x[i];
                    curvature.row(i, d);
                }
            }
            RowKind::FrictionDof | RowKind::FrictionTendon => {
                let i = group.first;
                let (r, loss) = (rows.regulariser[i], rows.frictionloss[i]);
                if x[i] <= -r * loss {
                    forces[i] = loss;
                    cost += -0.5 * r * loss * loss - loss * x[i];
                } else if x[i] >= r * loss {
                    forces[i] = -loss;
                    cost += -0.5 * r * loss * loss + loss * x[i];
                } else {
                    forces[i] = -x[i] / r;
                    cost += 0.5 * x[i] * x[i] / r;
                    curvature.row(i, 1.0 / r);
                }
            }
            RowKind::ContactElliptic => {
                cost += elliptic(rows, group, x, forces, curvature);
            }
            _ => {
                for i in range {
                    if x[i] < 0.0 {
                        let d = 1.0 / rows.regulariser[i];
                        forces[i] = -d * x[i];
                        cost += 0.5 * d * x[i] * x[i];
                        curvature.row(i, d);
                    } else {
                        forces[i] = 0.0;
                    }
                }
            }
        }
    }
    cost
}

/// An elliptic contact's forces, cost and curvature (see the module's header).
fn elliptic(
    rows: &Rows,
    group: &Group,
    x: &[f64],
    forces: &mut [f64],
    curvature: &mut impl CurvatureSink,
) -> f64 {
    let (first, len, mu, f) = (group.first, group.len, group.mu, group.friction);
    let normal = mu * x[first];
    let mut u = [0.0; 6];
    for k in 1..len {
        u[k] = f[k - 1] * x[first + k];
    }
    let tangent = u[1..len].iter().map(|u| u * u).sum::<f64>().sqrt();
    // in the cone: no force
    if normal >= mu * tangent || (tangent == 0.0 && normal >= 0.0) {
        forces[first..first + len].fill(0.0);
        return 0.0;
    }
    // opposite the cone: every row a spring
    if mu * normal + tangent <= 0.0 || (tangent == 0.0 && normal < 0.0) {
        let mut cost = 0.0;
        for i in first..first + len {
            let d = 1.0 / rows.regulariser[i];
            forces[i] = -d * x[i];
            cost += 0.5 * d * x[i] * x[i];
            curvature.row(i, d);
        }
        return cost;
    }
    // on the cone's surface: s = ½ D_m h², h = N − μ T, ∇h = (μ, −μ f_k u_k / T)
    let dm = 1.0 / rows.regulariser[first] / (mu * mu * (1.0 + mu * mu));
    let h = normal - mu * tangent;
    forces[first] = -dm * h * mu;
    let mut surface = Surface {
        first,
        len,
        dm,
        gradient: [0.0; 6],
        c: mu * h / tangent,
        friction: f,
        direction: [0.0; 6],
    };
    surface.gradient[0] = mu;
    for k in 1..len {
        forces[first + k] = -forces[first] * u[k] * f[k - 1] / tangent;
        surface.direction[k] = u[k] / tangent;
        surface.gradient[k] = -mu * f[k - 1] * surface.direction[k];
    }
    curvature.surface(&surface);
    0.5 * dm * h * h
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::soft::rows::Group;

    /// Four degrees of freedom under an equality row, a friction-loss row, a limit and an
    /// elliptic contact of three rows (μ = 0.5), J with zeros in it as a robot's has.
    pub(in crate::soft) fn mixed_rows() -> Rows {
        let jacobian = vec![
            0.2, 0.0, 0.5, -0.7, // equality
            0.0, 1.0, 0.0, 0.0, // friction loss
            0.3, 0.0, -1.2, 0.0, // limit
            1.0, 0.5, 0.0, 0.2, // contact normal
            0.0, 0.7, 0.4, -0.3, // first tangent
            0.6, 0.0, 0.9, 0.0, // second tangent
        ];
        let group = |first, len, kind, mu| Group {
            first,
            len,
            kind,
            mu,
            friction: [1.0, 0.8, 0.0, 0.0, 0.0],
        };
        use RowKind::*;
        Rows {
            nv: 4,
            jacobian,
            kind: vec![
                Equality,
                FrictionDof,
                LimitJoint,
                ContactElliptic,
                ContactElliptic,
                ContactElliptic,
            ],
            id: vec![0; 6],
            position: vec![0.0; 6],
            margin: vec![0.0; 6],
            frictionloss: vec![0.0, 0.5, 0.0, 0.0, 0.0, 0.0],
            regulariser: vec![3e-2, 1e-2, 1e-1, 2e-2, 4e-2, 5e-2],
            reference: vec![0.4, 0.1, 2.0, 3.0, -1.0, 0.5],
            groups: vec![
                group(0, 1, Equality, 0.0),
                group(1, 1, FrictionDof, 0.0),
                group(2, 1, LimitJoint, 0.0),
                group(3, 3, ContactElliptic, 0.5),
            ],
            contact_rows: vec![Some(3)],
        }
    }

    #[test]
    fn the_curvature_is_minus_the_forces_derivative() {
        // x on the elliptic cone's surface, the friction row inside its Huber zone, the
        // equality's x positive (it pulls both ways)
        let rows = mixed_rows();
        let x = [0.3, 1e-3, -0.2, -0.3, 0.4, -0.1];
        let mut curvature = Curvature::default();
        let mut forces = [0.0; 6];
        forces_at(&rows, &x, &mut forces, &mut curvature);
        assert_eq!(curvature.blocks.len(), 1, "on the cone's surface");
        let dense = curvature.dense(6);
        // the line search's yᵀ H_s y, taken without the blocks
        let y = [0.7, -1.1, 0.4, 0.9, -0.6, 1.3];
        let mut along = Along::new(&y);
        forces_at(&rows, &x, &mut forces, &mut along);
        let y = nalgebra::DVector::from_column_slice(&y);
        let quadratic = (y.transpose() * &dense * &y)[0];
        assert!((along.value - quadratic).abs() < 1e-12 * quadratic.abs());
        // H_s = −∂f/∂x, by central differences
        let step = 1e-6;
        for k in 0..6 {
            let (mut up, mut down) = (x, x);
            up[k] += step;
            down[k] -= step;
            let (mut f_up, mut f_down) = ([0.0; 6], [0.0; 6]);
            forces_at(&rows, &up, &mut f_up, &mut ());
            forces_at(&rows, &down, &mut f_down, &mut ());
            for i in 0..6 {
                let derivative = -(f_up[i] - f_down[i]) / (2.0 * step);
                let scale = 1.0 + dense[(i, k)].abs();
                assert!(
                    (derivative - dense[(i, k)]).abs() < 1e-6 * scale,
                    "({i}, {k})"
                );
            }
        }
    }
}
