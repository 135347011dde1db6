use super::*;

fn reason(uri: &str, dir: &Path) -> String {
    resolve("buffer 0", uri, dir).unwrap_err().to_string()
}

#[test]
fn names_that_leave_the_folder_are_refused_before_anything_is_opened() {
    let dir = tempfile::tempdir().unwrap();
    // None of these exists: a refusal that opened or resolved them would say so instead.
    for (uri, why) in [
        ("../x.bin", "climbs out"),
        ("a/../../x.bin", "climbs out"),
        ("%2e%2e/x.bin", "climbs out"),
        ("..\\x.bin", "climbs out"),
        ("/etc/passwd", "absolute path"),
        ("\\\\server\\x", "absolute path"),
        ("file:///etc/passwd", "scheme"),
        ("FILE:x.bin", "scheme"),
        ("http://example.invalid/x.bin", "scheme"),
        ("C:\\x.bin", "scheme"),
        ("x%00.bin", "NUL"),
    ] {
        let r = reason(uri, dir.path());
        assert!(r.starts_with("buffer 0: "), "{r}");
        assert!(
            r.contains(why) && r.contains("its own folder"),
            "{uri}: {r}"
        );
    }
    assert!(reason("%zz", dir.path()).contains("not a valid URI"));
}

#[test]
fn files_inside_the_folder_and_data_uris_are_resolved() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("sub dir")).unwrap();
    std::fs::write(dir.path().join("sub dir/x.bin"), b"x").unwrap();
    assert_eq!(
        resolve("image 1", "./sub%20dir/x.bin", dir.path()).unwrap(),
        AssetSource::File(dir.path().join("./sub dir/x.bin"))
    );
    assert_eq!(
        resolve(
            "image 1",
            "data:application/octet-stream;base64,AAEC/w==",
            dir.path()
        )
        .unwrap(),
        AssetSource::Data(vec![0, 1, 2, 255])
    );
    assert!(reason("data:text/plain,hello", dir.path()).contains("not base64"));
    assert!(reason("missing.bin", dir.path()).contains("missing.bin"));
}

#[cfg(unix)]
#[test]
fn a_link_out_of_the_folder_is_refused() {
    let outside = tempfile::tempdir().unwrap();
    std::fs::write(outside.path().join("secret.bin"), b"x").unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(outside.path().join("secret.bin"), dir.path().join("x.bin"))
        .unwrap();
    assert!(reason("x.bin", dir.path()).contains("through a link"));
}
