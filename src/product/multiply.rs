//! The product of `N` functions as a Haar tree (Sun 2006 section 3.4.4, eq. 3.13): the
//! coefficients of the pointwise product, computed on the trees, so that a product of fixed
//! factors is computed once and reused (Sun 2006's just-in-time radiance transfer, eq. 3.9).
//!
//! **Derivation.** The product's block sums are built bottom-up in one synchronous traversal:
//! on a node where two or more functions have nodes, the sum over each quadrant is either
//! returned by the child (when a function has a node there) or `(B/2)^2` times the product of
//! the functions' quadrant means; the product's mean on the node is the sum over `B^2` and its
//! detail steps are `sum_q sign_q x sum_q / B^2`. Where exactly one function has a node, the
//! product is that function times the (constant) others, so its subtree is copied, scaled.
//! Where none has, the product is constant and gets no node. The output has a node wherever an
//! input has one; cost `O(N)` per node of the union of the inputs' supports.
//!
//! Sun 2006's `FunctionProduct` instead adds every node's contribution to all its ancestors'
//! details (`updateParents`, `O(depth)` per node); the bottom-up sums give the same numbers
//! without the walk back up.

use super::basis::wavelet_signs;
use super::integral::{IntegralOptions, check_trees, descend};
use super::transport::Transport;
use super::tree::{HaarTree, Node, NodePosition};
use crate::{Result, Sample};

/// The Haar tree of the pointwise product of `factors` (at least one), all kept.
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, Selection, multiply::product};
/// use ndarray::Array4;
/// let f = Array4::from_shape_fn((1, 4, 4, 1), |(_, i, j, _)| (i + 2 * j) as f64);
/// let g = Array4::from_shape_fn((1, 4, 4, 1), |(_, i, j, _)| 1.0 + (i * j) as f64);
/// let tf = HaarTree::<f64, 1>::from_pixels(f.view(), FaceLayout::Stacked, Selection::All).unwrap();
/// let tg = HaarTree::<f64, 1>::from_pixels(g.view(), FaceLayout::Stacked, Selection::All).unwrap();
/// let fg = product(&[&tf, &tg]).unwrap().to_pixels().unwrap();
/// assert!(fg.iter().zip((&f * &g).iter()).all(|(a, b)| (a - b).abs() < 1e-12));
/// ```
pub fn product<T: Sample, const C: usize>(factors: &[&HaarTree<T, C>]) -> Result<HaarTree<T, C>> {
    multiply_trees(factors)
}

/// The product of a transport and plain factors: a transport (it carries the weight once).
///
/// ```
/// use haarshift::product::{FaceLayout, HaarTree, IntegralOptions, Selection, Transport,
///     WeightedPixels, multiply::weighted_product, product_integral};
/// use ndarray::{Array3, Array4};
/// let f = Array4::from_shape_fn((2, 4, 4, 1), |(k, i, j, _)| (k + i + 2 * j) as f64);
/// let w = WeightedPixels::<f64, 1>::new(f.view(), Array3::from_elem((2, 4, 4), 0.5).view()).unwrap();
/// let t = Transport::new(&w, FaceLayout::Stacked, Selection::All).unwrap();
/// let g = HaarTree::<f64, 1>::from_pixels(f.view(), FaceLayout::Stacked, Selection::All).unwrap();
/// let tg = weighted_product(&t, &[&g]).unwrap();
/// let direct = product_integral(&t, &[&g, &g], IntegralOptions::default()).unwrap();
/// let reused = product_integral(&tg, &[&g], IntegralOptions::default()).unwrap();
/// assert!((direct.value[0] - reused.value[0]).abs() < 1e-12 * direct.value[0]);
/// ```
pub fn weighted_product<T: Sample, const C: usize>(
    transport: &Transport<T, C>,
    factors: &[&HaarTree<T, C>],
) -> Result<Transport<T, C>> {
    let mut trees = Vec::with_capacity(factors.len() + 1);
    trees.push(transport.tree());
    trees.extend_from_slice(factors);
    Ok(Transport::from_weighted_tree(multiply_trees(&trees)?))
}

fn multiply_trees<T: Sample, const C: usize>(trees: &[&HaarTree<T, C>]) -> Result<HaarTree<T, C>> {
    check_trees(trees, IntegralOptions::default())?;
    let first = trees[0];
    let s = first.side();
    let mut b = Builder {
        trees,
        signs: wavelet_signs().map(|q| q.map(T::from_f64)),
        inv_area: (0..=first.levels())
            .map(|l| T::one() / T::from_f64(((s >> l) * (s >> l)) as f64))
            .collect(),
        levels: first.levels(),
        nodes: Vec::new(),
        positions: Vec::new(),
        active: Vec::new(),
    };
    let inv_s = T::one() / T::from_f64(s as f64);
    let mut scaling = Vec::with_capacity(first.faces());
    let mut roots = Vec::with_capacity(first.faces());
    for face in 0..first.faces() {
        b.active.clear();
        let mut cum = [T::one(); C];
        for (k, tree) in trees.iter().enumerate() {
            match tree.root(face) {
                Some(root) => b.active.push((k as u32, root)),
                None => {
                    for (c, sc) in cum.iter_mut().zip(tree.scaling()[face]) {
                        *c *= sc * inv_s;
                    }
                }
            }
        }
        if b.active.is_empty() {
            // Constant face: pixel sum S^2 x product of means, over S.
            scaling.push(cum.map(|v| v * T::from_f64(s as f64)));
            roots.push(None);
            continue;
        }
        let root = b.allocate(1);
        let pos = NodePosition {
            face: face as u32,
            level: 0,
            row: 0,
            col: 0,
        };
        let sum = b.build(root, pos, 0, cum);
        scaling.push(sum.map(|v| v * inv_s));
        roots.push(Some(root as u32));
    }
    Ok(HaarTree::from_parts(
        first.faces(),
        first.levels() as u32,
        first.layout(),
        scaling,
        roots,
        b.nodes,
        b.positions,
    ))
}

