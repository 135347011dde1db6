//! Files written by other tools: a run-length-encoded Radiance `.hdr` (as the shared
//! environment maps are) and half-float OpenEXR with layer-prefixed channel names, compressed,
//! written through the `exr` crate's own API rather than this crate's writer.

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec,
    WritableImage, f16,
};
use ndarray::Array3;

use super::read_image;
use crate::Channels;

fn testdata(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata")
        .join(name)
}

/// `testdata/envmaps/rooitou_park_32x16.hdr` (made by `scripts/make_test_hdr.py` from a shared
/// envmap) is new-style RLE with run packets; it decodes to the values its generator computed
/// from the RGBE bytes (mantissa * 2^(e - 136)), bit for bit. A decoder with the wrong exponent
/// offset is off by a power of two, one that misreads a run shifts the rest of its scanline.
#[test]
fn run_length_encoded_radiance_reads_the_generators_values() {
    let path = testdata("envmaps/rooitou_park_32x16.hdr");
    let bytes = std::fs::read(&path).unwrap();
    let size_line = b"-Y 16 +X 32\n";
    let header_end = bytes
        .windows(size_line.len())
        .position(|w| w == size_line)
        .unwrap()
        + size_line.len();
    // The first scanline starts with the new-style RLE marker 2 2 0 32; its packets include
    // runs (a count byte above 128 at a packet start).
    assert_eq!(&bytes[header_end..header_end + 4], &[2, 2, 0, 32]);
    let (mut pos, mut runs) = (header_end + 4, 0);
    for _ in 0..4 {
        let mut x = 0;
        while x < 32 {
            let count = bytes[pos] as usize;
            if count > 128 {
                runs += 1;
                (x, pos) = (x + count - 128, pos + 2);
            } else {
                (x, pos) = (x + count, pos + 1 + count);
            }
        }
    }
    assert!(runs > 0, "no run packets in the first scanline");
    assert!(
        bytes.len() < 16 * 32 * 4,
        "not compressed: {} bytes",
        bytes.len()
    );

    let image = read_image::<f32>(&path).unwrap();
    assert_eq!(image.channels(), Channels::Rgb);
    let values = read_image::<f32>(testdata("envmaps/rooitou_park_32x16_values.npy")).unwrap();
    assert_eq!((image.height(), image.width()), (16, 32));
    assert_eq!(image.planes(), values.planes());
    assert!(values.planes().iter().all(|&v| v > 0.0));
}

/// A half-float EXR with channels `diffuse.R`, `diffuse.G`, `diffuse.B`, `diffuse.A` (stored
/// in the file sorted by name), ZIP-compressed, reads as RGBA with the half values exactly.
#[test]
fn half_float_exr_with_layer_prefixes_reads_its_values() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("layered.exr");
    let (w, h) = (7usize, 5usize);
    let value = |c: usize, i: usize| f16::from_f32(0.125 * (c * 40 + i) as f32 - 3.0 + 1e-3);
    let names = ["diffuse.R", "diffuse.G", "diffuse.B", "diffuse.A"];
    let channels: Vec<AnyChannel<FlatSamples>> = names
        .iter()
        .enumerate()
        .map(|(c, name)| {
            AnyChannel::new(
                *name,
                FlatSamples::F16((0..w * h).map(|i| value(c, i)).collect()),
            )
        })
        .collect();
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named("diffuse"),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    Image::from_layer(layer).write().to_file(&path).unwrap();

    let image = read_image::<f32>(&path).unwrap();
    assert_eq!(image.channels(), Channels::Rgba);
    assert_eq!(image.depth(), crate::SampleDepth::F16);
    let want = Array3::from_shape_fn((4, h, w), |(c, r, x)| value(c, r * w + x).to_f32());
    assert_eq!(image.planes(), want);
}
