//! sin and cos of a joint angle in arithmetic alone, so that a batch kernel computes them in
//! vector lanes (a library call per lane would cost as much as the rest of the kernel) and a
//! one-state call gets the same digits from the same operations.
//!
//! Method (Cody & Waite 1980; the kernels of Sun's fdlibm, 1993): reduce x by the nearest
//! multiple n of π/2, r = x − n π/2 with π/2 split in three parts (each product n·part exact for
//! |n| < 2²⁰), evaluate the minimax polynomials of sin and cos on |r| ≤ π/4 (error below 2⁻⁵⁸),
//! and pick and sign them by the quadrant n mod 4. Accurate to an ulp or so; beyond
//! [`REDUCTION_LIMIT`] the library's sin and cos are used.

// the constants are written as published, to 21 digits; each rounds to the intended double
#![allow(clippy::excessive_precision)]

use super::Real;
use crate::dispatch::multiversion;
use nalgebra::SimdBool;
#[cfg(target_arch = "x86_64")]
use simba::simd::{AutoF64x4, AutoF64x8};

/// Largest |x| the three-part reduction handles (|n| < 2²⁰ with margin); beyond it, and for
/// non-finite x, the standard library's functions answer.
pub const REDUCTION_LIMIT: f64 = 1e5;

/// π/2 in three parts of 33 significant bits (fdlibm's `pio2_1`, `pio2_2`, `pio2_3`).
const HALF_PI: [f64; 3] = [
    1.570_796_326_734_125_614_17,
    6.077_100_506_506_192_249_32e-11,
    2.022_266_248_711_166_455_80e-21,
];

/// sin r = r + r³ (S1 + r² (S2 + ... + r² S6)) on |r| ≤ π/4 (fdlibm `k_sin.c`).
const SIN: [f64; 6] = [
    -1.666_666_666_666_663_243_48e-1,
    8.333_333_333_322_489_461_24e-3,
    -1.984_126_982_985_794_931_34e-4,
    2.755_731_370_707_006_767_89e-6,
    -2.505_076_025_340_686_341_95e-8,
    1.589_690_995_211_550_102_21e-10,
];

/// cos r = 1 − r²/2 + r⁴ (C1 + r² (C2 + ... + r² C6)) on |r| ≤ π/4 (fdlibm `k_cos.c`).
const COS: [f64; 6] = [
    4.166_666_666_666_660_190_37e-2,
    -1.388_888_888_887_410_957_49e-3,
    2.480_158_728_947_672_941_78e-5,
    -2.755_731_435_139_066_330_35e-7,
    2.087_572_321_298_174_827_90e-9,
    -1.135_964_755_778_819_482_65e-11,
];

/// Adding and subtracting 1.5·2⁵² rounds a float below 2⁵¹ in magnitude to the nearest integer.
const ROUNDING: f64 = 6_755_399_441_055_744.0;

