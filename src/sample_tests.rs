use super::round_to_code;

/// The oracle: round half away from zero, then clamp.
fn oracle(x: f64, max: f64) -> f64 {
    x.round().clamp(0.0, max)
}

#[test]
fn round_to_code_equals_round_then_clamp() {
    for max in [255.0, 65535.0] {
        // Every half and quarter step over and beyond the range, and the neighbours of
        // every tie in f32 and f64.
        for i in -2000..=(4 * 65536 + 2000) {
            let x = f64::from(i) / 4.0;
            for v in [x, x.next_up(), x.next_down()] {
                assert_eq!(round_to_code(v, max), oracle(v, max), "{v} max {max}");
            }
            let f = x as f32;
            for v in [f, f.next_up(), f.next_down()] {
                let expected = oracle(f64::from(v), max) as f32;
                assert_eq!(round_to_code(v, max), expected, "{v} max {max}");
            }
        }
    }
}
