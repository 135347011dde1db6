//! The sparse coefficient quadtree of a function on a set of square faces (Sun 2006's
//! augmented quadtree, section 2.2.1), stored flat.
//!
//! **Storage.** One arena of [`Node`]s for all faces (face after face, breadth first within
//! a face); the children of a node are contiguous, found from `first_child` and a 4-bit mask
//! of which quadrants exist (no pointers, no allocation per node). A parallel array holds each
//! node's position, used only when a tree is turned back into arrays.
//!
//! **What a node holds** (for each of the `C` channels):
//! * `mean`: the mean of the (pruned) function over the node's block, Sun 2006's "parent
//!   sum" `p_sum` (section 2.2.2) in value units: the face mean plus, for every ancestor, its
//!   details' signs on the quadrant that leads here times their steps.
//! * `step[H, V, D]`: each detail's orthonormal coefficient divided by the block side
//!   `B = S >> level`, i.e. the amount the detail adds to (or takes from) each quadrant's mean.
//!   Dividing by a power of two is exact, so [`HaarTree::to_coefficients`] returns the
//!   orthonormal coefficients bit for bit.
//!
//! A node exists when one of its details is kept or it is the ancestor of one that is (a
//! *structural* node, with zero steps for the details that were not kept).
//!
//! **Normalisation.** The face's scaling coefficient is orthonormal: the pixel sum over `S`
//! (so the face mean is `scaling / S`). Detail coefficients are those of
//! [`transform::pyramid`](crate::transform::pyramid) with
//! [`Normalization::Orthonormal`](crate::transform::Normalization), the basis of
//! [`basis::BasisFunction::discrete`](super::basis::BasisFunction::discrete).

use ndarray::{Array4, ArrayView2, ArrayView4, Axis, s};
use rayon::prelude::*;

use super::basis::wavelet_signs;
use super::selection::{self, Candidate, FaceLayout, Selection};
use crate::transform::{Normalization, pyramid};
use crate::{Error, Result, Sample, ensure_finite};

/// No child / no root.
const NONE: u32 = u32::MAX;

/// One node of the flat quadtree; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node<T, const C: usize> {
    /// The mean of the function over the node's block, per channel.
    pub mean: [T; C],
    /// `H`, `V`, `D` details divided by the block side, per channel.
    pub step: [[T; C]; 3],
    /// Index of the first child (the others follow, in quadrant order).
    pub first_child: u32,
    /// Bit `q` set when the child in quadrant `q` ([`quadrant`](super::basis::quadrant)) exists.
    pub children: u8,
}

impl<T: Sample, const C: usize> Node<T, C> {
    /// The arena index of the child in quadrant `q`, if it exists.
    #[inline(always)]
    pub fn child(&self, q: usize) -> Option<u32> {
        if self.children & (1 << q) == 0 {
            return None;
        }
        let before = (self.children & ((1u8 << q) - 1)).count_ones();
        Some(self.first_child + before)
    }

    /// The function's mean over quadrant `q` of this node: `mean + sum of sign x step`.
    #[inline(always)]
    pub fn quadrant_mean(&self, signs: &[T; 3]) -> [T; C] {
        std::array::from_fn(|ch| {
            self.mean[ch]
                + signs[0] * self.step[0][ch]
                + signs[1] * self.step[1][ch]
                + signs[2] * self.step[2][ch]
        })
    }
}

/// Where a node is: detail level and block position within its face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodePosition {
    /// The face.
    pub face: u32,
    /// Detail level, 0 coarsest.
    pub level: u8,
    /// Block row, `0..2^level`.
    pub row: u32,
    /// Block column, `0..2^level`.
    pub col: u32,
}

