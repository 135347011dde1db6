//! The triple product integral (`N = 3`, lighting x transport x BRDF), two fast paths:
//! sparse on trees ([`triple_integral`]) and dense over full coefficient arrays
//! ([`dense_triple_integral`], `O(M)`, seed 002 sections 3.6 and 4.4).
//!
//! On a node of side `B` where all three functions have nodes, with means `m_k` and detail
//! steps `s_k = (h_k, v_k, d_k)` (orthonormal detail over `B`), the node adds
//!
//! `B^2 [ m_1 (s_2 . s_3) + m_2 (s_1 . s_3) + m_3 (s_1 . s_2) + h_1 (v_2 d_3 + d_2 v_3) + v_1 (h_2 d_3 + d_2 h_3) + d_1 (h_2 v_3 + v_2 h_3) ]`
//!
//! to the integral, and where only two do, `B^2 m_absent (s_i . s_j)`. These are Ng et al.'s
//! three cases of tripling coefficients (seed 002 Theorem 7): a parent times two equal
//! wavelets (the dot products, whose parent factor is the mean `m`, i.e. the parent sum), three
//! different wavelets on one node (the last three terms), and the three scaling functions
//! (`S^2 m_1 m_2 m_3` per face). In the orthonormal basis the case-2 coefficient `2^j` and the
//! case-3 coefficient `+-2^j` of a parent both become the step/mean units used here, with no
//! scale factors left over. It is [`fold_excess`](super::integral) specialised to three
//! functions (tested equal to the general traversal).
//!
//! The dense path stores, per function, the mean and the three steps of every node of the
//! complete quadtree as four flat arrays, level after level ("vectorised parent sums", seed
//! 002 section 4.4), so the sum over nodes is one vectorisable loop per level.

use super::basis::wavelet_signs;
use super::integral::{Integral, IntegralOptions, check_trees};
use super::transport::Transport;
use super::tree::{HaarTree, Node};
use crate::{Error, Result, Sample};

/// The product integral of a transport and two factors by the three-function traversal.
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, IntegralOptions, Selection, Transport,
///     WeightedPixels, product_integral, triple::triple_integral};
/// use ndarray::{Array3, Array4};
/// let f = Array4::from_shape_fn((6, 8, 8, 1), |(k, i, j, _)| (1 + k + i * j) as f64);
/// let w = WeightedPixels::new(f.view(), Array3::ones((6, 8, 8)).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::Stacked, Selection::Largest(40)).unwrap();
/// let g = HaarTree::from_pixels(f.view(), FaceLayout::Stacked, Selection::Largest(25)).unwrap();
/// let fast = triple_integral(&t, &g, &g).unwrap().value[0];
/// let general = product_integral(&t, &[&g, &g], IntegralOptions::default()).unwrap().value[0];
/// assert!((fast - general).abs() < 1e-12 * general);
/// ```
pub fn triple_integral<T: Sample, const C: usize>(
    transport: &Transport<T, C>,
    f: &HaarTree<T, C>,
    g: &HaarTree<T, C>,
) -> Result<Integral<C>> {
    let trees = [transport.tree(), f, g];
    check_trees(&trees, IntegralOptions::default())?;
    let s = f.side();
    let mut walk = Triple {
        nodes: trees.map(|t| t.nodes()),
        signs: wavelet_signs().map(|q| q.map(T::from_f64)),
        area: (0..f.levels())
            .map(|l| T::from_f64(((s >> l) * (s >> l)) as f64))
            .collect(),
        sum: [0.0; C],
        visited: 0,
    };
    let inv_s = T::one() / T::from_f64(s as f64);
    for face in 0..f.faces() {
        let means = trees.map(|t| t.scaling()[face].map(|v| v * inv_s));
        let area = (s * s) as f64;
        for (ch, sum) in walk.sum.iter_mut().enumerate() {
            *sum += area * (means[0][ch] * means[1][ch] * means[2][ch]).as_f64();
        }
        let roots = trees.map(|t| t.root(face));
        walk.visit(roots, means, 0);
    }
    Ok(Integral {
        value: walk.sum,
        visited: walk.visited,
    })
}

struct Triple<'a, T, const C: usize> {
    nodes: [&'a [Node<T, C>]; 3],
    signs: [[T; 3]; 4],
    area: Vec<T>,
    sum: [f64; C],
    visited: usize,
}

