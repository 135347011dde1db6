//! Many sparse Haar functions in three flat arrays: what the transport of every vertex, the
//! sample maps of an occlusion field and the fixed products of just-in-time radiance transfer
//! all are.
//!
//! Row `r` is a run of `(index, value)` pairs: `indices[offsets[r]..offsets[r + 1]]` are
//! face-Mallat positions (`face x S^2 + row x S + col`, the layout of
//! [`TransportSet`](crate::TransportSet)) and `values` the matching coefficients (one channel
//! as `f32`, or several as an array). No allocation per row. The arrays may be read in place
//! from a memory-mapped file (a scene cache's transport, [`crate::mapped`]): reading a row
//! is the same either way, and appending a row copies a mapped array first.

use crate::mapped::Buffer;

/// Rows of sparse coefficients; see the [module docs](self).
///
/// ```
/// use haarshift_relight::precompute::sparse::SparseRows;
/// let mut rows = SparseRows::<f32>::new();
/// rows.push(&[0, 5], &[2.0, -1.0]);
/// rows.push(&[], &[]);
/// assert_eq!(rows.len(), 2);
/// assert_eq!(rows.row(0), (&[0u32, 5][..], &[2.0f32, -1.0][..]));
/// assert_eq!(rows.row(1).0.len(), 0);
/// assert_eq!(rows.coefficient_count(), 2);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SparseRows<V> {
    offsets: Buffer<u64>,
    indices: Buffer<u32>,
    values: Buffer<V>,
}

impl<V: Copy + 'static> Default for SparseRows<V> {
    fn default() -> Self {
        Self::new()
    }
}

/// Rows from `(indices, values)` pairs, one row each, in order.
///
/// ```
/// use haarshift_relight::precompute::sparse::SparseRows;
/// let rows: SparseRows<f32> = [(vec![1u32, 4], vec![0.5f32, 2.0]), (vec![], vec![])]
///     .iter()
///     .map(|(i, v)| (i, v))
///     .collect();
/// assert_eq!(rows.len(), 2);
/// assert_eq!(rows.row(0), (&[1u32, 4][..], &[0.5f32, 2.0][..]));
/// ```
impl<V: Copy + 'static, I: AsRef<[u32]>, W: AsRef<[V]>> FromIterator<(I, W)> for SparseRows<V> {
    fn from_iter<It: IntoIterator<Item = (I, W)>>(rows: It) -> Self {
        let mut out = SparseRows::new();
        for (indices, values) in rows {
            out.push(indices.as_ref(), values.as_ref());
        }
        out
    }
}

impl<V: Copy + 'static> SparseRows<V> {
    /// No rows.
    pub fn new() -> Self {
        SparseRows {
            offsets: vec![0].into(),
            indices: Vec::new().into(),
            values: Vec::new().into(),
        }
    }

    /// Rows from their flat parts, when they are consistent: offsets start at 0, never
    /// decrease and end at the length of `indices`, which `values` matches, and each row's
    /// indices ascend.
    pub(crate) fn from_parts(
        offsets: Buffer<u64>,
        indices: Buffer<u32>,
        values: Buffer<V>,
    ) -> Option<Self> {
        let consistent = offsets.first() == Some(&0)
            && offsets.windows(2).all(|w| w[0] <= w[1])
            && offsets.last().copied() == Some(indices.len() as u64)
            && indices.len() == values.len()
            && offsets.windows(2).all(|w| {
                indices[w[0] as usize..w[1] as usize]
                    .windows(2)
                    .all(|p| p[0] < p[1])
            });
        consistent.then_some(SparseRows {
            offsets,
            indices,
            values,
        })
    }

    /// Appends one row.
    pub fn push(&mut self, indices: &[u32], values: &[V]) {
        debug_assert_eq!(indices.len(), values.len());
        self.indices.to_mut().extend_from_slice(indices);
        self.values.to_mut().extend_from_slice(values);
        let end = self.indices.len() as u64;
        self.offsets.to_mut().push(end);
    }

    /// Row `r`'s indices and values.
    #[inline]
    pub fn row(&self, r: usize) -> (&[u32], &[V]) {
        let (a, b) = (self.offsets[r] as usize, self.offsets[r + 1] as usize);
        (&self.indices[a..b], &self.values[a..b])
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Whether there is no row.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Coefficients in all rows.
    pub fn coefficient_count(&self) -> usize {
        self.values.len()
    }

    /// Bytes of the three arrays.
    pub fn bytes(&self) -> usize {
        self.offsets.len() * 8 + self.indices.len() * 4 + self.values.len() * size_of::<V>()
    }

    /// The flat arrays: offsets (`rows + 1`), indices, values.
    pub(crate) fn parts(&self) -> (&[u64], &[u32], &[V]) {
        (&self.offsets, &self.indices, &self.values)
    }

    /// The same rows with values seen as `U` when `U` is `V` itself (sharing a mapped file's
    /// pages, copying owned arrays); `None` for another type.
    pub(crate) fn shared_as<U: 'static>(&self) -> Option<SparseRows<U>> {
        Some(SparseRows {
            offsets: self.offsets.clone(),
            indices: self.indices.clone(),
            values: self.values.shared_as()?,
        })
    }

    /// Whether the arrays are read in place from a memory-mapped file.
    pub(crate) fn is_mapped(&self) -> bool {
        self.offsets.is_mapped() && self.indices.is_mapped() && self.values.is_mapped()
    }
}
