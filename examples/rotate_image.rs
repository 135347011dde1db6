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
