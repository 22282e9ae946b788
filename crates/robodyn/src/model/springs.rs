//! The joints' springs and dampers, with their polynomial terms.
//!
//! ```text
//! spring:  f = −(k + k₁ x + k₂ x²) x      x = q ⊖ q_ref on a hinge or slide (signed)
//!          f = −(k + k₁ θ + k₂ θ²) d      d the displacement of a ball, or of either half of a
//!                                         free joint (translation, rotation), θ = |d|
//! damper:  f = −(b + b₁ |q̇| + b₂ q̇²) q̇   per velocity coordinate
//! ```
//!
//! Reference: MuJoCo's documentation, "Computation", §Passive forces, "Polynomial forces"
//! (the stiffness polynomial in the standard form, the damping polynomial anti-symmetrised); on
//! balls and free joints MuJoCo takes the coefficient at the rotation angle and at the distance
//! (measured with MuJoCo 4.0). Only k and b are the linear terms the rest of the library knows.

use super::Model;
use crate::error::{Error, Result};
use crate::spatial::{Mat3, Mat6, Vec3};

/// c + c₁ x + c₂ x²: a spring's or damper's coefficient at x (MuJoCo's `mju_polyForce`).
pub(crate) fn polynomial_coefficient(linear: f64, [c1, c2]: &[f64; 2], x: f64) -> f64 {
    linear + x * (c1 + c2 * x)
}

/// d/dx [c x + c₁ x² + c₂ x³] = c + 2 c₁ x + 3 c₂ x²: the slope of a force along x.
pub(crate) fn polynomial_slope(linear: f64, [c1, c2]: &[f64; 2], x: f64) -> f64 {
    linear + x * (2.0 * c1 + 3.0 * c2 * x)
}

/// ∫₀ˣ (c + c₁ s + c₂ s²) s ds = c x²/2 + c₁ x³/3 + c₂ x⁴/4: a spring's energy at x.
fn polynomial_energy(linear: f64, [c1, c2]: &[f64; 2], x: f64) -> f64 {
    x * x * (linear / 2.0 + x * (c1 / 3.0 + c2 * x / 4.0))
}

/// Refuses higher terms that are not `nv` finite pairs.
fn check_terms(argument: &str, terms: &[[f64; 2]], nv: usize) -> Result<()> {
    let refuse = |message: String| {
        Err(Error::InvalidValue {
            argument: argument.into(),
            message,
        })
    };
    if terms.len() != nv {
        return refuse(format!("expected {nv} rows, got {}", terms.len()));
    }
    match terms.iter().position(|t| !t.iter().all(|x| x.is_finite())) {
        Some(row) => refuse(format!(
            "expected finite values, got {:?} in row {row}",
            terms[row]
        )),
        None => Ok(()),
    }
}

/// How one block of a joint's velocity coordinates measures its spring's stretch.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stretch {
    /// A hinge's or slide's signed x.
    Signed,
    /// A ball's, or half a free joint's, three coordinates: the coefficient at their length.
    Length,
}

/// A joint's spring blocks (offset in its velocity coordinates, size, how it stretches) by its
/// number of velocity coordinates: one per hinge or slide, one per ball, two per free joint.
fn spring_blocks(nv: usize) -> &'static [(usize, usize, Stretch)] {
    match nv {
        1 => &[(0, 1, Stretch::Signed)],
        3 => &[(0, 3, Stretch::Length)],
        6 => &[(0, 3, Stretch::Length), (3, 3, Stretch::Length)],
        _ => &[],
    }
}

/// The stretch s of a block of displacements: x itself, or the block's length.
fn stretch_of(block: &[f64], stretch: Stretch) -> f64 {
    match stretch {
        Stretch::Signed => block[0],
        Stretch::Length => block.iter().map(|d| d * d).sum::<f64>().sqrt(),
    }
}

