//! The lighting's rows as a frame's dot products gather them ([`LightRows`]).

use crate::light::lighting::Lighting;
use haarshift::Sample;

use super::lit::LitTexels;
use super::{LANES, RUN, add_run, sum_runs};

/// Rows in the compact table: slot 0 the zero row, then up to 255 non-zero rows.
const SLOTS: usize = 256;

/// The lighting's RGB rows (four lanes each), as [`gather`](Self::gather) reads them at a
/// vertex's coefficient indices.
///
/// **Why two forms.** A vertex's indices are spread over every texel, so each coefficient is
/// one read at a random row. For a 6 x 64^2 cube the rows are 393 KB in f32: more than the
/// first-level cache holds, so those reads, not the arithmetic, set a frame's time. A lighting
/// truncated to its largest coefficients (200 of 24,576 in the viewer) has few non-zero rows:
/// then each index maps through a byte per texel (24 KB for the cube) to one of 256 rows
/// (4 KB), two reads that stay in the first-level cache. The products are the same numbers
/// (a zero row is zero either way), so are the sums (tested). A compact table also knows
/// which texels are lit ([`LitTexels`]): [`dot`](Self::dot) then visits only the terms that
/// meet a non-zero row.
#[derive(Debug)]
pub(crate) enum LightRows<T: Sample> {
    /// Every row, padded to a power of two (`rows[i & (len - 1)]`).
    Dense(Vec<T::Quad>),
    /// `rows[slots[i & (len - 1)]]`: `slots` padded to a power of two, slot 0 the zero row;
    /// `lit` the texels of the other slots.
    Compact {
        slots: Vec<u8>,
        rows: Box<[T::Quad; SLOTS]>,
        lit: LitTexels,
    },
}

impl<T: Sample> LightRows<T> {
    /// The rows of `lighting` in `T`, compact when at most 255 are non-zero.
    pub(crate) fn new(lighting: &Lighting) -> Self {
        let dense = lighting.quads::<T>();
        let nonzero: Vec<usize> = (0..dense.len())
            .filter(|&i| T::first_three(dense[i]).iter().any(|x| *x != T::zero()))
            .collect();
        if nonzero.len() >= SLOTS {
            return LightRows::Dense(dense);
        }
        let lit = LitTexels::new(dense.len(), nonzero.iter().copied());
        let mut slots = vec![0u8; dense.len()];
        let mut rows = Box::new([T::Quad::default(); SLOTS]);
        for (k, &i) in nonzero.iter().enumerate() {
            // Slot k + 1 <= 255: fewer than SLOTS rows are non-zero.
            slots[i] = (k + 1) as u8;
            rows[k + 1] = dense[i];
        }
        LightRows::Compact { slots, rows, lit }
    }

    /// `sum_k value(b_k) rows[index(a_k)]` per channel, by [`sum_runs`]: `index` is called
    /// once per term, in order.
    #[inline(always)]
    pub(crate) fn gather<A: Copy, B: Copy>(
        &self,
        a: &[A],
        b: &[B],
        mut index: impl FnMut(A) -> usize,
        value: impl Fn(B) -> T,
    ) -> [f64; 3] {
        match self {
            LightRows::Dense(rows) => {
                let mask = rows.len() - 1;
                sum_runs::<T, _, _>(a, b, |x, y| rows[index(x) & mask] * value(y))
            }
            LightRows::Compact { slots, rows, .. } => {
                let mask = slots.len() - 1;
                sum_runs::<T, _, _>(a, b, |x, y| {
                    rows[usize::from(slots[index(x) & mask])] * value(y)
                })
            }
        }
    }

    /// `sum_k values[k] rows[indices[k]]` per channel: [`gather`](Self::gather)'s sums, bit
    /// for bit, with `buffers` kept from vertex to vertex.
    ///
    /// Compact rows visit only the lit terms ([`LitTexels::positions`]), each added to the
    /// accumulator it has in [`sum_runs`] (lane `k % LANES` of run `k / RUN`, every run's
    /// accumulators kept apart, so no branch waits on where a run ends); the runs are then
    /// added in order. Why the sums do not change: a term at an unlit texel is
    /// `0 x value = ±0` (the transport is finite: checked when it is made or read), and adding
    /// ±0 changes no accumulator's bits, since an accumulator starts at +0 and a sum that
    /// cancels rounds to +0, never -0.
    #[inline(always)]
    pub(crate) fn dot(
        &self,
        indices: &[u32],
        values: &[T],
        buffers: &mut DotBuffers<T>,
    ) -> [f64; 3] {
        let LightRows::Compact { slots, rows, lit } = self else {
            return self.gather(indices, values, |i| i as usize, |t| t);
        };
        let n = lit.positions(indices, &mut buffers.positions);
        let mask = slots.len() - 1;
        let acc = &mut buffers.runs;
        acc.clear();
        acc.resize(indices.len().div_ceil(RUN) * LANES, T::Quad::default());
        for &k in &buffers.positions[..n] {
            let k = k as usize;
            acc[k / RUN * LANES + k % LANES] +=
                rows[usize::from(slots[indices[k] as usize & mask])] * values[k];
        }
        let mut total = [0.0; 3];
        for run in acc.as_chunks::<LANES>().0 {
            add_run::<T>(&mut total, *run);
        }
        total
    }
}

/// What [`LightRows::dot`] keeps from vertex to vertex: the positions of the lit terms and
/// the runs' accumulators.
#[derive(Debug, Default)]
pub(crate) struct DotBuffers<T: Sample> {
    positions: Vec<u32>,
    runs: Vec<T::Quad>,
}
