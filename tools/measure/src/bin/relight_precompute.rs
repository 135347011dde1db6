//! Times the visibility precomputation of a scene and reports rays per second, the transport's
//! size and the method's working memory; run it under `/usr/bin/time -v` for the peak memory
//! of the whole process.
//!
//! ```text
//! cargo run --release -p haarshift-measure --bin relight_precompute -- SCENE PARAM RESOLUTION KEEP ORDER [SH]
//!   SCENE       bunny (the bunny on its ground plane) | cubes (Vollick and Lessig, 85,860 vertices)
//!               | cylinder-and-bump | plane-with-sphere
//!   PARAM       latlong | cube
//!   RESOLUTION  face side: lat-long N x 2N, cube 6 x N x N
//!   KEEP        visibility coefficients kept per vertex, or all
//!   ORDER       vertex (rays through the BVH) | direction (Microsoft 2003's shadow maps, 2048^2)
//!   SH          optional: also project onto this many bands of spherical harmonics
//! ```
//!
//! For example `cargo run --release -p haarshift-measure --bin relight_precompute -- cubes cube 64 414 vertex`; the
//! committed figures come from the CLI (`scripts/relight_speed.sh`).

use std::path::Path;
use std::time::Instant;

use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift_relight::{
    Generator, Mesh, SceneBvh, VisibilityOptions, add_ground_plane, direction_major, vertex_major,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if !(5..=6).contains(&args.len()) {
        eprintln!("usage: relight_precompute SCENE PARAM RESOLUTION KEEP ORDER [SH]");
        std::process::exit(2);
    }
    let mesh = match args[0].as_str() {
        "bunny" => {
            let path =
                Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testdata/meshes/bunny.ply");
            let mut m = Mesh::load(&path)?;
            add_ground_plane(&mut m)?;
            m
        }
        "cubes" => Generator::Cubes {
            count: 10,
            cells: 10,
            distance: 1.5,
        }
        .mesh()?,
        "cylinder-and-bump" => Generator::CylinderAndBump { cells: 96 }.mesh()?,
        "plane-with-sphere" => Generator::PlaneWithSphere {}.mesh()?,
        other => return Err(format!("unknown scene {other}").into()),
    };
    let param = Parameterization::new(args[1].parse::<ParamKind>()?, args[2].parse()?)?;
    let mut options = VisibilityOptions::new(param);
    options.progress = true;
    if args[3] != "all" {
        options.keep = Selection::Largest(args[3].parse()?);
    }
    options.sh_bands = args.get(5).map(|b| b.parse()).transpose()?;
    println!(
        "scene {} ({} vertices, {} triangles), {} {} ({} directions), keep {}, order {}, sh bands {:?}, {} threads",
        args[0],
        mesh.vertex_count(),
        mesh.triangles().len(),
        param.kind(),
        param.face_size(),
        param.texels(),
        args[3],
        args[4],
        options.sh_bands,
        rayon::current_num_threads()
    );
    let start = Instant::now();
    let bvh = SceneBvh::new(&mesh);
    println!("bvh build: {:.3} s", start.elapsed().as_secs_f64());
    let (set, report) = match args[4].as_str() {
        "vertex" => vertex_major(&mesh, &bvh, &options)?,
        "direction" => direction_major(&mesh, &options, 2048)?,
        other => return Err(format!("unknown order {other}").into()),
    };
    println!(
        "precompute: {:.1} s, {} rays, {:.2} M rays/s",
        report.seconds,
        report.rays,
        report.rays as f64 / report.seconds / 1e6
    );
    println!(
        "transport: {:.1} MB stored, working memory {:.1} MB",
        set.stored_bytes() as f64 / 1e6,
        report.working_bytes as f64 / 1e6
    );
    Ok(())
}