impl Model {
    /// Each spring block of the model (first velocity coordinate, size, how it stretches).
    fn model_spring_blocks(&self) -> impl Iterator<Item = (usize, usize, Stretch)> + '_ {
        (1..self.nbodies()).flat_map(move |i| {
            let start = self.idx_v[i];
            spring_blocks(self.joints[i].nv())
                .iter()
                .map(move |&(offset, size, stretch)| (start + offset, size, stretch))
        })
    }

    /// Whether any joint has a spring (a linear or a higher stiffness term).
    pub fn has_springs(&self) -> bool {
        self.stiffness.iter().any(|k| *k != 0.0)
            || self.stiffness_poly.iter().any(|t| *t != [0.0; 2])
    }

    /// Whether any joint has a damper (a linear or a higher damping term).
    pub fn has_dampers(&self) -> bool {
        self.damping.iter().any(|b| *b != 0.0) || self.damping_poly.iter().any(|t| *t != [0.0; 2])
    }

    /// The springs' forces `−(k + k₁ s + k₂ s²) d` in place of the displacements `d = q ⊖ q_ref`
    /// (nv), `s` the signed x on a hinge or slide, the block's length on a ball or on either
    /// half of a free joint. k is each coordinate's own, k₁ and k₂ the block's (its first
    /// coordinate's).
    pub fn spring_forces(&self, displacement: &mut [f64]) {
        for (start, size, stretch) in self.model_spring_blocks() {
            let block = &mut displacement[start..start + size];
            let higher = polynomial_coefficient(
                0.0,
                &self.stiffness_poly[start],
                stretch_of(block, stretch),
            );
            for (d, k) in block
                .iter_mut()
                .zip(&self.stiffness.as_slice()[start..start + size])
            {
                *d *= -(k + higher);
            }
        }
    }

    /// The springs' energy `Σ (k d²/2 + k₁ s³/3 + k₂ s⁴/4)` at the displacements `d` (nv), `s`
    /// as in [`Model::spring_forces`] (its potential: the forces are minus its gradient).
    pub fn spring_energy_at(&self, displacement: &[f64]) -> f64 {
        self.model_spring_blocks()
            .map(|(start, size, stretch)| {
                let block = &displacement[start..start + size];
                let linear: f64 = block
                    .iter()
                    .zip(&self.stiffness.as_slice()[start..start + size])
                    .map(|(d, k)| k * d * d / 2.0)
                    .sum();
                let s = stretch_of(block, stretch);
                linear + polynomial_energy(0.0, &self.stiffness_poly[start], s)
            })
            .sum()
    }

    /// ∂f/∂d of body `i`'s joint spring at its displacement `d` (the joint's nv coordinates),
    /// into the leading nv × nv block of `slope`: on a hinge or slide −(k + 2 k₁ x + 3 k₂ x²),
    /// on a length block −diag(k) − (k₁ s + k₂ s²) I − (k₁ + 2 k₂ s) d dᵀ / s (s = |d|).
    pub fn joint_spring_slope(&self, i: usize, displacement: &[f64], slope: &mut Mat6) {
        let first = self.idx_v[i];
        for &(offset, size, stretch) in spring_blocks(self.joints[i].nv()) {
            let dof = first + offset;
            let (k, terms) = (self.stiffness[dof], &self.stiffness_poly[dof]);
            let block = &displacement[offset..offset + size];
            match stretch {
                Stretch::Signed => {
                    slope[(offset, offset)] = -polynomial_slope(k, terms, block[0]);
                }
                Stretch::Length => {
                    let d = Vec3::from_column_slice(block);
                    let s = d.norm();
                    // (k₁ + 2 k₂ s) d dᵀ / s, which goes to 0 with d
                    let outer = match s > 0.0 {
                        true => d * d.transpose() * ((terms[0] + 2.0 * terms[1] * s) / s),
                        false => Mat3::zeros(),
                    };
                    let own = Vec3::from_column_slice(&self.stiffness.as_slice()[dof..dof + 3]);
                    let higher = polynomial_coefficient(0.0, terms, s);
                    let block = Mat3::from_diagonal(&own.add_scalar(higher)) + outer;
                    slope
                        .fixed_view_mut::<3, 3>(offset, offset)
                        .copy_from(&-block);
                }
            }
        }
    }

    /// Sets the springs' higher terms (k₁, k₂) per velocity coordinate (nv): finite, and the
    /// same on every coordinate of a ball or of either half of a free joint (one stretch, one
    /// coefficient), else an error naming the joint.
    pub fn set_stiffness_poly(&mut self, terms: &[[f64; 2]]) -> Result<()> {
        check_terms("stiffness_poly", terms, self.nv)?;
        for i in 1..self.nbodies() {
            for &(offset, size, _) in spring_blocks(self.joints[i].nv()) {
                let first = self.idx_v[i] + offset;
                if terms[first..first + size]
                    .iter()
                    .any(|t| *t != terms[first])
                {
                    return Err(Error::InvalidValue {
                        argument: "stiffness_poly".into(),
                        message: format!(
                            "joint '{}': expected the same (k₁, k₂) on coordinates {}..{} (one \
                             stretch, one coefficient), got {:?}",
                            self.joint_names[i],
                            first,
                            first + size,
                            &terms[first..first + size]
                        ),
                    });
                }
            }
        }
        self.stiffness_poly = terms.to_vec();
        Ok(())
    }

    /// Sets the dampers' higher terms (b₁, b₂) per velocity coordinate (nv), finite.
    pub fn set_damping_poly(&mut self, terms: &[[f64; 2]]) -> Result<()> {
        check_terms("damping_poly", terms, self.nv)?;
        self.damping_poly = terms.to_vec();
        Ok(())
    }

    /// The damper's force on velocity coordinate `dof` at speed `rate`:
    /// `−(b + b₁ |q̇| + b₂ q̇²) q̇`.
    pub fn damper_force(&self, dof: usize, rate: f64) -> f64 {
        -rate * polynomial_coefficient(self.damping[dof], &self.damping_poly[dof], rate.abs())
    }

    /// ∂f/∂q̇ of the damper on `dof` at speed `rate`: `−(b + 2 b₁ |q̇| + 3 b₂ q̇²)`.
    pub fn damper_slope(&self, dof: usize, rate: f64) -> f64 {
        -polynomial_slope(self.damping[dof], &self.damping_poly[dof], rate.abs())
    }
}

