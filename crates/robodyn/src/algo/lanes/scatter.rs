//! Rows into lanes and back. A group is held lane-interleaved (vector j holds entry j of each
//! state); the batch is row-major, one row per state, so taking a group's inputs from it and
//! putting its result back are transposes. Taken one lane at a time, the compiler renders them
//! as one gather or scatter per row piece (a load or store per value); a square tile of vectors
//! transposed in registers by shuffles (log₂ LANES stages, each exchanging one bit of the row
//! index with the same bit of the column index) and loaded or stored whole is several times
//! cheaper, which matters where results are large (a Talos derivative batch writes 4 332
//! numbers per state; `benchmarks/README.md`) and where the kernel is short (a Talos RNEA
//! gathers 115 numbers per state).

use crate::dispatch::multiversion;
use crate::spatial::Real;
use simba::simd::{AutoF64x4, AutoF64x8};

/// How a lane type is taken from rows and put back into them.
pub(super) trait LaneRows: Real {
    /// Entry j of row l of the row-major `rows` (width `size`), from `offset` on, = lane l of
    /// `lanes[j]` (`offset` places one block of a stacked result).
    fn scatter(lanes: &[Self], rows: &mut [f64], size: usize, offset: usize);

    /// Lane l of `lanes[j]` = entry j of row l of the row-major `rows` (`Self::LANES` rows of
    /// width `lanes.len()`).
    fn gather(rows: &[f64], lanes: &mut [Self]);
}

impl LaneRows for AutoF64x4 {
    #[inline(always)]
    fn scatter(lanes: &[Self], rows: &mut [f64], size: usize, offset: usize) {
        let tiled = scatter_four_tiles(lanes, rows, size, offset);
        scatter_by_lane(&lanes[tiled..], rows, size, offset + tiled)
    }

    #[inline(always)]
    fn gather(rows: &[f64], lanes: &mut [Self]) {
        let tiled = gather_four_tiles(rows, lanes);
        gather_by_lane(rows, lanes, tiled)
    }
}

impl LaneRows for AutoF64x8 {
    #[inline(always)]
    fn scatter(lanes: &[Self], rows: &mut [f64], size: usize, offset: usize) {
        let tiled = scatter_eight_tiles(lanes, rows, size, offset);
        scatter_by_lane(&lanes[tiled..], rows, size, offset + tiled)
    }

    #[inline(always)]
    fn gather(rows: &[f64], lanes: &mut [Self]) {
        let tiled = gather_eight_tiles(rows, lanes);
        gather_by_lane(rows, lanes, tiled)
    }
}

multiversion! {
    /// The whole 4 × 4 tiles of [`LaneRows::scatter`], transposed in registers where the CPU has
    /// AVX ([`crate::dispatch`]); returns how many columns they cover (none without).
    #[inline(always)]
    fn scatter_four_tiles(lanes: &[AutoF64x4], rows: &mut [f64], size: usize, offset: usize) -> usize {
        scatter_four_avx for ["avx"] => { x86::scatter_four(lanes, rows, size, offset) }
        baseline => { 0 }
    }
}

multiversion! {
    /// The whole 4 × 4 tiles of [`LaneRows::gather`], as [`scatter_four_tiles`].
    #[inline(always)]
    fn gather_four_tiles(rows: &[f64], lanes: &mut [AutoF64x4]) -> usize {
        gather_four_avx for ["avx"] => { x86::gather_four(rows, lanes) }
        baseline => { 0 }
    }
}

multiversion! {
    /// The whole 8 × 8 tiles of [`LaneRows::scatter`], transposed in registers where the CPU has
    /// AVX-512F; returns how many columns they cover (none without).
    #[inline(always)]
    fn scatter_eight_tiles(lanes: &[AutoF64x8], rows: &mut [f64], size: usize, offset: usize) -> usize {
        scatter_eight_avx512 for ["avx512f"] => { x86::scatter_eight(lanes, rows, size, offset) }
        baseline => { 0 }
    }
}

multiversion! {
    /// The whole 8 × 8 tiles of [`LaneRows::gather`], as [`scatter_eight_tiles`].
    #[inline(always)]
    fn gather_eight_tiles(rows: &[f64], lanes: &mut [AutoF64x8]) -> usize {
        gather_eight_avx512 for ["avx512f"] => { x86::gather_eight(rows, lanes) }
        baseline => { 0 }
    }
}

