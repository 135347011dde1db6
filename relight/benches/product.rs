//! Product integrals on real data: the rooitou park envmap, the visibility of bunny vertices
//! (rays through the relighting module's BVH against `testdata/meshes/bunny.obj`) and a
//! Phong-50 lobe, sampled at the texel centres of a cube map (6 x S^2) or a lat-long map
//! (H x 2H) of the library's parameterisations (bilinear lookups in the lat-long envmap: data
//! preparation for timing only); weights are the texels' exact solid angles.
//!
//! Groups: `targets` (the speed targets, f32, one channel and RGB) and `scaling`
//! (N = 3..6 functions; cube S = 32..256 and lat-long H = 64..256; 1 %..100 % kept: tree vs
//! pixel domain vs pairwise), each benchmark short (10 samples, 0.5 s) so that the whole table
//! runs in minutes; and `vertex` (a dynamic scene's per-vertex products, from sparse
//! coefficients: the quadtree product against the texel product, lat-long 32 to cube 64).
//! One core: run with `RAYON_NUM_THREADS=1`; `python3
//! benches/product_table.py --run-cargo` runs it and writes the tables under
//! `results/product/`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use haarshift::faces::{ParamKind, Parameterization, SphereMap};
use haarshift::product::baseline::{pairwise_integral, pixel_integral, pixel_integral_of_trees};
use haarshift::product::multiply::product;
use haarshift::product::texel::TexelProduct;
use haarshift::product::triple::{
    DenseFaces, DenseTransport, dense_triple_integral, triple_integral,
};
use haarshift::product::{
    FaceLayout, HaarTree, IntegralOptions, Selection, Transport, WeightedPixels, product_integral,
};
use haarshift::sphere::LatLongMap;
use haarshift::sphere::latlong::angles;
use haarshift_relight::{Mesh, Occlusion, SceneBvh, ray_offset};
use ndarray::{Array3, Array4, Axis};
use std::time::Duration;

/// `f(direction, channels_out)` at every texel centre of `p`, `(faces, S, S, c)`.
fn sample(p: Parameterization, c: usize, f: impl Fn([f64; 3], &mut [f64]) + Sync) -> Array4<f64> {
    SphereMap::from_fn(p, c, f).expect("finite").into_array()
}

/// The bunny, its BVH, and the ray offset of the relighting precomputation.
struct Bunny {
    mesh: Mesh,
    bvh: SceneBvh,
    offset: f64,
}

fn bunny() -> Bunny {
    let mesh = Mesh::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../testdata/meshes/bunny.obj"
    )))
    .expect("bunny.obj");
    Bunny {
        bvh: SceneBvh::new(&mesh),
        offset: ray_offset(&mesh),
        mesh,
    }
}

/// Visibility of bunny vertex `k` (1 where the ray escapes), from the origin offset along its
/// normal as the relighting precomputation does.
fn visibility(bunny: &Bunny, k: usize, param: Parameterization) -> Array4<f64> {
    let (p, n) = (bunny.mesh.positions(), bunny.mesh.normals());
    let o: [f32; 3] = std::array::from_fn(|i| (p[[k, i]] + bunny.offset * n[[k, i]]) as f32);
    sample(param, 1, |d, px| {
        let d = d.map(|x| x as f32);
        px[0] = if bunny.bvh.occluded(o, d, f32::INFINITY) {
            0.0
        } else {
            1.0
        }
    })
}

/// A Phong lobe of exponent 50 about a fixed reflection direction.
fn phong(p: Parameterization) -> Array4<f64> {
    let r = [0.48, 0.6, 0.64];
    sample(p, 1, |d, px| {
        px[0] = (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]).max(0.0).powi(50)
    })
}

fn envmap(p: Parameterization, c: usize) -> Array4<f64> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../testdata/envmaps/rooitou_park_256x128.npy"
    );
    let data: Array3<f32> = ndarray_npy::read_npy(path).expect("test map");
    let map = LatLongMap::new(data.mapv(f64::from)).expect("2:1 map");
    sample(p, c, |d, px| {
        let (theta, phi) = angles(d);
        let mut rgb = [0.0; 3];
        map.bilinear(theta, phi, &mut rgb);
        if c == 1 {
            px[0] = (rgb[0] + rgb[1] + rgb[2]) / 3.0;
        } else {
            px.copy_from_slice(&rgb);
        }
    })
}

