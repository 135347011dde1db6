//! The rays of a vertex-major precomputation, for comparison with other ray tracers
//! (`benches/compare_rays.py`): cube 32 x 32 texel centres, one ray each above the horizon,
//! the CLI's `relight precompute SCENE --param cube --resolution 32 --visibility-samples 1`.
//!
//! ```text
//! cargo run --release -p haarshift-measure --bin rays -- SCENE [--tracer T] [--vertices A..B] [--export DIR] [--repeat R]
//!   SCENE       a mesh (PLY, OBJ) or a scene file (JSON), as the CLI reads it
//!   --tracer    the ray tracer, `packets` or `embree` (RayTracer; the best available by default)
//!   --vertices  precompute these vertices only (all by default)
//!   --export    write the mesh as Embree takes it (vertices.npy f32 (V, 3), triangles.npy
//!               i32 (T, 3)) and every ray cast, in casting order: origins.npy and
//!               directions.npy f32 (N, 3), blocked.npy u8 (N,) (the tracer's answers), and
//!               the same rays' answers through our packets, packets.npy u8 (N,)
//!   --repeat    time the precomputation (rays and Haar encoding, `vertex_range`) R times
//!               on the rayon pool (RAYON_NUM_THREADS) and print the fastest as JSON
//! ```
//!
//! The rays exported are those the precomputation asks its [`Occlusion`] about, recorded as
//! it asks (one thread, so in vertex order): the same f32 numbers, not a re-derivation.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use haarshift::faces::{ParamKind, Parameterization};
use haarshift_relight::{
    Occlusion, RayTracer, Scene, SceneBvh, TransportSet, VisibilityOptions, vertex_range,
};
use ndarray::{Array1, Array2};

/// Every ray asked: origins, directions, answers (1: blocked).
type Recorded = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u8>);

/// Answers through `inner` and records every ray and answer.
struct Recorder<'a, O> {
    inner: &'a O,
    rays: Mutex<Recorded>,
}

impl<O: Occlusion> Recorder<'_, O> {
    /// Every ray `vertex_range` casts for `vertices`, on one thread (so in vertex order).
    fn record(
        inner: &O,
        mesh: &haarshift_relight::Mesh,
        options: &VisibilityOptions,
        vertices: Range<usize>,
    ) -> Result<Recorded, Box<dyn std::error::Error>> {
        let recorder = Recorder {
            inner,
            rays: Mutex::default(),
        };
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
        one.install(|| vertex_range(mesh, &recorder, options, vertices))?;
        Ok(recorder.rays.into_inner()?)
    }
}

impl<O: Occlusion> Occlusion for Recorder<'_, O> {
    fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
        let mut blocked = [false];
        self.occluded_from(origin, &[direction], t_max, &mut blocked);
        blocked[0]
    }

    fn occluded_from(&self, o: [f32; 3], d: &[[f32; 3]], t_max: f32, blocked: &mut [bool]) {
        self.inner.occluded_from(o, d, t_max, blocked);
        let mut rays = self.rays.lock().expect("no thread panicked");
        rays.0.extend(std::iter::repeat_n(o, d.len()));
        rays.1.extend_from_slice(d);
        rays.2.extend(blocked.iter().map(|&b| u8::from(b)));
    }
}

fn rows(v: Vec<[f32; 3]>) -> Array2<f32> {
    let n = v.len();
    Array2::from_shape_vec((n, 3), v.into_iter().flatten().collect()).expect("n x 3")
}

/// The fastest of `repeat` precomputations of `vertices` through `occlusion`: rays and
/// seconds.
fn fastest(
    scene: &Scene,
    occlusion: &impl Occlusion,
    options: &VisibilityOptions,
    vertices: &Range<usize>,
    repeat: usize,
) -> haarshift_relight::Result<(u64, f64)> {
    let mut best = (0, f64::INFINITY);
    for _ in 0..repeat {
        let (_, report): (TransportSet, _) =
            vertex_range(&scene.mesh, occlusion, options, vertices.clone())?;
        best = (report.rays, best.1.min(report.seconds));
    }
    Ok(best)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let usage = "usage: rays SCENE [--tracer T] [--vertices A..B] [--export DIR] [--repeat R]";
    let scene = Scene::load(Path::new(&args.next().ok_or(usage)?))?;
    let mesh = &scene.mesh;
    let (mut vertices, mut export, mut repeat, mut tracer) = (
        0..mesh.vertex_count(),
        None::<PathBuf>,
        0,
        RayTracer::best(),
    );
    while let Some(flag) = args.next() {
        match flag.as_str() {
            "--vertices" => {
                let range = args.next().ok_or(usage)?;
                let (a, b) = range.split_once("..").ok_or(usage)?;
                vertices = a.parse()?..b.parse()?;
            }
            "--export" => export = Some(args.next().ok_or(usage)?.into()),
            "--repeat" => repeat = args.next().ok_or(usage)?.parse()?,
            "--tracer" => tracer = args.next().ok_or(usage)?.parse()?,
            _ => return Err(usage.into()),
        }
    }
    let options = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 32)?);
    let start = Instant::now();
    let bvh = SceneBvh::with_tracer(mesh, tracer);
    let build = start.elapsed().as_secs_f64();
    if bvh.tracer() != tracer {
        return Err(format!("the {tracer} ray tracer is not available in this build").into());
    }
    if let Some(dir) = export {
        std::fs::create_dir_all(&dir)?;
        let (origins, directions, blocked) =
            Recorder::record(&bvh, mesh, &options, vertices.clone())?;
        let packets = SceneBvh::with_tracer(mesh, RayTracer::Packets);
        let (_, packet_directions, packet_blocked) =
            Recorder::record(&packets, mesh, &options, vertices.clone())?;
        assert_eq!(
            packet_directions, directions,
            "both tracers are asked the same rays"
        );
        let positions = mesh.positions().mapv(|x| x as f32);
        let triangles = mesh.triangles().iter().flatten().map(|&i| i as i32);
        let triangles = Array2::from_shape_vec((mesh.triangles().len(), 3), triangles.collect())?;
        ndarray_npy::write_npy(dir.join("vertices.npy"), &positions)?;
        ndarray_npy::write_npy(dir.join("triangles.npy"), &triangles)?;
        ndarray_npy::write_npy(dir.join("origins.npy"), &rows(origins))?;
        ndarray_npy::write_npy(dir.join("directions.npy"), &rows(directions))?;
        ndarray_npy::write_npy(dir.join("blocked.npy"), &Array1::from(blocked))?;
        ndarray_npy::write_npy(dir.join("packets.npy"), &Array1::from(packet_blocked))?;
    }
    if repeat > 0 {
        let (rays, seconds) = fastest(&scene, &bvh, &options, &vertices, repeat)?;
        println!(
            "{{\"tracer\": \"{tracer}\", \"triangles\": {}, \"vertices\": {}, \"threads\": {}, \
             \"build_seconds\": {build}, \"rays\": {rays}, \"seconds\": {seconds}}}",
            mesh.triangles().len(),
            vertices.len(),
            rayon::current_num_threads()
        );
    }
    Ok(())
}
