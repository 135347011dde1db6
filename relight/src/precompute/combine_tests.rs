use proptest::prelude::*;

use super::*;

/// A term of an output row as the tests draw it: a set, its rows, one weight each.
type Drawn = (usize, Vec<u32>, Vec<f32>);

/// The plain sum of the contract: a dense `f64` row over all texels, every term's rows added
/// entry by entry in order, then rounded to `f32`.
fn plain_sum(sets: &[SparseRows<f32>], texels: usize, terms: &[Drawn]) -> Vec<f32> {
    let mut sum = vec![0.0f64; texels];
    for (set, hits, w) in terms {
        for (&i, &w) in hits.iter().zip(w) {
            let (indices, values) = sets[*set].row(i as usize);
            for (&t, &x) in indices.iter().zip(values) {
                sum[t as usize] += f64::from(w) * f64::from(x);
            }
        }
    }
    sum.iter().map(|&x| x as f32).collect()
}

/// Each output row of `kernel` (or the planner's choice), as `(row, texels)`.
fn combined(
    sets: &[SparseRows<f32>],
    texels: usize,
    rows: &[Vec<Drawn>],
    kernel: Option<Kernel>,
) -> Vec<(usize, Vec<f32>)> {
    let combiner = RowCombiner::plan(texels, sets.iter().collect(), kernel);
    let terms = |r: usize| -> Terms<'_> {
        (rows[r].iter())
            .map(|(set, hits, w)| {
                let w = Weights {
                    values: w,
                    stride: 1,
                    offset: 0,
                };
                (*set, &hits[..], w)
            })
            .collect()
    };
    combiner.combine(rows.len(), terms, |r, _, out| (r, out.to_vec()))
}

/// `count` rows over `texels` texels, each a random subset with values in -1..1 (some zero).
fn sparse_rows(texels: usize, count: usize) -> impl Strategy<Value = SparseRows<f32>> {
    let row = proptest::collection::btree_map(0..texels as u32, -1.0f32..1.0, 0..=texels);
    proptest::collection::vec(row, count).prop_map(|rows| {
        let mut out = SparseRows::new();
        for row in rows {
            let (indices, values): (Vec<u32>, Vec<f32>) = row
                .into_iter()
                .map(|(t, x)| (t, if x.abs() < 0.1 { 0.0 } else { x }))
                .unzip();
            out.push(&indices, &values);
        }
        out
    })
}

/// Texels (some not a multiple of [`TILE`]), 1 to 3 sets of 6 rows, and 1 to 20 output
/// rows of terms with weights in -2..2 (zeros among them).
fn problem() -> impl Strategy<Value = (usize, Vec<SparseRows<f32>>, Vec<Vec<Drawn>>)> {
    (1usize..200, 1usize..=3).prop_flat_map(|(texels, set_count)| {
        let term = (
            0..set_count,
            proptest::collection::vec((0u32..6, -2.0f32..2.0), 0..8),
        )
            .prop_map(|(set, hits)| {
                let (hits, w): (Vec<u32>, Vec<f32>) = hits
                    .into_iter()
                    .map(|(i, w)| (i, if w.abs() < 0.2 { 0.0 } else { w }))
                    .unzip();
                (set, hits, w)
            });
        (
            Just(texels),
            proptest::collection::vec(sparse_rows(texels, 6), set_count),
            proptest::collection::vec(proptest::collection::vec(term, 0..3), 1..20),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn both_kernels_give_the_bits_of_the_plain_sum((texels, sets, rows) in problem()) {
        for kernel in [Kernel::Scatter, Kernel::Tiles] {
            let out = combined(&sets, texels, &rows, Some(kernel));
            prop_assert_eq!(out.len(), rows.len());
            for (r, (row, texels_out)) in out.iter().enumerate() {
                prop_assert_eq!(*row, r);
                let want = plain_sum(&sets, texels, &rows[r]);
                let bits = |x: &[f32]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(bits(texels_out), bits(&want), "{:?} row {}", kernel, r);
            }
        }
    }
}

#[test]
fn the_planner_tiles_dense_rows_and_scatters_sparse_ones() {
    let texels = 4096;
    let mut dense = SparseRows::new();
    let mut sparse = SparseRows::new();
    for r in 0..10u32 {
        let all: Vec<u32> = (0..texels as u32).filter(|t| (t + r) % 3 != 0).collect();
        dense.push(&all, &vec![0.5; all.len()]);
        // One entry in every fourth tile: each segment 1/64 full.
        let few: Vec<u32> = (0..texels as u32)
            .step_by(4 * TILE)
            .map(|t| t + r)
            .collect();
        sparse.push(&few, &vec![0.5; few.len()]);
    }
    let planned = |set: &SparseRows<f32>| RowCombiner::plan(texels, vec![set], None).kernel();
    assert_eq!(planned(&dense), Kernel::Tiles);
    assert_eq!(planned(&sparse), Kernel::Scatter);
    // Held beyond the rows: the tiles (dense: every segment of 10 rows, 64 tiles) and a chunk
    // of output rows for each thread.
    let combiner = RowCombiner::plan(texels, vec![&dense], None);
    let tiles = 10 * 64 * (TILE * 4 + 4);
    let chunk = 2 * texels * 4;
    assert_eq!(
        combiner.bytes(10),
        tiles + chunk * rayon::current_num_threads()
    );
}

#[test]
fn a_combination_of_no_rows_or_of_empty_rows_is_empty() {
    let set = SparseRows::new();
    for kernel in [Kernel::Scatter, Kernel::Tiles] {
        assert!(combined(std::slice::from_ref(&set), 64, &[], Some(kernel)).is_empty());
        let one = vec![vec![(0, vec![], vec![])]];
        assert_eq!(
            combined(std::slice::from_ref(&set), 64, &one, Some(kernel)),
            [(0, vec![0.0; 64])]
        );
    }
}
