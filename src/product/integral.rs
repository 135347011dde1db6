//! The product integral of `N` functions on sparse trees: Sun 2006's tree traversal
//! (sections 3.4.2-3.4.3), derived again for the discrete orthonormal basis.
//!
//! **Derivation.** Write the integral over a face as the pixel sum `I = sum_p prod_k f_k(p)`.
//! On a node `X` of block side `B`, each function is `m_k` (its mean on `X`, the node's "parent
//! sum") plus its own three details (a step of `+-h_k, +-v_k, +-d_k` on the quadrants, the
//! signs of [`basis::quadrant_sign`](super::basis::quadrant_sign)) plus finer details of zero
//! mean on each quadrant. Telescoping from the pixels up,
//!
//! `I = S^2 prod_k m_k(face) + sum over nodes X of B^2 [ (1/4) sum_q prod_k m_k(X_q) - prod_k m_k(X) ]`.
//!
//! The bracket is the scaling component of the product of the functions' four-component
//! vectors `(m, h, v, d)` under the Klein-group product of the quadrant sign patterns
//! (`H x V = D` and so on: [`basis::product`](super::basis::product) on one node), minus the
//! product of the means. It is folded function by function in `O(1)` each (Sun 2006's table
//! `T`, `getProductIntegralDP`, but without the `2^j`, `4^j` factors that its continuous
//! normalisation needs), tracking the excess over `prod m` directly so that nothing cancels.
//! A node contributes only when at least two functions have a node there: with one, the
//! bracket is zero (its details sum to zero over the quadrants) and so is everything below.
//! A function without a node at `X` is constant there and multiplies the bracket (Sun 2006's
//! `cum`). Cost: `O(N)` per visited node.
//!
//! **Depth limit** (Sun 2006 Fig. 3.5): with [`IntegralOptions::finest_level`] `= Some(L)` only
//! nodes of detail levels `0..=L` are visited, which is exactly the integral of the functions
//! averaged over blocks of side `S >> (L + 1)`.
//!
//! **Normalisation of the result:** the weighted pixel sum itself (no `1/S^2`, no `4 pi`):
//! with the transport's weights the sphere's solid angles, the integral over the sphere.
//! Accumulated in f64 for both sample types.

use super::basis::wavelet_signs;
use super::transport::Transport;
use super::tree::HaarTree;
use crate::{Error, Result, Sample};

/// Options of [`product_integral`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IntegralOptions {
    /// The finest detail level visited (`None`: all); `L` means levels `0..=L`, as the sphere
    /// module's `level`.
    pub finest_level: Option<usize>,
}

/// A product integral per channel, with the number of tree nodes where it did work.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integral<const C: usize> {
    /// The weighted pixel sum of the product, per channel.
    pub value: [f64; C],
    /// Nodes visited (where two or more functions have a node).
    pub visited: usize,
}

/// The integral of `transport x factors[0] x ...` over all faces: the pixel sum of the product
/// of the functions the trees represent (the transport carrying the weight).
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, IntegralOptions, Selection, Transport,
///     WeightedPixels, product_integral};
/// use ndarray::{Array3, Array4, Axis};
/// let f = Array4::from_shape_fn((2, 4, 4, 1), |(k, i, j, _)| (1 + k + i * j) as f64);
/// let g = Array4::from_shape_fn((2, 4, 4, 1), |(k, i, j, _)| (2 * k + i + j) as f64 - 3.0);
/// let w = WeightedPixels::<f64, 1>::new(f.view(), Array3::ones((2, 4, 4)).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::Stacked, Selection::All).unwrap();
/// let g_tree = HaarTree::<f64, 1>::from_pixels(g.view(), FaceLayout::Stacked, Selection::All).unwrap();
/// let i = product_integral(&t, &[&g_tree], IntegralOptions::default()).unwrap();
/// let pixel: f64 = (&f * &g).sum();
/// assert!((i.value[0] - pixel).abs() < 1e-12 * pixel.abs());
/// ```
pub fn product_integral<T: Sample, const C: usize>(
    transport: &Transport<T, C>,
    factors: &[&HaarTree<T, C>],
    options: IntegralOptions,
) -> Result<Integral<C>> {
    let mut trees = Vec::with_capacity(factors.len() + 1);
    trees.push(transport.tree());
    trees.extend_from_slice(factors);
    integrate_trees(&trees, options)
}

/// Checks that `trees` share their faces and that the depth limit fits; returns the finest
/// level to visit.
pub(crate) fn check_trees<T: Sample, const C: usize>(
    trees: &[&HaarTree<T, C>],
    options: IntegralOptions,
) -> Result<usize> {
    let Some(first) = trees.first() else {
        return Err(Error::parameter("functions", "no function to integrate"));
    };
    for t in &trees[1..] {
        first.check_compatible(t)?;
    }
    let levels = first.levels();
    match options.finest_level {
        Some(l) if l >= levels => Err(Error::parameter(
            "depth",
            format!(
                "detail level {l} does not exist: faces of side {} have levels 0..={}",
                first.side(),
                levels.saturating_sub(1)
            ),
        )),
        Some(l) => Ok(l),
        None => Ok(levels.saturating_sub(1)),
    }
}

