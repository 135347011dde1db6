use super::LitTexels;

proptest::proptest! {
    /// The positions found are the lit ones, ascending, sixteen at a time (where the CPU
    /// can) and one at a time alike, whatever the buffer held before.
    #[test]
    fn positions_are_the_lit_terms_in_order(
        lit in proptest::collection::vec(0usize..1024, 0..200),
        indices in proptest::collection::vec(0u32..1024, 0..100),
    ) {
        let table = LitTexels::new(1024, lit.iter().copied());
        let want: Vec<u32> = (0..indices.len() as u32)
            .filter(|&k| lit.contains(&(indices[k as usize] as usize)))
            .collect();
        let mut out = vec![7; 3];
        let n = table.positions(&indices, &mut out);
        proptest::prop_assert_eq!(&out[..n], &want[..]);
        let mut one = vec![7; indices.len() + 16];
        let n = table.positions_one_at_a_time(&indices, 0, 0, &mut one);
        proptest::prop_assert_eq!(&one[..n], &want[..]);
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("popcnt")
        {
            let mut wide = vec![7; indices.len() + 16];
            // SAFETY: the features are there and `wide` has the room asked for.
            let n = unsafe { table.positions_avx512(&indices, &mut wide) };
            proptest::prop_assert_eq!(&wide[..n], &want[..]);
        }
    }
}
