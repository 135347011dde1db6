#![no_main]
//! The `merl` reader on arbitrary bytes; see `../harness.rs`.

#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::run("merl", data));
