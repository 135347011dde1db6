#![no_main]
//! The glTF reader (`.gltf` text or `.glb` by its magic) on arbitrary bytes; see `../harness.rs`.

#[path = "../harness.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::run("gltf", data));