/// `(sin x, cos x)`, in every lane at once.
#[inline(always)]
pub fn sin_cos<S: Real>(x: S) -> (S, S) {
    let splat = S::splat;
    // n = round(x 2/π), r = x − n π/2
    let n = (x * splat(std::f64::consts::FRAC_2_PI) + splat(ROUNDING)) - splat(ROUNDING);
    let r = ((x - n * splat(HALF_PI[0])) - n * splat(HALF_PI[1])) - n * splat(HALF_PI[2]);
    let z = r * r;
    // c0 + c1 z + ... + c5 z⁵ by Estrin's scheme, (c0 + c1 z) + z² ((c2 + c3 z) + z² (c4 + c5 z)):
    // half the dependent steps of Horner's rule, so a joint's sine waits less for its polynomial
    let z2 = z * z;
    let polynomial = |c: &[f64; 6]| {
        let pair = |k: usize| splat(c[k]) + splat(c[k + 1]) * z;
        pair(0) + z2 * (pair(2) + z2 * pair(4))
    };
    let sin_r = r + r * z * polynomial(&SIN);
    // 1 − z/2 rounded, and what that rounding lost added back
    let half_z = splat(0.5) * z;
    let w = splat(1.0) - half_z;
    let cos_r = w + (((splat(1.0) - w) - half_z) + z2 * polynomial(&COS));
    // quadrant k = n mod 4: (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s); for an integer n,
    // floor(n/4) is (n − 1.5)/4 rounded, which is never a tie (no library floor call)
    let quarter = ((n - splat(1.5)) * splat(0.25) + splat(ROUNDING)) - splat(ROUNDING);
    let k = n - splat(4.0) * quarter;
    let odd = k.simd_eq(splat(1.0)) | k.simd_eq(splat(3.0));
    let (sin, cos) = (cos_r.select(odd, sin_r), sin_r.select(odd, cos_r));
    let sin = (-sin).select(k.simd_ge(splat(2.0)), sin);
    let cos = (-cos).select(k.simd_eq(splat(1.0)) | k.simd_eq(splat(2.0)), cos);
    // the lanes beyond the reduction's range from the library, each lane on its own
    let beyond = x.simd_abs().simd_gt(splat(REDUCTION_LIMIT));
    if beyond.any() {
        let (sin_far, cos_far) = x.simd_sin_cos();
        return (sin_far.select(beyond, sin), cos_far.select(beyond, cos));
    }
    (sin, cos)
}

multiversion! {
    /// `out[k] = (sin, cos)` of `q[indices[k]]`: several values per evaluation in vector lanes
    /// where the CPU has them (each lane gets the digits of [`sin_cos`] of its value alone), else
    /// one by one. A joint's sine costs as much as the rest of its transform; four at once halve
    /// a forward kinematics' time spent on them. With AVX-512, eight indices at a time while more
    /// than four are left, then four in AVX2 lanes (an evaluation in eight lanes costs about two
    /// in four, so a group of four or fewer takes four); with AVX2, four at a time.
    #[inline(never)]
    pub fn sin_cos_at(q: &[f64], indices: &[usize], out: &mut [(f64, f64)]) {
        sin_cos_at_avx512 for ["avx512f"] => {
            let mut start = 0;
            while indices.len() - start > 4 {
                let end = indices.len().min(start + 8);
                sin_cos_in_lanes::<AutoF64x8, 8>(q, &indices[start..end], &mut out[start..end]);
                start = end;
            }
            if start < indices.len() {
                sin_cos_in_lanes::<AutoF64x4, 4>(q, &indices[start..], &mut out[start..]);
            }
        }
        sin_cos_at_avx2 for ["avx2"] => {
            for (group, turns) in indices.chunks(4).zip(out.chunks_mut(4)) {
                sin_cos_in_lanes::<AutoF64x4, 4>(q, group, turns);
            }
        }
        baseline => { sin_cos_one_by_one(q, indices, out) }
    }
}

/// [`sin_cos_at`] one value at a time, in `f64` or lanes.
#[inline(always)]
pub(crate) fn sin_cos_one_by_one<S: Real>(q: &[S], indices: &[usize], out: &mut [(S, S)]) {
    for (turn, &index) in out.iter_mut().zip(indices) {
        *turn = sin_cos(q[index]);
    }
}