impl<T: Sample, const C: usize> Triple<'_, T, C> {
    /// Visits a node where function `k` has node `at[k]` or, when `None`, the constant
    /// `constant[k]`.
    fn visit(&mut self, at: [Option<u32>; 3], constant: [[T; C]; 3], level: usize) {
        let present = at.iter().filter(|a| a.is_some()).count();
        if present < 2 {
            return;
        }
        let n: [Option<&Node<T, C>>; 3] =
            std::array::from_fn(|k| at[k].map(|i| &self.nodes[k][i as usize]));
        let area = self.area[level];
        for ch in 0..C {
            let dot = |a: &Node<T, C>, b: &Node<T, C>| {
                a.step[0][ch] * b.step[0][ch]
                    + a.step[1][ch] * b.step[1][ch]
                    + a.step[2][ch] * b.step[2][ch]
            };
            let excess = match n {
                [Some(a), Some(b), Some(c)] => {
                    let ([h1, v1, d1], [h2, v2, d2], [h3, v3, d3]) = (
                        a.step.map(|s| s[ch]),
                        b.step.map(|s| s[ch]),
                        c.step.map(|s| s[ch]),
                    );
                    a.mean[ch] * dot(b, c)
                        + b.mean[ch] * dot(a, c)
                        + c.mean[ch] * dot(a, b)
                        + h1 * (v2 * d3 + d2 * v3)
                        + v1 * (h2 * d3 + d2 * h3)
                        + d1 * (h2 * v3 + v2 * h3)
                }
                [None, Some(b), Some(c)] => constant[0][ch] * dot(b, c),
                [Some(a), None, Some(c)] => constant[1][ch] * dot(a, c),
                [Some(a), Some(b), None] => constant[2][ch] * dot(a, b),
                _ => T::zero(),
            };
            self.sum[ch] += (area * excess).as_f64();
        }
        self.visited += 1;
        if level + 1 == self.area.len() {
            return;
        }
        for q in 0..4 {
            let mut child = [None; 3];
            let mut child_constant = constant;
            for k in 0..3 {
                if let Some(node) = n[k] {
                    match node.child(q) {
                        Some(c) => child[k] = Some(c),
                        None => child_constant[k] = node.quadrant_mean(&self.signs[q]),
                    }
                }
            }
            self.visit(child, child_constant, level + 1);
        }
    }
}

/// One function on the complete quadtrees of its faces: mean and steps of every node, as flat
/// arrays (face after face, level after level, nodes row-major, channels innermost).
#[derive(Clone, Debug, PartialEq)]
pub struct DenseFaces<T, const C: usize> {
    faces: usize,
    n: u32,
    /// Face means, `[face][channel]`.
    face_mean: Vec<[T; C]>,
    mean: Vec<T>,
    step: [Vec<T>; 3],
}

/// A [`DenseFaces`] that carries the weight (made only from a [`Transport`]).
#[derive(Clone, Debug, PartialEq)]
pub struct DenseTransport<T, const C: usize>(DenseFaces<T, C>);

impl<T: Sample, const C: usize> DenseFaces<T, C> {
    /// The complete quadtrees of the function `tree` represents (dropped details are zero).
    pub fn from_tree(tree: &HaarTree<T, C>) -> Self {
        let (faces, s, n) = (tree.faces(), tree.side(), tree.levels());
        let coeffs = tree.to_coefficients();
        let per_face = ((1usize << (2 * n)) - 1) / 3;
        let len = faces * per_face * C;
        let mut mean = vec![T::zero(); len];
        let mut step = [
            vec![T::zero(); len],
            vec![T::zero(); len],
            vec![T::zero(); len],
        ];
        let signs = wavelet_signs().map(|q| q.map(T::from_f64));
        let inv_s = T::one() / T::from_f64(s as f64);
        let face_mean: Vec<[T; C]> = tree
            .scaling()
            .iter()
            .map(|sc| sc.map(|v| v * inv_s))
            .collect();
        for face in 0..faces {
            let base = face * per_face;
            let mut level_start = 0;
            for level in 0..n {
                let side = 1usize << level;
                let inv_b = T::from_f64(side as f64) * inv_s;
                for row in 0..side {
                    for col in 0..side {
                        let node = base + level_start + row * side + col;
                        let cells = [
                            (row, side + col),
                            (side + row, col),
                            (side + row, side + col),
                        ];
                        for (band, (r, c)) in cells.into_iter().enumerate() {
                            for ch in 0..C {
                                step[band][node * C + ch] = coeffs[[face, r, c, ch]] * inv_b;
                            }
                        }
                        for ch in 0..C {
                            mean[node * C + ch] = if level == 0 {
                                face_mean[face][ch]
                            } else {
                                let parent_side = side / 2;
                                let parent = base + level_start - parent_side * parent_side
                                    + (row / 2) * parent_side
                                    + col / 2;
                                let sg = &signs[2 * (row & 1) + (col & 1)];
                                mean[parent * C + ch]
                                    + sg[0] * step[0][parent * C + ch]
                                    + sg[1] * step[1][parent * C + ch]
                                    + sg[2] * step[2][parent * C + ch]
                            };
                        }
                    }
                }
                level_start += side * side;
            }
        }
        DenseFaces {
            faces,
            n: n as u32,
            face_mean,
            mean,
            step,
        }
    }
}