/// A function on `F` square faces of side `S = 2^n`, `C` channels, as a sparse Haar quadtree
/// per face; see the [module docs](self). This is a plain *factor*; a factor that carries the
/// integration weight is a [`Transport`](super::Transport).
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, Selection};
/// use ndarray::{Array3, Axis};
/// // Two 4x4 faces, one channel: (faces, S, S) plus a channel axis.
/// let pixels = Array3::from_shape_fn((2, 4, 4), |(f, i, j)| (f * 16 + i * 4 + j) as f64);
/// let full = HaarTree::<f64, 1>::from_pixels(pixels.view().insert_axis(Axis(3)),
///     FaceLayout::Stacked, Selection::All).unwrap();
/// assert_eq!(full.kept(), 2 * 15);
/// assert_eq!(full.to_pixels().unwrap().index_axis(Axis(3), 0), pixels);
/// let sparse = full.select(Selection::Largest(3)).unwrap();
/// assert_eq!(sparse.kept(), 3);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct HaarTree<T, const C: usize> {
    faces: usize,
    n: u32,
    layout: FaceLayout,
    scaling: Vec<[T; C]>,
    roots: Vec<u32>,
    nodes: Vec<Node<T, C>>,
    positions: Vec<NodePosition>,
    kept: usize,
}

/// Checks a `(faces, S, S, C)` array: non-empty, square power-of-two faces, `C` channels.
pub(crate) fn check_face_array(
    shape: &[usize],
    channels: usize,
    what: &str,
) -> Result<(usize, usize)> {
    let [faces, h, w, c] = shape else {
        return Err(Error::shape(
            shape,
            format!("{what} must be (faces, S, S, C)"),
        ));
    };
    if *faces == 0 || h != w || !h.is_power_of_two() || *c != channels {
        return Err(Error::shape(
            shape,
            format!("{what} must be (faces >= 1, S, S, {channels}) with S a power of two"),
        ));
    }
    Ok((*faces, *h))
}

impl<T: Sample, const C: usize> HaarTree<T, C> {
    /// Transforms `pixels` (`(faces, S, S, C)`, `S` a power of two, finite) to orthonormal
    /// Haar pyramids, face by face, and keeps the coefficients `selection` picks.
    pub fn from_pixels(
        pixels: ArrayView4<'_, T>,
        layout: FaceLayout,
        selection: Selection,
    ) -> Result<Self> {
        let (faces, s) = check_face_array(pixels.shape(), C, "pixels")?;
        ensure_finite(&pixels)?;
        let n = s.trailing_zeros() as usize;
        let mut coeffs = Array4::zeros(pixels.raw_dim());
        coeffs
            .outer_iter_mut()
            .into_par_iter()
            .zip(pixels.outer_iter().into_par_iter())
            .try_for_each(|(mut out, face)| -> Result<()> {
                for ch in 0..C {
                    let plane: ArrayView2<'_, T> = face.index_axis(Axis(2), ch);
                    let c = pyramid::forward(plane, n, Normalization::Orthonormal)?;
                    out.index_axis_mut(Axis(2), ch).assign(&c);
                }
                Ok(())
            })?;
        Self::build(coeffs.view(), faces, s, layout, selection)
    }

    /// Builds the tree from per-face orthonormal Mallat coefficient arrays (`(faces, S, S, C)`,
    /// each face a full-depth pyramid of [`transform::pyramid`](crate::transform::pyramid)).
    pub fn from_coefficients(
        coefficients: ArrayView4<'_, T>,
        layout: FaceLayout,
        selection: Selection,
    ) -> Result<Self> {
        let (faces, s) = check_face_array(coefficients.shape(), C, "coefficients")?;
        ensure_finite(&coefficients)?;
        Self::build(coefficients, faces, s, layout, selection)
    }

    /// This tree with a new selection applied to its coefficients (a tree keeps no dropped
    /// coefficient, so this can only keep fewer).
    pub fn select(&self, selection: Selection) -> Result<Self> {
        let coeffs = self.to_coefficients();
        Self::build(
            coeffs.view(),
            self.faces,
            self.side(),
            self.layout,
            selection,
        )
    }

    fn build(
        coeffs: ArrayView4<'_, T>,
        faces: usize,
        s: usize,
        layout: FaceLayout,
        selection: Selection,
    ) -> Result<Self> {
        let n = s.trailing_zeros();
        let limit = selection_limit(faces, s, selection)?;
        let kept = kept_mask::<T, C>(coeffs, faces, s, layout, selection, limit);
        let mut tree = HaarTree {
            faces,
            n,
            layout,
            scaling: Vec::with_capacity(faces),
            roots: Vec::with_capacity(faces),
            nodes: Vec::new(),
            positions: Vec::new(),
            kept: kept.iter().filter(|&&k| k).count(),
        };
        for face in 0..faces {
            tree.add_face(coeffs, &kept[face * s * s..(face + 1) * s * s], face);
        }
        Ok(tree)
    }

