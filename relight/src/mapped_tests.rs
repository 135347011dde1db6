use super::*;

fn file_of(bytes: &[u8]) -> (tempfile::TempDir, MappedFile) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("numbers");
    std::fs::write(&path, bytes).unwrap();
    let file = MappedFile::open(&path).unwrap();
    (dir, file)
}

#[test]
fn a_mapped_buffer_reads_the_files_little_endian_numbers_in_place() {
    let values = [1.5f32, -2.0, 3.25];
    let mut bytes = vec![0u8; 8];
    values.iter().for_each(|v| bytes.extend(v.to_le_bytes()));
    let (_dir, file) = file_of(&bytes);
    let buffer = Buffer::<f32>::mapped(&file, 8, 3).unwrap();
    assert!(buffer.is_mapped());
    assert_eq!(&*buffer, &values);
    assert_eq!(buffer, Buffer::from(values.to_vec()));
    // In place: the slice points into the map.
    assert_eq!(
        buffer.as_ptr() as usize,
        file.bytes()[8..].as_ptr() as usize
    );
}

#[test]
fn a_buffer_past_the_end_or_misaligned_is_not_mapped() {
    let (_dir, file) = file_of(&[0u8; 32]);
    assert!(Buffer::<u64>::mapped(&file, 8, 3).is_some());
    assert!(Buffer::<u64>::mapped(&file, 8, 4).is_none(), "past the end");
    assert!(Buffer::<u64>::mapped(&file, 4, 1).is_none(), "misaligned");
    assert!(
        Buffer::<u64>::mapped(&file, 8, usize::MAX).is_none(),
        "overflow"
    );
}

#[test]
fn changing_a_mapped_buffer_copies_it_and_leaves_the_file_alone() {
    let (_dir, file) = file_of(&7u32.to_le_bytes());
    let mut buffer = Buffer::<u32>::mapped(&file, 0, 1).unwrap();
    buffer.to_mut().push(9);
    assert!(!buffer.is_mapped());
    assert_eq!(&*buffer, &[7, 9]);
    assert_eq!(file.bytes(), &7u32.to_le_bytes());
}

#[test]
fn a_buffer_is_shared_as_its_own_type_only() {
    let (_dir, file) = file_of(&1.0f32.to_le_bytes());
    let buffer = Buffer::<f32>::mapped(&file, 0, 1).unwrap();
    let same = buffer.shared_as::<f32>().unwrap();
    assert!(same.is_mapped());
    assert_eq!(same.as_ptr(), buffer.as_ptr());
    assert!(buffer.shared_as::<u32>().is_none());
    assert!(Buffer::from(vec![1.0f32]).shared_as::<f64>().is_none());
}
