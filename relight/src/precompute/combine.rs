//! The bounce gather's row combination: for each output row `v`, the weighted sum of stored
//! sparse rows `out_v[t] = sum over sets s, then hit rows j of w_j,s x row_s(i_j)[t]`, added in
//! `f64` in exactly that order for every texel `t` and rounded once to `f32`.
//!
//! Two kernels compute it, and give the same bits: where one adds an entry the other lacks,
//! the entry is zero, and `w x 0 = +-0` (a finite `w`) changes no sum that starts at `+0`
//! (such a sum is never `-0`, so adding a zero of either sign leaves it as it is):
//! - [`Kernel::Scatter`] adds each sparse row into a dense `f64` accumulator over every
//!   texel. It reads each hit row afresh for every output row: the bunny's rows hold about
//!   2,170 entries each (`results/relight/bounces.md`: 6,364,004 coefficients for 2,928
//!   vertices), so an output row's hundreds of hit rows come from beyond the L2 cache, and
//!   the scatter runs at the speed of that read.
//! - [`Kernel::Tiles`] first regroups every row by tiles of [`TILE`] texels, each non-empty
//!   segment stored densely and one tile's segments of every row together; it then makes
//!   every output row's tile before moving to the next tile, so that the tile's segments
//!   (1/96 of the tiles at cube 6 x 32^2) are read from the L2 cache by every output row of
//!   a chunk, in vector adds without indices. It pays when the stored rows are dense at the tile's scale.
//!
//! [`RowCombiner::plan`] chooses: tiles when the dense segments and their slot table take at
//! most twice the bytes of the sparse rows (segments about a quarter full or more), the
//! scatter otherwise (the cubes scene's rows keep 414 of 24,576 coefficients, under 2%). The
//! tiles are counted in the working memory a precomputation reports.

use rayon::prelude::*;

use crate::precompute::sparse::SparseRows;

/// Texels of one tile of [`Kernel::Tiles`]: 64 `f64` sums, eight AVX-512 registers.
pub(crate) const TILE: usize = 64;

/// About the bytes of one chunk of output rows' texels.
const CHUNK_BYTES: usize = 4 << 20;

/// Which way a [`RowCombiner`] adds rows; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kernel {
    /// Each sparse row into a dense accumulator over every texel.
    Scatter,
    /// Dense segments, tile by tile.
    Tiles,
}

/// The stored rows of some sets, ready to be combined; see the [module docs](self).
pub(crate) struct RowCombiner<'a> {
    texels: usize,
    sets: Vec<&'a SparseRows<f32>>,
    /// With [`Kernel::Tiles`], each set regrouped by tiles.
    tiles: Option<Vec<DenseTiles>>,
}

/// The terms of one output row: for each set (by its place in [`RowCombiner::plan`]'s
/// `sets`), the rows it adds and their weights.
pub(crate) type Terms<'t> = Vec<(usize, &'t [u32], Weights<'t>)>;

/// The weights of a term's rows: `values[j * stride + offset]` for row `j`.
#[derive(Clone, Copy)]
pub(crate) struct Weights<'t> {
    /// The weights of every channel, row after row.
    pub values: &'t [f32],
    /// Weights a row (the channels).
    pub stride: usize,
    /// The channel.
    pub offset: usize,
}

impl Weights<'_> {
    /// Row `j`'s weight.
    pub(crate) fn at(&self, j: usize) -> f64 {
        f64::from(self.values[j * self.stride + self.offset])
    }
}