    /// Appends one face's nodes, breadth first.
    fn add_face(&mut self, coeffs: ArrayView4<'_, T>, kept: &[bool], face: usize) {
        let s = self.side();
        let n = self.n as usize;
        let at =
            |r: usize, c: usize| -> [T; C] { std::array::from_fn(|ch| coeffs[[face, r, c, ch]]) };
        let scaling = at(0, 0);
        self.scaling.push(scaling);
        let present = presence(kept, s);
        if n == 0 || !present[0][0] {
            self.roots.push(NONE);
            return;
        }
        let signs = wavelet_signs().map(|q| q.map(T::from_f64));
        let inv_s = T::one() / T::from_f64(s as f64);
        let first = self.nodes.len();
        self.roots.push(first as u32);
        let node_at = |level: usize, row: usize, col: usize, mean: [T; C]| {
            let side = 1usize << level;
            let inv_b = T::from_f64(side as f64) * inv_s;
            let cells = [
                (row, side + col),
                (side + row, col),
                (side + row, side + col),
            ];
            let step = cells.map(|(r, c)| {
                if kept[r * s + c] {
                    at(r, c).map(|v| v * inv_b)
                } else {
                    [T::zero(); C]
                }
            });
            Node {
                mean,
                step,
                first_child: NONE,
                children: 0,
            }
        };
        self.nodes
            .push(node_at(0, 0, 0, scaling.map(|v| v * inv_s)));
        self.positions.push(NodePosition {
            face: face as u32,
            level: 0,
            row: 0,
            col: 0,
        });
        let mut i = first;
        while i < self.nodes.len() {
            let NodePosition {
                level, row, col, ..
            } = self.positions[i];
            let (level, row, col) = (level as usize, row as usize, col as usize);
            if level + 1 < n {
                let parent = self.nodes[i];
                let mut mask = 0u8;
                let first_child = self.nodes.len() as u32;
                for (q, sign) in signs.iter().enumerate() {
                    let (r, c) = (2 * row + (q >> 1), 2 * col + (q & 1));
                    if present[level + 1][r << (level + 1) | c] {
                        mask |= 1 << q;
                        self.nodes
                            .push(node_at(level + 1, r, c, parent.quadrant_mean(sign)));
                        self.positions.push(NodePosition {
                            face: face as u32,
                            level: (level + 1) as u8,
                            row: r as u32,
                            col: c as u32,
                        });
                    }
                }
                if mask != 0 {
                    self.nodes[i].first_child = first_child;
                    self.nodes[i].children = mask;
                }
            }
            i += 1;
        }
    }

