//! Occlusion rays of the vertex-major precomputation: our packet traversal (`RayTracer::Packets`)
//! against the single-ray CWBVH path it replaced (`single_ray`, the named baseline), in the same
//! run, on one thread. Two groups on the bunny (1,839 vertices, 3,674 triangles) with cube
//! 32 x 32 texel-centre rays, one per texel above the horizon:
//!
//! * `rays/cast`: the rays of 64 vertices alone, each vertex's rays asked at once
//!   ([`Occlusion::occluded_from`]; the baseline answers them one by one);
//! * `rays/precompute`: the precomputation of those vertices (rays and Haar encoding).
//!
//! `cargo bench -p haarshift-relight --bench rays`; the ratio is baseline time over packet time. The comparison with
//! Embree on the same rays is `benches/compare_rays.py`.

use criterion::{Criterion, criterion_group, criterion_main};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift_relight::{
    Mesh, Occlusion, RayTracer, SceneBvh, VisibilityOptions, ray_offset, vertex_range,
};

#[path = "single_ray.rs"]
mod single_ray;

const VERTICES: usize = 64;

/// Each of the first vertices' ray origin and its directions above the horizon.
fn rays(mesh: &Mesh, param: Parameterization) -> Vec<([f32; 3], Vec<[f32; 3]>)> {
    let s = param.face_size();
    let eps = ray_offset(mesh);
    (0..VERTICES)
        .map(|v| {
            let p = [0, 1, 2].map(|k| mesh.positions()[[v, k]]);
            let n = [0, 1, 2].map(|k| mesh.normals()[[v, k]]);
            let directions = (0..param.texels())
                .map(|t| param.texel_direction(t / (s * s), (t / s) % s, t % s))
                .filter(|d| d[0] * n[0] + d[1] * n[1] + d[2] * n[2] > 0.0)
                .map(|d| d.map(|x| x as f32))
                .collect();
            ([0, 1, 2].map(|k| (p[k] + eps * n[k]) as f32), directions)
        })
        .collect()
}

fn cast(occlusion: &impl Occlusion, work: &[([f32; 3], Vec<[f32; 3]>)]) -> usize {
    let mut blocked = vec![false; 6 * 32 * 32];
    work.iter()
        .map(|(o, d)| {
            let b = &mut blocked[..d.len()];
            occlusion.occluded_from(*o, d, f32::INFINITY, b);
            b.iter().filter(|&&x| x).count()
        })
        .sum()
}

fn bench(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/meshes/bunny.ply");
    let mesh = Mesh::load(path.as_ref()).unwrap();
    let param = Parameterization::new(ParamKind::Cube, 32).unwrap();
    let packets = SceneBvh::with_tracer(&mesh, RayTracer::Packets);
    let baseline = single_ray::SingleRay::new(&mesh);
    let work = rays(&mesh, param);
    assert_eq!(cast(&packets, &work), cast(&baseline, &work));
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let options = VisibilityOptions::new(param);
    let mut group = c.benchmark_group("rays");
    group.sample_size(10);
    group.bench_function("cast/single_ray", |b| b.iter(|| cast(&baseline, &work)));
    group.bench_function("cast/packets", |b| b.iter(|| cast(&packets, &work)));
    let precompute = |o: &(dyn Fn() -> usize + Sync)| one.install(o);
    group.bench_function("precompute/single_ray", |b| {
        b.iter(|| {
            precompute(&|| {
                vertex_range(&mesh, &baseline, &options, 0..VERTICES)
                    .unwrap()
                    .0
                    .vertex_count()
            })
        })
    });
    group.bench_function("precompute/packets", |b| {
        b.iter(|| {
            precompute(&|| {
                vertex_range(&mesh, &packets, &options, 0..VERTICES)
                    .unwrap()
                    .0
                    .vertex_count()
            })
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
