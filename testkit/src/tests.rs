use super::*;

// One test: it alone sets the variable, so no other test of this crate sees it change.
#[test]
fn a_required_component_fails_and_any_other_is_skipped() {
    // SAFETY: no other thread of this test binary reads or writes the environment.
    unsafe { std::env::set_var(REQUIRE, " embree ,chromium") };
    assert!(required("chromium") && required("embree"));
    assert!(!required("chrom") && !required("slurm"));
    assert_eq!(
        needs(
            "slurm",
            Err::<(), _>("an example: this test checks the skip line itself")
        ),
        None
    );
    assert_eq!(needs("slurm", Ok::<_, String>(3)), Some(3));
    let failed = std::panic::catch_unwind(|| needs("chromium", Err::<(), _>("no chromium")));
    let message = *failed.unwrap_err().downcast::<String>().unwrap();
    assert!(
        message.contains("chromium is required (HAARSHIFT_REQUIRE) but missing: no chromium"),
        "{message}"
    );
    // SAFETY: as above.
    unsafe { std::env::remove_var(REQUIRE) };
    assert!(!required("chromium"));
    assert_eq!(
        needs(
            "chromium",
            Err::<(), _>("an example: this test checks the skip line itself")
        ),
        None
    );
}