    /// Builds the tree of the function whose non-zero orthonormal coefficients are given
    /// sparsely: `indices` are face-Mallat positions (`face x S^2 + row x S + col`, any order,
    /// no repeats; `(face, 0, 0)` is the face's scaling coefficient), `values` their `C`
    /// channels. Every given detail is kept. The cost is that of the entries and their
    /// ancestors, not of the faces, which is what per-vertex products of sparse factors need.
    ///
    /// ```
    /// use haarshift::product::{FaceLayout, HaarTree, Selection};
    /// use ndarray::Array4;
    /// let f = Array4::from_shape_fn((2, 8, 8, 1), |(k, i, j, _)| ((k + 3 * i) ^ j) as f64);
    /// let full = HaarTree::<f64, 1>::from_pixels(f.view(), FaceLayout::Stacked,
    ///     Selection::Largest(9)).unwrap();
    /// let (indices, values) = full.sparse_coefficients();
    /// let rebuilt = HaarTree::from_sparse(2, 8, FaceLayout::Stacked, &indices, &values).unwrap();
    /// assert_eq!(rebuilt.to_coefficients(), full.to_coefficients());
    /// assert_eq!(rebuilt.kept(), 9);
    /// ```
    pub fn from_sparse(
        faces: usize,
        side: usize,
        layout: FaceLayout,
        indices: &[u32],
        values: &[[T; C]],
    ) -> Result<Self> {
        check_face_array(&[faces, side, side, C], C, "a sparse function")?;
        let area = side * side;
        if indices.len() != values.len()
            || indices.iter().any(|&i| i as usize >= faces * area)
            || values.iter().flatten().any(|v| !v.as_f64().is_finite())
        {
            return Err(Error::parameter(
                "coefficients",
                format!(
                    "{} indices and {} values: one finite value per index below {}",
                    indices.len(),
                    values.len(),
                    faces * area
                ),
            ));
        }
        let n = side.trailing_zeros();
        let mut scaling = vec![[T::zero(); C]; faces];
        // (face, level, Morton code of the block, band, value) for every detail.
        let mut details = Vec::with_capacity(indices.len());
        for (&i, &v) in indices.iter().zip(values) {
            let (face, at) = (i as usize / area, i as usize % area);
            match mallat_detail(at / side, at % side) {
                None => scaling[face] = v,
                Some((band, level, row, col)) => {
                    details.push((NodeKey::new(face, level, row, col), band, v))
                }
            }
        }
        // Sorted once; every later match is a forward merge, not a search (this runs per
        // vertex and per looked-up map in dynamic scenes).
        details.sort_unstable_by_key(|d| d.0);
        let keys = with_ancestors(details.iter().map(|d| d.0).collect());
        let mut nodes = vec![
            Node {
                mean: [T::zero(); C],
                step: [[T::zero(); C]; 3],
                first_child: NONE,
                children: 0,
            };
            keys.len()
        ];
        let inv_s = T::one() / T::from_f64(side as f64);
        let mut at = 0;
        for &(key, band, v) in &details {
            while keys[at] != key {
                at += 1;
            }
            let inv_b = T::from_f64((1u64 << key.level) as f64) * inv_s;
            nodes[at].step[band] = v.map(|x| x * inv_b);
        }
        let signs = wavelet_signs().map(|q| q.map(T::from_f64));
        let mut roots = vec![None; faces];
        let mut positions = Vec::with_capacity(keys.len());
        // Parents ascend with their children within a face's level; `p` only jumps back
        // where a new level or face starts.
        let mut p = 0;
        for at in 0..keys.len() {
            let key = keys[at];
            match key.parent() {
                None => {
                    roots[key.face as usize] = Some(at as u32);
                    nodes[at].mean = scaling[key.face as usize].map(|x| x * inv_s);
                    positions.push(NodePosition {
                        face: key.face,
                        level: 0,
                        row: 0,
                        col: 0,
                    });
                }
                Some(parent) => {
                    if keys[p] > parent {
                        p = keys[..at].partition_point(|k| *k < parent);
                    }
                    while keys[p] < parent {
                        p += 1;
                    }
                    let q = (key.morton & 3) as usize;
                    if nodes[p].children == 0 {
                        nodes[p].first_child = at as u32;
                    }
                    nodes[p].children |= 1 << q;
                    nodes[at].mean = nodes[p].quadrant_mean(&signs[q]);
                    let up: NodePosition = positions[p];
                    positions.push(NodePosition {
                        level: key.level,
                        row: 2 * up.row + (q >> 1) as u32,
                        col: 2 * up.col + (q & 1) as u32,
                        ..up
                    });
                }
            }
        }
        Ok(Self::from_parts(
            faces, n, layout, scaling, roots, nodes, positions,
        ))
    }

    /// The tree's non-zero orthonormal coefficients, ascending face-Mallat index (the
    /// inverse of [`from_sparse`](Self::from_sparse); scaling coefficients included when
    /// non-zero).
    pub fn sparse_coefficients(&self) -> (Vec<u32>, Vec<[T; C]>) {
        let s = self.side();
        let mut entries: Vec<(u32, [T; C])> = self
            .scaling
            .iter()
            .enumerate()
            .filter(|(_, v)| v.iter().any(|x| *x != T::zero()))
            .map(|(face, v)| ((face * s * s) as u32, *v))
            .collect();
        for (node, pos) in self.nodes.iter().zip(&self.positions) {
            let side = 1usize << pos.level;
            let b = T::from_f64((s / side) as f64);
            let (r, c) = (pos.row as usize, pos.col as usize);
            let cells = [(r, side + c), (side + r, c), (side + r, side + c)];
            for (step, (i, j)) in node.step.iter().zip(cells) {
                if step.iter().any(|x| *x != T::zero()) {
                    let index = pos.face as usize * s * s + i * s + j;
                    entries.push((index as u32, step.map(|x| x * b)));
                }
            }
        }
        entries.sort_unstable_by_key(|e| e.0);
        entries.into_iter().unzip()
    }

