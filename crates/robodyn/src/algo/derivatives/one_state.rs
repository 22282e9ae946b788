//! A single call's derivative passes, each a function of its own built for the baseline and for
//! AVX2 and FMA, chosen at run time: a pass is a small struct whose `run` is inlined into the
//! dispatching function (a closure would not be, and would keep the baseline instruction set).

use super::{
    acceleration_terms, derivative_products, velocity_terms, DerivativeBuffers, TorqueDerivatives,
};
use crate::model::Model;
use crate::spatial::Force;

/// Runs `pass` as a function of its own, compiled for AVX2 and FMA where the processor has them
/// (the same operations in the same order, so the same result bit for bit: no product is fused).
#[inline(never)]
pub(super) fn one_state(pass: impl OneStatePass) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor has AVX2 and FMA, just checked.
        return unsafe { one_state_avx2(pass) };
    }
    pass.run()
}

/// [`one_state`]'s pass compiled for AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn one_state_avx2(pass: impl OneStatePass) {
    pass.run()
}

/// A pass of the one-state derivatives with its arguments; `run` is inlined into [`one_state`]'s
/// builds (a closure would not be, and would keep the baseline instruction set).
pub(super) trait OneStatePass {
    fn run(self);
}

/// [`velocity_terms`] of one state.
pub(super) struct VelocityTerms<'p, 'b> {
    pub(super) model: &'p Model,
    pub(super) b: &'p mut DerivativeBuffers<'b, f64>,
    pub(super) q: &'p [f64],
    pub(super) v: &'p [f64],
    pub(super) f_ext: Option<&'p [Force]>,
}

impl OneStatePass for VelocityTerms<'_, '_> {
    #[inline(always)]
    fn run(self) {
        velocity_terms(self.model, self.b, self.q, self.v, self.f_ext)
    }
}

/// [`acceleration_terms`] of one state.
pub(super) struct AccelerationTerms<'p, 'b> {
    pub(super) model: &'p Model,
    pub(super) b: &'p mut DerivativeBuffers<'b, f64>,
    pub(super) a: Option<&'p [f64]>,
}

impl OneStatePass for AccelerationTerms<'_, '_> {
    #[inline(always)]
    fn run(self) {
        acceleration_terms(self.model, self.b, self.a)
    }
}

/// [`derivative_products`] of one state.
pub(super) struct DerivativeProducts<'p, 'b, T, const MASS_MATRIX: bool> {
    pub(super) model: &'p Model,
    pub(super) b: &'p mut DerivativeBuffers<'b, f64>,
    pub(super) v: &'p [f64],
    pub(super) out: &'p mut T,
}

impl<T: TorqueDerivatives<f64>, const MASS_MATRIX: bool> OneStatePass
    for DerivativeProducts<'_, '_, T, MASS_MATRIX>
{
    #[inline(always)]
    fn run(self) {
        derivative_products::<_, MASS_MATRIX>(self.model, self.b, self.v, self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{derivative_passes, rnea_derivatives_row_major, RowMajor};
    use super::*;
    use crate::io::bundled::floating_ur5_state;
    use crate::Data;

    /// A single call's passes, built for AVX2 and FMA where the processor has them, equal the
    /// baseline build of the same passes bit for bit (the claim of `one_state`).
    #[test]
    fn the_dispatched_passes_equal_the_baseline_build_bit_for_bit() {
        let (model, q, v, a) = floating_ur5_state();
        let nv = model.nv;
        let mut dispatched = vec![vec![0.0; nv * nv]; 2];
        let mut data = Data::new(&model);
        let [by_q, by_v] = &mut dispatched[..] else {
            unreachable!()
        };
        rnea_derivatives_row_major(&model, &mut data, (&q, &v, &a, None), by_q, by_v).unwrap();
        let mut baseline = vec![vec![0.0; nv * nv]; 2];
        let [by_q, by_v] = &mut baseline[..] else {
            unreachable!()
        };
        let mut rows = RowMajor { by_q, by_v, nv };
        let mut other = Data::new(&model);
        let mut buffers = DerivativeBuffers::of(&mut other);
        derivative_passes(&model, &mut buffers, (&q, &v, &a, None), &mut rows);
        assert_eq!(dispatched, baseline);
        assert_eq!(data.tau, other.tau);
    }
}