fn to32(a: &Array4<f64>) -> Array4<f32> {
    a.mapv(|v| v as f32)
}

fn rgb(a: &Array4<f64>) -> Array4<f32> {
    let a = to32(a);
    ndarray::concatenate(Axis(3), &[a.view(), a.view(), a.view()]).expect("same shape")
}

const ALL: IntegralOptions = IntegralOptions { finest_level: None };

/// Transport (visibility x solid angle) and factors (envmap, Phong, more visibilities).
struct Scene<const C: usize> {
    weighted: WeightedPixels<f32, C>,
    factors: Vec<Array4<f32>>,
    layout: FaceLayout,
}

fn scene<const C: usize>(bunny: &Bunny, p: Parameterization, extra: usize) -> Scene<C> {
    let widen = |a: &Array4<f64>| if C == 1 { to32(a) } else { rgb(a) };
    let vis = widen(&visibility(bunny, 100, p));
    let weights = p.solid_angles().mapv(|v| v as f32);
    let env = if C == 1 {
        to32(&envmap(p, 1))
    } else {
        to32(&envmap(p, 3))
    };
    let mut factors = vec![env, widen(&phong(p))];
    for k in 0..extra {
        factors.push(widen(&visibility(bunny, 400 + 300 * k, p)));
    }
    Scene {
        weighted: WeightedPixels::new(vis.view(), weights.view()).expect("shapes"),
        factors,
        layout: match p.kind() {
            ParamKind::LatLong => FaceLayout::SideBySide,
            ParamKind::Cube => FaceLayout::Stacked,
        },
    }
}

fn trees<const C: usize>(
    sc: &Scene<C>,
    keep: [Selection; 3],
    rest: Selection,
) -> (Transport<f32, C>, Vec<HaarTree<f32, C>>) {
    let t = Transport::new(&sc.weighted, sc.layout, keep[0]).expect("transport");
    let f = sc
        .factors
        .iter()
        .enumerate()
        .map(|(k, m)| {
            HaarTree::from_pixels(m.view(), sc.layout, if k < 2 { keep[k + 1] } else { rest })
                .expect("tree")
        })
        .collect();
    (t, f)
}

fn targets_for<const C: usize>(c: &mut Criterion, bunny: &Bunny, label: &str) {
    let sc = scene::<C>(bunny, param(ParamKind::Cube, 64), 0);
    let mut group = c.benchmark_group(format!("targets_{label}"));
    group.sample_size(30);
    group.warm_up_time(Duration::from_millis(300));
    group.measurement_time(Duration::from_secs(1));
    for (name, keep) in [
        (
            "200-70-70_total",
            [
                Selection::Largest(200),
                Selection::Largest(70),
                Selection::Largest(70),
            ],
        ),
        (
            "200-70-70_per_face",
            [
                Selection::LargestPerFace(200),
                Selection::LargestPerFace(70),
                Selection::LargestPerFace(70),
            ],
        ),
        ("full", [Selection::All; 3]),
    ] {
        let (t, f) = trees(&sc, keep, Selection::All);
        group.bench_function(BenchmarkId::new("triple", name), |b| {
            b.iter(|| triple_integral(black_box(&t), &f[0], &f[1]).expect("ok"))
        });
        group.bench_function(BenchmarkId::new("general", name), |b| {
            b.iter(|| product_integral(black_box(&t), &[&f[0], &f[1]], ALL).expect("ok"))
        });
        if name == "full" {
            let (dt, d0, d1) = (
                DenseTransport::from_transport(&t),
                DenseFaces::from_tree(&f[0]),
                DenseFaces::from_tree(&f[1]),
            );
            group.bench_function(BenchmarkId::new("dense", name), |b| {
                b.iter(|| dense_triple_integral(black_box(&dt), &d0, &d1).expect("ok"))
            });
            let views: Vec<_> = sc.factors.iter().map(|m| m.view()).collect();
            group.bench_function(BenchmarkId::new("pixel_stored", name), |b| {
                b.iter(|| pixel_integral(black_box(&sc.weighted), &views).expect("ok"))
            });
        }
    }
    group.finish();
}