    /// Number of faces.
    pub fn faces(&self) -> usize {
        self.faces
    }

    /// Side `S` of each face.
    pub fn side(&self) -> usize {
        1 << self.n
    }

    /// Detail levels per face, `log2 S`.
    pub fn levels(&self) -> usize {
        self.n as usize
    }

    /// How ties in the selection were broken.
    pub fn layout(&self) -> FaceLayout {
        self.layout
    }

    /// Number of detail coefficients kept (scaling coefficients not counted).
    pub fn kept(&self) -> usize {
        self.kept
    }

    /// The orthonormal scaling coefficient of each face (pixel sum over `S`).
    pub fn scaling(&self) -> &[[T; C]] {
        &self.scaling
    }

    /// The arena index of each face's root node (detail level 0), `None` when the face has no
    /// detail kept.
    pub fn root(&self, face: usize) -> Option<u32> {
        self.roots.get(face).copied().filter(|&r| r != NONE)
    }

    /// The node arena.
    pub fn nodes(&self) -> &[Node<T, C>] {
        &self.nodes
    }

    /// Position of every node, parallel to [`nodes`](Self::nodes).
    pub fn positions(&self) -> &[NodePosition] {
        &self.positions
    }

    /// Whether `other` lives on the same faces (count and side), for operations on several trees.
    pub(crate) fn check_compatible(&self, other: &Self) -> Result<()> {
        if (self.faces, self.n) != (other.faces, other.n) {
            return Err(Error::shape(
                &[other.faces, other.side(), other.side()],
                format!(
                    "trees live on different faces ({} x {}^2 and {} x {}^2)",
                    self.faces,
                    self.side(),
                    other.faces,
                    other.side()
                ),
            ));
        }
        Ok(())
    }

    /// The orthonormal per-face Mallat arrays, `(faces, S, S, C)`, zero where not kept.
    pub fn to_coefficients(&self) -> Array4<T> {
        let s = self.side();
        let mut out = Array4::zeros((self.faces, s, s, C));
        for (face, sc) in self.scaling.iter().enumerate() {
            for ch in 0..C {
                out[[face, 0, 0, ch]] = sc[ch];
            }
        }
        for (node, pos) in self.nodes.iter().zip(&self.positions) {
            let side = 1usize << pos.level;
            let b = T::from_f64((s / side) as f64);
            let (f, r, c) = (pos.face as usize, pos.row as usize, pos.col as usize);
            let cells = [(r, side + c), (side + r, c), (side + r, side + c)];
            for (band, (i, j)) in cells.into_iter().enumerate() {
                for ch in 0..C {
                    out[[f, i, j, ch]] = node.step[band][ch] * b;
                }
            }
        }
        out
    }

    /// The function the tree represents, `(faces, S, S, C)`: the inverse transform of
    /// [`to_coefficients`](Self::to_coefficients).
    pub fn to_pixels(&self) -> Result<Array4<T>> {
        let mut out = self.to_coefficients();
        let n = self.levels();
        out.outer_iter_mut()
            .into_par_iter()
            .try_for_each(|mut face| -> Result<()> {
                for ch in 0..C {
                    let mut plane = face.index_axis_mut(Axis(2), ch);
                    let p = pyramid::inverse(plane.view(), n, Normalization::Orthonormal)?;
                    plane.assign(&p);
                }
                Ok(())
            })?;
        Ok(out)
    }

