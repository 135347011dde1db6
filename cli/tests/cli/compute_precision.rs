//! The float type the commands compute in: f32 for 8- and 16-bit, f16 and f32 data, bit for
//! bit the library's f32 result; f64 for float64 `.npy` files or with `--compute f64`;
//! float16 `.npy` input; and echoed numbers in a readable form.

use std::path::Path;

use crate::common::{p, succeeds_with_stdout};

use haarshift::io::{WriteOptions, read_image, write_image};
use haarshift::kernels::{Outside, ShiftMethod, shift_plane};
use haarshift::rotate::{Canvas, RotateOptions, rotate_image};
use haarshift::{Channels, PlanarImage, Sample, SampleDepth};
use ndarray::Array3;

/// A `channels` image of `h x w` at `depth`: scrambled whole numbers over the depth's range
/// (Fibonacci hashing of the index), divided by 7 for float depths so that the values are not
/// whole numbers.
fn image<T: Sample>(channels: Channels, h: usize, w: usize, depth: SampleDepth) -> PlanarImage<T> {
    let max = depth.integer_max().unwrap_or(1000.0) as u64 + 1;
    let scale = if depth.integer_max().is_some() {
        1.0
    } else {
        1.0 / 7.0
    };
    let c = channels.count();
    let values = (0..(c * h * w) as u64).map(|i| {
        let scrambled = (i.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) % max;
        T::from_f64(scrambled as f64 * scale)
    });
    let planes = Array3::from_shape_vec((c, h, w), values.collect()).unwrap();
    PlanarImage::new(planes, channels, depth).unwrap()
}

/// Writes `image` to `dir/name` and returns the path.
fn save<T: Sample>(dir: &Path, name: &str, image: &PlanarImage<T>) -> std::path::PathBuf {
    let path = dir.join(name);
    write_image(image, &path, WriteOptions::default()).unwrap();
    path
}

/// The library's keys rotation by 30 degrees (expanded canvas) of the file at `path`, in `T`.
fn library_rotation<T: Sample>(path: &Path) -> PlanarImage<T> {
    let kernel = ShiftMethod::Keys.kernel::<T>();
    let options = RotateOptions {
        canvas: Canvas::Expand,
        ..Default::default()
    };
    rotate_image(
        &read_image::<T>(path).unwrap(),
        30.0,
        kernel.as_ref(),
        &options,
    )
    .unwrap()
}

/// `haarshift rotate INPUT -o OUTPUT --method keys --angle 30 --canvas expand EXTRA...`.
fn rotate_keys_30(input: &Path, output: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "rotate",
        p(input),
        "-o",
        p(output),
        "--method",
        "keys",
        "--angle",
        "30",
        "--canvas",
        "expand",
    ];
    args.extend_from_slice(extra);
    succeeds_with_stdout(&args)
}

/// Whether two images differ in at least one sample.
fn differ<T: Sample>(a: &PlanarImage<T>, b: &PlanarImage<T>) -> bool {
    a.planes().iter().zip(b.planes()).any(|(x, y)| x != y)
}

#[test]
fn f32_files_rotate_in_f32_bit_for_bit_as_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let input = save(
        dir.path(),
        "in.npy",
        &image::<f32>(Channels::Rgb, 37, 53, SampleDepth::F32),
    );
    let out = dir.path().join("out.npy");
    let said = rotate_keys_30(&input, &out, &[]);
    assert!(said.contains("with keys in f32"), "{said}");
    let cli = read_image::<f32>(&out).unwrap();
    assert_eq!(cli.depth(), SampleDepth::F32);
    let expected = library_rotation::<f32>(&input);
    assert_eq!(cli, expected);
    // The f64 path rounded to f32 is another image: the comparison above can tell them apart.
    let via_f64 = library_rotation::<f64>(&input);
    let (planes, channels, depth) = via_f64.into_parts();
    let via_f64 = PlanarImage::new(planes.mapv(|v| v as f32), channels, depth).unwrap();
    assert!(differ(&cli, &via_f64));

    // On request the same file goes through f64.
    let out64 = dir.path().join("out64.npy");
    let said = rotate_keys_30(&input, &out64, &["--compute", "f64"]);
    assert!(said.contains("with keys in f64"), "{said}");
    assert_eq!(read_image::<f32>(&out64).unwrap(), via_f64);
}

