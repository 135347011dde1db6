use super::*;
use crate::kernel_cycle::{run_rotation_cycle, synthetic_images};
use crate::rotation_cycle::NoMeter;
use haarshift::rotate::{RotateOptions, rotate_plane};
use ndarray::{Array2, s};
use proptest::prelude::*;

/// `q` dominates `p`: no worse in both coordinates and better in one.
fn dominates(q: (f64, f64), p: (f64, f64)) -> bool {
    q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1)
}

/// Brute force: point `i` is on the frontier of `pts` when nothing dominates it and no
/// earlier point equals it.
fn on_frontier(pts: &[(f64, f64)], i: usize) -> bool {
    !pts.iter().any(|&q| dominates(q, pts[i])) && pts[..i].iter().all(|&q| q != pts[i])
}

fn spec(k: usize) -> MethodSpec {
    MethodSpec {
        method: format!("m{}", k / 2),
        supersample: (k % 2) as u32,
        ..Default::default()
    }
}

proptest! {
    /// Hand-made runs (methods x images, small integer figures so that ties happen): the
    /// aggregates are recomputed directly, and each frontier flag agrees with a brute-force
    /// dominance check on the aggregates.
    #[test]
    fn aggregates_and_frontier_flags_agree_with_brute_force(
        figures in proptest::collection::vec((1u8..6, 1u8..6, 1u8..6), 3..40),
        methods in 1usize..8,
    ) {
        let runs: Vec<CycleRecord> = figures
            .iter()
            .enumerate()
            .map(|(i, &(rms, seconds, mb))| CycleRecord {
                image: format!("img{}", i / methods),
                method: spec(i % methods),
                steps: 16,
                crop: 32,
                rms: f64::from(rms),
                psnr: 0.0,
                max_error: f64::from(rms) * 3.0,
                seconds: f64::from(seconds),
                peak_bytes: Some(u64::from(mb) << 20),
            })
            .collect();
        let points = summarize(&runs);
        prop_assert_eq!(points.len(), methods.min(runs.len()));
        for (k, p) in points.iter().enumerate() {
            let members: Vec<&CycleRecord> =
                runs.iter().filter(|r| r.method == spec(k)).collect();
            prop_assert_eq!(&p.method, &spec(k));
            prop_assert_eq!(p.images, members.len());
            let mean = members.iter().map(|r| r.rms).sum::<f64>() / members.len() as f64;
            prop_assert!((p.mean_rms - mean).abs() < 1e-12);
            let total: f64 = members.iter().map(|r| r.seconds).sum();
            prop_assert_eq!(p.total_seconds, total);
            // The median: as many runs strictly faster as strictly slower, at most half.
            let faster = members.iter().filter(|r| r.seconds < p.median_seconds).count();
            let slower = members.iter().filter(|r| r.seconds > p.median_seconds).count();
            prop_assert!(2 * faster <= members.len() && 2 * slower <= members.len());
            prop_assert_eq!(p.peak_bytes, members.iter().filter_map(|r| r.peak_bytes).max());
            let worst = members.iter().map(|r| r.max_error).fold(0.0, f64::max);
            prop_assert_eq!(p.max_error, worst);
        }
        let time: Vec<(f64, f64)> = points.iter().map(|p| (p.total_seconds, p.mean_rms)).collect();
        let memory: Vec<(f64, f64)> = points
            .iter()
            .map(|p| (p.peak_bytes.unwrap() as f64, p.mean_rms))
            .collect();
        for (i, p) in points.iter().enumerate() {
            prop_assert_eq!(p.time_frontier, on_frontier(&time, i), "time {}", i);
            prop_assert_eq!(p.memory_frontier, on_frontier(&memory, i), "memory {}", i);
        }
    }
}

#[test]
fn unmeasured_memory_puts_nothing_on_the_memory_frontier() {
    let run = |method: &str, rms| CycleRecord {
        image: "a".into(),
        method: MethodSpec {
            method: method.into(),
            ..Default::default()
        },
        steps: 16,
        crop: 8,
        rms,
        psnr: 0.0,
        max_error: rms,
        seconds: 1.0,
        peak_bytes: None,
    };
    let points = summarize(&[run("a", 1.0), run("b", 2.0)]);
    assert_eq!(points[0].peak_bytes, None);
    assert!(points.iter().all(|p| !p.memory_frontier));
    assert_eq!(
        points.iter().map(|p| p.time_frontier).collect::<Vec<_>>(),
        vec![true, false]
    );
}