/// [`LaneRows::scatter`] one value at a time: any lane type, and the columns left after the
/// whole tiles.
#[inline(always)]
fn scatter_by_lane<S: Real>(lanes: &[S], rows: &mut [f64], size: usize, offset: usize) {
    for (j, lane) in lanes.iter().enumerate() {
        for l in 0..S::LANES {
            rows[l * size + offset + j] = lane.extract(l);
        }
    }
}

/// [`LaneRows::gather`] one value at a time, from column `first` on: any lane type, and the
/// columns left after the whole tiles.
#[inline(always)]
fn gather_by_lane<S: Real>(rows: &[f64], lanes: &mut [S], first: usize) {
    let size = lanes.len();
    for (j, lane) in lanes.iter_mut().enumerate().skip(first) {
        *lane = S::from_lanes(|l| rows[l * size + j]);
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use simba::simd::{AutoF64x4, AutoF64x8, AutoSimd};
    use std::arch::x86_64::*;

    /// A vector register of N lanes, loaded and stored whole, and an N × N tile of them
    /// transposed in registers. Safety (every method): only on a CPU with the register's
    /// instructions (inlined into callers compiled for them).
    trait Tile<const N: usize>: Copy {
        unsafe fn load(from: &[f64]) -> Self;
        unsafe fn store(self, to: &mut [f64]);
        /// Vector l of the result holds entry l of each vector given.
        unsafe fn transpose(tile: [Self; N]) -> [Self; N];
    }

    impl Tile<4> for __m256d {
        #[inline(always)]
        unsafe fn load(from: &[f64]) -> Self {
            _mm256_loadu_pd(from[..4].as_ptr())
        }

        #[inline(always)]
        unsafe fn store(self, to: &mut [f64]) {
            _mm256_storeu_pd(to[..4].as_mut_ptr(), self)
        }

        #[inline(always)]
        unsafe fn transpose([r0, r1, r2, r3]: [Self; 4]) -> [Self; 4] {
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
            [
                _mm256_unpacklo_pd(s0, s1),
                _mm256_unpackhi_pd(s0, s1),
                _mm256_unpacklo_pd(s2, s3),
                _mm256_unpackhi_pd(s2, s3),
            ]
        }
    }

    /// The stages of an 8 × 8 transpose: b, and the pairs of rows (i, i + b) it exchanges.
    const STAGES: [(usize, [(usize, usize); 4]); 3] = [
        (4, [(0, 4), (1, 5), (2, 6), (3, 7)]),
        (2, [(0, 2), (1, 3), (4, 6), (5, 7)]),
        (1, [(0, 1), (2, 3), (4, 5), (6, 7)]),
    ];

    /// For each stage of [`STAGES`], where row i (bit b clear) and row i + b take their entries
    /// from, as indices into the pair (row i, row i + b): `[low, high]`.
    const STAGE_INDICES: [[[i64; 8]; 2]; 3] = {
        let mut indices = [[[0; 8]; 2]; 3];
        let mut stage = 0;
        while stage < 3 {
            let b = STAGES[stage].0;
            let mut c = 0;
            while c < 8 {
                let (low, high) = match c & b == 0 {
                    true => (c, c + b),
                    false => (c - b + 8, c + 8),
                };
                indices[stage][0][c] = low as i64;
                indices[stage][1][c] = high as i64;
                c += 1;
            }
            stage += 1;
        }
        indices
    };

    impl Tile<8> for __m512d {
        #[inline(always)]
        unsafe fn load(from: &[f64]) -> Self {
            _mm512_loadu_pd(from[..8].as_ptr())
        }

        #[inline(always)]
        unsafe fn store(self, to: &mut [f64]) {
            _mm512_storeu_pd(to[..8].as_mut_ptr(), self)
        }

        #[inline(always)]
        unsafe fn transpose(mut r: [Self; 8]) -> [Self; 8] {
            // exchange row bit b with column bit b, b = 4, 2, 1
            for ((_, pairs), [low, high]) in STAGES.iter().zip(&STAGE_INDICES) {
                let low = _mm512_loadu_si512(low.as_ptr().cast());
                let high = _mm512_loadu_si512(high.as_ptr().cast());
                for &(i, j) in pairs {
                    let (x, y) = (r[i], r[j]);
                    r[i] = _mm512_permutex2var_pd(x, low, y);
                    r[j] = _mm512_permutex2var_pd(x, high, y);
                }
            }
            r
        }
    }

    /// The whole N × N tiles of [`super::LaneRows::scatter`]; returns how many columns they cover.
    #[inline(always)]
    unsafe fn scatter_tiles<V: Tile<N>, const N: usize>(
        lanes: &[AutoSimd<[f64; N]>],
        rows: &mut [f64],
        size: usize,
        offset: usize,
    ) -> usize {
        let rows = &mut rows[..N * size];
        let tiles = lanes.chunks_exact(N);
        let tiled = N * tiles.len();
        for (t, tile) in tiles.enumerate() {
            let tile = std::array::from_fn(|j| V::load(&tile[j].0));
            for (l, row) in V::transpose(tile).into_iter().enumerate() {
                row.store(&mut rows[l * size + offset + N * t..]);
            }
        }
        tiled
    }

    /// The whole N × N tiles of [`super::LaneRows::gather`]; returns how many columns they cover.
    #[inline(always)]
    unsafe fn gather_tiles<V: Tile<N>, const N: usize>(
        rows: &[f64],
        lanes: &mut [AutoSimd<[f64; N]>],
    ) -> usize {
        let size = lanes.len();
        let rows = &rows[..N * size];
        let tiles = lanes.chunks_exact_mut(N);
        let tiled = N * tiles.len();
        for (t, tile) in tiles.enumerate() {
            let pieces = std::array::from_fn(|l| V::load(&rows[l * size + N * t..]));
            for (lane, vector) in tile.iter_mut().zip(V::transpose(pieces)) {
                vector.store(&mut lane.0);
            }
        }
        tiled
    }

    /// [`scatter_tiles`] of 4 × 4. Safety: only on a CPU with AVX, inlined into a function
    /// built for it.
    #[inline(always)]
    pub(super) unsafe fn scatter_four(
        lanes: &[AutoF64x4],
        rows: &mut [f64],
        size: usize,
        offset: usize,
    ) -> usize {
        scatter_tiles::<__m256d, 4>(lanes, rows, size, offset)
    }

    /// [`gather_tiles`] of 4 × 4. Safety: as [`scatter_four`].
    #[inline(always)]
    pub(super) unsafe fn gather_four(rows: &[f64], lanes: &mut [AutoF64x4]) -> usize {
        gather_tiles::<__m256d, 4>(rows, lanes)
    }

    /// [`scatter_tiles`] of 8 × 8. Safety: only on a CPU with AVX-512F, inlined into a function
    /// built for it.
    #[inline(always)]
    pub(super) unsafe fn scatter_eight(
        lanes: &[AutoF64x8],
        rows: &mut [f64],
        size: usize,
        offset: usize,
    ) -> usize {
        scatter_tiles::<__m512d, 8>(lanes, rows, size, offset)
    }

    /// [`gather_tiles`] of 8 × 8. Safety: as [`scatter_eight`].
    #[inline(always)]
    pub(super) unsafe fn gather_eight(rows: &[f64], lanes: &mut [AutoF64x8]) -> usize {
        gather_tiles::<__m512d, 8>(rows, lanes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane type's scatter (the register transposes where the CPU has them) equals the value
    /// by value one, for widths with and without whole tiles and at an offset into the rows.
    fn equals_by_lane<S: LaneRows>() {
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

    /// Each lane type's gather (the register transposes where the CPU has them) equals the value
    /// by value one, for widths with and without whole tiles.
    fn gather_equals_by_lane<S: LaneRows>() {
        for size in [1, 3, 4, 8, 17, 39, 40] {
            let rows: Vec<f64> = (0..S::LANES * size).map(|k| k as f64 + 0.5).collect();
            let mut tiled = vec![S::splat(-1.0); size];
            S::gather(&rows, &mut tiled);
            let mut by_lane = vec![S::splat(-1.0); size];
            gather_by_lane(&rows, &mut by_lane, 0);
            assert_eq!(tiled, by_lane, "{} lanes, {size} values", S::LANES);
            // and the scatter puts the rows back
            let mut back = vec![0.0; rows.len()];
            S::scatter(&tiled, &mut back, size, 0);
            assert_eq!(back, rows, "{} lanes, {size} values", S::LANES);
        }
    }

    #[test]
    fn gather_equals_the_value_by_value_gather() {
        gather_equals_by_lane::<AutoF64x4>();
        gather_equals_by_lane::<AutoF64x8>();
    }
}
