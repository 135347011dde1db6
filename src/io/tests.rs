//! Round trips for every format, depth and channel layout, and every error case, on small
//! images generated into a temporary directory.

use std::path::{Path, PathBuf};

use ndarray::{Array2, Array3};

use super::*;
use crate::Channels;
use crate::transform::{Layout, Levels, Normalization, TransformSpec};

/// A deterministic image whose samples cover the whole range of `depth` (0 and the maximum
/// included) for integer depths, and signed fractional values for float depths.
fn pattern(channels: Channels, depth: SampleDepth, h: usize, w: usize) -> PlanarImage<f64> {
    let planes = Array3::from_shape_fn((channels.count(), h, w), |(k, i, j)| {
        let n = (i * 131 + j * 71 + k * 977) as u64;
        let hash = n.wrapping_mul(2_654_435_761) % 1_000_003;
        match depth.integer_max() {
            Some(max) => match (i + j + k) % 7 {
                0 => 0.0,
                1 => max,
                _ => (hash % (max as u64 + 1)) as f64,
            },
            // Multiples of 1/8 in [-128, 128) have at most 11 significant bits: exact in f16.
            None => (hash % 2048) as f64 / 8.0 - 128.0,
        }
    });
    PlanarImage::new(planes, channels, depth).unwrap()
}

fn roundtrip(image: &PlanarImage<f64>, path: &Path) -> PlanarImage<f64> {
    write_image(image, path, WriteOptions::default()).unwrap();
    read_image::<f64>(path).unwrap()
}

fn image_max_abs_diff(a: &PlanarImage<f64>, b: &PlanarImage<f64>) -> f64 {
    assert_eq!(a.planes().dim(), b.planes().dim());
    a.planes()
        .iter()
        .zip(b.planes().iter())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn message(err: &Error) -> String {
    err.to_string()
}

#[test]
fn lossless_formats_round_trip_exactly_for_every_depth_and_channel_layout() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, &[SampleDepth])] = &[
        ("png", &[SampleDepth::U8, SampleDepth::U16]),
        ("tif", &[SampleDepth::U8, SampleDepth::U16]),
        ("exr", &[SampleDepth::F16, SampleDepth::F32]),
        ("npy", &[SampleDepth::F32, SampleDepth::F64]),
    ];
    for &(ext, depths) in cases {
        for &depth in depths {
            for &channels in Channels::ALL {
                let image = pattern(channels, depth, 7, 13);
                let path = dir.path().join(format!("{channels}-{depth}.{ext}"));
                let back = roundtrip(&image, &path);
                assert_eq!(back, image, "{ext} {depth} {channels}");
            }
        }
    }
}

#[test]
fn f32_reads_equal_f64_reads() {
    let dir = tempfile::tempdir().unwrap();
    let image = pattern(Channels::Rgb, SampleDepth::U16, 5, 6);
    let path = dir.path().join("a.png");
    write_image(&image, &path, WriteOptions::default()).unwrap();
    let narrow = read_image::<f32>(&path).unwrap();
    let wide = read_image::<f64>(&path).unwrap();
    assert_eq!(narrow.planes().mapv(f64::from), wide.planes());
}

#[test]
fn npy_layout_is_h_by_w_by_c_and_gray_is_two_dimensional() {
    let dir = tempfile::tempdir().unwrap();
    let rgb = pattern(Channels::Rgb, SampleDepth::F64, 3, 4);
    let path = dir.path().join("rgb.npy");
    write_image(&rgb, &path, WriteOptions::default()).unwrap();
    let raw: ndarray::ArrayD<f64> = ndarray_npy::read_npy(&path).unwrap();
    assert_eq!(raw.shape(), &[3, 4, 3]);
    assert_eq!(raw[[2, 1, 0]], rgb.planes()[[0, 2, 1]]);
    assert_eq!(raw[[1, 3, 2]], rgb.planes()[[2, 1, 3]]);

    let gray = pattern(Channels::Gray, SampleDepth::F32, 3, 4);
    let path = dir.path().join("gray.npy");
    write_image(&gray, &path, WriteOptions::default()).unwrap();
    let raw: ndarray::ArrayD<f32> = ndarray_npy::read_npy(&path).unwrap();
    assert_eq!(raw.shape(), &[3, 4]);
}

