//! Rotate an image by three shears on its Haar coefficients, and by Keys's cubic for comparison.
//!
//! ```sh
//! cargo run --release -p haarshift --example rotate_image -- testdata/coins.png 30 out
//! ```
//! writes `out/haar.png` and `out/keys.png`: the image turned 30 degrees counter-clockwise, the
//! canvas grown to hold it.

use std::path::Path;

use haarshift::io::{WriteOptions, read_image, write_image};
use haarshift::kernels::ShiftMethod;
use haarshift::rotate::{Canvas, RotateOptions, rotate_image};

fn rotate(input: &Path, degrees: f64, out_dir: &Path) -> haarshift::Result<()> {
    let image = read_image::<f32>(input)?;
    std::fs::create_dir_all(out_dir).map_err(|source| haarshift::Error::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let options = RotateOptions {
        canvas: Canvas::Expand,
        ..Default::default()
    };
    // Haar: each shear a shift of the rows' Haar coefficients (Alnasser 2008, ch. 3).
    for method in [ShiftMethod::Haar, ShiftMethod::Keys] {
        let kernel = method.kernel::<f32>();
        let rotated = rotate_image(&image, degrees, kernel.as_ref(), &options)?;
        let path = out_dir.join(format!("{method}.png"));
        write_image(&rotated, &path, WriteOptions::default())?;
        println!(
            "{}: {} x {}",
            path.display(),
            rotated.width(),
            rotated.height()
        );
    }
    Ok(())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, degrees, out_dir] = args.as_slice() else {
        eprintln!("usage: rotate_image INPUT DEGREES OUT_DIR");
        std::process::exit(2);
    };
    let degrees: f64 = degrees.parse().unwrap_or(f64::NAN);
    if let Err(e) = rotate(input.as_ref(), degrees, out_dir.as_ref()) {
        eprintln!("rotate_image: {e}");
        std::process::exit(1);
    }
}

#[test]
fn rotates_the_test_image_both_ways() {
    let dir = tempfile::tempdir().unwrap();
    let coins = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/coins.png");
    rotate(coins.as_ref(), 90.0, dir.path()).unwrap();
    let original = read_image::<f32>(coins).unwrap();
    for name in ["haar.png", "keys.png"] {
        let r = read_image::<f32>(dir.path().join(name)).unwrap();
        // A quarter turn swaps the sides and, on the pixel grid, moves each pixel exactly.
        assert_eq!(
            (r.height(), r.width()),
            (original.width(), original.height())
        );
        assert_eq!(
            r.plane(0)[[0, 0]],
            original.plane(0)[[0, original.width() - 1]]
        );
    }
}
