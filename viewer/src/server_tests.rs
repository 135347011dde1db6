#[test]
fn result_files_are_the_records_and_plain_png_names_only() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("relight.json"), b"[]").unwrap();
    std::fs::write(dir.path().join("a-plot.png"), b"png").unwrap();
    std::fs::write(dir.path().join("secret.txt"), b"no").unwrap();
    let read = |name| super::result_file(dir.path(), name).map(|(_, b)| b);
    assert_eq!(read("relight.json"), Some(b"[]".to_vec()));
    assert_eq!(read("files/a-plot.png"), Some(b"png".to_vec()));
    assert_eq!(read("files"), Some(br#"["a-plot.png"]"#.to_vec()));
    for refused in [
        "files/secret.txt",
        "secret.txt",
        "files/../a-plot.png",
        "files/.png",
        "files/sub/a.png",
        "files/missing.png",
        "relight.csv",
    ] {
        assert_eq!(read(refused), None, "{refused}");
    }
}