#[test]
fn integer_images_keep_their_values_in_float_formats() {
    let dir = tempfile::tempdir().unwrap();
    let image = pattern(Channels::Rgba, SampleDepth::U16, 4, 5);
    for ext in ["exr", "npy"] {
        let back = roundtrip(&image, &dir.path().join(format!("x.{ext}")));
        assert_eq!(back.depth(), SampleDepth::F32);
        assert_eq!(back.planes(), image.planes(), "{ext}");
    }
}

#[test]
fn integer_depths_rescale_by_257_and_round_to_nearest_then_clamp() {
    let dir = tempfile::tempdir().unwrap();
    let eight = pattern(Channels::Gray, SampleDepth::U8, 4, 4);
    let path = dir.path().join("wide.png");
    let to16 = WriteOptions {
        depth: Some(SampleDepth::U16),
        ..Default::default()
    };
    write_image(&eight, &path, to16).unwrap();
    let wide = read_image::<f64>(&path).unwrap();
    assert_eq!(wide.depth(), SampleDepth::U16);
    assert_eq!(wide.planes(), eight.planes().mapv(|v| v * 257.0));

    // A float image given an integer depth: values are code values, rounded and clamped.
    let values = [-3.2, 0.4, 0.5, 2.5, 254.5, 300.0, 127.49, 127.51];
    let expect = [0.0, 0.0, 1.0, 3.0, 255.0, 255.0, 127.0, 128.0];
    let float = PlanarImage::from_gray(
        Array2::from_shape_vec((1, 8), values.to_vec()).unwrap(),
        SampleDepth::F32,
    )
    .unwrap();
    let path = dir.path().join("codes.png");
    let err = write_image(&float, &path, WriteOptions::default()).unwrap_err();
    assert!(message(&err).contains("8- or 16-bit"), "{err}");
    let to8 = WriteOptions {
        depth: Some(SampleDepth::U8),
        ..Default::default()
    };
    write_image(&float, &path, to8).unwrap();
    let back = read_image::<f64>(&path).unwrap();
    assert_eq!(back.plane(0).iter().copied().collect::<Vec<_>>(), expect);
}

#[test]
fn jpeg_is_eight_bit_close_and_refuses_alpha() {
    let dir = tempfile::tempdir().unwrap();
    // Smooth content: JPEG at quality 95 stays within a few code values.
    let smooth = |scale: f64, depth| {
        let planes = Array3::from_shape_fn((3, 32, 32), |(k, i, j)| {
            ((i * 4 + j * 3 + k * 20) as f64 * scale).min(255.0 * scale)
        });
        PlanarImage::new(planes, Channels::Rgb, depth).unwrap()
    };
    let eight = smooth(1.0, SampleDepth::U8);
    let back = roundtrip(&eight, &dir.path().join("a.jpg"));
    assert_eq!(back.depth(), SampleDepth::U8);
    let err = image_max_abs_diff(&back, &eight);
    // Measured 1 code value (1 for 16-bit input, 0 for gray); bound 3 (the decoder may take
    // another SIMD path, and round differently, on another machine).
    assert!(err <= 3.0, "max error {err}");

    // 16-bit input is scaled to 8 bits.
    let sixteen = smooth(257.0, SampleDepth::U16);
    let back16 = roundtrip(&sixteen, &dir.path().join("b.jpeg"));
    assert_eq!(back16.depth(), SampleDepth::U8);
    assert!(image_max_abs_diff(&back16, &eight) <= 3.0);

    let gray = PlanarImage::new(
        eight.planes().slice(ndarray::s![..1, .., ..]).to_owned(),
        Channels::Gray,
        SampleDepth::U8,
    )
    .unwrap();
    let back_gray = roundtrip(&gray, &dir.path().join("g.jpg"));
    assert_eq!(back_gray.channels(), Channels::Gray);
    assert!(image_max_abs_diff(&back_gray, &gray) <= 3.0);

    let rgba = pattern(Channels::Rgba, SampleDepth::U8, 4, 4);
    let err = write_image(&rgba, dir.path().join("c.jpg"), WriteOptions::default()).unwrap_err();
    assert!(message(&err).contains("alpha"), "{err}");
}