#[test]
fn eight_and_sixteen_bit_pngs_rotate_in_f32_and_keep_their_depth() {
    let dir = tempfile::tempdir().unwrap();
    for (depth, channels) in [
        (SampleDepth::U8, Channels::Rgb),
        (SampleDepth::U16, Channels::Gray),
        (SampleDepth::U8, Channels::Rgba),
    ] {
        let name = format!("{depth}-{channels}.png");
        let input = save(dir.path(), &name, &image::<f32>(channels, 29, 41, depth));
        let out = dir.path().join(format!("out-{name}"));
        rotate_keys_30(&input, &out, &[]);
        let cli = read_image::<f32>(&out).unwrap();
        assert_eq!(cli.depth(), depth, "{name}");
        assert_eq!(cli, library_rotation::<f32>(&input), "{name}");
        if depth == SampleDepth::U16 {
            // Full 16-bit codes, not 8-bit ones scaled by 257.
            let off_grid = cli.planes().iter().filter(|&&v| v % 257.0 != 0.0).count();
            assert!(off_grid > cli.planes().len() / 2, "{off_grid}");
        }
    }
}

#[test]
fn float64_files_go_through_f64() {
    let dir = tempfile::tempdir().unwrap();
    let input = save(
        dir.path(),
        "in.npy",
        &image::<f64>(Channels::Gray, 33, 47, SampleDepth::F64),
    );
    let out = dir.path().join("out.npy");
    let said = rotate_keys_30(&input, &out, &[]);
    assert!(said.contains("with keys in f64"), "{said}");
    let cli = read_image::<f64>(&out).unwrap();
    assert_eq!(cli.depth(), SampleDepth::F64);
    let expected = library_rotation::<f64>(&input);
    assert_eq!(cli, expected);
    // The f32 path gives other values (so the test above can fail).
    let via_f32 = library_rotation::<f32>(&input);
    assert!(
        cli.planes()
            .iter()
            .zip(via_f32.planes())
            .any(|(&a, &b)| a != f64::from(b))
    );
}

#[test]
fn shift_computes_in_f32_for_f32_files() {
    let dir = tempfile::tempdir().unwrap();
    let input = save(
        dir.path(),
        "in.npy",
        &image::<f32>(Channels::Gray, 24, 40, SampleDepth::F32),
    );
    let out = dir.path().join("out.npy");
    let flags = ["--method", "keys", "--dx", "0.3", "--dy", "-1.7"];
    let mut args = vec!["shift", p(&input), "-o", p(&out)];
    args.extend_from_slice(&flags);
    let said = succeeds_with_stdout(&args);
    assert!(
        said.contains("shifted by (0.3, -1.7) with keys in f32"),
        "{said}"
    );
    let original = read_image::<f32>(&input).unwrap();
    let kernel = ShiftMethod::Keys.kernel::<f32>();
    let outside = Outside::Boundary(haarshift::BoundaryMode::Wrap);
    let expected = shift_plane(original.plane(0), 0.3, -1.7, kernel.as_ref(), outside).unwrap();
    assert_eq!(read_image::<f32>(&out).unwrap().plane(0), expected);
}

