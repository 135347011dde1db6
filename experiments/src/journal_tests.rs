use super::*;

#[test]
fn a_line_cut_short_is_dropped_and_the_run_goes_on_after_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    let mut journal = Journal::create(&path, "o", false).unwrap();
    journal.unit("a", || Ok(1u32)).unwrap();
    journal.unit("b", || Ok(2u32)).unwrap();
    drop(journal);
    // The kill came while "b" was being written.
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, &text[..text.len() - 5]).unwrap();
    let mut journal = Journal::resume(&path, "o").unwrap();
    assert_eq!(journal.unit("a", || Ok(10u32)).unwrap(), 1);
    assert_eq!(journal.unit("b", || Ok(20u32)).unwrap(), 20);
    drop(journal);
    let mut journal = Journal::resume(&path, "o").unwrap();
    assert_eq!(journal.unit("b", || Ok(30u32)).unwrap(), 20);
    assert_eq!(journal.resumed(), 1);
}

#[test]
fn other_options_a_damaged_line_or_another_file_are_refused_naming_why() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    let mut journal = Journal::create(&path, "quick", false).unwrap();
    journal.unit("a", || Ok(1u32)).unwrap();
    drop(journal);
    let e = Journal::resume(&path, "full").unwrap_err().to_string();
    assert!(e.contains("a run with other options or inputs"), "{e}");
    let e = Journal::create(&path, "quick", false).unwrap_err();
    assert!(
        matches!(e, Error::Core(haarshift::Error::OutputExists { .. })),
        "{e}"
    );
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("\"unit\"", "\"u\"") + "{}\n").unwrap();
    let e = Journal::resume(&path, "quick").unwrap_err().to_string();
    assert!(e.contains("line 2 is damaged"), "{e}");
    std::fs::write(&path, "time,rms\n1,2\n").unwrap();
    let e = Journal::resume(&path, "quick").unwrap_err().to_string();
    assert!(e.contains("is not a haarshift journal 1 file"), "{e}");
}

#[test]
fn a_journal_in_memory_measures_every_unit_and_writes_nothing() {
    let mut journal = Journal::in_memory();
    assert_eq!(journal.unit("a", || Ok(1u8)).unwrap(), 1);
    assert_eq!(journal.unit("a", || Ok(2u8)).unwrap(), 2);
    assert_eq!(journal.sidecar("grid.png"), None);
    journal.finish().unwrap();
}

#[test]
fn a_fingerprint_changes_with_the_contents_of_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, "{}").unwrap();
    let before = Journal::fingerprint(std::slice::from_ref(&path)).unwrap();
    assert!(before.ends_with("(2 bytes, CRC-32 a3a6bf43)"), "{before}");
    std::fs::write(&path, "[]").unwrap();
    assert_ne!(Journal::fingerprint(&[path]).unwrap(), before);
}
