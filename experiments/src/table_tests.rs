use super::*;

#[test]
fn rows_are_padded_and_aligned() {
    let mut t = Table::new(["a", "bb"]);
    t.push(["xyz"]);
    t.push(["1", "2", "3"]);
    assert_eq!(t.len(), 2);
    assert_eq!(
        t.to_string(),
        "| a   | bb |\n|-----|----|\n| xyz |    |\n| 1   | 2  |\n"
    );
}

#[test]
fn significant_digits_round_correctly() {
    assert_eq!(significant(2.449, 2), "2.4");
    assert_eq!(significant(-0.05, 2), "-0.050");
    assert_eq!(significant(123456.0, 3), "123456");
    assert_eq!(significant(1.5e7, 2), "1.5e7");
    assert_eq!(significant(0.0, 3), "0");
}