fn targets(c: &mut Criterion) {
    let bunny = bunny();
    targets_for::<1>(c, &bunny, "mono");
    targets_for::<3>(c, &bunny, "rgb");
}

fn param(kind: ParamKind, size: usize) -> Parameterization {
    Parameterization::new(kind, size).expect("a power of two")
}

/// Sizes from the environment variable `name` (comma-separated), or `default`.
fn sizes(name: &str, default: &[usize]) -> Vec<usize> {
    std::env::var(name)
        .map(|v| {
            v.split(',')
                .filter(|x| !x.is_empty())
                .map(|x| x.parse().expect("size"))
                .collect()
        })
        .unwrap_or_else(|_| default.to_vec())
}

fn scaling(c: &mut Criterion) {
    let bunny = bunny();
    let cube = sizes("PRODUCT_BENCH_SIZES", &[32, 64, 128, 256]);
    let latlong = sizes("PRODUCT_BENCH_LATLONG", &[64, 128, 256]);
    let params = cube
        .into_iter()
        .map(|s| param(ParamKind::Cube, s))
        .chain(latlong.into_iter().map(|h| param(ParamKind::LatLong, h)));
    for p in params {
        let (s, faces) = (p.face_size(), p.faces());
        let sc = scene::<1>(&bunny, p, 3);
        let details = faces * (s * s - 1);
        let mut group = c.benchmark_group(format!("scaling_{}{s}", p.kind()));
        group.sample_size(10);
        group.warm_up_time(Duration::from_millis(200));
        group.measurement_time(Duration::from_millis(500));
        for percent in [1usize, 5, 10, 100] {
            let sel = if percent == 100 {
                Selection::All
            } else {
                Selection::Largest(details * percent / 100)
            };
            let (t, f) = trees(&sc, [sel; 3], sel);
            for n in 3..=6 {
                let refs: Vec<&HaarTree<f32, 1>> = f[..n - 1].iter().collect();
                let id = format!("N{n}_keep{percent}");
                group.bench_function(BenchmarkId::new("tree", &id), |b| {
                    b.iter(|| product_integral(black_box(&t), &refs, ALL).expect("ok"))
                });
                group.bench_function(BenchmarkId::new("pixel_inverse", &id), |b| {
                    b.iter(|| pixel_integral_of_trees(black_box(&t), &refs).expect("ok"))
                });
                group.bench_function(BenchmarkId::new("pairwise", &id), |b| {
                    b.iter(|| pairwise_integral(black_box(&t), &refs).expect("ok"))
                });
                if percent == 100 {
                    let views: Vec<_> = sc.factors[..n - 1].iter().map(|m| m.view()).collect();
                    group.bench_function(BenchmarkId::new("pixel_stored", &id), |b| {
                        b.iter(|| pixel_integral(black_box(&sc.weighted), &views).expect("ok"))
                    });
                }
            }
        }
        group.finish();
    }
}

/// A sparse function's coefficients: the largest `keep` of `pixels` (one channel).
fn sparse_of(pixels: &Array4<f64>, layout: FaceLayout, keep: usize) -> (Vec<u32>, Vec<f32>) {
    let tree =
        HaarTree::<f32, 1>::from_pixels(to32(pixels).view(), layout, Selection::Largest(keep))
            .expect("tree");
    let (i, v) = tree.sparse_coefficients();
    (i, v.into_iter().map(|[x]| x).collect())
}