#[test]
fn hdr_round_trips_to_rgbe_precision_and_reads_a_doubled_signature() {
    let dir = tempfile::tempdir().unwrap();
    let planes = Array3::from_shape_fn((3, 6, 10), |(k, i, j)| {
        0.01 + (i * 10 + j) as f64 * 0.37 + k as f64 * 5.0
    });
    let image = PlanarImage::new(planes, Channels::Rgb, SampleDepth::F32).unwrap();
    let path = dir.path().join("a.hdr");
    let back = roundtrip(&image, &path);
    assert_eq!(back.depth(), SampleDepth::F32);
    for (x, y) in back.planes().iter().zip(image.planes().iter()) {
        // RGBE keeps 8 mantissa bits relative to the pixel's largest channel.
        let scale = 2f64.powi(-7) * image.planes().iter().fold(0.0f64, |m, v| m.max(*v));
        assert!((x - y).abs() <= scale, "{x} vs {y}");
    }

    // Some real files (Poly Haven's st_fagans_interior) repeat the signature line.
    let bytes = std::fs::read(&path).unwrap();
    let mut doubled = b"#?RADIANCE\n".to_vec();
    doubled.extend_from_slice(&bytes);
    let twice = dir.path().join("twice.hdr");
    std::fs::write(&twice, &doubled).unwrap();
    assert!(bytes.starts_with(b"#?RADIANCE\n"));
    assert_eq!(read_image::<f64>(&twice).unwrap(), back);

    let gray = pattern(Channels::Gray, SampleDepth::F32, 3, 3);
    let err = write_image(&gray, dir.path().join("g.hdr"), WriteOptions::default()).unwrap_err();
    assert!(message(&err).contains("RGB only"), "{err}");
}

#[test]
fn content_decides_the_format_not_the_name() {
    let dir = tempfile::tempdir().unwrap();
    let image = pattern(Channels::Rgb, SampleDepth::U8, 5, 5);
    let png = dir.path().join("a.png");
    write_image(&image, &png, WriteOptions::default()).unwrap();
    let misnamed = dir.path().join("really-a-png.jpg");
    std::fs::copy(&png, &misnamed).unwrap();
    assert_eq!(read_image::<f64>(&misnamed).unwrap(), image);
}

#[test]
fn real_photographs_read_with_their_sizes_and_depths() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata");
    let expect = [
        ("camera.png", Channels::Gray, 512, 512),
        ("astronaut.png", Channels::Rgb, 512, 512),
        ("brick.png", Channels::Gray, 512, 512),
        ("text.png", Channels::Gray, 172, 448),
        ("coins.png", Channels::Gray, 303, 384),
        ("chelsea.png", Channels::Rgb, 300, 451),
    ];
    for (name, channels, h, w) in expect {
        let img = read_image::<f32>(data.join(name)).unwrap();
        assert_eq!(
            (img.channels(), img.height(), img.width(), img.depth()),
            (channels, h, w, SampleDepth::U8),
            "{name}"
        );
        let (lo, hi) = img
            .planes()
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        assert!(0.0 <= lo && lo < hi && hi <= 255.0, "{name}: {lo}..{hi}");
        assert!(img.planes().iter().all(|v| v.fract() == 0.0));
    }
}

/// Writes `bytes` to `name` in `dir` and returns the error reading it gives.
fn read_error(dir: &Path, name: &str, bytes: &[u8]) -> (PathBuf, Error) {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let err = read_image::<f32>(&path).unwrap_err();
    (path, err)
}

