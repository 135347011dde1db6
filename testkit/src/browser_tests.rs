use super::{BrowserError, find_chromium};
use std::os::unix::fs::PermissionsExt;

#[test]
fn only_an_executable_file_counts_as_chromium() {
    let dir = tempfile::tempdir().unwrap();
    let (bin, other) = (dir.path().join("bin"), dir.path().join("other"));
    std::fs::create_dir_all(&bin).unwrap();
    std::fs::create_dir_all(other.join("chromium")).unwrap(); // a directory of that name
    let browser = bin.join("chromium");
    std::fs::write(&browser, "#!/bin/sh\n").unwrap();
    let mode = |m| std::fs::set_permissions(&browser, std::fs::Permissions::from_mode(m));
    let path = std::env::join_paths([&other, &bin]).unwrap();
    let found =
        |named: Option<&std::path::Path>| find_chromium(named.map(Into::into), Some(path.clone()));

    mode(0o644).unwrap();
    let absent = found(None).unwrap_err().to_string();
    assert!(
        absent.contains("no chromium on the PATH (apt-get install chromium"),
        "{absent}"
    );
    let named = found(Some(&browser)).unwrap_err().to_string();
    assert!(
        named.contains("no executable file (apt-get install chromium"),
        "{named}"
    );
    let missing = dir.path().join("nonexistent");
    // Neither a missing file nor a directory is the browser asked for.
    let refused = |named: &std::path::Path| {
        crate::assert_err_matches!(
            found(Some(named)),
            BrowserError {
                what: "browser",
                ..
            },
            &format!(
                "$CHROMIUM names {}, which is no executable file",
                named.display()
            )
        );
    };
    refused(&missing);
    refused(&other.join("chromium"));

    mode(0o755).unwrap();
    assert_eq!(found(None).unwrap(), browser);
    assert_eq!(found(Some(&browser)).unwrap(), browser);
    assert_eq!(found(Some("".as_ref())).unwrap(), browser, "empty: not set");
    // A $CHROMIUM that is missing is absent, even with one on the PATH.
    refused(&missing);
    crate::assert_err_matches!(
        find_chromium(None, None),
        BrowserError {
            what: "browser",
            ..
        },
        "no chromium on the PATH"
    );
}
