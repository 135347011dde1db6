use super::*;
use haarshift::Channels;
use image::AnimationDecoder;
use image::codecs::gif::GifDecoder;
use ndarray::Array3;

/// Frame `k`: a left half of one colour and a right half of another, moving with `k`.
fn frame(k: usize) -> PlanarImage<f32> {
    let planes = Array3::from_shape_fn((3, 12, 20), |(c, _, j)| {
        let left = j < 10;
        [
            [200.0, 40.0 + 20.0 * k as f32, 10.0],
            [0.0, 90.0, 250.0 - 30.0 * k as f32],
        ][usize::from(!left)][c]
    });
    PlanarImage::new(planes, Channels::Rgb, SampleDepth::U8).unwrap()
}

#[test]
fn a_written_gif_reads_back_with_its_frames_and_pixels() {
    let frames: Vec<_> = (0..5).map(frame).collect();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("turn.gif");
    write_gif(&frames, &path, 80, false).unwrap();
    let decoder =
        GifDecoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap())).unwrap();
    let back = decoder.into_frames().collect_frames().unwrap();
    assert_eq!(back.len(), 5);
    for (k, f) in back.iter().enumerate() {
        assert_eq!(f.delay().numer_denom_ms(), (80, 1));
        let buffer = f.buffer();
        assert_eq!(buffer.dimensions(), (20, 12));
        for (x, want) in [(3u32, 0usize), (15, 10)] {
            let got = buffer.get_pixel(x, 6).0;
            for (c, &g) in got.iter().take(3).enumerate() {
                let w = frames[k].plane(c)[[6, want + 5]];
                // Two colours a frame: the palette holds both to NeuQuant's precision.
                assert!(
                    (g as f32 - w).abs() <= 4.0,
                    "frame {k} x {x} c {c}: {g} vs {w}"
                );
            }
        }
    }
}

#[test]
fn bad_sequences_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.gif");
    assert_err!(
        write_gif(&[], &path, 100, false),
        InvalidParameter { name: "frames", .. },
        "at least one frame"
    );
    let linear = PlanarImage::new(
        Array3::<f32>::zeros((3, 2, 2)),
        Channels::Rgb,
        SampleDepth::F32,
    )
    .unwrap();
    assert_err!(
        write_gif(&[frame(0), linear], &path, 100, false),
        InvalidParameter { name: "frames", .. },
        "every frame must be 20 x 12"
    );
    assert_err!(
        write_gif(&[frame(0)], &path, 5, false),
        InvalidParameter { name: "delay", .. },
        "5 ms"
    );
    assert!(!path.exists());
}