/// Asserts `err` is a one-line I/O or format error naming `path` and mentioning `needle`.
fn assert_names(err: &Error, path: &Path, needle: &str) {
    let text = message(err);
    assert!(
        matches!(err, Error::Io { .. } | Error::Format { .. }),
        "{err:?}"
    );
    assert!(text.starts_with(&path.display().to_string()), "{text}");
    assert!(text.contains(needle), "{text:?} lacks {needle:?}");
    assert!(!text.contains('\n'), "{text:?}");
}

/// A `.npy` file with a hand-written header (no data beyond `data`).
fn npy_bytes(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

/// The CRC-32 of PNG chunks (bitwise; only used to forge small headers).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A PNG signature and IHDR chunk claiming `w x h` RGB 8-bit, and nothing else.
fn png_header(w: u32, h: u32) -> Vec<u8> {
    let mut chunk = b"IHDR".to_vec();
    chunk.extend_from_slice(&w.to_be_bytes());
    chunk.extend_from_slice(&h.to_be_bytes());
    chunk.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    out.extend_from_slice(&13u32.to_be_bytes());
    out.extend_from_slice(&chunk);
    out.extend_from_slice(&crc32(&chunk).to_be_bytes());
    // An empty IDAT chunk: decoders read up to the first one before reporting the size.
    out.extend_from_slice(&0u32.to_be_bytes());
    out.extend_from_slice(b"IDAT");
    out.extend_from_slice(&crc32(b"IDAT").to_be_bytes());
    out
}

#[test]
fn crc32_matches_the_standard_check_value() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
}

#[test]
fn bad_inputs_give_one_line_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();

    let missing = d.join("missing.png");
    let err = read_image::<f32>(&missing).unwrap_err();
    assert_names(&err, &missing, "No such file");

    let (p, err) = read_error(d, "empty.png", b"");
    assert_names(&err, &p, "empty");

    let (p, err) = read_error(d, "text.png", b"this is not an image at all");
    assert_names(&err, &p, "not a valid PNG");

    let (p, err) = read_error(d, "notes.txt", b"this is not an image at all");
    assert_names(&err, &p, "unsupported file format");

    let mut corrupt = png_header(4, 4);
    corrupt.extend_from_slice(b"\0\0\0\x05IDATgarbage-garbage");
    let (p, err) = read_error(d, "corrupt.png", &corrupt);
    assert_names(&err, &p, "");

    // A valid PNG cut in half.
    let image = pattern(Channels::Rgb, SampleDepth::U8, 40, 40);
    let whole = d.join("whole.png");
    write_image(&image, &whole, WriteOptions::default()).unwrap();
    let bytes = std::fs::read(&whole).unwrap();
    let (p, err) = read_error(d, "truncated.png", &bytes[..bytes.len() / 2]);
    assert_names(&err, &p, "");

    let (p, err) = read_error(d, "huge.png", &png_header(1 << 20, 1 << 20));
    assert_names(&err, &p, "memory limit");

    let (p, err) = read_error(d, "huge.npy", &npy_bytes("<f8", "(100000, 100000, 3)", &[]));
    assert_names(&err, &p, "memory limit");

    let (p, err) = read_error(d, "zero.npy", &npy_bytes("<f8", "(0, 5)", &[]));
    assert_names(&err, &p, "zero size");

    let (p, err) = read_error(d, "short.npy", &npy_bytes("<f8", "(2, 2)", &[0; 16]));
    assert_names(&err, &p, "truncated");

    let (p, err) = read_error(d, "ints.npy", &npy_bytes("<i4", "(2, 2)", &[0; 16]));
    assert_names(&err, &p, "element type");

    let (p, err) = read_error(d, "five.npy", &npy_bytes("<f4", "(1, 1, 5)", &[0; 20]));
    assert_names(&err, &p, "not an image");

    let mut nan = [0u8; 32];
    nan[8..16].copy_from_slice(&f64::NAN.to_le_bytes());
    let (p, err) = read_error(d, "nan.npy", &npy_bytes("<f8", "(2, 2)", &nan));
    assert_names(&err, &p, "non-finite value NaN at index [0, 0, 1]");
}