#[test]
fn absurd_ranges_are_refused() {
    let grid = |p, r, s| TradeoffGrid {
        max_precision: p,
        max_retained_precision: r,
        max_supersample: s,
    };
    assert!(grid(20, 20, 8).validate().is_ok());
    for (bad, name) in [
        (grid(21, 0, 0), "precision"),
        (grid(0, 21, 0), "precision"),
        (grid(0, 0, 9), "supersample"),
        (grid(u32::MAX, 1, 1), "precision"),
    ] {
        assert_err!(
            bad.validate(),
            InvalidParameter { .. },
            name,
            "above the maximum"
        );
    }
}

#[test]
fn the_grid_holds_every_kernel_at_every_parameter() {
    let grid = TradeoffGrid {
        max_precision: 2,
        max_retained_precision: 3,
        max_supersample: 2,
    };
    let configs = grid.every_configuration();
    for &method in ShiftMethod::ALL {
        let mine: Vec<&KernelCycle> = configs.iter().filter(|c| c.method == method).collect();
        if method == ShiftMethod::Haar {
            let mut compact: Vec<(u32, u32)> = mine
                .iter()
                .filter(|c| !c.options.retain)
                .map(|c| (c.options.precision, c.supersample))
                .collect();
            compact.sort();
            let want: Vec<(u32, u32)> =
                (0..=2).flat_map(|h| (0..=2).map(move |s| (h, s))).collect();
            assert_eq!(compact, want);
            let retained: Vec<(u32, u32)> = mine
                .iter()
                .filter(|c| c.options.retain)
                .map(|c| (c.options.precision, c.supersample))
                .collect();
            assert_eq!(retained, vec![(1, 0), (2, 0), (3, 0)]);
        } else {
            let supersamples: Vec<u32> = mine.iter().map(|c| c.supersample).collect();
            assert_eq!(supersamples, vec![0, 1, 2], "{method}");
        }
    }
    assert_eq!(configs.len(), 8 * 3 + 3 * 3 + 3);
}

/// One configuration through the grid and the summary, against the protocol done here from
/// its definition with no experiment or chain code: the 20x20 crop padded by 10 on every
/// side; with supersampling 1, each pixel a 2x2 block of the grid twice as fine, five single
/// rotations by 72 degrees there, and the 2x2 block means back; the RMS and the largest
/// error over the pixels whose centres lie within 20/2 - 2 = 8 of the canvas centre.
#[test]
fn one_point_agrees_with_an_independent_computation() {
    let image = synthetic_images().unwrap()[1].centre_crop(20).unwrap();
    let grid = TradeoffGrid {
        max_precision: 1,
        max_retained_precision: 1,
        max_supersample: 1,
    };
    let keys = KernelCycle::new(ShiftMethod::Keys, KernelOptions::default(), 0);
    let configs = grid.expand(&[keys]);
    let runs =
        run_rotation_cycle(std::slice::from_ref(&image), &configs, 5, &NoMeter, |_| {}).unwrap();
    let points = summarize(&runs);
    let point = points.iter().find(|p| p.method.supersample == 1).unwrap();
    assert_eq!(point.method.method, "keys");

    let mut canvas = Array2::<f64>::zeros((40, 40));
    canvas.slice_mut(s![10..30, 10..30]).assign(&image.plane);
    let kernel = ShiftMethod::Keys.kernel::<f64>();
    let mut fine = Array2::from_shape_fn((80, 80), |(r, c)| canvas[[r / 2, c / 2]]);
    for _ in 0..5 {
        fine = rotate_plane(
            fine.view(),
            72.0,
            kernel.as_ref(),
            &RotateOptions::default(),
        )
        .unwrap();
    }
    let (mut sum_sq, mut max_error, mut count) = (0.0f64, 0.0f64, 0usize);
    for ((r, c), &want) in canvas.indexed_iter() {
        let (dr, dc) = (r as f64 - 19.5, c as f64 - 19.5);
        if dr * dr + dc * dc <= 8.0 * 8.0 {
            let block = fine.slice(s![2 * r..2 * r + 2, 2 * c..2 * c + 2]).sum() / 4.0;
            let d = (block - want).abs();
            sum_sq += d * d;
            max_error = max_error.max(d);
            count += 1;
        }
    }
    let rms = (sum_sq / count as f64).sqrt();
    assert!(count > 150 && rms > 0.5, "a real error to compare: {rms}");
    // The summation order of the block means differs from the library's: rounding only.
    assert!(
        (point.mean_rms - rms).abs() < 1e-12 * rms,
        "{} vs {rms}",
        point.mean_rms
    );
    assert!((point.max_error - max_error).abs() < 1e-12 * max_error);
    assert_eq!((point.images, point.steps), (1, 5));
}
