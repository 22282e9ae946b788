//! Ideal elasto-plastic springs (MJCF `springyield` y on joints and tendons): a spring stretched
//! past its yield moves its reference so that the stretch stays y. The references that move
//! are the plastic state p, carried beside (q, v) and the activations (MuJoCo's
//! `mjData.plastic`), and moved after each step at the new configuration:
//!
//! ```text
//! hinge, slide   x = q − r:            |x| > y  ⇒  r ← q − y sign(x)
//! ball           θ â = r⁻¹ ⊗ q ⊖ 1:   θ > y    ⇒  r ← q ⊗ exp(−y â)
//! tendon         dead band [l, h] at its length L:
//!                L > h + y  ⇒  both move by (L − h) − y (l stays at 0 when l = 0 < h: a slack
//!                               tendon stretches only its upper end)
//!                L < l − y  ⇒  both move by (L − l) + y
//! ```
//!
//! Reference: MuJoCo 4.0's XML reference (`springyield` of joints and tendons) and its
//! "Plastic state" (Simulation chapter); the rules above, when they apply and their order were
//! measured against `mj_step` (tests/test_plasticity.py). The state's layout is MuJoCo's: the
//! plastic joints in order (one value on a hinge or slide, the reference quaternion on a ball,
//! in robodyn's order [x, y, z, w]), then the plastic tendons (their [l, h]).

use super::Model;
use crate::error::{check_vector, Error, Result};

/// What one entry of the plastic state belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlasticSlot {
    /// Body `i`'s joint: its spring reference (nq of the joint).
    Joint(usize),
    /// Tendon `t`: its spring's dead band [l, h].
    Tendon(usize),
}

/// The spring references a state's plastic part gives: the joints' (nq) and the tendons' dead
/// bands, the model's own where nothing is plastic.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpringReferences {
    /// q_ref, nq.
    pub configuration: Vec<f64>,
    /// Each tendon's [l, h].
    pub bands: Vec<[f64; 2]>,
}

impl SpringReferences {
    /// The references of `model` with the plastic state `plastic` in place (allocates nothing
    /// once sized).
    pub fn update(&mut self, model: &Model, plastic: &[f64]) {
        self.configuration.clear();
        self.configuration
            .extend_from_slice(model.spring_reference.as_slice());
        self.bands.clear();
        self.bands
            .extend(model.tendons.iter().map(|t| t.spring_length));
        for (slot, start) in model.plastic_slots() {
            match slot {
                PlasticSlot::Joint(i) => {
                    let range = model.q_range(i);
                    let n = range.len();
                    self.configuration[range].copy_from_slice(&plastic[start..start + n]);
                }
                PlasticSlot::Tendon(t) => {
                    self.bands[t] = [plastic[start], plastic[start + 1]];
                }
            }
        }
    }
}