    /// Assembles a tree from parts made by an operation on trees (the product).
    pub(crate) fn from_parts(
        faces: usize,
        n: u32,
        layout: FaceLayout,
        scaling: Vec<[T; C]>,
        roots: Vec<Option<u32>>,
        nodes: Vec<Node<T, C>>,
        positions: Vec<NodePosition>,
    ) -> Self {
        let kept = nodes
            .iter()
            .map(|node| {
                node.step
                    .iter()
                    .filter(|s| s.iter().any(|v| *v != T::zero()))
                    .count()
            })
            .sum();
        HaarTree {
            faces,
            n,
            layout,
            scaling,
            roots: roots.into_iter().map(|r| r.unwrap_or(NONE)).collect(),
            nodes,
            positions,
            kept,
        }
    }
}

/// The most details `selection` keeps of `faces` faces of side `s` ([`Selection::limit`]),
/// refusing more per face than a face has.
pub(crate) fn selection_limit(
    faces: usize,
    s: usize,
    selection: Selection,
) -> Result<Option<usize>> {
    let details_per_face = s * s - 1;
    let limit = selection.limit(faces * details_per_face)?;
    if let Selection::LargestPerFace(k) = selection
        && k > details_per_face
    {
        return Err(Error::parameter(
            "keep",
            format!("{k} coefficients per face asked for but a face has {details_per_face}"),
        ));
    }
    Ok(limit)
}

/// Which Mallat positions (per face, `S x S`, row-major, faces concatenated) hold a kept
/// detail coefficient.
pub(crate) fn kept_mask<T: Sample, const C: usize>(
    coeffs: ArrayView4<'_, T>,
    faces: usize,
    s: usize,
    layout: FaceLayout,
    selection: Selection,
    limit: Option<usize>,
) -> Vec<bool> {
    let n = s.trailing_zeros() as usize;
    let mut kept = vec![false; faces * s * s];
    let candidates = |face: usize| {
        let face_view = coeffs.slice(s![face, .., .., ..]);
        (0..n).flat_map(move |level| {
            let side = 1usize << level;
            (0..3).flat_map(move |band| {
                (0..side * side).map(move |k| {
                    let (row, col) = (k / side, k % side);
                    let (r, c) = match band {
                        0 => (row, side + col),
                        1 => (side + row, col),
                        _ => (side + row, side + col),
                    };
                    let magnitude2 = (0..C)
                        .map(|ch| face_view[[r, c, ch]].as_f64().powi(2))
                        .sum::<f64>();
                    let index = layout.index(faces, s, face, band, level, row, col);
                    Candidate {
                        magnitude2,
                        index,
                        slot: face * s * s + r * s + c,
                    }
                })
            })
        })
    };
    let mut mark = |pool: &mut [Candidate], k: usize| {
        let count = selection::keep_largest(pool, k);
        for cand in &pool[..count] {
            kept[cand.slot] = true;
        }
    };
    match selection {
        Selection::All => {
            for face in 0..faces {
                for cand in candidates(face) {
                    kept[cand.slot] = true;
                }
            }
        }
        Selection::Threshold(t) => {
            for face in 0..faces {
                for cand in candidates(face) {
                    kept[cand.slot] = cand.magnitude2 > t * t;
                }
            }
        }
        Selection::Largest(_) => {
            let mut pool: Vec<_> = (0..faces).flat_map(candidates).collect();
            mark(&mut pool, limit.unwrap_or(0));
        }
        Selection::LargestPerFace(_) => {
            for face in 0..faces {
                let mut pool: Vec<_> = candidates(face).collect();
                mark(&mut pool, limit.unwrap_or(0));
            }
        }
    }
    kept
}

/// For each level, which nodes exist: a detail of the node is kept, or a child exists.
fn presence(kept: &[bool], s: usize) -> Vec<Vec<bool>> {
    let n = s.trailing_zeros() as usize;
    let mut present: Vec<Vec<bool>> = (0..n).map(|l| vec![false; 1 << (2 * l)]).collect();
    for level in (0..n).rev() {
        let side = 1usize << level;
        for row in 0..side {
            for col in 0..side {
                let own = [
                    (row, side + col),
                    (side + row, col),
                    (side + row, side + col),
                ]
                .iter()
                .any(|&(r, c)| kept[r * s + c]);
                let child = level + 1 < n
                    && (0..4).any(|q| {
                        let (r, c) = (2 * row + (q >> 1), 2 * col + (q & 1));
                        present[level + 1][r * 2 * side + c]
                    });
                present[level][row * side + col] = own || child;
            }
        }
    }
    present
}

