//! Where the body-coordinate CRBA keeps what it fills: the forces `F_d = I^c S_d` of the
//! coordinates d of a subtree, carried to the parent joint by joint, and M's columns.
//!
//! One state keeps its forces by component ([`ForceRows`]): component c of consecutive forces is
//! consecutive, so that `S_jᵀ F_d` for `S_j = ±e_c` is a run of one row, and a joint carries its
//! subtree's forces four at a time, a component of four forces read as one vector (`f64x4`).
//! Each force is carried by the same operations as alone, so the values are the same bit for bit.
//! Lanes keep theirs as forces, one after the other (each lane is a state already).

use crate::spatial::{signed, Force, ForceProduct, ForceStore, Real, Transform, Turn};
use simba::simd::AutoF64x4;
use std::ops::Range;

/// Where the body-coordinate CRBA keeps the forces `F_d = I^c S_d` of the coordinates d.
pub(crate) trait SubtreeForces<S: Real> {
    /// `F_d = force`.
    fn set(&mut self, d: usize, force: &Force<S>);

    /// `S_kᵀ F_d` for `S_k = ±e_c` (c in [`Force::plucker`]'s order; `negative`: −): ±
    /// component c of `F_d`, for the coordinates d of `rows` in turn.
    fn unit_projections(
        &self,
        c: usize,
        negative: bool,
        rows: Range<usize>,
    ) -> impl Iterator<Item = S>;

    /// `F_d`.
    fn force(&self, d: usize) -> Force<S>;

    /// `F_d ← Xᵀ F_d` for the coordinates d of `subtree`, X of the pattern `turn` where it is
    /// `Some` ([`Transform::transpose_apply_force_turned`]).
    fn carry(&mut self, x: &Transform<S>, turn: Option<Turn>, subtree: Range<usize>);
}

impl<S: Real> SubtreeForces<S> for &mut [Force<S>] {
    #[inline(always)]
    fn set(&mut self, d: usize, force: &Force<S>) {
        self[d] = *force;
    }

    #[inline(always)]
    fn unit_projections(
        &self,
        c: usize,
        negative: bool,
        rows: Range<usize>,
    ) -> impl Iterator<Item = S> {
        self[rows]
            .iter()
            .map(move |force| signed(force.component(c), negative))
    }

    #[inline(always)]
    fn force(&self, d: usize) -> Force<S> {
        self[d]
    }

    #[inline(always)]
    fn carry(&mut self, x: &Transform<S>, turn: Option<Turn>, subtree: Range<usize>) {
        x.transpose_apply_forces_turned(turn, &mut self[subtree]);
    }
}

/// The room [`ForceRows`] takes for a model's coordinates, kept between calls (in `Data`).
#[derive(Debug, Clone)]
pub(crate) struct ForceRowsRoom {
    rows: Vec<f64>,
    nv: usize,
}

impl ForceRowsRoom {
    /// Room for the forces of `nv` coordinates.
    pub(crate) fn new(nv: usize) -> Self {
        ForceRowsRoom {
            rows: vec![0.0; 6 * (nv + ForceRows::PADDING)],
            nv,
        }
    }

    /// The forces' rows, in this room.
    pub(crate) fn rows(&mut self) -> ForceRows<'_> {
        ForceRows {
            rows: &mut self.rows,
            nv: self.nv,
        }
    }
}

/// One state's forces by component: `rows[c (nv + 3) + 3 + d]` is component c of `F_d`. Each
/// row starts with three unused values, so that a subtree's forces are carried in whole groups
/// of four ending at its last one; the places before its first hold forces of bodies not
/// reached yet (written when they are) or the unused values.
pub(crate) struct ForceRows<'r> {
    rows: &'r mut [f64],
    nv: usize,
}

impl ForceRows<'_> {
    /// The values unused at the start of each row.
    const PADDING: usize = 3;

    /// The distance from one component's row to the next.
    #[inline(always)]
    fn stride(&self) -> usize {
        self.nv + Self::PADDING
    }

    #[inline(always)]
    fn at(&self, c: usize, d: usize) -> usize {
        c * self.stride() + Self::PADDING + d
    }
}

impl SubtreeForces<f64> for ForceRows<'_> {
    #[inline(always)]
    fn set(&mut self, d: usize, force: &Force) {
        // the six components, a row apart: one bounds check for all
        let stride = self.stride();
        let first = self.at(0, d);
        let components = &mut self.rows[first..=first + 5 * stride];
        for (c, value) in force.plucker().into_iter().enumerate() {
            components[c * stride] = value;
        }
    }

    #[inline(always)]
    fn unit_projections(
        &self,
        c: usize,
        negative: bool,
        rows: Range<usize>,
    ) -> impl Iterator<Item = f64> {
        // component c of consecutive forces is consecutive
        let components = &self.rows[self.at(c, rows.start)..self.at(c, rows.end)];
        components
            .iter()
            .map(move |&component| signed(component, negative))
    }

    #[inline(always)]
    fn force(&self, d: usize) -> Force {
        let c = |c: usize| self.rows[self.at(c, d)];
        Force::from_plucker([c(0), c(1), c(2), c(3), c(4), c(5)])
    }

    #[inline(always)]
    fn carry(&mut self, x: &Transform, turn: Option<Turn>, subtree: Range<usize>) {
        // whole groups of four ending at the subtree's last force
        let (stride, end) = (self.stride(), ForceRows::PADDING + subtree.end);
        let mut groups = FourForces::of(self.rows, stride, end, subtree.len().div_ceil(4));
        x.transpose_apply_stored_forces_turned(turn, &mut groups);
    }
}