impl Model {
    /// The plastic springs with the first index of each one's state: the joints with a yield
    /// (hinges, slides and balls) in order, then the tendons with one.
    pub fn plastic_slots(&self) -> impl Iterator<Item = (PlasticSlot, usize)> + '_ {
        let joints = (1..self.nbodies())
            .filter(|&i| self.spring_yield[i] > 0.0 && matches!(self.joints[i].nq(), 1 | 4))
            .map(|i| (PlasticSlot::Joint(i), self.joints[i].nq()));
        let tendons = (self.tendons.iter().enumerate())
            .filter(|(_, tendon)| tendon.spring_yield > 0.0)
            .map(|(t, _)| (PlasticSlot::Tendon(t), 2));
        joints.chain(tendons).scan(0, |next, (slot, size)| {
            let start = *next;
            *next += size;
            Some((slot, start))
        })
    }

    /// The plastic state's length (MuJoCo's `nplastic`).
    pub fn nplastic(&self) -> usize {
        self.plastic_slots()
            .map(|(slot, _)| match slot {
                PlasticSlot::Joint(i) => self.joints[i].nq(),
                PlasticSlot::Tendon(_) => 2,
            })
            .sum()
    }

    /// The plastic state before anything yields: the springs' own references (`springref`,
    /// `springlength`).
    pub fn initial_plastic(&self) -> Vec<f64> {
        let mut plastic = Vec::with_capacity(self.nplastic());
        for (slot, _) in self.plastic_slots() {
            match slot {
                PlasticSlot::Joint(i) => {
                    plastic.extend_from_slice(&self.spring_reference.as_slice()[self.q_range(i)])
                }
                PlasticSlot::Tendon(t) => plastic.extend_from_slice(&self.tendons[t].spring_length),
            }
        }
        plastic
    }

    /// Refuses a plastic state `plastic` (the argument's name) that is not nplastic finite
    /// values with unit quaternions on balls and l ≤ h on tendons.
    pub fn check_plastic(&self, argument: &str, plastic: &[f64]) -> Result<()> {
        check_vector(argument, plastic, self.nplastic())?;
        let refuse = |message: String| {
            Err(Error::InvalidValue {
                argument: argument.into(),
                message,
            })
        };
        for (slot, start) in self.plastic_slots() {
            match slot {
                PlasticSlot::Joint(i) if self.joints[i].nq() == 4 => {
                    if let Err(norm) = super::check_unit_quaternion(&plastic[start..start + 4]) {
                        return refuse(format!(
                            "expected the unit quaternion [qx, qy, qz, qw] of joint '{}''s spring \
                             reference at {argument}[{start}..{}], got norm {norm}",
                            self.joint_names[i],
                            start + 4
                        ));
                    }
                }
                PlasticSlot::Tendon(t) if plastic[start] > plastic[start + 1] => {
                    return refuse(format!(
                        "expected tendon '{}''s dead band low ≤ high at {argument}[{start}..{}], \
                         got {:?}",
                        self.tendons[t].name,
                        start + 2,
                        &plastic[start..start + 2]
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Moves the plastic state `plastic` where a spring at the configuration `q` and the
    /// tendons' lengths `tendon_lengths` there is stretched past its yield (see the module's
    /// header).
    pub fn yield_springs(&self, q: &[f64], tendon_lengths: &[f64], plastic: &mut [f64]) {
        let mut displacement = [0.0; 3];
        for (slot, start) in self.plastic_slots() {
            match slot {
                PlasticSlot::Joint(i) => {
                    let (joint, y) = (&self.joints[i], self.spring_yield[i]);
                    let (q, n) = (&q[self.q_range(i)], joint.nv());
                    let reference = &mut plastic[start..start + joint.nq()];
                    // θ â = q ⊖ r; past the yield r = q ⊕ (−y â)
                    let d = &mut displacement[..n];
                    joint.difference(reference, q, d);
                    let stretch = d.iter().map(|x| x * x).sum::<f64>().sqrt();
                    if stretch > y {
                        d.iter_mut().for_each(|x| *x *= -y / stretch);
                        joint.integrate(q, d, reference);
                    }
                }
                PlasticSlot::Tendon(t) => {
                    let (y, length) = (self.tendons[t].spring_yield, tendon_lengths[t]);
                    let (low, high) = (plastic[start], plastic[start + 1]);
                    // the band moves by e = (L − h) − y or (L − l) + y (in MuJoCo's order of
                    // operations: the same numbers to the last bit); a slack tendon (l = 0 < h)
                    // stretches its upper end only
                    let band = if length > high + y {
                        let e = (length - high) - y;
                        let slack = low == 0.0 && high > 0.0;
                        [if slack { 0.0 } else { low + e }, high + e]
                    } else if length < low - y {
                        let e = (length - low) + y;
                        [low + e, high + e]
                    } else {
                        [low, high]
                    };
                    plastic[start..start + 2].copy_from_slice(&band);
                }
            }
        }
    }

    /// Whether some tendon's spring is plastic (its yield needs the tendons' lengths).
    pub fn has_plastic_tendons(&self) -> bool {
        self.tendons.iter().any(|t| t.spring_yield > 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::Joint;
    use crate::model::{JointProperties, ModelBuilder, NewBody};
    use crate::spatial::{Inertia, Transform, Vec3};

    /// A hinge (yield 0.1) carrying a ball (yield 0.2).
    fn hinge_and_ball() -> Model {
        let mut builder = ModelBuilder::new("plastic", "world");
        let inertia = Inertia::from_com(1.0, &Vec3::zeros(), &crate::spatial::Mat3::identity());
        let mut parent = 0;
        for (name, joint, y) in [
            ("hinge", Joint::Revolute { axis: Vec3::z() }, 0.1),
            ("ball", Joint::Spherical, 0.2),
        ] {
            let properties = JointProperties {
                spring_yield: y,
                ..JointProperties::default()
            };
            parent = builder
                .add_body(NewBody {
                    parent,
                    joint,
                    joint_name: name,
                    x_tree: Transform::IDENTITY,
                    properties,
                    name,
                    inertia,
                })
                .unwrap();
        }
        builder.build()
    }

    #[test]
    fn a_hinge_past_its_yield_drags_its_reference_and_a_ball_turns_its_reference_after_it() {
        let model = hinge_and_ball();
        assert_eq!(model.nplastic(), 5);
        let mut plastic = model.initial_plastic();
        assert_eq!(plastic, [0.0, 0.0, 0.0, 0.0, 1.0]);
        // a half turn about z on the ball, 0.3 on the hinge
        let (s, c) = (0.25f64.sin(), 0.25f64.cos());
        let q = [0.3, 0.0, 0.0, s, c];
        model.yield_springs(&q, &[], &mut plastic);
        assert!((plastic[0] - 0.2).abs() < 1e-15);
        // the reference now 0.2 rad behind q about the same axis: 0.5 − 0.2 = 0.3 rad from 1
        let expected = [0.0, 0.0, 0.15f64.sin(), 0.15f64.cos()];
        for (a, b) in plastic[1..].iter().zip(expected) {
            assert!((a - b).abs() < 1e-15, "{plastic:?}");
        }
        // within the yield nothing moves
        let before = plastic.clone();
        model.yield_springs(&[0.25, 0.0, 0.0, s, c], &[], &mut plastic);
        assert_eq!(plastic, before);
    }
}