/// The detail at Mallat position `(r, c)` of a face: `(band, level, row, col)` with band
/// 0 = H `(row, 2^l + col)`, 1 = V `(2^l + row, col)`, 2 = D; `None` for the scaling
/// coefficient `(0, 0)`.
#[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
pub fn mallat_detail(r: usize, c: usize) -> Option<(usize, usize, usize, usize)> {
    let m = r.max(c);
    if m == 0 {
        return None;
    }
    let level = (usize::BITS - 1 - m.leading_zeros()) as usize;
    let side = 1 << level;
    Some(if r < side {
        (0, level, r, c - side)
    } else if c < side {
        (1, level, r - side, c)
    } else {
        (2, level, r - side, c - side)
    })
}

/// A node's place, ordered as the arena is: face, then level, then the block's Morton code
/// (row bits above column bits, so the last two bits are the quadrant in its parent).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct NodeKey {
    face: u32,
    level: u8,
    morton: u64,
}

/// The bits of `x` (below 2^32) moved to the even positions.
fn spread_bits(x: usize) -> u64 {
    let mut v = x as u64 & 0xFFFF_FFFF;
    v = (v | (v << 16)) & 0x0000_FFFF_0000_FFFF;
    v = (v | (v << 8)) & 0x00FF_00FF_00FF_00FF;
    v = (v | (v << 4)) & 0x0F0F_0F0F_0F0F_0F0F;
    v = (v | (v << 2)) & 0x3333_3333_3333_3333;
    (v | (v << 1)) & 0x5555_5555_5555_5555
}

/// `keys` and all their ancestors, sorted by (face, level, Morton code) and without repeats:
/// breadth first with each node's children contiguous and in quadrant order, the arena's
/// order. One sort of the given keys; the ancestors come level by level, already sorted.
fn with_ancestors(mut keys: Vec<NodeKey>) -> Vec<NodeKey> {
    keys.sort_unstable();
    keys.dedup();
    let mut out = Vec::with_capacity(keys.len() * 2);
    for face_keys in keys.chunk_by(|a, b| a.face == b.face) {
        let face = face_keys[0].face;
        let finest = face_keys.last().map_or(0, |k| k.level as usize);
        let mut levels: Vec<Vec<u64>> = vec![Vec::new(); finest + 1];
        for k in face_keys {
            levels[k.level as usize].push(k.morton);
        }
        for l in (1..=finest).rev() {
            let merged = merge_sorted(&levels[l - 1], levels[l].iter().map(|m| m >> 2));
            levels[l - 1] = merged;
        }
        for (l, mortons) in levels.iter().enumerate() {
            out.extend(mortons.iter().map(|&morton| NodeKey {
                face,
                level: l as u8,
                morton,
            }));
        }
    }
    out
}

/// The union of the ascending `a` and the ascending (repeats allowed) `b`, ascending,
/// without repeats.
fn merge_sorted(a: &[u64], b: impl Iterator<Item = u64>) -> Vec<u64> {
    let mut out: Vec<u64> = Vec::with_capacity(a.len() + 8);
    let push = |x: u64, out: &mut Vec<u64>| {
        if out.last() != Some(&x) {
            out.push(x);
        }
    };
    let mut a = a.iter().copied().peekable();
    for x in b {
        while let Some(y) = a.next_if(|&y| y < x) {
            push(y, &mut out);
        }
        push(x, &mut out);
    }
    for y in a {
        push(y, &mut out);
    }
    out
}

impl NodeKey {
    fn new(face: usize, level: usize, row: usize, col: usize) -> Self {
        NodeKey {
            face: face as u32,
            level: level as u8,
            morton: spread_bits(row) << 1 | spread_bits(col),
        }
    }

    fn parent(self) -> Option<NodeKey> {
        (self.level > 0).then(|| NodeKey {
            face: self.face,
            level: self.level - 1,
            morton: self.morton >> 2,
        })
    }
}
