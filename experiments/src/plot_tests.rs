use super::*;

#[test]
fn plots_draw_points_and_text_in_their_colours() {
    let p = |label: &str, x, y| LabeledPoint {
        label: label.into(),
        x,
        y,
    };
    let pts = [p("a", 1.0, 10.0), p("b", 100.0, 0.1)];
    let img = log_log_scatter("t", "x", "y", &pts, &pts[..1]).unwrap();
    let blue = img.pixels().filter(|px| px.0 == [0, 0, 255]).count();
    assert!(
        blue > 100,
        "two filled circles of radius 5: {blue} blue pixels"
    );
    // Text was rendered: dark anti-aliased pixels exist beyond the black axes.
    let grey = img
        .pixels()
        .filter(|px| px.0[0] == px.0[1] && px.0[1] == px.0[2] && (30..200).contains(&px.0[0]))
        .count();
    assert!(grey > 200, "{grey} grey text pixels");
}

/// Labels never overlap each other or a marker; a lone point gets its first spot; a point
/// hidden under labels placed before it gets none.
#[test]
fn labels_are_placed_without_overlaps() {
    let anchors = [(100, 100), (100, 100), (104, 112), (400, 300), (100, 100)];
    let sizes = [(60, 14), (60, 14), (30, 14), (50, 14), (60, 14)];
    let offsets = place_labels(&anchors, &sizes, &[3, 0, 1, 2, 4]);
    assert_eq!(offsets[3], Some(label_spots(50, 14)[0]));
    let boxes: Vec<(i32, i32, i32, i32)> = (0..5)
        .filter_map(|i| {
            let (dx, dy) = offsets[i]?;
            let (x, y) = (anchors[i].0 + dx, anchors[i].1 + dy);
            Some((x, y, x + sizes[i].0 as i32, y + sizes[i].1 as i32))
        })
        .collect();
    for (k, a) in boxes.iter().enumerate() {
        for b in &boxes[k + 1..] {
            let disjoint = a.2 <= b.0 || b.2 <= a.0 || a.3 <= b.1 || b.3 <= a.1;
            assert!(disjoint, "{a:?} overlaps {b:?}");
        }
        for &(x, y) in &anchors {
            let clear = a.2 <= x - 5 || x + 6 <= a.0 || a.3 <= y - 5 || y + 6 <= a.1;
            assert!(clear, "{a:?} covers the marker at {x},{y}");
        }
    }
    // Three labels at one spot: two sides and three heights give room for all three.
    assert!(offsets[0].is_some() && offsets[1].is_some() && offsets[4].is_some());
    assert_ne!(offsets[0], offsets[1]);
}

#[test]
fn log_plots_refuse_non_positive_values() {
    let pts = [LabeledPoint {
        label: "zero".into(),
        x: 0.0,
        y: 1.0,
    }];
    assert_err!(
        log_log_scatter("t", "x", "y", &pts, &[]),
        InvalidParameter { name: "plot", .. },
        "positive, finite"
    );
    let s = Series {
        name: "s".into(),
        values: vec![None],
    };
    assert_err!(
        category_points("t", "y", &["a".into()], &[s]),
        InvalidParameter { name: "plot", .. },
        "positive, finite"
    );
}
