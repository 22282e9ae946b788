//! Lanes back into rows. A group's result is held lane-interleaved (vector j holds entry j of
//! each state); the output is row-major, one row per state, so putting it back is a transpose.
//! Taken one lane at a time, the compiler renders it as one gather per row piece; a square tile
//! of lane vectors transposed in registers by shuffles (log₂ LANES stages, each exchanging one
//! bit of the row index with the same bit of the column index) and stored whole row by row is
//! several times cheaper, which matters where results are large (a Talos derivative batch
//! writes 4 332 numbers per state; `benchmarks/README.md`).

use crate::spatial::Real;
use simba::simd::{AutoF64x4, AutoF64x8};

/// How a lane type is put back into rows.
pub(super) trait Scatter: Real {
    /// Entry j of row l of the row-major `rows` (width `size`), from `offset` on, = lane l of
    /// `lanes[j]` (`offset` places one block of a stacked result).
    fn scatter(lanes: &[Self], rows: &mut [f64], size: usize, offset: usize);
}

impl Scatter for AutoF64x4 {
    #[inline(always)]
    fn scatter(lanes: &[Self], rows: &mut [f64], size: usize, offset: usize) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX
            let tiled = unsafe { x86::scatter_four(lanes, rows, size, offset) };
            return scatter_by_lane(&lanes[tiled..], rows, size, offset + tiled);
        }
        scatter_by_lane(lanes, rows, size, offset)
    }
}

impl Scatter for AutoF64x8 {
    #[inline(always)]
    fn scatter(lanes: &[Self], rows: &mut [f64], size: usize, offset: usize) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F
            let tiled = unsafe { x86::scatter_eight(lanes, rows, size, offset) };
            return scatter_by_lane(&lanes[tiled..], rows, size, offset + tiled);
        }
        scatter_by_lane(lanes, rows, size, offset)
    }
}

/// [`Scatter::scatter`] one value at a time: any lane type, and the columns left after the
/// whole tiles.
#[inline(always)]
fn scatter_by_lane<S: Real>(lanes: &[S], rows: &mut [f64], size: usize, offset: usize) {
    for (j, lane) in lanes.iter().enumerate() {
        for l in 0..S::LANES {
            rows[l * size + offset + j] = lane.extract(l);
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use simba::simd::{AutoF64x4, AutoF64x8};
    use std::arch::x86_64::*;

    /// The whole 4 × 4 tiles of [`super::Scatter::scatter`]; returns how many columns they cover.
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn scatter_four(
        lanes: &[AutoF64x4],
        rows: &mut [f64],
        size: usize,
        offset: usize,
    ) -> usize {
        let rows = &mut rows[..4 * size];
        let tiles = lanes.chunks_exact(4);
        let tiled = 4 * tiles.len();
        for (t, tile) in tiles.enumerate() {
            let [r0, r1, r2, r3] = std::array::from_fn(|j| _mm256_loadu_pd(tile[j].0.as_ptr()));
            // exchange row bit 1 with column bit 1: 2 × 2 blocks of 2 × 2
            let (s0, s2) = (
                _mm256_permute2f128_pd::<0x20>(r0, r2),
                _mm256_permute2f128_pd::<0x31>(r0, r2),
            );
            let (s1, s3) = (
                _mm256_permute2f128_pd::<0x20>(r1, r3),
                _mm256_permute2f128_pd::<0x31>(r1, r3),
            );
            // exchange row bit 0 with column bit 0
            let transposed = [
                _mm256_unpacklo_pd(s0, s1),
                _mm256_unpackhi_pd(s0, s1),
                _mm256_unpacklo_pd(s2, s3),
                _mm256_unpackhi_pd(s2, s3),
            ];
            for (l, row) in transposed.into_iter().enumerate() {
                let start = l * size + offset + 4 * t;
                _mm256_storeu_pd(rows[start..start + 4].as_mut_ptr(), row);
            }
        }
        tiled
    }

    /// The stages of an 8 × 8 transpose: b, and the pairs of rows (i, i + b) it exchanges.
    const STAGES: [(usize, [(usize, usize); 4]); 3] = [
        (4, [(0, 4), (1, 5), (2, 6), (3, 7)]),
        (2, [(0, 2), (1, 3), (4, 6), (5, 7)]),
        (1, [(0, 1), (2, 3), (4, 5), (6, 7)]),
    ];

    /// The whole 8 × 8 tiles of [`super::Scatter::scatter`]; returns how many columns they cover.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn scatter_eight(
        lanes: &[AutoF64x8],
        rows: &mut [f64],
        size: usize,
        offset: usize,
    ) -> usize {
        let rows = &mut rows[..8 * size];
        let tiles = lanes.chunks_exact(8);
        let tiled = 8 * tiles.len();
        // for each stage b: where row i (bit b clear) and row i + b take their entries from, as
        // indices into the pair (row i, row i + b), and the pairs
        let stages = STAGES.map(|(b, pairs)| {
            let from = |c: usize, high: bool| match (c & b == 0, high) {
                (true, false) => c,
                (false, false) => c - b + 8,
                (true, true) => c + b,
                (false, true) => c + 8,
            };
            let indices = |high| std::array::from_fn::<i64, 8, _>(|c| from(c, high) as i64);
            let (low, high) = (indices(false), indices(true));
            (
                pairs,
                _mm512_loadu_si512(low.as_ptr().cast()),
                _mm512_loadu_si512(high.as_ptr().cast()),
            )
        });
        for (t, tile) in tiles.enumerate() {
            let mut r: [__m512d; 8] = std::array::from_fn(|j| _mm512_loadu_pd(tile[j].0.as_ptr()));
            // exchange row bit b with column bit b, b = 4, 2, 1
            for (pairs, low, high) in stages {
                for (i, j) in pairs {
                    let (x, y) = (r[i], r[j]);
                    r[i] = _mm512_permutex2var_pd(x, low, y);
                    r[j] = _mm512_permutex2var_pd(x, high, y);
                }
            }
            for (l, row) in r.into_iter().enumerate() {
                let start = l * size + offset + 8 * t;
                _mm512_storeu_pd(rows[start..start + 8].as_mut_ptr(), row);
            }
        }
        tiled
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane type's scatter (the register transposes where the CPU has them) equals the value
    /// by value one, for widths with and without whole tiles and at an offset into the rows.
    fn equals_by_lane<S: Scatter>() {
        for (count, size, offset) in [(3, 3, 0), (8, 8, 0), (17, 40, 5), (36, 108, 72)] {
            let lanes: Vec<S> = (0..count)
                .map(|j| S::from_lanes(|l| (100 * j + l) as f64 + 0.25))
                .collect();
            let mut tiled = vec![-1.0; S::LANES * size];
            S::scatter(&lanes, &mut tiled, size, offset);
            let mut by_lane = vec![-1.0; S::LANES * size];
            scatter_by_lane(&lanes, &mut by_lane, size, offset);
            assert_eq!(tiled, by_lane, "{} lanes, {count} values", S::LANES);
        }
    }

    #[test]
    fn scatter_equals_the_value_by_value_scatter() {
        equals_by_lane::<AutoF64x4>();
        equals_by_lane::<AutoF64x8>();
    }
}
