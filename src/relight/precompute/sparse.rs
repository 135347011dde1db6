//! Many sparse Haar functions in three flat arrays: what the transport of every vertex, the
//! sample maps of an occlusion field and the fixed products of just-in-time radiance transfer
//! all are.
//!
//! Row `r` is a run of `(index, value)` pairs: `indices[offsets[r]..offsets[r + 1]]` are
//! face-Mallat positions (`face x S^2 + row x S + col`, the layout of
//! [`TransportSet`](crate::relight::TransportSet)) and `values` the matching coefficients (one channel
//! as `f32`, or several as an array). No allocation per row.

/// Rows of sparse coefficients; see the [module docs](self).
///
/// ```
/// use haarshift::relight::precompute::sparse::SparseRows;
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
    offsets: Vec<u64>,
    indices: Vec<u32>,
    values: Vec<V>,
}

impl<V: Copy> Default for SparseRows<V> {
    fn default() -> Self {
        Self::new()
    }
}

/// Rows from `(indices, values)` pairs, one row each, in order.
///
/// ```
/// use haarshift::relight::precompute::sparse::SparseRows;
/// let rows: SparseRows<f32> = [(vec![1u32, 4], vec![0.5f32, 2.0]), (vec![], vec![])]
///     .iter()
///     .map(|(i, v)| (i, v))
///     .collect();
/// assert_eq!(rows.len(), 2);
/// assert_eq!(rows.row(0), (&[1u32, 4][..], &[0.5f32, 2.0][..]));
/// ```
impl<V: Copy, I: AsRef<[u32]>, W: AsRef<[V]>> FromIterator<(I, W)> for SparseRows<V> {
    fn from_iter<It: IntoIterator<Item = (I, W)>>(rows: It) -> Self {
        let mut out = SparseRows::new();
        for (indices, values) in rows {
            out.push(indices.as_ref(), values.as_ref());
        }
        out
    }
}

impl<V: Copy> SparseRows<V> {
    /// No rows.
    pub fn new() -> Self {
        SparseRows {
            offsets: vec![0],
            indices: Vec::new(),
            values: Vec::new(),
        }
    }

    /// Rows from their flat parts, when they are consistent: offsets start at 0, never
    /// decrease and end at the length of `indices`, which `values` matches.
    pub(crate) fn from_parts(offsets: Vec<u64>, indices: Vec<u32>, values: Vec<V>) -> Option<Self> {
        let consistent = offsets.first() == Some(&0)
            && offsets.windows(2).all(|w| w[0] <= w[1])
            && offsets.last().copied() == Some(indices.len() as u64)
            && indices.len() == values.len();
        consistent.then_some(SparseRows {
            offsets,
            indices,
            values,
        })
    }

    /// Appends one row.
    pub fn push(&mut self, indices: &[u32], values: &[V]) {
        debug_assert_eq!(indices.len(), values.len());
        self.indices.extend_from_slice(indices);
        self.values.extend_from_slice(values);
        self.offsets.push(self.indices.len() as u64);
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
}
