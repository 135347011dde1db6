//! The triple product integral (`N = 3`, lighting x transport x BRDF), two fast paths:
//! sparse on trees ([`triple_integral`]) and dense over full coefficient arrays
//! ([`dense_triple_integral`], `O(M)`, Vollick and Lessig sections 3.6 and 4.4).
//!
//! On a node of side `B` where all three functions have nodes, with means `m_k` and detail
//! steps `s_k = (h_k, v_k, d_k)` (orthonormal detail over `B`), the node adds
//!
//! `B^2 [ m_1 (s_2 . s_3) + m_2 (s_1 . s_3) + m_3 (s_1 . s_2) + h_1 (v_2 d_3 + d_2 v_3) + v_1 (h_2 d_3 + d_2 h_3) + d_1 (h_2 v_3 + v_2 h_3) ]`
//!
//! to the integral, and where only two do, `B^2 m_absent (s_i . s_j)`. These are Ng et al.'s
//! three cases of tripling coefficients (Vollick and Lessig Theorem 7): a parent times two equal
//! wavelets (the dot products, whose parent factor is the mean `m`, i.e. the parent sum), three
//! different wavelets on one node (the last three terms), and the three scaling functions
//! (`S^2 m_1 m_2 m_3` per face). In the orthonormal basis the case-2 coefficient `2^j` and the
//! case-3 coefficient `+-2^j` of a parent both become the step/mean units used here, with no
//! scale factors left over. It is [`fold_excess`](super::integral) specialised to three
//! functions (tested equal to the general traversal).
//!
//! The dense path stores, per function and channel, the mean (the parent sum, carried down
//! level by level) and the three steps of every node of the complete quadtree as structure-of-
//! arrays chunks of 16 nodes, level after level ("vectorised parent sums", Vollick and Lessig section
//! 4.4); the transport's values carry their block area `B^2`, so the whole sum is one
//! branch-free loop over all nodes that the compiler vectorises. Regrouped by the transport's
//! four components, the excess is `m_1 (s_2 . s_3) + h_1 (m_2 h_3 + h_2 m_3 + v_2 d_3 + d_2
//! v_3) + ...` (the Klein-group product of the other two, dotted with the transport's node):
//! 19 multiplications a node instead of 27.

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
/// let w = WeightedPixels::<f64, 1>::new(f.view(), Array3::ones((6, 8, 8)).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::Stacked, Selection::Largest(40)).unwrap();
/// let g = HaarTree::<f64, 1>::from_pixels(f.view(), FaceLayout::Stacked, Selection::Largest(25)).unwrap();
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

/// Nodes per chunk of the dense layout: the width of the kernel's accumulators (four SSE
/// registers of f32, or two AVX ones).
const LANES: usize = 16;

/// `LANES` nodes of one channel: `[mean, H step, V step, D step][node]`.
type Chunk<T> = [[T; LANES]; 4];

/// Chunks whose excess is summed in the sample type before it is added to the f64 total
/// (1,024 nodes: f32 rounding stays at the level of the data's own).
const CHUNKS_PER_BLOCK: usize = 64;

/// One function on the complete quadtrees of its faces, as flat structure-of-arrays chunks:
/// per channel, every node's mean (the parent sum, carried down level by level) and three
/// steps, face after face, level after level, nodes row-major, `LANES` nodes to a chunk (the
/// last one padded with zero nodes, which add nothing).
#[derive(Clone, Debug, PartialEq)]
pub struct DenseFaces<T, const C: usize> {
    faces: usize,
    n: u32,
    /// Face means, `[face][channel]`.
    face_mean: Vec<[T; C]>,
    /// `chunks[channel]`.
    chunks: [Vec<Chunk<T>>; C],
}

/// A [`DenseFaces`] that carries the weight (made only from a [`Transport`]), with each node's
/// block area `B^2` (and each face's `S^2`) folded into its values, so that the kernel sums
/// all levels in one loop.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseTransport<T, const C: usize>(DenseFaces<T, C>);

impl<T: Sample, const C: usize> DenseFaces<T, C> {
    /// The complete quadtrees of the function `tree` represents (dropped details are zero).
    pub fn from_tree(tree: &HaarTree<T, C>) -> Self {
        Self::build(tree, false)
    }