/// The product integral of the functions of `trees` (the caller has settled the weight).
pub(crate) fn integrate_trees<T: Sample, const C: usize>(
    trees: &[&HaarTree<T, C>],
    options: IntegralOptions,
) -> Result<Integral<C>> {
    let finest = check_trees(trees, options)?;
    let s = trees[0].side();
    let mut walk = Walk {
        trees,
        signs: wavelet_signs().map(|q| q.map(T::from_f64)),
        finest,
        area: (0..trees[0].levels())
            .map(|l| T::from_f64(((s >> l) * (s >> l)) as f64))
            .collect(),
        active: Vec::with_capacity(trees.len() * (trees[0].levels() + 1)),
        sum: [0.0; C],
        visited: 0,
    };
    let inv_s = 1.0 / s as f64;
    for face in 0..trees[0].faces() {
        let mut scaling_term = [(s * s) as f64; C];
        let mut cum = [T::one(); C];
        walk.active.clear();
        for (k, tree) in trees.iter().enumerate() {
            let mean = tree.scaling()[face].map(|v| v.as_f64() * inv_s);
            for ch in 0..C {
                scaling_term[ch] *= mean[ch];
            }
            match tree.root(face) {
                Some(root) => walk.active.push((k as u32, root)),
                None => {
                    for ch in 0..C {
                        cum[ch] *= T::from_f64(mean[ch]);
                    }
                }
            }
        }
        for (sum, term) in walk.sum.iter_mut().zip(scaling_term) {
            *sum += term;
        }
        if walk.active.len() >= 2 {
            walk.visit(0, 0, cum);
        }
    }
    Ok(Integral {
        value: walk.sum,
        visited: walk.visited,
    })
}

/// The synchronous traversal of several trees.
struct Walk<'a, T, const C: usize> {
    trees: &'a [&'a HaarTree<T, C>],
    /// `[quadrant][H, V, D]` signs.
    signs: [[T; 3]; 4],
    /// Deepest level visited.
    finest: usize,
    /// `B^2` per level.
    area: Vec<T>,
    /// `(tree, node)` of the functions present at the nodes on the current path, one run per
    /// level (children's runs pushed after their parent's).
    active: Vec<(u32, u32)>,
    sum: [f64; C],
    visited: usize,
}

impl<T: Sample, const C: usize> Walk<'_, T, C> {
    /// Visits the node whose active functions are `active[start..]`, at `level`, with the
    /// product `cum` of the inactive functions' (constant) values.
    fn visit(&mut self, start: usize, level: usize, cum: [T; C]) {
        let trees = self.trees;
        let end = self.active.len();
        let excess = fold_excess(
            self.active[start..end]
                .iter()
                .map(|&(t, n)| &trees[t as usize].nodes()[n as usize]),
        );
        let area = self.area[level];
        for ch in 0..C {
            self.sum[ch] += (area * cum[ch] * excess[ch]).as_f64();
        }
        self.visited += 1;
        if level == self.finest {
            return;
        }
        for q in 0..4 {
            let base = self.active.len();
            let child_cum = descend(trees, &mut self.active, start, q, &self.signs[q], cum);
            if self.active.len() - base >= 2 {
                self.visit(base, level + 1, child_cum);
            }
            self.active.truncate(base);
        }
    }
}

/// Steps from the node whose functions are `active[start..]` into its quadrant `q`: pushes
/// the functions that have a child there onto `active` and returns `cum` times the quadrant
/// means of those that do not (constant below).
#[inline(always)]
pub(crate) fn descend<T: Sample, const C: usize>(
    trees: &[&HaarTree<T, C>],
    active: &mut Vec<(u32, u32)>,
    start: usize,
    q: usize,
    signs: &[T; 3],
    mut cum: [T; C],
) -> [T; C] {
    let end = active.len();
    for k in start..end {
        let (t, n) = active[k];
        let node = &trees[t as usize].nodes()[n as usize];
        match node.child(q) {
            Some(c) => active.push((t, c)),
            None => {
                let m = node.quadrant_mean(signs);
                for (c, m) in cum.iter_mut().zip(m) {
                    *c *= m;
                }
            }
        }
    }
    cum
}

/// `(1/4) sum_q prod_k m_k(X_q) - prod_k m_k(X)` for the nodes of one block (see the module
/// docs): the Klein-group fold, tracking the excess over the product of means.
#[inline(always)]
pub(crate) fn fold_excess<'a, T: Sample, const C: usize>(
    mut nodes: impl Iterator<Item = &'a super::tree::Node<T, C>>,
) -> [T; C] {
    let Some(first) = nodes.next() else {
        return [T::zero(); C];
    };
    let mut w = first.mean;
    let mut p = [T::zero(); C];
    let [mut x, mut y, mut z] = first.step;
    for node in nodes {
        let (m, [a, b, c]) = (node.mean, node.step);
        for ch in 0..C {
            let full = w[ch] + p[ch];
            let p2 = p[ch] * m[ch] + x[ch] * a[ch] + y[ch] * b[ch] + z[ch] * c[ch];
            let x2 = full * a[ch] + x[ch] * m[ch] + y[ch] * c[ch] + z[ch] * b[ch];
            let y2 = full * b[ch] + y[ch] * m[ch] + x[ch] * c[ch] + z[ch] * a[ch];
            let z2 = full * c[ch] + z[ch] * m[ch] + x[ch] * b[ch] + y[ch] * a[ch];
            (p[ch], x[ch], y[ch], z[ch]) = (p2, x2, y2, z2);
            w[ch] *= m[ch];
        }
    }
    p
}
