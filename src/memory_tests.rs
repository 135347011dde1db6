use super::*;

#[test]
fn the_high_water_mark_is_read_in_kibibytes() {
    let status = "Name:\tx\nVmPeak:\t  9000 kB\nVmHWM:\t    2048 kB\nVmRSS:\t 1000 kB\n";
    assert_eq!(parse_vm_hwm(status), Some(2048 * 1024));
    assert_eq!(parse_vm_hwm("VmRSS:\t1 kB\n"), None);
    assert_eq!(parse_vm_hwm("VmHWM:\t12 MB\n"), None);
    assert_eq!(parse_vm_hwm("VmHWM:\tmany kB\n"), None);
}

#[test]
fn a_touched_block_raises_the_peak() {
    let Some(before) = peak_resident_bytes() else {
        return; // not Linux
    };
    let block = std::hint::black_box(vec![7u8; 64 << 20]);
    let after = peak_resident_bytes().unwrap();
    assert!(after >= before);
    assert!(after >= block.len() as u64, "{after} < 64 MiB");
    assert_eq!(block[block.len() - 1], 7);
}
