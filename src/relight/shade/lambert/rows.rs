//! The lighting's rows as a frame's dot products gather them ([`LightRows`]).

use crate::Sample;
use crate::relight::light::lighting::Lighting;

use super::sum_runs;

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
/// (a zero row is zero either way), so are the sums (tested).
#[derive(Debug)]
pub(crate) enum LightRows<T: Sample> {
    /// Every row, padded to a power of two (`rows[i & (len - 1)]`).
    Dense(Vec<T::Quad>),
    /// `rows[slots[i & (len - 1)]]`: `slots` padded to a power of two, slot 0 the zero row.
    Compact {
        slots: Vec<u8>,
        rows: Box<[T::Quad; SLOTS]>,
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
        let mut slots = vec![0u8; dense.len()];
        let mut rows = Box::new([T::Quad::default(); SLOTS]);
        for (k, &i) in nonzero.iter().enumerate() {
            // Slot k + 1 <= 255: fewer than SLOTS rows are non-zero.
            slots[i] = (k + 1) as u8;
            rows[k + 1] = dense[i];
        }
        LightRows::Compact { slots, rows }
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
            LightRows::Compact { slots, rows } => {
                let mask = slots.len() - 1;
                sum_runs::<T, _, _>(a, b, |x, y| {
                    rows[usize::from(slots[index(x) & mask])] * value(y)
                })
            }
        }
    }
}