impl<T: Sample, const C: usize> DenseTransport<T, C> {
    /// The complete quadtrees of a transport.
    pub fn from_transport(transport: &Transport<T, C>) -> Self {
        DenseTransport(DenseFaces::from_tree(transport.tree()))
    }
}

/// Lanes of partial sums: lets the compiler vectorise the reduction.
const LANES: usize = 8;

/// The triple product integral over complete quadtrees, `O(M)`.
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, Selection, Transport, WeightedPixels};
/// use haarshift::product::triple::{DenseFaces, DenseTransport, dense_triple_integral, triple_integral};
/// use ndarray::{Array3, Array4};
/// let f = Array4::from_shape_fn((6, 8, 8, 1), |(k, i, j, _)| (1 + k + i * j) as f64);
/// let w = WeightedPixels::new(f.view(), Array3::ones((6, 8, 8)).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::Stacked, Selection::All).unwrap();
/// let g = HaarTree::from_pixels(f.view(), FaceLayout::Stacked, Selection::All).unwrap();
/// let (dt, dg) = (DenseTransport::from_transport(&t), DenseFaces::from_tree(&g));
/// let dense = dense_triple_integral(&dt, &dg, &dg).unwrap()[0];
/// let sparse = triple_integral(&t, &g, &g).unwrap().value[0];
/// assert!((dense - sparse).abs() < 1e-12 * sparse);
/// ```
pub fn dense_triple_integral<T: Sample, const C: usize>(
    transport: &DenseTransport<T, C>,
    f: &DenseFaces<T, C>,
    g: &DenseFaces<T, C>,
) -> Result<[f64; C]> {
    let t = &transport.0;
    for x in [f, g] {
        if (x.faces, x.n) != (t.faces, t.n) {
            return Err(Error::shape(
                &[x.faces, 1 << x.n, 1 << x.n],
                format!(
                    "dense functions live on different faces ({} x {}^2 expected)",
                    t.faces,
                    1u64 << t.n
                ),
            ));
        }
    }
    let s = 1usize << t.n;
    let per_face = t.mean.len() / t.faces.max(1);
    let mut sum = [0.0f64; C];
    for face in 0..t.faces {
        for (ch, sum) in sum.iter_mut().enumerate() {
            let m = t.face_mean[face][ch] * f.face_mean[face][ch] * g.face_mean[face][ch];
            *sum += (s * s) as f64 * m.as_f64();
        }
        let mut start = face * per_face;
        for level in 0..t.n as usize {
            let len = (1usize << (2 * level)) * C;
            let range = start..start + len;
            let b = (s >> level) as f64;
            let level_sum = level_excess(t, f, g, range, &mut [T::zero(); LANES]);
            for (ch, v) in level_sum.iter().enumerate() {
                sum[ch] += b * b * v;
            }
            start += len;
        }
    }
    Ok(sum)
}

/// The sum of the three-function excess over the nodes in `range`, per channel.
fn level_excess<T: Sample, const C: usize>(
    t: &DenseFaces<T, C>,
    f: &DenseFaces<T, C>,
    g: &DenseFaces<T, C>,
    range: std::ops::Range<usize>,
    lanes: &mut [T; LANES],
) -> [f64; C] {
    let excess = |i: usize| {
        let (m1, h1, v1, d1) = (t.mean[i], t.step[0][i], t.step[1][i], t.step[2][i]);
        let (m2, h2, v2, d2) = (f.mean[i], f.step[0][i], f.step[1][i], f.step[2][i]);
        let (m3, h3, v3, d3) = (g.mean[i], g.step[0][i], g.step[1][i], g.step[2][i]);
        m1 * (h2 * h3 + v2 * v3 + d2 * d3)
            + m2 * (h1 * h3 + v1 * v3 + d1 * d3)
            + m3 * (h1 * h2 + v1 * v2 + d1 * d2)
            + h1 * (v2 * d3 + d2 * v3)
            + v1 * (h2 * d3 + d2 * h3)
            + d1 * (h2 * v3 + v2 * h3)
    };
    let mut out = [0.0; C];
    if C == 1 && range.len() >= LANES {
        // One channel: LANES independent partial sums, vectorised.
        lanes.fill(T::zero());
        let whole = range.start + range.len() / LANES * LANES;
        for base in (range.start..whole).step_by(LANES) {
            for (k, lane) in lanes.iter_mut().enumerate() {
                *lane += excess(base + k);
            }
        }
        let tail: T = (whole..range.end).map(excess).sum();
        out[0] = lanes.iter().map(|v| v.as_f64()).sum::<f64>() + tail.as_f64();
        return out;
    }
    for i in range {
        out[i % C] += excess(i).as_f64();
    }
    out
}