impl<'a> RowCombiner<'a> {
    /// Rows over `texels` (at least 1) texels of `sets`, combined by `kernel` or, when `None`,
    /// by the kernel the rows' density calls for.
    pub(crate) fn plan(
        texels: usize,
        sets: Vec<&'a SparseRows<f32>>,
        kernel: Option<Kernel>,
    ) -> Self {
        debug_assert!(texels > 0, "a parameterisation has texels");
        let counts: Vec<usize> = match kernel {
            Some(Kernel::Scatter) => Vec::new(),
            _ => sets.iter().map(|s| segment_count(s)).collect(),
        };
        let kernel = kernel.unwrap_or_else(|| {
            let tiles = texels.div_ceil(TILE);
            let sparse: usize = sets.iter().map(|s| s.coefficient_count() * 8).sum();
            let dense: usize = (sets.iter().zip(&counts))
                .map(|(s, &c)| c * TILE * 4 + tiles * s.len() * 4)
                .sum();
            if dense <= 2 * sparse {
                Kernel::Tiles
            } else {
                Kernel::Scatter
            }
        });
        // A slot is a u32 and `EMPTY` is none: more segments than that keep to the scatter.
        let fits = counts.iter().all(|&c| c < EMPTY as usize);
        let tiles = (kernel == Kernel::Tiles && fits)
            .then(|| sets.iter().map(|s| DenseTiles::new(s, texels)).collect());
        RowCombiner {
            texels,
            sets,
            tiles,
        }
    }

    /// The kernel planned.
    #[cfg(test)]
    pub(crate) fn kernel(&self) -> Kernel {
        if self.tiles.is_some() {
            Kernel::Tiles
        } else {
            Kernel::Scatter
        }
    }

    /// Bytes [`combine`](Self::combine) holds for `n` output rows besides the sets' own rows:
    /// the tiles and each thread's chunk of output rows.
    pub(crate) fn bytes(&self, n: usize) -> usize {
        let tiles: usize = (self.tiles.iter().flatten())
            .map(|t| t.slot.len() * 4 + t.values.len() * 4)
            .sum();
        let chunk = self.chunk(n) * self.texels * 4;
        tiles + chunk * rayon::current_num_threads()
    }

    /// Output rows a chunk: their texels near [`CHUNK_BYTES`], and at least eight chunks to
    /// share between the threads.
    fn chunk(&self, n: usize) -> usize {
        (CHUNK_BYTES / (self.texels * 4)).clamp(1, n.div_ceil(8).max(1))
    }

    /// Output rows `0..n` from `terms(r)`, in parallel over chunks of rows:
    /// `finish(r, terms_r, out_r)` receives each output row's terms and texels in order of `r`
    /// within a chunk, and its results are returned in order of `r`.
    pub(crate) fn combine<'t, R: Send>(
        &self,
        n: usize,
        terms: impl Fn(usize) -> Terms<'t> + Sync,
        finish: impl Fn(usize, &Terms<'t>, &[f32]) -> R + Sync,
    ) -> Vec<R> {
        let (texels, chunk) = (self.texels, self.chunk(n));
        let chunks: Vec<Vec<R>> = (0..n.div_ceil(chunk))
            .into_par_iter()
            .map(|k| {
                let rows = k * chunk..((k + 1) * chunk).min(n);
                let terms: Vec<Terms<'t>> = rows.clone().map(&terms).collect();
                let mut out = vec![0.0f32; terms.len() * texels];
                match &self.tiles {
                    Some(tiles) => add_tiles(tiles, &terms, &mut out),
                    None => self.add_scatter(&terms, &mut out),
                }
                rows.zip(terms.iter().zip(out.chunks_exact(texels)))
                    .map(|(r, (t, o))| finish(r, t, o))
                    .collect()
            })
            .collect();
        chunks.into_iter().flatten().collect()
    }

    /// [`Kernel::Scatter`] for the output rows of `terms`, into `out` (their texels, row by row).
    fn add_scatter(&self, terms: &[Terms<'_>], out: &mut [f32]) {
        let mut dense = vec![0.0f64; self.texels];
        for (row, o) in terms.iter().zip(out.chunks_exact_mut(self.texels)) {
            dense.fill(0.0);
            for &(set, hits, w) in row {
                for (j, &i) in hits.iter().enumerate() {
                    let (indices, values) = self.sets[set].row(i as usize);
                    let wj = w.at(j);
                    for (&t, &x) in indices.iter().zip(values) {
                        dense[t as usize] += wj * f64::from(x);
                    }
                }
            }
            for (o, &d) in o.iter_mut().zip(&dense) {
                *o = d as f32;
            }
        }
    }
}

/// Every output row's tile `k` before tile `k + 1`; compiled for AVX-512 or AVX2 where the CPU
/// has them (no fused multiply-adds, so every CPU gets the same bits).
fn add_tiles(tiles: &[DenseTiles], terms: &[Terms<'_>], out: &mut [f32]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F, the only feature `add_tiles_avx512` is compiled for.
            return unsafe { add_tiles_avx512(tiles, terms, out) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, the only feature `add_tiles_avx2` is compiled for.
            return unsafe { add_tiles_avx2(tiles, terms, out) };
        }
    }
    add_tiles_portable(tiles, terms, out)
}

/// [`add_tiles_portable`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn add_tiles_avx512(tiles: &[DenseTiles], terms: &[Terms<'_>], out: &mut [f32]) {
    add_tiles_portable(tiles, terms, out)
}

