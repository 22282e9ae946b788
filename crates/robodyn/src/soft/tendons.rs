//! The tendons' lengths L and Jacobians J = ∂L̇/∂q̇ at one configuration (MuJoCo's `ten_length`
//! and `ten_J`, computed by its `mj_tendon`).
//!
//! Reference: MuJoCo's documentation, "Computation", §Tendons, and its XML reference
//! (`<tendon><spatial>`, `<pulley divisor>`). A fixed tendon is linear in q:
//! ```text
//!   L = Σ_k c_k q_k,                          J = Σ_k c_k e_k
//! ```
//! A spatial tendon is the length of its path through sites p₀, p₁, …; a pulley starts a new
//! branch, whose segments count divided by the pulley's divisor d:
//! ```text
//!   L = Σ_i |p_{i+1} − p_i| / d,              J = Σ_i u_iᵀ (J_{p_{i+1}} − J_{p_i}) / d
//! ```
//! with u_i = (p_{i+1} − p_i) / |p_{i+1} − p_i| and J_p the Jacobian of the point p (its velocity
//! over q̇, in robodyn's coordinates); a segment between two sites of one body adds no J, a
//! vanishing one (shorter than 1e-15, MuJoCo's `mjMINVAL`) takes the x axis for u_i, as MuJoCo.
//! Between two sites, a sphere or cylinder that the path wraps around ([`super::wrap`]) adds
//! two points t₀, t₁ on its surface: the pieces p_i → t₀ and t₁ → p_{i+1} count as segments
//! (t₀, t₁ moving with the geom's body), and the path over the surface adds its length to L
//! but nothing to J (the geodesic's length is stationary as its ends slide on the surface).

use super::weights::{point_columns, world_point};
use super::wrap::{wrap, Surface, Wrap};
use super::TINY;
use crate::algo::forward_kinematics;
use crate::error::Result;
use crate::model::{Model, Tendon};
use crate::spatial::{Transform, Vec3};
use crate::Data;
use nalgebra::DMatrix;

/// Every tendon's L and J at one configuration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TendonKinematics {
    /// L per tendon.
    pub lengths: Vec<f64>,
    /// J: one row per tendon, nv columns.
    pub jacobian: DMatrix<f64>,
}

impl TendonKinematics {
    /// L and J of `model`'s tendons at q, its bodies placed at `x_world` (`X_{body←0}`).
    pub fn update(&mut self, model: &Model, q: &[f64], x_world: &[Transform]) {
        let count = model.tendons.len();
        self.lengths.resize(count, 0.0);
        if self.jacobian.shape() != (count, model.nv) {
            self.jacobian = DMatrix::zeros(count, model.nv);
        }
        self.jacobian.fill(0.0);
        for (t, tendon) in model.tendons.iter().enumerate() {
            self.lengths[t] = if tendon.is_spatial() {
                self.spatial(model, t, tendon, x_world)
            } else {
                // L = Σ c_k q_k, J = Σ c_k e_k
                let mut length = 0.0;
                for (k, p, c) in tendon.entries(model) {
                    length += c * q[p];
                    self.jacobian[(t, k)] += c;
                }
                length
            };
        }
    }

    /// L and J at q, the bodies placed by forward kinematics.
    pub fn at(model: &Model, data: &mut Data, q: &[f64]) -> Result<Self> {
        let x_world = forward_kinematics(model, data, q)?.to_vec();
        let mut kinematics = TendonKinematics::default();
        kinematics.update(model, q, &x_world);
        Ok(kinematics)
    }

    /// A spatial tendon's L, its J into row `t`.
    fn spatial(&mut self, model: &Model, t: usize, tendon: &Tendon, x_world: &[Transform]) -> f64 {
        let mut length = 0.0;
        let mut previous: Option<(usize, Vec3)> = None;
        for site in tendon.path_sites() {
            let (body, divisor) = (site.body, site.divisor);
            let p = world_point(&x_world[body], &site.point);
            if let (false, Some(from)) = (site.starts_branch, previous) {
                let wrapped = (site.wrapped)
                    .and_then(|(geom, side)| wrap_around(model, x_world, geom, side, from.1, p));
                match wrapped {
                    // p_i → t₀, over the surface, t₁ → p_{i+1}; t₀ and t₁ move with the geom
                    Some((geom_body, wrap)) => {
                        let [t0, t1] = wrap.points;
                        length += ((t0 - from.1).norm() + wrap.arc + (p - t1).norm()) / divisor;
                        self.add_segment(model, x_world, t, (from, (geom_body, t0)), divisor);
                        self.add_segment(model, x_world, t, ((geom_body, t1), (body, p)), divisor);
                    }
                    // the straight segment
                    None => {
                        length += (p - from.1).norm() / divisor;
                        self.add_segment(model, x_world, t, (from, (body, p)), divisor);
                    }
                }
            }
            previous = Some((body, p));
        }
        length
    }