#[cfg(test)]
mod tests {
    use crate::joint::Joint;
    use crate::model::{JointProperties, ModelBuilder, NewBody};
    use crate::spatial::{Inertia, Mat3, Transform, Vec3};

    /// A hinge, a ball and a free joint in a chain, all with polynomial springs and dampers.
    fn model() -> crate::Model {
        let mut builder = ModelBuilder::new("springs", "world");
        let properties = JointProperties {
            stiffness: 2.0,
            stiffness_poly: [0.7, 1.3],
            damping: 0.5,
            damping_poly: [0.3, 0.9],
            ..JointProperties::default()
        };
        let joints = [
            Joint::Free,
            Joint::Revolute { axis: Vec3::z() },
            Joint::Spherical,
        ];
        for (i, joint) in joints.into_iter().enumerate() {
            builder
                .add_body(NewBody {
                    parent: i,
                    joint,
                    joint_name: &format!("j{i}"),
                    x_tree: Transform::IDENTITY,
                    properties,
                    name: &format!("b{i}"),
                    inertia: Inertia::from_com(1.0, &Vec3::zeros(), &Mat3::identity()),
                })
                .unwrap();
        }
        builder.build()
    }

    /// The forces are minus the energy's gradient, and the slopes the forces' Jacobian (central
    /// differences); a hinge's force at x is −(2 + 0.7 x + 1.3 x²) x.
    #[test]
    fn forces_are_the_energy_gradient_and_slopes_their_jacobian() {
        let model = model();
        let d: Vec<f64> = (0..model.nv)
            .map(|k| 0.3 * (k as f64 + 1.0).sin())
            .collect();
        let forces = |d: &[f64]| {
            let mut f = d.to_vec();
            model.spring_forces(&mut f);
            f
        };
        let f = forces(&d);
        let x = d[6];
        assert!((f[6] + (2.0 + 0.7 * x + 1.3 * x * x) * x).abs() < 1e-15);
        let h = 1e-6;
        let mut slopes = nalgebra::DMatrix::zeros(model.nv, model.nv);
        for i in 1..model.nbodies() {
            let (first, nv) = (model.idx_v[i], model.joints[i].nv());
            let mut block = crate::spatial::Mat6::zeros();
            model.joint_spring_slope(i, &d[first..first + nv], &mut block);
            let block = block.view((0, 0), (nv, nv));
            slopes.view_mut((first, first), (nv, nv)).copy_from(&block);
        }
        for k in 0..model.nv {
            let (mut up, mut down) = (d.clone(), d.clone());
            up[k] += h;
            down[k] -= h;
            let gradient =
                (model.spring_energy_at(&up) - model.spring_energy_at(&down)) / (2.0 * h);
            assert!((gradient + f[k]).abs() < 1e-8, "coordinate {k}");
            let (f_up, f_down) = (forces(&up), forces(&down));
            for r in 0..model.nv {
                let numeric = (f_up[r] - f_down[r]) / (2.0 * h);
                assert!((numeric - slopes[(r, k)]).abs() < 1e-8, "({r}, {k})");
            }
        }
    }

    /// The damper is odd in q̇, and its slope the derivative of its force (−b at rest).
    #[test]
    fn damper_is_odd_and_its_slope_is_its_derivative() {
        let model = model();
        assert_eq!(model.damper_slope(6, 0.0), -0.5);
        for rate in [-1.7, -0.2, 0.4, 2.5] {
            let force = model.damper_force(6, rate);
            assert_eq!(force, -model.damper_force(6, -rate));
            assert!((force + rate * (0.5 + 0.3 * rate.abs() + 0.9 * rate * rate)).abs() < 1e-15);
            let h = 1e-6;
            let numeric =
                (model.damper_force(6, rate + h) - model.damper_force(6, rate - h)) / (2.0 * h);
            assert!((numeric - model.damper_slope(6, rate)).abs() < 1e-8);
        }
    }
}