struct Builder<'a, T, const C: usize> {
    trees: &'a [&'a HaarTree<T, C>],
    signs: [[T; 3]; 4],
    /// `1 / B^2` per level (one more than the levels: the pixels).
    inv_area: Vec<T>,
    levels: usize,
    nodes: Vec<Node<T, C>>,
    positions: Vec<NodePosition>,
    active: Vec<(u32, u32)>,
}

impl<T: Sample, const C: usize> Builder<'_, T, C> {
    /// Appends `count` placeholder nodes; returns the first index.
    fn allocate(&mut self, count: usize) -> usize {
        let first = self.nodes.len();
        let blank = Node {
            mean: [T::zero(); C],
            step: [[T::zero(); C]; 3],
            first_child: u32::MAX,
            children: 0,
        };
        self.nodes.resize(first + count, blank);
        self.positions.resize(
            first + count,
            NodePosition {
                face: 0,
                level: 0,
                row: 0,
                col: 0,
            },
        );
        first
    }

    /// Fills output node `slot` at `pos` from the functions `active[start..]` (at least one)
    /// and the product `cum` of the others; returns the product's pixel sum over the block.
    fn build(&mut self, slot: usize, pos: NodePosition, start: usize, cum: [T; C]) -> [T; C] {
        self.positions[slot] = pos;
        let end = self.active.len();
        let level = pos.level as usize;
        if end - start == 1 {
            let (t, n) = self.active[start];
            return self.copy_scaled(slot, pos, t, n, cum);
        }
        let trees = self.trees;
        // Which quadrants have a child in some function.
        let mut mask = 0u8;
        for &(t, n) in &self.active[start..end] {
            mask |= trees[t as usize].nodes()[n as usize].children;
        }
        let first_child = if mask != 0 {
            self.allocate(mask.count_ones() as usize)
        } else {
            0
        };
        let mut sums = [[T::zero(); C]; 4];
        let mut next = first_child;
        for (q, sum) in sums.iter_mut().enumerate() {
            let base = self.active.len();
            let child_cum = descend(trees, &mut self.active, start, q, &self.signs[q], cum);
            *sum = if self.active.len() > base {
                let child_pos = NodePosition {
                    face: pos.face,
                    level: pos.level + 1,
                    row: 2 * pos.row + (q >> 1) as u32,
                    col: 2 * pos.col + (q & 1) as u32,
                };
                let child = next;
                next += 1;
                self.build(child, child_pos, base, child_cum)
            } else {
                let area = T::one() / self.inv_area[level + 1];
                child_cum.map(|v| v * area)
            };
            self.active.truncate(base);
        }
        let inv = self.inv_area[level];
        let node = &mut self.nodes[slot];
        node.first_child = if mask != 0 {
            first_child as u32
        } else {
            u32::MAX
        };
        node.children = mask;
        let mut total = [T::zero(); C];
        for ch in 0..C {
            total[ch] = sums.iter().map(|s| s[ch]).sum();
            node.mean[ch] = total[ch] * inv;
            for band in 0..3 {
                let signed: T = (0..4).map(|q| self.signs[q][band] * sums[q][ch]).sum();
                node.step[band][ch] = signed * inv;
            }
        }
        debug_assert!(level < self.levels);
        total
    }

    /// Copies node `n` of tree `t` and its subtree into `slot`, times `cum`; returns the pixel
    /// sum of the copy over the block.
    fn copy_scaled(
        &mut self,
        slot: usize,
        pos: NodePosition,
        t: u32,
        n: u32,
        cum: [T; C],
    ) -> [T; C] {
        let trees = self.trees;
        let src = &trees[t as usize].nodes()[n as usize];
        let scale = |v: [T; C]| -> [T; C] { std::array::from_fn(|ch| v[ch] * cum[ch]) };
        let first_child = if src.children != 0 {
            self.allocate(src.children.count_ones() as usize)
        } else {
            0
        };
        self.positions[slot] = pos;
        self.nodes[slot] = Node {
            mean: scale(src.mean),
            step: src.step.map(scale),
            first_child: if src.children != 0 {
                first_child as u32
            } else {
                u32::MAX
            },
            children: src.children,
        };
        let mut next = first_child;
        for q in 0..4 {
            if let Some(c) = src.child(q) {
                let child_pos = NodePosition {
                    face: pos.face,
                    level: pos.level + 1,
                    row: 2 * pos.row + (q >> 1) as u32,
                    col: 2 * pos.col + (q & 1) as u32,
                };
                self.copy_scaled(next, child_pos, t, c, cum);
                next += 1;
            }
        }
        let inv = self.inv_area[pos.level as usize];
        self.nodes[slot].mean.map(|m| m / inv)
    }
}