    /// Adds a straight piece's `u_iᵀ (J_{p_{i+1}} − J_{p_i}) / d` to row `t` (nothing between two
    /// points of one body).
    fn add_segment(
        &mut self,
        model: &Model,
        x_world: &[Transform],
        t: usize,
        ((from_body, from), (body, p)): ((usize, Vec3), (usize, Vec3)),
        divisor: f64,
    ) {
        if from_body == body {
            return;
        }
        let segment = p - from;
        let norm = segment.norm();
        // MuJoCo's direction of a vanishing segment: the x axis
        let u = if norm < TINY {
            Vec3::x()
        } else {
            segment / norm
        } / divisor;
        let mut row = self.jacobian.row_mut(t);
        point_columns(model, x_world, body, &p, |k, linear, _| {
            row[k] += u.dot(linear)
        });
        point_columns(model, x_world, from_body, &from, |k, linear, _| {
            row[k] -= u.dot(linear)
        });
    }

    /// L̇ of tendon `t` at the velocity v: `J_t v`.
    pub fn rate(&self, t: usize, v: &[f64]) -> f64 {
        self.jacobian.row(t).iter().zip(v).map(|(j, v)| j * v).sum()
    }

    /// Adds `scale J_t` to `row` (nv).
    pub fn add_to_row(&self, t: usize, scale: f64, row: &mut [f64]) {
        for (entry, j) in row.iter_mut().zip(self.jacobian.row(t).iter()) {
            *entry += scale * j;
        }
    }
}

/// The wrap of the path from `from` to `to` around geom `geom` (a sphere or a cylinder), its
/// side site `side` (body, position in its frame): the geom's body and the [`Wrap`]; `None`
/// where the path stays straight.
fn wrap_around(
    model: &Model,
    x_world: &[Transform],
    geom: usize,
    side: Option<(usize, Vec3)>,
    from: Vec3,
    to: Vec3,
) -> Option<(usize, Wrap)> {
    let geom = &model.geoms[geom];
    let surface = Surface::of(&geom.shape)?;
    // X_{geom←0} = X_{geom←body} X_{body←0}: its axes and origin in the world
    let x = geom.placement * x_world[geom.body];
    let side = side.map(|(body, point)| world_point(&x_world[body], &point));
    let frame = (&x.rotation.transpose(), &x.translation);
    wrap((&from, &to), frame, surface, side.as_ref()).map(|w| (geom.body, w))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::io::load_mjcf_str;

    /// A cord from the world through an arm to a free box, a pulley's branch, two sites on one
    /// body; a fixed tendon across the arm and a hinge on a second tree; both with an inertia.
    pub(crate) const CORDS: &str = r#"<mujoco>
      <worldbody>
        <site name="anchor" pos="0 0.2 1.6"/>
        <body name="upper" pos="0 0 1"><joint name="shoulder" axis="0 1 0"/><geom size=".05"/>
          <site name="a" pos=".2 0 .05"/><site name="b" pos=".3 0 0"/>
          <body pos=".4 0 0"><joint name="reach" type="slide" axis="1 0 0"/><geom size=".05"/>
            <site name="tip" pos=".3 0 0"/></body></body>
        <body name="float" pos="0.6 0.1 1.2" euler="0.3 0.2 0.1"><freejoint/><geom size=".05"/>
          <site name="eye"/></body>
        <body name="other" pos="0 1 1"><joint name="swing" axis="1 0 0"/><geom size=".05"/></body>
      </worldbody>
      <tendon>
        <spatial armature="0.4"><site site="anchor"/><site site="a"/><site site="b"/>
          <site site="tip"/><site site="eye"/><pulley divisor="3"/><site site="eye"/>
          <site site="anchor"/></spatial>
        <fixed armature="0.7"><joint joint="shoulder" coef="1"/><joint joint="reach" coef="-2"/>
          <joint joint="swing" coef="0.5"/></fixed>
      </tendon>
    </mujoco>"#;

    #[test]
    fn the_jacobian_is_the_lengths_rate() {
        let model = load_mjcf_str(CORDS, "cords.xml").unwrap();
        let mut data = Data::new(&model);
        let q = model.neutral_configuration.clone();
        let v: Vec<f64> = (0..model.nv).map(|k| 0.3 - 0.1 * k as f64).collect();
        let at = TendonKinematics::at(&model, &mut data, q.as_slice()).unwrap();
        // (L(q ⊕ εv) − L(q ⊕ −εv)) / 2ε
        let mut moved = |sign: f64| {
            let step: Vec<f64> = v.iter().map(|x| sign * 1e-6 * x).collect();
            let mut q1 = vec![0.0; model.nq];
            model.integrate(q.as_slice(), &step, &mut q1).unwrap();
            TendonKinematics::at(&model, &mut data, &q1)
                .unwrap()
                .lengths[0]
        };
        let rate = (moved(1.0) - moved(-1.0)) / 2e-6;
        assert!(
            (at.rate(0, &v) - rate).abs() < 1e-8,
            "{} vs {rate}",
            at.rate(0, &v)
        );
        // the pulley's branch, eye to anchor, counts a third
        let text = CORDS.replace("divisor=\"3\"", "divisor=\"1\"");
        let single = load_mjcf_str(&text, "single.xml").unwrap();
        let q = single.neutral_configuration.clone();
        let whole = TendonKinematics::at(&single, &mut Data::new(&single), q.as_slice()).unwrap();
        let branch = (0.6f64 * 0.6 + 0.1 * 0.1 + 0.4 * 0.4).sqrt();
        let two_thirds = whole.lengths[0] - at.lengths[0];
        assert!(
            (two_thirds - 2.0 / 3.0 * branch).abs() < 1e-14,
            "{two_thirds}"
        );
    }
}
