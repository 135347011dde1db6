//! Per-vertex transport, stored sparse: what the precomputation makes and the cache keeps.
//!
//! For vertex `v` the transport is the function on the sphere's texels
//! `T_v(t) = V(v, t) max(0, n_v . w_t) dOmega_t` (Sun 2006 eq. 3.9: visibility x cosine, with
//! the texel solid angle folded in, [`haarshift::product::Transport`]), Haar-transformed
//! (orthonormal, face by face) and truncated to the coefficients a [`Selection`] keeps. Only the
//! kept non-zero coefficients are stored: for each vertex a run of `(index, value)` pairs, all
//! vertices in three flat arrays (offsets, indices, values), no allocation per vertex. The
//! index of a coefficient is its row-major position in the `(faces, S, S)` Mallat array (face
//! after face, each face a full-depth pyramid of
//! [`transform::pyramid`](haarshift::transform::pyramid)); the face's scaling coefficient is at
//! `(face, 0, 0)`.
//!
//! A set may also carry the same transport projected onto spherical harmonics
//! ([`ShTransfer`], Microsoft 2003's low-frequency transfer), made from the same values by the same
//! precomputation, for the comparison method.

use ndarray::{Array3, Array4, ArrayView3};

use crate::mapped::Buffer;
use crate::precompute::sparse::SparseRows;
use crate::sh_transfer::{ShProjector, ShTransfer};
use crate::{Error, Result};
use haarshift::faces::Parameterization;
use haarshift::faces::integrate::layout;
use haarshift::product::kept::kept_coefficients;
use haarshift::product::{HaarTree, Selection, Transport};

/// The sparse transport of every vertex; see the [module docs](self).
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::TransportSet;
/// use haarshift::faces::{ParamKind, Parameterization};
/// use ndarray::Array3;
/// let param = Parameterization::new(ParamKind::LatLong, 4).unwrap();
/// let mut set = TransportSet::new(param, Selection::Largest(3));
/// // One vertex that sees every texel with cosine 1: its transport is the solid angle.
/// set.push(Array3::ones((2, 4, 4)).view()).unwrap();
/// let t = set.transport(0).unwrap();
/// let total: f32 = t.tree().to_pixels().unwrap().sum();
/// assert!((total - 4.0 * std::f32::consts::PI).abs() < 1e-5);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct TransportSet {
    param: Parameterization,
    keep: Selection,
    rows: SparseRows<f32>,
    sh: Option<ShTransfer>,
}

impl TransportSet {
    /// An empty set for `param`, truncating each vertex's transport with `keep`.
    pub fn new(param: Parameterization, keep: Selection) -> Self {
        TransportSet {
            param,
            keep,
            rows: SparseRows::new(),
            sh: None,
        }
    }

    /// An empty set that also projects every vertex onto `bands` bands of spherical harmonics
    /// ([`ShTransfer`]; 1 to [`MAX_SH_BANDS`](crate::sh_transfer::MAX_SH_BANDS)).
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift_relight::TransportSet;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// use ndarray::Array3;
    /// let param = Parameterization::new(ParamKind::LatLong, 32).unwrap();
    /// let mut set = TransportSet::with_sh(param, Selection::All, 2).unwrap();
    /// set.push(Array3::ones((2, 32, 32)).view()).unwrap(); // sees everything, cosine 1
    /// let t = set.sh().unwrap().coefficients();
    /// // Only Y_00 survives: int 1 x Y_00 = 4 pi / (2 sqrt pi) = 2 sqrt pi.
    /// assert!((t[[0, 0]] - 2.0 * std::f32::consts::PI.sqrt()).abs() < 1e-5);
    /// assert!(t[[0, 2]].abs() < 1e-5);
    /// ```
    pub fn with_sh(param: Parameterization, keep: Selection, bands: usize) -> Result<Self> {
        let mut set = Self::new(param, keep);
        set.sh = Some(ShTransfer::empty(bands)?);
        Ok(set)
    }

    /// The set from stored parts (the cache): checked for consistency.
    pub(crate) fn from_parts(
        param: Parameterization,
        keep: Selection,
        offsets: Buffer<u64>,
        indices: Buffer<u32>,
        values: Buffer<f32>,
        sh: Option<ShTransfer>,
    ) -> Result<Self> {
        let texels = param.texels() as u32;
        let vertices = offsets.len().saturating_sub(1);
        let rows = SparseRows::from_parts(offsets, indices, values).filter(|rows| {
            let (_, indices, values) = rows.parts();
            indices.iter().all(|&i| i < texels)
                && values.iter().all(|v| v.is_finite())
                && sh.as_ref().is_none_or(|t| t.vertex_count() == vertices)
        });
        let Some(rows) = rows else {
            return Err(Error::parameter(
                "transport",
                "offsets, indices, values and transfer do not describe sparse trees of this \
                 resolution, one per vertex",
            ));
        };
        Ok(TransportSet {
            param,
            keep,
            rows,
            sh,
        })
    }