/// [`add_tiles_portable`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn add_tiles_avx2(tiles: &[DenseTiles], terms: &[Terms<'_>], out: &mut [f32]) {
    add_tiles_portable(tiles, terms, out)
}

/// [`Kernel::Tiles`] for the output rows of `terms`, into `out` (their texels, row by row):
/// one source for every target, so that each compiles the same adds in the same order.
#[inline(always)]
fn add_tiles_portable(tiles: &[DenseTiles], terms: &[Terms<'_>], out: &mut [f32]) {
    let Some(first) = tiles.first() else { return };
    let texels = first.texels;
    let mut acc = [0.0f64; TILE];
    for k in 0..texels.div_ceil(TILE) {
        let (from, to) = (k * TILE, ((k + 1) * TILE).min(texels));
        for (row, o) in terms.iter().zip(out.chunks_exact_mut(texels)) {
            acc.fill(0.0);
            for &(set, hits, w) in row {
                let set = &tiles[set];
                let slots = &set.slot[k * set.rows..(k + 1) * set.rows];
                for (j, &i) in hits.iter().enumerate() {
                    let s = slots[i as usize];
                    if s != EMPTY {
                        let s = s as usize * TILE;
                        let x: &[f32; TILE] = set.values[s..s + TILE].try_into().expect("TILE");
                        let wj = w.at(j);
                        for (a, &x) in acc.iter_mut().zip(x) {
                            *a += wj * f64::from(x);
                        }
                    }
                }
            }
            for (o, &a) in o[from..to].iter_mut().zip(&acc) {
                *o = a as f32;
            }
        }
    }
}

/// A slot of no segment.
const EMPTY: u32 = u32::MAX;

/// Rows regrouped by tiles of [`TILE`] texels: row `r`'s segment of tile `k` is
/// `values[slot[k * rows + r] * TILE..][..TILE]` (zero where the row has no entry), or
/// nothing when `slot` is [`EMPTY`]. Segments are stored tile by tile.
struct DenseTiles {
    texels: usize,
    rows: usize,
    slot: Vec<u32>,
    values: Vec<f32>,
}

/// The non-empty (row, tile) segments of `rows`.
fn segment_count(rows: &SparseRows<f32>) -> usize {
    (0..rows.len())
        .map(|r| {
            let (indices, _) = rows.row(r);
            let mut last = usize::MAX;
            indices
                .iter()
                .filter(|&&t| std::mem::replace(&mut last, t as usize / TILE) != t as usize / TILE)
                .count()
        })
        .sum()
}

impl DenseTiles {
    fn new(rows: &SparseRows<f32>, texels: usize) -> Self {
        let (n, tiles) = (rows.len(), texels.div_ceil(TILE));
        let mut slot = vec![EMPTY; tiles * n];
        for r in 0..n {
            for &t in rows.row(r).0 {
                slot[t as usize / TILE * n + r] = 0;
            }
        }
        // Numbered tile by tile (`plan` checked that they fit below `EMPTY`).
        let mut segments = 0;
        for (s, k) in slot.iter_mut().filter(|s| **s == 0).zip(0u32..) {
            (*s, segments) = (k, k as usize + 1);
        }
        let mut values = vec![0.0f32; segments * TILE];
        for r in 0..n {
            let (indices, x) = rows.row(r);
            for (&t, &x) in indices.iter().zip(x) {
                let t = t as usize;
                values[slot[t / TILE * n + r] as usize * TILE + t % TILE] = x;
            }
        }
        DenseTiles {
            texels,
            rows: n,
            slot,
            values,
        }
    }
}

#[cfg(test)]
#[path = "combine_tests.rs"]
mod tests;