#[test]
fn non_finite_exr_is_refused_on_read_and_non_finite_images_on_write() {
    let dir = tempfile::tempdir().unwrap();
    // Write an EXR with an infinity through the exr crate directly.
    let path = dir.path().join("inf.exr");
    let mut values = vec![1.0f32; 6];
    values[4] = f32::INFINITY;
    let channels = exr::prelude::AnyChannels::sort(exr::prelude::SmallVec::from_vec(vec![
        exr::prelude::AnyChannel::new("Y", exr::prelude::FlatSamples::F32(values)),
    ]));
    let layer = exr::prelude::Layer::new(
        (3, 2),
        exr::prelude::LayerAttributes::default(),
        exr::prelude::Encoding::UNCOMPRESSED,
        channels,
    );
    use exr::prelude::WritableImage;
    exr::prelude::Image::from_layer(layer)
        .write()
        .to_file(&path)
        .unwrap();
    let err = read_image::<f32>(&path).unwrap_err();
    assert_names(&err, &path, "non-finite value inf at index [0, 1, 1]");

    let mut image = pattern(Channels::Gray, SampleDepth::F32, 2, 2);
    image.plane_mut(0)[[1, 0]] = f64::NAN;
    let out = dir.path().join("nan.npy");
    let err = write_image(&image, &out, WriteOptions::default()).unwrap_err();
    assert_names(&err, &out, "non-finite");
    assert!(!out.exists());
}

#[test]
fn half_float_overflow_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut image = pattern(Channels::Gray, SampleDepth::F16, 2, 2);
    image.plane_mut(0)[[0, 0]] = 1e6;
    let out = dir.path().join("big.exr");
    let err = write_image(&image, &out, WriteOptions::default()).unwrap_err();
    assert_names(&err, &out, "half float");
}

#[test]
fn unknown_output_extension_and_missing_directory_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let image = pattern(Channels::Gray, SampleDepth::U8, 2, 2);
    let gif = dir.path().join("a.gif");
    let err = write_image(&image, &gif, WriteOptions::default()).unwrap_err();
    assert_names(&err, &gif, "output format");
    let nowhere = dir.path().join("no/such/dir/a.png");
    let err = write_image(&image, &nowhere, WriteOptions::default()).unwrap_err();
    assert_names(&err, &nowhere, "directory does not exist");
}

#[test]
fn existing_outputs_are_kept_unless_forced_and_no_temporary_files_remain() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.png");
    let first = pattern(Channels::Gray, SampleDepth::U8, 3, 3);
    let second = first.map_planes(|p| Ok(p.mapv(|v| 255.0 - v))).unwrap();
    write_image(&first, &path, WriteOptions::default()).unwrap();
    let err = write_image(&second, &path, WriteOptions::default()).unwrap_err();
    assert!(matches!(err, Error::OutputExists { .. }), "{err:?}");
    // The library's message serves every caller: the CLI adds its --force.
    assert!(message(&err).contains("already exists") && !message(&err).contains("--force"));
    assert_eq!(read_image::<f64>(&path).unwrap(), first);
    let forced = WriteOptions {
        force: true,
        ..Default::default()
    };
    write_image(&second, &path, forced).unwrap();
    assert_eq!(read_image::<f64>(&path).unwrap(), second);
    // A failing write (JPEG with alpha) leaves nothing behind.
    let rgba = pattern(Channels::Rgba, SampleDepth::U8, 2, 2);
    assert_err!(
        write_image(&rgba, dir.path().join("x.jpg"), forced),
        Format { .. },
        "x.jpg",
        "alpha channel"
    );
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["out.png"]);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_ne!(
            mode & 0o044,
            0,
            "output readable by others like any new file: {mode:o}"
        );
    }
}

