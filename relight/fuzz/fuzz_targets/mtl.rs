#![no_main]
//! The MTL reader on arbitrary bytes, as the library of a fixed OBJ; see `../harness.rs`.

#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::run("mtl", data));