    /// The dense layout of `tree`, its values times the block area when `area_weighted`.
    fn build(tree: &HaarTree<T, C>, area_weighted: bool) -> Self {
        let (faces, s, n) = (tree.faces(), tree.side(), tree.levels());
        let coeffs = tree.to_coefficients();
        let per_face = ((1usize << (2 * n)) - 1) / 3;
        let nodes = faces * per_face;
        let blank: Chunk<T> = [[T::zero(); LANES]; 4];
        let mut chunks: [Vec<Chunk<T>>; C] =
            std::array::from_fn(|_| vec![blank; nodes.div_ceil(LANES)]);
        let signs = wavelet_signs().map(|q| q.map(T::from_f64));
        let inv_s = T::one() / T::from_f64(s as f64);
        let face_mean: Vec<[T; C]> = tree
            .scaling()
            .iter()
            .map(|sc| sc.map(|v| v * inv_s))
            .collect();
        // The parent sums, carried level by level: `means[level]` holds one level's node means
        // (row-major), computed from the level above's means and steps.
        for (ch, chunks) in chunks.iter_mut().enumerate() {
            let mut value = |node: usize, part: usize, v: T| {
                chunks[node / LANES][part][node % LANES] = v;
            };
            for face in 0..faces {
                let base = face * per_face;
                let mut level_start = 0;
                let mut parent: (Vec<T>, [Vec<T>; 3]) =
                    (vec![face_mean[face][ch]], Default::default());
                for level in 0..n {
                    let side = 1usize << level;
                    let inv_b = T::from_f64(side as f64) * inv_s;
                    let area = if area_weighted {
                        T::from_f64(((s >> level) * (s >> level)) as f64)
                    } else {
                        T::one()
                    };
                    let mut mean = vec![T::zero(); side * side];
                    let mut step: [Vec<T>; 3] =
                        std::array::from_fn(|_| vec![T::zero(); side * side]);
                    for row in 0..side {
                        for col in 0..side {
                            let k = row * side + col;
                            mean[k] = if level == 0 {
                                parent.0[0]
                            } else {
                                let p = (row / 2) * (side / 2) + col / 2;
                                let sg = &signs[2 * (row & 1) + (col & 1)];
                                parent.0[p]
                                    + sg[0] * parent.1[0][p]
                                    + sg[1] * parent.1[1][p]
                                    + sg[2] * parent.1[2][p]
                            };
                            let cells = [
                                (row, side + col),
                                (side + row, col),
                                (side + row, side + col),
                            ];
                            for (band, (r, c)) in cells.into_iter().enumerate() {
                                step[band][k] = coeffs[[face, r, c, ch]] * inv_b;
                            }
                            let node = base + level_start + k;
                            value(node, 0, mean[k] * area);
                            for (band, st) in step.iter().enumerate() {
                                value(node, band + 1, st[k] * area);
                            }
                        }
                    }
                    parent = (mean, step);
                    level_start += side * side;
                }
            }
        }
        DenseFaces {
            faces,
            n: n as u32,
            face_mean,
            chunks,
        }
    }
}

impl<T: Sample, const C: usize> DenseTransport<T, C> {
    /// The complete quadtrees of a transport.
    pub fn from_transport(transport: &Transport<T, C>) -> Self {
        let mut dense = DenseFaces::build(transport.tree(), true);
        let area = T::from_f64(dense.side() as f64 * dense.side() as f64);
        for m in &mut dense.face_mean {
            *m = m.map(|v| v * area);
        }
        DenseTransport(dense)
    }
}

impl<T, const C: usize> DenseFaces<T, C> {
    /// The face side `S`.
    fn side(&self) -> usize {
        1 << self.n
    }
}

/// The triple product integral over complete quadtrees, `O(M)`: one branch-free loop over
/// all nodes of all faces and levels (the block areas are folded into the transport).
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, Selection, Transport, WeightedPixels};
/// use haarshift::product::triple::{DenseFaces, DenseTransport, dense_triple_integral, triple_integral};
/// use ndarray::{Array3, Array4};
/// let f = Array4::from_shape_fn((6, 8, 8, 1), |(k, i, j, _)| (1 + k + i * j) as f64);
/// let w = WeightedPixels::<f64, 1>::new(f.view(), Array3::ones((6, 8, 8)).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::Stacked, Selection::All).unwrap();
/// let g = HaarTree::<f64, 1>::from_pixels(f.view(), FaceLayout::Stacked, Selection::All).unwrap();
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
                &[x.faces, x.side(), x.side()],
                format!(
                    "dense functions live on different faces ({} x {}^2 expected)",
                    t.faces,
                    t.side()
                ),
            ));
        }
    }
    Ok(std::array::from_fn(|ch| {
        let scaling: f64 = (0..t.faces)
            .map(|face| {
                (t.face_mean[face][ch] * f.face_mean[face][ch] * g.face_mean[face][ch]).as_f64()
            })
            .sum();
        scaling + excess_sum(&t.chunks[ch], &f.chunks[ch], &g.chunks[ch])
    }))
}

/// The sum over nodes of the three-function excess (see the [module docs](self)), chunk by
/// chunk: `LANES` independent accumulators, no branch, fixed-size inner loops the compiler
/// vectorises.
fn excess_sum<T: Sample>(t: &[Chunk<T>], f: &[Chunk<T>], g: &[Chunk<T>]) -> f64 {
    let mut total = 0.0;
    for ((t, f), g) in t
        .chunks(CHUNKS_PER_BLOCK)
        .zip(f.chunks(CHUNKS_PER_BLOCK))
        .zip(g.chunks(CHUNKS_PER_BLOCK))
    {
        let mut acc = [T::zero(); LANES];
        for (([m1, h1, v1, d1], [m2, h2, v2, d2]), [m3, h3, v3, d3]) in t.iter().zip(f).zip(g) {
            for k in 0..LANES {
                // The Klein-group product of f and g (its scalar part without m2 m3), dotted
                // with the transport's node: every term has one factor of each function.
                let s = h2[k] * h3[k] + v2[k] * v3[k] + d2[k] * d3[k];
                let h = m2[k] * h3[k] + h2[k] * m3[k] + v2[k] * d3[k] + d2[k] * v3[k];
                let v = m2[k] * v3[k] + v2[k] * m3[k] + h2[k] * d3[k] + d2[k] * h3[k];
                let d = m2[k] * d3[k] + d2[k] * m3[k] + h2[k] * v3[k] + v2[k] * h3[k];
                acc[k] += m1[k] * s + h1[k] * h + v1[k] * v + d1[k] * d;
            }
        }
        total += acc.iter().map(|v| v.as_f64()).sum::<f64>();
    }
    total
}
