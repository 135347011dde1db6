//! Rotate a lat-long environment map on its Haar coefficients (the chain rule, Alnasser 2008,
//! ch. 4) and measure it against the per-pixel reference.
//!
//! ```sh
//! cargo run --release -p haarshift --example rotate_envmap -- \
//!     testdata/envmaps/rooitou_park_1k.hdr 30 20 0 rotated.exr
//! ```
//! turns the map by yaw 30, pitch 20, roll 0 degrees (`g(p) = f(R p)`), writes it, and prints
//! the solid-angle weighted RMS error against the reference.

use std::path::Path;

use haarshift::io::{WriteOptions, read_image, write_image};
use haarshift::sphere::map_error::weighted_rms;
use haarshift::sphere::{LatLongMap, Method, SphereOptions, SphereRotation, rotate_map};

fn rotate(input: &Path, [yaw, pitch, roll]: [f64; 3], output: &Path) -> haarshift::Result<f64> {
    let image = read_image::<f64>(input)?;
    let map = LatLongMap::from_image(&image)?;
    let rotation = SphereRotation::from_degrees(yaw, pitch, roll)?;
    let haar = rotate_map(&map, &rotation, &SphereOptions::default())?;
    let reference = SphereOptions {
        method: Method::Reference,
        ..Default::default()
    };
    let truth = rotate_map(&map, &rotation, &reference)?;
    write_image(
        &haar.map.to_image(image.depth())?,
        output,
        WriteOptions::default(),
    )?;
    weighted_rms(&haar.map, &truth.map)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, yaw, pitch, roll, output] = args.as_slice() else {
        eprintln!("usage: rotate_envmap INPUT YAW PITCH ROLL OUTPUT");
        std::process::exit(2);
    };
    let angles = [yaw, pitch, roll].map(|a| a.parse().unwrap_or(f64::NAN));
    match rotate(input.as_ref(), angles, output.as_ref()) {
        Ok(rms) => println!("{output}: weighted RMS against the reference {rms:.3e}"),
        Err(e) => {
            eprintln!("rotate_envmap: {e}");
            std::process::exit(1);
        }
    }
}