    /// Encodes one more vertex from its unweighted values `V x max(0, n . w)`, `(faces, S, S)`:
    /// weighted by the solid angles, transformed, truncated, stored (and projected onto the
    /// spherical harmonics when the set carries them). It makes its tables on every call; the
    /// precomputation makes them once. A value that is not finite is refused, as a cache file
    /// holding one is: a frame skips the terms its lighting leaves dark, which is exact only
    /// for finite transport.
    ///
    /// ```
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// use haarshift::product::Selection;
    /// use haarshift_relight::TransportSet;
    /// use ndarray::Array3;
    /// let param = Parameterization::new(ParamKind::Cube, 4).unwrap();
    /// let mut set = TransportSet::new(param, Selection::All);
    /// set.push(Array3::ones((6, 4, 4)).view()).unwrap();
    /// let mut bad = Array3::ones((6, 4, 4));
    /// bad[[2, 1, 3]] = f32::INFINITY;
    /// assert!(set.push(bad.view()).is_err());
    /// assert_eq!(set.vertex_count(), 1);
    /// ```
    pub fn push(&mut self, values: ArrayView3<'_, f32>) -> Result<()> {
        let bands = self.sh.as_ref().map(ShTransfer::bands);
        let vertex = Encoder::new(self.param, self.keep, bands)?.encode(values)?;
        self.extend(&vertex);
        Ok(())
    }

    /// Appends one vertex's already encoded coefficients.
    pub(crate) fn extend(&mut self, vertex: &Encoded) {
        self.rows.push(&vertex.indices, &vertex.coefficients);
        if let Some(t) = &mut self.sh {
            t.push(&vertex.sh);
        }
    }

    /// Appends every vertex of `other` after this set's (the merge of shards): both must have
    /// the same parameterisation, truncation and spherical-harmonic bands.
    pub(crate) fn append(&mut self, other: &TransportSet) -> Result<()> {
        let bands = |s: &TransportSet| s.sh.as_ref().map(ShTransfer::bands);
        if (self.param, self.keep, bands(self)) != (other.param, other.keep, bands(other)) {
            return Err(Error::parameter(
                "transport",
                "only sets of the same parameterisation, truncation and bands are joined",
            ));
        }
        for v in 0..other.vertex_count() {
            let (indices, values) = other.coefficients(v);
            self.rows.push(indices, values);
        }
        if let (Some(mine), Some(theirs)) = (&mut self.sh, &other.sh) {
            theirs
                .as_slice()
                .chunks_exact(theirs.bands() * theirs.bands())
                .for_each(|row| mine.push(row));
        }
        Ok(())
    }

    /// The vertices `vertices` of this set as a set of their own (a shard's rows of a whole
    /// cache's transport).
    pub(crate) fn part(&self, vertices: std::ops::Range<usize>) -> Result<TransportSet> {
        if vertices.start > vertices.end || vertices.end > self.vertex_count() {
            return Err(Error::parameter(
                "vertices",
                format!(
                    "{}..{} of a set of {}",
                    vertices.start,
                    vertices.end,
                    self.vertex_count()
                ),
            ));
        }
        self.picked(vertices)
    }

    /// The set with its vertex `order[k]` as its `k`-th (the refined scene's order, from the
    /// order the refinement made its vertices in).
    pub(crate) fn reordered(&self, order: &[u32]) -> Result<TransportSet> {
        self.picked(order.iter().map(|&v| v as usize))
    }

    /// A set of these vertices' rows (and harmonic transfer), in the order given.
    fn picked(&self, vertices: impl Iterator<Item = usize>) -> Result<TransportSet> {
        let mut out = match &self.sh {
            Some(t) => TransportSet::with_sh(self.param, self.keep, t.bands())?,
            None => TransportSet::new(self.param, self.keep),
        };
        for v in vertices {
            let (indices, values) = self.coefficients(v);
            out.rows.push(indices, values);
            if let (Some(mine), Some(theirs)) = (&mut out.sh, &self.sh) {
                let n = theirs.bands() * theirs.bands();
                mine.push(&theirs.as_slice()[v * n..(v + 1) * n]);
            }
        }
        Ok(out)
    }

    /// The spherical-harmonic transfer, when the set was made with it.
    pub fn sh(&self) -> Option<&ShTransfer> {
        self.sh.as_ref()
    }

    /// The parameterisation the transport is sampled in.
    pub fn param(&self) -> Parameterization {
        self.param
    }

    /// The truncation applied to each vertex.
    pub fn keep(&self) -> Selection {
        self.keep
    }

    /// Vertices stored.
    pub fn vertex_count(&self) -> usize {
        self.rows.len()
    }

    /// Vertex `v`'s stored coefficients: Mallat indices and values.
    pub fn coefficients(&self, v: usize) -> (&[u32], &[f32]) {
        self.rows.row(v)
    }

    /// The flat arrays: per-vertex offsets (`V + 1`), indices, values.
    pub(crate) fn parts(&self) -> (&[u64], &[u32], &[f32]) {
        self.rows.parts()
    }