/// Per vertex of a dynamic scene (`relight::dynamic::JustInTimeTransfer`), from sparse coefficients: the
/// fixed product of its transport (70 kept), two occlusion maps (200 each) and the lighting
/// (200, RGB), and a frame's `<T, O_a O_b>`; by quadtrees (`from_sparse`, `product`,
/// `triple_integral`) and by texels ([`TexelProduct`]).
fn vertex(c: &mut Criterion) {
    let bunny = bunny();
    for p in [
        param(ParamKind::LatLong, 32),
        param(ParamKind::Cube, 32),
        param(ParamKind::Cube, 64),
    ] {
        let (faces, s) = (p.faces(), p.face_size());
        let layout = match p.kind() {
            ParamKind::LatLong => FaceLayout::SideBySide,
            ParamKind::Cube => FaceLayout::Stacked,
        };
        let weights = p.solid_angles();
        let transport = visibility(&bunny, 100, p) * &weights.insert_axis(Axis(3));
        let own = sparse_of(&transport, layout, 70);
        let maps = [
            sparse_of(&visibility(&bunny, 400, p), layout, 200),
            sparse_of(&visibility(&bunny, 700, p), layout, 200),
        ];
        let light = HaarTree::<f32, 3>::from_pixels(
            to32(&envmap(p, 3)).view(),
            layout,
            Selection::Largest(200),
        )
        .expect("tree");
        let (li, lv) = light.sparse_coefficients();
        let widen = |(i, v): &(Vec<u32>, Vec<f32>)| -> HaarTree<f32, 3> {
            let v: Vec<[f32; 3]> = v.iter().map(|&x| [x; 3]).collect();
            HaarTree::from_sparse(faces, s, layout, i, &v).expect("tree")
        };
        let mut group = c.benchmark_group(format!("vertex_{}{s}", p.kind()));
        group.sample_size(20);
        group.warm_up_time(Duration::from_millis(300));
        group.measurement_time(Duration::from_secs(1));
        group.bench_function("fixed_product/tree", |b| {
            b.iter(|| {
                let light = HaarTree::from_sparse(faces, s, layout, &li, &lv).expect("tree");
                let trees = [widen(&own), widen(&maps[0]), widen(&maps[1])];
                product(&[&trees[0], &trees[1], &trees[2], &light])
                    .expect("ok")
                    .sparse_coefficients()
            })
        });
        let mut shared = TexelProduct::<f32>::new(faces, s).expect("faces");
        shared.multiply(&li, &lv).expect("ok");
        let mut texels = TexelProduct::<f32>::new(faces, s).expect("faces");
        let (mut ti, mut tv) = (Vec::new(), Vec::new());
        let mut fixed = |ti: &mut Vec<u32>, tv: &mut Vec<[f32; 3]>| {
            texels.reset();
            for (i, v) in [&own, &maps[0], &maps[1]] {
                texels.multiply(i, v).expect("ok");
            }
            texels.multiply_by(&shared).expect("ok");
            texels.sparse_coefficients(ti, tv);
        };
        group.bench_function("fixed_product/texel", |b| {
            b.iter(|| fixed(&mut ti, &mut tv))
        });
        // The fixed product a frame dots with (the same for both methods).
        fixed(&mut ti, &mut tv);
        // The transport of T's own tree (weights folded in: ones), built per vertex as
        // `JustInTimeTransfer` builds it; the bench builds it once and times `from_sparse` in its stead.
        let t_pixels = HaarTree::from_sparse(faces, s, layout, &ti, &tv)
            .expect("tree")
            .to_pixels()
            .expect("ok");
        let ones = ndarray::Array3::<f32>::ones((faces, s, s));
        let weighted = WeightedPixels::new(t_pixels.view(), ones.view()).expect("ok");
        let t = Transport::new(&weighted, layout, Selection::All).expect("transport");
        group.bench_function("moving_dot/tree", |b| {
            b.iter(|| {
                black_box(HaarTree::from_sparse(faces, s, layout, &ti, &tv).expect("tree"));
                triple_integral(&t, &widen(&maps[0]), &widen(&maps[1])).expect("ok")
            })
        });
        group.bench_function("moving_dot/texel", |b| {
            b.iter(|| {
                texels.reset();
                for (i, v) in &maps {
                    texels.multiply(i, v).expect("ok");
                }
                texels.dot(&ti, &tv).expect("ok")
            })
        });
        group.finish();
    }
}

criterion_group!(benches, targets, scaling, vertex);
criterion_main!(benches);
