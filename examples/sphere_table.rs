//! Prints the sphere-rotation comparison table for the test map:
//! `cargo run --release --example sphere_table [--json FILE]`.

use haarshift::sphere::{LatLongMap, Method, experiment};
use ndarray::Array3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/testdata/envmaps/rooitou_park_256x128.npy"
    );
    let data: Array3<f32> = ndarray_npy::read_npy(path)?;
    let map = LatLongMap::new(data)?;
    let rotations = [
        (0.0, 5.0, 0.0),
        (0.0, 30.0, 0.0),
        (0.0, 90.0, 0.0),
        (40.0, -25.0, 60.0),
    ];
    let methods = [
        (Method::Bilinear, None),
        (Method::Bicubic, None),
        (Method::Haar, None),
        (Method::Bilinear, Some(5)),
        (Method::Haar, Some(5)),
        (Method::Haar, Some(4)),
        (Method::Haar, Some(3)),
    ];
    let records = experiment::run("rooitou_park_256x128", &map, &rotations, &methods, 8)?;
    println!(
        "| yaw | pitch | roll | method | level | rms | relative rms | rms at level | coefficient rms | energy error | ms |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &records {
        let c = &r.comparison;
        println!(
            "| {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.5} | {:+.1e} | {:.1} |",
            r.yaw,
            r.pitch,
            r.roll,
            r.method,
            r.level,
            c.rms,
            c.relative_rms,
            c.rms_at_level,
            c.coefficient_rms,
            c.energy_error,
            r.seconds * 1e3
        );
    }
    if let Some(pos) = std::env::args().position(|a| a == "--json") {
        let file = std::env::args().nth(pos + 1).ok_or("--json needs a file")?;
        std::fs::write(file, serde_json::to_string_pretty(&records)?)?;
    }
    Ok(())
}
