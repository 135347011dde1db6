//! Which of a vertex's terms meet a non-zero lighting row ([`LitTexels`]).

/// A bit per texel, set where the lighting's row is non-zero: what a frame tests each of a
/// vertex's coefficient indices against before it gathers anything.
///
/// **Why.** A lighting truncated to its largest coefficients (200 of 24,576 in the viewer)
/// meets few of a vertex's coefficients: 6.6% of the cubes scene's (the `relight` bench
/// prints the share). Finding those terms first, sixteen indices at a time, and then summing
/// only them leaves a frame little to do beyond reading its transport
/// (`results/relight/frame_floor.md`). With AVX-512 the sixteen tests are one gather from this
/// table (4 KB for a 6 x 64^2 cube, its 24,576 texels padded to 32,768: it stays in the
/// first-level cache) and the positions found are packed with one compress; without it they
/// are tested one at a time. Both find the same positions (tested).
#[derive(Debug)]
pub(crate) struct LitTexels {
    words: Vec<u32>,
    /// Whether the CPU can test sixteen at a time (asked once, not per vertex).
    wide: bool,
    /// `32 x words.len() - 1`: a valid index `i` equals `i & mask` (no bounds check).
    mask: usize,
}

impl LitTexels {
    /// The lit texels among `texels` (a power of two), given in any order.
    pub(crate) fn new(texels: usize, lit: impl IntoIterator<Item = usize>) -> Self {
        debug_assert!(texels.is_power_of_two());
        let bits = texels.max(32);
        let mut words = vec![0u32; bits / 32];
        for i in lit {
            words[i >> 5] |= 1 << (i & 31);
        }
        #[cfg(target_arch = "x86_64")]
        let wide = std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("popcnt");
        #[cfg(not(target_arch = "x86_64"))]
        let wide = false;
        LitTexels {
            words,
            wide,
            mask: bits - 1,
        }
    }

    /// Whether texel `i` is lit.
    #[inline(always)]
    fn contains(&self, i: u32) -> bool {
        let i = i as usize & self.mask;
        (self.words[i >> 5] >> (i & 31)) & 1 != 0
    }

    /// The positions `k` at which `indices[k]` is lit, ascending, written to `out[..n]`; returns
    /// `n`. `out` is grown to `indices.len() + 16` entries when shorter and never cleared:
    /// the caller keeps it from vertex to vertex, and only `out[..n]` means anything.
    pub(crate) fn positions(&self, indices: &[u32], out: &mut Vec<u32>) -> usize {
        let room = indices.len() + 16;
        if out.len() < room {
            out.resize(room, 0);
        }
        if self.wide {
            // SAFETY: the CPU has the two features `positions_avx512` is compiled for (`wide`
            // is never set elsewhere), and `out` has room for `indices.len() + 16` positions.
            #[cfg(target_arch = "x86_64")]
            return unsafe { self.positions_avx512(indices, out) };
        }
        self.positions_one_at_a_time(indices, 0, 0, out)
    }

    /// [`positions`](Self::positions) from `indices[start..]` on, `n` found before.
    fn positions_one_at_a_time(
        &self,
        indices: &[u32],
        start: usize,
        mut n: usize,
        out: &mut [u32],
    ) -> usize {
        for (k, &i) in indices.iter().enumerate().skip(start) {
            // Written whether or not it is lit, kept only if it is: no branch to mispredict.
            out[n] = k as u32;
            n += usize::from(self.contains(i));
        }
        n
    }

    /// [`positions`](Self::positions), sixteen indices at a time.
    ///
    /// # Safety
    /// `out.len() >= indices.len() + 16` (each group stores sixteen lanes past the positions
    /// found so far).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,popcnt")]
    unsafe fn positions_avx512(&self, indices: &[u32], out: &mut [u32]) -> usize {
        use std::arch::x86_64::{
            _mm512_add_epi32, _mm512_and_si512, _mm512_i32gather_epi32, _mm512_loadu_si512,
            _mm512_maskz_compress_epi32, _mm512_set1_epi32, _mm512_setr_epi32, _mm512_srli_epi32,
            _mm512_srlv_epi32, _mm512_storeu_si512, _mm512_test_epi32_mask,
        };
        let mask = _mm512_set1_epi32(self.mask as i32);
        let (low5, one) = (_mm512_set1_epi32(31), _mm512_set1_epi32(1));
        let lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
        let (groups, _) = indices.as_chunks::<16>();
        let mut n = 0;
        for (g, group) in groups.iter().enumerate() {
            // SAFETY: sixteen u32 read from `group`.
            let i = _mm512_and_si512(unsafe { _mm512_loadu_si512(group.as_ptr().cast()) }, mask);
            // SAFETY: `(i & mask) >> 5 < words.len()`.
            let words = unsafe {
                _mm512_i32gather_epi32::<4>(_mm512_srli_epi32::<5>(i), self.words.as_ptr().cast())
            };
            let lit =
                _mm512_test_epi32_mask(_mm512_srlv_epi32(words, _mm512_and_si512(i, low5)), one);
            // Positions of an index slice fit i32: it is one vertex's coefficients (< texels).
            let k = _mm512_add_epi32(lanes, _mm512_set1_epi32((16 * g) as i32));
            // SAFETY: n <= 16 g, so sixteen lanes from n end within `out` (the caller's room).
            unsafe {
                _mm512_storeu_si512(
                    out.as_mut_ptr().add(n).cast(),
                    _mm512_maskz_compress_epi32(lit, k),
                )
            };
            n += lit.count_ones() as usize;
        }
        self.positions_one_at_a_time(indices, 16 * groups.len(), n, out)
    }
}

#[cfg(test)]
#[path = "lit_tests.rs"]
mod tests;