#[test]
fn reading_leaves_the_input_untouched_and_outputs_may_not_be_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("in.tif");
    write_image(
        &pattern(Channels::Rgb, SampleDepth::U16, 4, 4),
        &path,
        WriteOptions::default(),
    )
    .unwrap();
    let before = (
        std::fs::read(&path).unwrap(),
        std::fs::metadata(&path).unwrap().modified().unwrap(),
    );
    read_image::<f64>(&path).unwrap();
    let after = (
        std::fs::read(&path).unwrap(),
        std::fs::metadata(&path).unwrap().modified().unwrap(),
    );
    assert_eq!(before, after);

    assert_err!(
        ensure_distinct_paths(&path, &path),
        Io { .. },
        "in.tif",
        "is the input file"
    );
    #[cfg(unix)]
    {
        let link = dir.path().join("link.tif");
        std::os::unix::fs::symlink(&path, &link).unwrap();
        let err = ensure_distinct_paths(&path, &link).unwrap_err();
        assert_names(&err, &link, "is the input file");
        let hard = dir.path().join("hard.tif");
        std::fs::hard_link(&path, &hard).unwrap();
        assert_err!(
            ensure_distinct_paths(&path, &hard),
            Io { .. },
            "hard.tif",
            "is the input file"
        );
    }
    assert!(ensure_distinct_paths(&path, &dir.path().join("new.tif")).is_ok());
}

#[test]
fn coefficient_files_restore_images_exactly_for_every_layout_norm_and_padding() {
    let dir = tempfile::tempdir().unwrap();
    let image = pattern(Channels::GrayAlpha, SampleDepth::U16, 11, 6);
    for &layout in Layout::ALL {
        for &normalization in Normalization::ALL {
            for &padding in crate::BoundaryMode::ALL {
                for levels in [Levels::Full, Levels::Count(1)] {
                    let spec = TransformSpec {
                        layout,
                        normalization,
                        levels,
                        padding,
                    };
                    let coeffs = CoefficientFile::forward(&image, &spec).unwrap();
                    let path = dir
                        .path()
                        .join(format!("{layout}-{normalization}-{padding}-{levels}.npy"));
                    coeffs.write(&path, WriteOptions::default()).unwrap();
                    let back = CoefficientFile::read(&path).unwrap();
                    assert_eq!(back, coeffs, "stored exactly");
                    let restored = back.inverse().unwrap();
                    assert_eq!(restored.depth(), SampleDepth::U16);
                    // Measured at most 7.3e-11 (values up to 65535); bound 4x.
                    assert!(image_max_abs_diff(&restored, &image) < 3e-10);
                    let png = path.with_extension("png");
                    write_image(&restored, &png, WriteOptions::default()).unwrap();
                    assert_eq!(read_image::<f64>(&png).unwrap(), image);
                }
            }
        }
    }
}