/// `turns[k] = (sin, cos)` of `q[group[k]]` for up to `N` indices, in one evaluation in `N`
/// lanes (the lanes beyond the group's end hold zeros).
#[inline(always)]
fn sin_cos_in_lanes<V, const N: usize>(q: &[f64], group: &[usize], turns: &mut [(f64, f64)])
where
    V: Real + From<[f64; N]>,
    [f64; N]: From<V>,
{
    let x = V::from(std::array::from_fn(|lane| {
        group.get(lane).map_or(0.0, |&index| q[index])
    }));
    let (sin, cos) = sin_cos(x);
    let (sin, cos) = (<[f64; N]>::from(sin), <[f64; N]>::from(cos));
    for (lane, turn) in turns.iter_mut().enumerate() {
        *turn = (sin[lane], cos[lane]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use simba::simd::AutoF64x4;

    /// Both within this many units in the last place of 1 of the library's values.
    const ULPS: f64 = 2.0;

    fn check(x: f64) {
        let (sin, cos) = sin_cos(x);
        let (sin_ref, cos_ref) = x.sin_cos();
        let tolerance = ULPS * f64::EPSILON;
        assert!(
            (sin - sin_ref).abs() <= tolerance,
            "sin({x}) = {sin} != {sin_ref}"
        );
        assert!(
            (cos - cos_ref).abs() <= tolerance,
            "cos({x}) = {cos} != {cos_ref}"
        );
    }

    #[test]
    fn agrees_with_the_library_to_an_ulp() {
        for k in -400_000..=400_000 {
            check(k as f64 * 2.5e-4);
        }
        for k in 0..200 {
            let quarter = k as f64 * std::f64::consts::FRAC_PI_4;
            for x in [quarter, -quarter, quarter + 1e-9, quarter - 1e-12] {
                check(x);
            }
        }
        for x in [
            0.0, -0.0, 1e-300, -1e-20, 123.456, 9.99e4, -9.99e4, 1e5, 3e5, 1e300,
        ] {
            check(x);
        }
        assert!(sin_cos(f64::NAN).0.is_nan() && sin_cos(f64::INFINITY).1.is_nan());
    }

    #[test]
    fn values_gathered_in_lanes_equal_one_value_bit_for_bit() {
        let q = [
            0.3,
            -2.9,
            7.1,
            2.0e5,
            1e-9,
            -0.0,
            3.0,
            std::f64::consts::FRAC_PI_2,
            -4.0,
        ];
        let indices = [8, 0, 3, 3, 5, 1, 2, 7, 6, 4];
        // every count of indices (whole and partial groups of four and eight), by the run-time
        // choice, each lane width the processor has, and the fallback
        for count in 0..=indices.len() {
            let indices = &indices[..count];
            let mut outs = vec![[(0.0, 0.0); 10]; 2];
            sin_cos_at(&q, indices, &mut outs[0][..count]);
            sin_cos_one_by_one(&q, indices, &mut outs[1][..count]);
            #[cfg(target_arch = "x86_64")]
            {
                if std::arch::is_x86_feature_detected!("avx2") {
                    let mut out = [(0.0, 0.0); 10];
                    // SAFETY: the processor has AVX2, just checked.
                    unsafe { sin_cos_at_avx2(&q, indices, &mut out[..count]) };
                    outs.push(out);
                }
                if std::arch::is_x86_feature_detected!("avx512f") {
                    let mut out = [(0.0, 0.0); 10];
                    // SAFETY: the processor has AVX-512F, just checked.
                    unsafe { sin_cos_at_avx512(&q, indices, &mut out[..count]) };
                    outs.push(out);
                }
            }
            for out in outs {
                for (k, &index) in indices.iter().enumerate() {
                    let (s, c) = sin_cos(q[index]);
                    assert_eq!(
                        (out[k].0.to_bits(), out[k].1.to_bits()),
                        (s.to_bits(), c.to_bits()),
                        "q[{index}] = {} of {count}",
                        q[index]
                    );
                }
            }
        }
    }

    #[test]
    fn lanes_equal_one_value_bit_for_bit() {
        let x = AutoF64x4::from([0.3, -2.9, 7.1, 2.0e5]);
        let (sin, cos) = sin_cos(x);
        for l in 0..4 {
            let (s, c) = sin_cos(x.0[l]);
            assert_eq!(
                (sin.0[l].to_bits(), cos.0[l].to_bits()),
                (s.to_bits(), c.to_bits())
            );
        }
    }
}
