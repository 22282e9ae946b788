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

/// ∂²s/∂x²: one value per active row whose cost is its own, a dense block per elliptic contact
/// on its cone's surface (0 elsewhere).
#[derive(Debug, Clone, Default)]
pub(super) struct Curvature {
    /// (row, ∂²s/∂x_row²).
    pub(super) diagonal: Vec<(usize, f64)>,
    /// (first row, rows, the block).
    pub(super) blocks: Vec<(usize, usize, [[f64; 6]; 6])>,
}

impl Curvature {
    pub(super) fn clear(&mut self) {
        self.diagonal.clear();
        self.blocks.clear();
    }

    /// yᵀ H_s y.
    pub(super) fn along(&self, y: &[f64]) -> f64 {
        let diagonal: f64 = self.diagonal.iter().map(|&(i, d)| d * y[i] * y[i]).sum();
        let blocks: f64 = self
            .blocks
            .iter()
            .map(|(first, len, block)| {
                let y = &y[*first..first + len];
                (0..*len)
                    .map(|a| (0..*len).map(|b| y[a] * block[a][b] * y[b]).sum::<f64>())
                    .sum::<f64>()
            })
            .sum();
        diagonal + blocks
    }
}

/// The forces `f` of every row at `x = J q̈ − a_ref` (`x` per row), into `forces`; the cost `s`
/// is returned. With `curvature`, each group's ∂²s/∂x² goes into it.
pub(super) fn forces_at(
    rows: &Rows,
    x: &[f64],
    forces: &mut [f64],
    mut curvature: Option<&mut Curvature>,
) -> f64 {
    if let Some(c) = curvature.as_deref_mut() {
        c.clear();
    }
    let mut cost = 0.0;
    for group in &rows.groups {
        let range = group.first..group.first + group.len;
        match group.kind {
            RowKind::Equality => {
                for i in range {
                    let d = 1.0 / rows.regulariser[i];
                    forces[i] = -d * x[i];
                    cost += 0.5 * d * x[i] * x[i];
                    if let Some(c) = curvature.as_deref_mut() {
                        c.diagonal.push((i, d));
                    }
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
                    if let Some(c) = curvature.as_deref_mut() {
                        c.diagonal.push((i, 1.0 / r));
                    }
                }
            }
            RowKind::ContactElliptic => {
                cost += elliptic(rows, group, x, forces, curvature.as_deref_mut());
            }
            _ => {
                for i in range {
                    if x[i] < 0.0 {
                        let d = 1.0 / rows.regulariser[i];
                        forces[i] = -d * x[i];
                        cost += 0.5 * d * x[i] * x[i];
                        if let Some(c) = curvature.as_deref_mut() {
                            c.diagonal.push((i, d));
                        }
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
    curvature: Option<&mut Curvature>,
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
        let mut curvature = curvature;
        for i in first..first + len {
            let d = 1.0 / rows.regulariser[i];
            forces[i] = -d * x[i];
            cost += 0.5 * d * x[i] * x[i];
            if let Some(c) = curvature.as_deref_mut() {
                c.diagonal.push((i, d));
            }
        }
        return cost;
    }
    // on the cone's surface: s = ½ D_m h², h = N − μ T
    let dm = 1.0 / rows.regulariser[first] / (mu * mu * (1.0 + mu * mu));
    let h = normal - mu * tangent;
    forces[first] = -dm * h * mu;
    for k in 1..len {
        forces[first + k] = -forces[first] * u[k] * f[k - 1] / tangent;
    }
    if let Some(curvature) = curvature {
        // ∇h = (μ, −μ f_k u_k / T);  ∇²s = D_m (∇h ∇hᵀ − μ h diag(f) (I − û ûᵀ) diag(f) / T)
        let mut gradient = [0.0; 6];
        gradient[0] = mu;
        for k in 1..len {
            gradient[k] = -mu * f[k - 1] * u[k] / tangent;
        }
        let mut block = [[0.0; 6]; 6];
        for a in 0..len {
            for b in 0..len {
                let mut value = gradient[a] * gradient[b];
                if a > 0 && b > 0 {
                    let projector = f64::from(u8::from(a == b)) - u[a] * u[b] / (tangent * tangent);
                    value -= mu * h * f[a - 1] * f[b - 1] * projector / tangent;
                }
                block[a][b] = dm * value;
            }
        }
        curvature.blocks.push((first, len, block));
    }
    0.5 * dm * h * h
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::soft::rows::Group;
    use nalgebra::DMatrix;

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
        forces_at(&rows, &x, &mut forces, Some(&mut curvature));
        assert_eq!(curvature.blocks.len(), 1, "on the cone's surface");
        let mut dense = DMatrix::zeros(6, 6);
        for &(i, d) in &curvature.diagonal {
            dense[(i, i)] = d;
        }
        for (first, len, block) in &curvature.blocks {
            for a in 0..*len {
                for b in 0..*len {
                    dense[(first + a, first + b)] += block[a][b];
                }
            }
        }
        // H_s = −∂f/∂x, by central differences
        let step = 1e-6;
        for k in 0..6 {
            let (mut up, mut down) = (x, x);
            up[k] += step;
            down[k] -= step;
            let (mut f_up, mut f_down) = ([0.0; 6], [0.0; 6]);
            forces_at(&rows, &up, &mut f_up, None);
            forces_at(&rows, &down, &mut f_down, None);
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