#[test]
fn coefficient_sidecars_are_checked_against_requests_and_shapes() {
    let dir = tempfile::tempdir().unwrap();
    let image = pattern(Channels::Rgb, SampleDepth::U8, 8, 16);
    let spec = TransformSpec {
        levels: Levels::Count(2),
        ..Default::default()
    };
    let coeffs = CoefficientFile::forward(&image, &spec).unwrap();
    let path = dir.path().join("c.npy");
    coeffs.write(&path, WriteOptions::default()).unwrap();
    let sidecar = CoefficientFile::<f64>::sidecar_path(&path);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&sidecar).unwrap()).unwrap();
    assert_eq!(json["transform"]["levels"], serde_json::json!([2, 2]));
    assert_eq!(json["channels"], "rgb");
    assert_eq!(json["depth"], "u8");
    assert_eq!(json["shape"], serde_json::json!([3, 8, 16]));

    let stored = || StoredCoefficients::read(&path, &ReadOptions::default()).unwrap();
    let agreeing = TransformRequest {
        layout: Some(Layout::Pyramid),
        levels: Some(Levels::Count(2)),
        ..Default::default()
    };
    assert_eq!(stored().resolve(&agreeing).unwrap(), coeffs);
    for (request, needle) in [
        (
            TransformRequest {
                layout: Some(Layout::Separable),
                ..Default::default()
            },
            "layout separable was requested",
        ),
        (
            TransformRequest {
                normalization: Some(Normalization::Orthonormal),
                ..Default::default()
            },
            "normalisation",
        ),
        (
            TransformRequest {
                levels: Some(Levels::Full),
                ..Default::default()
            },
            "levels full",
        ),
        (
            TransformRequest {
                padding: Some(crate::BoundaryMode::Wrap),
                ..Default::default()
            },
            "padding wrap",
        ),
    ] {
        let err = stored().resolve(&request).unwrap_err();
        assert_names(&err, &path, needle);
    }

    // Overwriting needs force even when only the sidecar exists.
    std::fs::remove_file(&path).unwrap();
    let err = coeffs.write(&path, WriteOptions::default()).unwrap_err();
    assert!(matches!(err, Error::OutputExists { .. }), "{err:?}");
    let force = WriteOptions {
        force: true,
        ..Default::default()
    };
    coeffs.write(&path, force).unwrap();

    std::fs::write(&sidecar, b"{ not json").unwrap();
    let err = StoredCoefficients::read(&path, &ReadOptions::default()).unwrap_err();
    assert_names(&err, &sidecar, "invalid sidecar");

    coeffs.write(&path, force).unwrap();
    let other =
        CoefficientFile::forward(&pattern(Channels::Rgb, SampleDepth::U8, 4, 4), &spec).unwrap();
    let other_path = dir.path().join("other.npy");
    other.write(&other_path, WriteOptions::default()).unwrap();
    std::fs::copy(CoefficientFile::<f64>::sidecar_path(&other_path), &sidecar).unwrap();
    let err = StoredCoefficients::read(&path, &ReadOptions::default()).unwrap_err();
    assert_names(&err, &sidecar, "sidecar describes a [3, 4, 4] array");
}

#[test]
fn coefficients_without_a_sidecar_use_the_request_and_do_not_crop() {
    let dir = tempfile::tempdir().unwrap();
    let plane = Array2::from_shape_fn((4, 8), |(i, j)| (i * 8 + j) as f64);
    let spec = TransformSpec {
        layout: Layout::Separable,
        normalization: Normalization::Orthonormal,
        ..Default::default()
    };
    let expected = spec.forward(plane.view()).unwrap();
    let path = dir.path().join("raw.npy");
    ndarray_npy::write_npy(&path, &expected.as_array().to_owned()).unwrap();
    let stored = StoredCoefficients::read(&path, &ReadOptions::default()).unwrap();
    assert!(stored.metadata.is_none());
    let request = TransformRequest {
        layout: Some(Layout::Separable),
        normalization: Some(Normalization::Orthonormal),
        ..Default::default()
    };
    let file = stored.resolve(&request).unwrap();
    let meta = file.metadata();
    assert_eq!(meta.transform, *expected.info());
    assert_eq!(
        (meta.channels, meta.depth),
        (Channels::Gray, SampleDepth::F64)
    );
    let restored = file.inverse().unwrap();
    let err = restored
        .plane(0)
        .iter()
        .zip(plane.iter())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-12, "{err}");
    let err = CoefficientFile::read(&path).unwrap_err();
    assert!(message(&err).contains("sidecar is missing"), "{err}");
}

#[test]
fn float_tiffs_from_other_writers_read_as_f32() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("float.tif");
    let values: Vec<f32> = (0..2 * 3 * 3).map(|v| v as f32 * 0.25 - 1.0).collect();
    let mut file = std::fs::File::create(&path).unwrap();
    tiff::encoder::TiffEncoder::new(&mut file)
        .unwrap()
        .write_image::<tiff::encoder::colortype::RGB32Float>(3, 2, &values)
        .unwrap();
    let image = read_image::<f64>(&path).unwrap();
    assert_eq!(
        (
            image.channels(),
            image.depth(),
            image.height(),
            image.width()
        ),
        (Channels::Rgb, SampleDepth::F32, 2, 3)
    );
    // Pixel (1, 2), channel 1 is interleaved sample (1 * 3 + 2) * 3 + 1.
    assert_eq!(image.planes()[[1, 1, 2]], f64::from(values[16]));
}