    /// Every vertex's coefficients as rows.
    pub(crate) fn rows(&self) -> &SparseRows<f32> {
        &self.rows
    }

    /// Whether the coefficients are read in place from a memory-mapped cache file
    /// ([`SceneCache::read`](crate::SceneCache::read)) rather than held in memory.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift_relight::TransportSet;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let param = Parameterization::new(ParamKind::LatLong, 4).unwrap();
    /// assert!(!TransportSet::new(param, Selection::All).is_mapped());
    /// ```
    pub fn is_mapped(&self) -> bool {
        self.rows.is_mapped()
    }

    /// Haar coefficients stored, all vertices.
    pub fn coefficient_count(&self) -> usize {
        self.rows.coefficient_count()
    }

    /// Bytes held by the coefficient arrays (the spherical-harmonic transfer included).
    pub fn stored_bytes(&self) -> usize {
        let sh = self.sh.as_ref().map_or(0, ShTransfer::stored_bytes);
        self.rows.bytes() + sh
    }

    /// Vertex `v`'s transport as a tree for [`product_integral`](haarshift::product::product_integral).
    pub fn transport(&self, v: usize) -> Result<Transport<f32, 1>> {
        if v >= self.vertex_count() {
            return Err(Error::parameter(
                "vertex",
                format!("{v}: there are {} vertices", self.vertex_count()),
            ));
        }
        let s = self.param.face_size();
        let mut dense = Array4::<f32>::zeros((self.param.faces(), s, s, 1));
        let flat = dense.as_slice_mut().expect("fresh array is contiguous");
        let (indices, values) = self.coefficients(v);
        for (&i, &c) in indices.iter().zip(values) {
            flat[i as usize] = c;
        }
        // Threshold 0 keeps exactly the stored (non-zero) coefficients.
        let tree = HaarTree::from_coefficients(
            dense.view(),
            layout(self.param),
            Selection::Threshold(0.0),
        )?;
        Ok(Transport::from_weighted_tree(tree))
    }
}

/// One vertex as a [`TransportSet`] stores it.
pub(crate) struct Encoded {
    /// Mallat indices of the kept non-zero coefficients.
    pub(crate) indices: Vec<u32>,
    /// Their values.
    pub(crate) coefficients: Vec<f32>,
    /// The spherical-harmonic transfer vector (empty without it).
    pub(crate) sh: Vec<f32>,
}

/// Encodes vertices for the precomputation: the solid angles and (when asked) the table of
/// spherical harmonics at the texels, made once and shared by all vertices and threads.
pub(crate) struct Encoder {
    param: Parameterization,
    keep: Selection,
    weights: Array3<f32>,
    sh: Option<ShProjector>,
}

impl Encoder {
    /// The encoder of `param`'s texels, keeping `keep`, projecting onto `sh_bands` bands.
    pub(crate) fn new(
        param: Parameterization,
        keep: Selection,
        sh_bands: Option<usize>,
    ) -> Result<Self> {
        Ok(Encoder {
            param,
            keep,
            weights: param.solid_angles().mapv(|w| w as f32),
            sh: sh_bands.map(|b| ShProjector::new(param, b)).transpose()?,
        })
    }

    /// An empty set that [`Encoded`] vertices of this encoder extend.
    pub(crate) fn empty_set(&self) -> Result<TransportSet> {
        match &self.sh {
            Some(p) => TransportSet::with_sh(self.param, self.keep, p.bands()),
            None => Ok(TransportSet::new(self.param, self.keep)),
        }
    }

    /// One vertex from its unweighted values `(faces, S, S)`.
    pub(crate) fn encode(&self, values: ArrayView3<'_, f32>) -> Result<Encoded> {
        let (indices, coefficients) = encode(values, self.weights.view(), self.param, self.keep)?;
        let sh = match &self.sh {
            Some(p) => {
                let mut row = vec![0.0; p.len()];
                let flat = values.as_standard_layout();
                p.project(flat.as_slice().expect("standard layout"), &mut row);
                row
            }
            None => Vec::new(),
        };
        Ok(Encoded {
            indices,
            coefficients,
            sh,
        })
    }

    /// Bytes of the shared tables.
    pub(crate) fn bytes(&self) -> usize {
        self.weights.len() * 4 + self.sh.as_ref().map_or(0, ShProjector::bytes)
    }
}

/// Weights `values` by `weights`, transforms, keeps what `keep` picks: the non-zero kept
/// coefficients with their Mallat indices.
pub(crate) fn encode(
    values: ArrayView3<'_, f32>,
    weights: ArrayView3<'_, f32>,
    param: Parameterization,
    keep: Selection,
) -> Result<(Vec<u32>, Vec<f32>)> {
    if values.dim() != weights.dim() {
        return Err(Error::shape(
            values.shape(),
            "values must be shaped as the weights",
        ));
    }
    Ok(kept_coefficients(
        (&values * &weights).view(),
        layout(param),
        keep,
    )?)
}
