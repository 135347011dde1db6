//! Relight a mesh: precompute its per-vertex transport once, then shade it under an
//! environment map turned to three angles and render each view.
//!
//! ```sh
//! cargo run --release -p haarshift-relight --example relight_mesh -- \
//!     testdata/meshes/bunny.ply testdata/envmaps/venice_sunset_1k.hdr out
//! ```
//! writes `out/yaw0.png`, `out/yaw120.png` and `out/yaw240.png`.

use std::path::Path;

use haarshift::faces::{ParamKind, Parameterization};
use haarshift::sphere::SphereRotation;
use haarshift_relight::light::environment::Environment;
use haarshift_relight::precompute::{PrecomputeOptions, precompute};
use haarshift_relight::render::output::write_render;
use haarshift_relight::render::{Background, Camera, DEFAULT_FOV, LitMesh, render};
use haarshift_relight::shade::{FrameSpec, ShaderSpec, ShadingInput};
use haarshift_relight::{Mesh, Result, Scene, VisibilityOptions};

fn relight(mesh: &Path, map: &Path, out_dir: &Path) -> Result<()> {
    // Visibility x cosine at 32 x 64 directions a vertex, on a ground plane, Haar-transformed.
    let scene = Scene::from_mesh(Mesh::load(mesh)?, true)?;
    let param = Parameterization::new(ParamKind::LatLong, 32)?;
    let (cache, report) = precompute(
        scene,
        &PrecomputeOptions::new(VisibilityOptions::new(param)),
    )?;
    println!(
        "precomputed {} vertices, {} rays",
        cache.mesh.vertex_count(),
        report.rays
    );
    let mut shader = ShaderSpec::default().build(&ShadingInput::cache(&cache))?;
    let environment = Environment::load(map)?;
    let bounds = cache.mesh.bounds();
    let camera = Camera::framing(bounds.min, bounds.max, DEFAULT_FOV)?;
    for yaw in [0.0, 120.0, 240.0] {
        let rotation = SphereRotation::from_degrees(yaw, 0.0, 0.0)?;
        let frame = FrameSpec {
            environment: &environment,
            rotation,
            eye: None,
        };
        // Each frame: one sparse dot product a vertex with the lighting's kept coefficients.
        let radiance = shader.shade(&frame)?.radiance.to_f32();
        let lit = LitMesh {
            positions: cache.mesh.positions(),
            triangles: cache.mesh.triangles(),
            radiance: radiance.view(),
        };
        let sky = environment.lat_long(256, &rotation)?;
        let image = render(&camera, 320, 240, &lit, Background::Environment(&sky))?;
        write_render(&image, &out_dir.join(format!("yaw{yaw}.png")), 0.0, false)?;
    }
    Ok(())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh, map, out_dir] = args.as_slice() else {
        eprintln!("usage: relight_mesh MESH ENVIRONMENT OUT_DIR");
        std::process::exit(2);
    };
    if let Err(e) = relight(mesh.as_ref(), map.as_ref(), out_dir.as_ref()) {
        eprintln!("relight_mesh: {e}");
        std::process::exit(1);
    }
}

#[test]
fn relights_the_bunny_under_a_turning_sky() {
    let dir = tempfile::tempdir().unwrap();
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata");
    let (mesh, map) = (
        format!("{data}/meshes/bunny.ply"),
        format!("{data}/envmaps/rooitou_park_32x16.hdr"),
    );
    relight(mesh.as_ref(), map.as_ref(), dir.path()).unwrap();
    let views = ["yaw0.png", "yaw120.png", "yaw240.png"]
        .map(|n| haarshift::io::read_image::<f32>(dir.path().join(n)).unwrap());
    assert!(views.iter().all(|v| (v.height(), v.width()) == (240, 320)));
    // The sun moves: the views differ.
    assert_ne!(views[0].planes(), views[1].planes());
}