/// Groups of four consecutive forces of [`ForceRows`], each group one force of `f64x4`
/// components.
struct FourForces<'r> {
    /// Each component's row, from the first group on, in groups of four.
    rows: [&'r mut [[f64; 4]]; 6],
}

impl<'r> FourForces<'r> {
    /// The `groups` groups of four forces that end before force `end` of the rows `rows`, a
    /// row `stride` values from the next.
    #[inline(always)]
    fn of(rows: &'r mut [f64], stride: usize, end: usize, groups: usize) -> Self {
        // every row cut to the same length: the groups' reads and writes then need no bounds
        // checks
        let start = end - 4 * groups;
        let mut component_rows = rows.chunks_mut(stride);
        let mut next_row = || {
            let row = component_rows.next().expect("six component rows");
            &mut row[start..end].as_chunks_mut::<4>().0[..groups]
        };
        FourForces {
            rows: [
                next_row(),
                next_row(),
                next_row(),
                next_row(),
                next_row(),
                next_row(),
            ],
        }
    }
}

impl ForceStore<AutoF64x4> for FourForces<'_> {
    #[inline(always)]
    fn replace_each(&mut self, product: &impl ForceProduct<AutoF64x4>) {
        let [n0, n1, n2, f0, f1, f2] = &mut self.rows;
        for g in 0..n0.len() {
            // four values at once (an array taken whole is one load)
            let four = AutoF64x4::from;
            let f = Force::from_plucker([
                four(n0[g]),
                four(n1[g]),
                four(n2[g]),
                four(f0[g]),
                four(f1[g]),
                four(f2[g]),
            ]);
            let [a0, a1, a2, l0, l1, l2] = product.of(&f).plucker();
            (n0[g], n1[g], n2[g]) = (a0.into(), a1.into(), a2.into());
            (f0[g], f1[g], f2[g]) = (l0.into(), l1.into(), l2.into());
        }
    }
}

/// M's storage as the body-coordinate CRBA fills it: column-major nv × nv, with the joints'
/// armature on the diagonal.
pub(crate) struct MassColumns<'b, S> {
    pub mass_matrix: &'b mut [S],
    pub nv: usize,
    pub armature: &'b [f64],
}

impl<S: Real> MassColumns<'_, S> {
    /// `H[d, col] = H[col, d] = h_d` for the values `h_col, h_col+1, …` (column col from its
    /// diagonal down, and row col from its diagonal right), the armature added to the diagonal.
    #[inline(always)]
    pub(crate) fn store(&mut self, col: usize, values: impl Iterator<Item = S>) {
        // H[col + j, col] down the column, H[col, col + j] a column apart along the row
        let diagonal = col * self.nv + col;
        for (j, h) in values.enumerate() {
            self.mass_matrix[diagonal + j] = h;
            self.mass_matrix[diagonal + j * self.nv] = h;
        }
        self.mass_matrix[diagonal] += S::splat(self.armature[col]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::Joint;
    use crate::model::tree_transform;
    use crate::spatial::{rotation_from_rpy, Vec3};
    use std::f64::consts::FRAC_PI_2;

    /// Forces kept by component and carried four at a time equal each force carried alone, bit
    /// for bit, turned or not; the forces after the subtree and those before its groups are
    /// untouched.
    #[test]
    fn forces_carried_in_rows_equal_each_carried_alone() {
        let nv = 11;
        let force = |d: usize| {
            let x = |c: usize| ((7 * d + 3 * c) as f64 * 0.37).sin();
            Force::from_plucker([x(0), x(1), x(2), x(3), x(4), x(5)])
        };
        let joint = Joint::Revolute {
            axis: Vec3::new(0.0, 0.0, -1.0),
        };
        for quarters in [(0, 0, 0), (1, 0, 0), (0, 1, 3), (2, 1, 1)] {
            let (a, b, c) = quarters;
            let rpy = |n: i32| f64::from(n) * FRAC_PI_2;
            let rotation = rotation_from_rpy(rpy(a), rpy(b), rpy(c));
            let tree = tree_transform(Transform::from_pose(&rotation, &Vec3::new(0.1, -0.4, 0.9)));
            let x = joint.transform_after(&[0.7], &tree);
            for turn in [None, joint.turn(&tree)] {
                for subtree in [0..1, 2..7, 3..11, 0..11, 9..10] {
                    let mut room = ForceRowsRoom::new(nv);
                    let mut rows = room.rows();
                    for d in 0..nv {
                        rows.set(d, &force(d));
                    }
                    rows.carry(&x, turn, subtree.clone());
                    let first_group = (subtree.end + ForceRows::PADDING
                        - 4 * subtree.len().div_ceil(4))
                    .saturating_sub(ForceRows::PADDING);
                    for d in 0..nv {
                        let expected = match d {
                            _ if subtree.contains(&d) => x.transpose_apply_force(&force(d)),
                            _ if d >= subtree.end || d < first_group => force(d),
                            _ => continue,
                        };
                        assert_eq!(rows.force(d), expected, "{quarters:?} {subtree:?} {d}");
                    }
                }
            }
        }
    }
}
