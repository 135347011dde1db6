//! What every fuzz target of the relighting's readers runs on one input, shared by the
//! libFuzzer targets (`fuzz_targets/`) and the stable replay test (`tests/fuzz_corpus.rs` in
//! the relighting crate), so that CI guards every corpus file and every crash without a
//! nightly toolchain. The core's image readers have theirs in the top-level `fuzz/`.
//!
//! Each reader takes a path, so the input is written to a file of the target's extension in
//! a directory of its own and read back; any `Result` is fine, a panic is the finding.
// Each fuzz target uses only `run`.
#![allow(dead_code)]

use haarshift_testkit::fuzz::{put, scratch};

use haarshift_relight::dynamic::fields::OcclusionField;
use haarshift_relight::dynamic::motion::MotionPath;
use haarshift_relight::light::environment::Environment;
use haarshift_relight::material::merl::MerlBrdf;
use haarshift_relight::scene::MeshAsset;
use haarshift_relight::scene::validate::{MemoryBudget, check_ground_extent};
use haarshift_relight::{Mesh, Scene, SceneCache, add_ground_plane};

/// The fuzz targets: one per reader and validated structure.
pub const TARGETS: [&str; 10] = [
    "ply", "obj", "gltf", "mtl", "scene", "motion", "hsr", "hsf", "merl", "envmap",
];

/// The budget of a fuzzed scene: 64 MiB, about 131,000 vertices, so that a valid generator of
/// millions of vertices is refused by the budget (the behaviour under test) rather than
/// built for seconds and reported as a timeout.
const SCENE_BUDGET: MemoryBudget = MemoryBudget {
    limit: 64 << 20,
    per_vertex: 0,
    shards: 1,
};

/// The texture a fuzzed glTF or MTL may name (`checker.png`, 81 bytes).
const CHECKER_PNG: &[u8] = include_bytes!("../../testdata/meshes/checker.png");

/// The OBJ whose library (`in.mtl`) the `mtl` target fuzzes.
const MTL_USER: &[u8] = b"mtllib in.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0.5 1\n\
    usemtl m\nf 1/1 2/2 3/3\n";

/// A mesh that was read goes on through the ground plane's validation and the BVH build, and
/// one ray is traced.
fn exercise(mesh: &Mesh) {
    let mut grounded = mesh.clone();
    if check_ground_extent(&grounded.bounds()).is_ok() {
        let _ = add_ground_plane(&mut grounded);
    }
    let bvh = haarshift_relight::SceneBvh::new(&grounded);
    use haarshift_relight::Occlusion;
    let _ = bvh.occluded([0.0; 3], [0.0, 1.0, 0.0], f32::INFINITY);
}

/// Runs `target` on `bytes`: panics only if the code under test does.
pub fn run(target: &str, bytes: &[u8]) {
    let dir = scratch();
    match target {
        "ply" | "obj" => {
            if let Ok(mesh) = Mesh::load(&put(&dir, &format!("in.{target}"), bytes)) {
                exercise(&mesh);
            }
        }
        "gltf" | "mtl" => {
            // The files an asset may name beside it: a 4 x 4 texture.
            put(&dir, "checker.png", CHECKER_PNG);
            let path = if target == "mtl" {
                // The input is the library of a fixed textured triangle that uses material `m`.
                put(&dir, "in.mtl", bytes);
                put(&dir, "in.obj", MTL_USER)
            } else if bytes.starts_with(b"glTF") {
                put(&dir, "in.glb", bytes)
            } else {
                put(&dir, "in.gltf", bytes)
            };
            if let Ok(asset) = MeshAsset::load_within(&path, &SCENE_BUDGET) {
                exercise(&asset.mesh);
            }
        }
        "scene" => {
            if let Ok(scene) = Scene::load_within(&put(&dir, "in.json", bytes), &SCENE_BUDGET) {
                exercise(&scene.mesh);
            }
        }
        "motion" => {
            if let Ok(path) = MotionPath::load(&put(&dir, "in.json", bytes)) {
                let _ = path.frame_count();
            }
        }
        "hsr" => {
            let _ = SceneCache::read(&put(&dir, "in.hsr", bytes));
        }
        "hsf" => {
            let _ = OcclusionField::read(&put(&dir, "in.hsf", bytes));
        }
        "merl" => {
            let _ = MerlBrdf::read(&put(&dir, "in.binary", bytes));
        }
        "envmap" => {
            let _ = Environment::load(&put(&dir, "in.hdr", bytes));
            let _ = Environment::load(&put(&dir, "in.npy", bytes));
        }
        other => panic!("no fuzz target {other}"),
    }
    let _ = std::fs::remove_dir_all(dir);
}