/// A `.npy` file of float16 values given as their bit patterns.
fn write_f16_npy(path: &Path, shape: (usize, usize), bits: &[u16], little_endian: bool) {
    let descriptor = if little_endian { "<f2" } else { ">f2" };
    let mut header = format!(
        "{{'descr': '{descriptor}', 'fortran_order': False, 'shape': ({}, {}), }}",
        shape.0, shape.1
    );
    // Magic, version, header length, header padded with spaces to 64 bytes, newline.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    for b in bits {
        let pair = if little_endian {
            b.to_le_bytes()
        } else {
            b.to_be_bytes()
        };
        bytes.extend_from_slice(&pair);
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn float16_npy_reads_the_values_it_stores() {
    // IEEE half precision: 0.5, -2, the largest finite 65504, 1/3 rounded (0.333251953125),
    // the smallest subnormal 2^-24, and -0.
    let bits = [0x3800, 0xC000, 0x7BFF, 0x3555, 0x0001, 0x8000];
    let values = [0.5, -2.0, 65504.0, 0.333251953125, 2f64.powi(-24), -0.0];
    let dir = tempfile::tempdir().unwrap();
    for little_endian in [true, false] {
        let path = dir.path().join(format!("half-{little_endian}.npy"));
        write_f16_npy(&path, (2, 3), &bits, little_endian);
        let read = read_image::<f64>(&path).unwrap();
        assert_eq!(read.depth(), SampleDepth::F16);
        assert_eq!(read.plane(0).iter().copied().collect::<Vec<_>>(), values);

        // Through the command line (f32, exact for half values): angle 0 copies them.
        let out = dir.path().join(format!("out-{little_endian}.npy"));
        succeeds_with_stdout(&["rotate", p(&path), "-o", p(&out), "--angle", "0"]);
        let written = read_image::<f64>(&out).unwrap();
        assert_eq!(written.depth(), SampleDepth::F32);
        assert_eq!(written.plane(0).iter().copied().collect::<Vec<_>>(), values);
    }
}

#[test]
fn echoed_numbers_are_short() {
    let dir = tempfile::tempdir().unwrap();
    let input = save(
        dir.path(),
        "in.png",
        &image::<f32>(Channels::Gray, 8, 8, SampleDepth::U8),
    );
    for (angle, shown) in [
        ("1e308", "1e308"),
        ("30", "30"),
        ("-12.5", "-12.5"),
        ("0.1", "0.1"),
        ("123456789", "1.23457e8"),
        ("0.00000025", "2.5e-7"),
        ("-0", "0"),
    ] {
        let out = dir.path().join(format!("out{angle}.png"));
        let said = succeeds_with_stdout(&["rotate", p(&input), "-o", p(&out), "--angle", angle]);
        let expected = format!("rotated by {shown} degrees");
        assert!(said.contains(&expected), "{said} lacks {expected}");
    }
    let out = dir.path().join("shifted.png");
    let said = succeeds_with_stdout(&[
        "shift",
        p(&input),
        "-o",
        p(&out),
        "--dx",
        "0.3333333333333333",
        "--dy",
        "4",
    ]);
    assert!(said.contains("shifted by (0.333333, 4)"), "{said}");
}

/// `image` rolled as `numpy.roll(image, (dy, dx), axis=(1, 2))` over its (power-of-two) size:
/// `out[r][c] = in[r - dy][c - dx]`.
fn rolled<T: Sample>(image: &PlanarImage<T>, dx: i64, dy: i64) -> Array3<T> {
    let planes = image.planes();
    let (_, h, w) = planes.dim();
    Array3::from_shape_fn(planes.dim(), |(k, r, c)| {
        planes[[
            k,
            (r as i64 - dy).rem_euclid(h as i64) as usize,
            (c as i64 - dx).rem_euclid(w as i64) as usize,
        ]]
    })
}

/// `haarshift shift INPUT -o out.npy --dx DX --dy DY --compute PRECISION` read back in `T`.
fn whole_shift_through_the_cli<T: Sample>(input: &Path, dx: i64, dy: i64) -> PlanarImage<T> {
    let out = input.with_extension(format!("{dx}_{dy}_{}.npy", T::NAME));
    let (dx, dy) = (dx.to_string(), dy.to_string());
    let args = ["shift", p(input), "-o", p(&out), "--dx", &dx, "--dy", &dy];
    let mut args = args.to_vec();
    args.extend(["--compute", T::NAME]);
    succeeds_with_stdout(&args);
    read_image::<T>(&out).unwrap()
}

#[test]
fn whole_haar_shifts_are_numpy_roll_bit_for_bit_in_f32_and_f64() {
    let dir = tempfile::tempdir().unwrap();
    let sixteen = save(
        dir.path(),
        "sixteen.png",
        &image::<f32>(Channels::Gray, 64, 128, SampleDepth::U16),
    );
    let camera = dir.path().join("camera.png");
    std::fs::copy(crate::common::testdata("camera.png"), &camera).unwrap();
    for input in [&camera, &sixteen] {
        for (dx, dy) in [(5, -3), (-1000, 77)] {
            let name = format!("{} by ({dx}, {dy})", input.display());
            let f32_out = whole_shift_through_the_cli::<f32>(input, dx, dy);
            assert_eq!(
                f32_out.planes(),
                rolled(&read_image::<f32>(input).unwrap(), dx, dy),
                "{name} in f32"
            );
            let f64_out = whole_shift_through_the_cli::<f64>(input, dx, dy);
            assert_eq!(
                f64_out.planes(),
                rolled(&read_image::<f64>(input).unwrap(), dx, dy),
                "{name} in f64"
            );
        }
    }
}
