use super::*;

const TEST: Format = Format {
    magic: b"HSFRAMED",
    version: 3,
    name: "test file",
    corrupt: SceneError::CacheCorrupt,
    other_version: |found, expected| SceneError::CacheVersion { found, expected },
};

#[test]
fn arrays_of_several_parts_read_back_at_aligned_offsets() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.bin");
    let size = TEST
        .write(&path, false, &"h", |body| {
            body.array([&[1.5f32][..], &[2.5, 3.5]]);
            body.array([&[7u64][..]]);
        })
        .unwrap();
    let bytes = std::fs::read(&path).unwrap();
    // The body: the header's length (8 bytes) and `"h"` (3), a gap of 5 to the f32s at 16
    // (12 bytes), a gap of 4 to the u64 at 32; then 16 bytes of prefix before it.
    assert_eq!((size, bytes.len()), (56, 56));
    let (header, mut r) = TEST.open::<String>(&bytes).unwrap();
    assert_eq!(header, "h");
    assert_eq!(r.values::<f32>(3).unwrap(), [1.5, 2.5, 3.5]);
    assert_eq!(r.values::<u64>(1).unwrap(), [7]);
}
