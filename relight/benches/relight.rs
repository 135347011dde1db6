//! Relighting's image half: the rasteriser on a 512 x 512 image of a 100,352-triangle sphere
//! (all threads, and one thread for the ratio), the solid-angle-weighted downsample of a
//! 512 x 1024 map to 128 x 256 beside the plain block mean, and the projection of a
//! 128 x 256 RGB map onto 9 bands (81) of spherical harmonics.
//!
//! And the relighting itself (`relight_cubes_85860`): Vollick and Lessig's Cubes scene (85,860 vertices)
//! at cube `6 x 64^2`, each vertex's transport keeping its 420 largest coefficients, a
//! lighting keeping its 200 largest, Lambertian: the lighting's encoding (the 512 x 1024 map
//! downsampled by solid-angle means, turned, converted to the cube, transformed, selected) and
//! the shading (one sparse dot per vertex, f32) timed separately and together, beside a plain
//! parallel read of the same offsets, indices and values (the frame's floor); the mapping
//! into the cube (its overlap table) is made once, as an animation makes it. The turn is a
//! yaw by whole columns of the working map (the animation's step: a column permutation) or a
//! general rotation (applied at the source's resolution, and, at lat-long 64, lat-long 128 and
//! cube 64, to the copy prefiltered to twice the working lat-long height). The transport is precomputed once
//! per run with the real ray caster ([`vertex_major`], a few minutes on two cores, with a
//! progress bar) and only when one of these benchmarks is selected; nothing is synthetic.
//!
//! And the spherical-harmonics baselines (`relight_sh_85860`) on a synthetic transfer of the
//! same 85,860 vertices at `B = 4, 6, 8` bands, RGB lighting: Lambertian [`shade_sh`] (`B^2`
//! per vertex and channel) beside the glossy Phong 50 triple product [`PhongSh::shade`] (`B^4`),
//! every vertex glossy; and the one-off [`PhongSh::new`] (the Gaunt table).
//! Run: `cargo bench -p haarshift-relight --bench relight -- --warm-up-time 1 --measurement-time 5`.

use criterion::{Criterion, criterion_group, criterion_main};
use rayon::prelude::*;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use haarshift::faces::param::SphereMap;
use haarshift::faces::param::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift::sphere::harmonics::SphericalHarmonics;
use haarshift::sphere::latlong::direction;
use haarshift::sphere::{LatLongMap, SphereRotation};
use haarshift_relight::light::downsample::downsample_solid_angle;
use haarshift_relight::light::environment::{Environment, LightRotation, SphereMapping};
use haarshift_relight::render::{Background, Camera, DEFAULT_FOV, LitMesh, render};
use haarshift_relight::shade::lambert::{CHUNK, QuantisedTransport};
use haarshift_relight::{
    Generator, Lighting, PhongSh, PreparedTransport, SceneBvh, ShTransfer, ShadeOptions,
    VisibilityOptions, shade_sh, vertex_major,
};
use ndarray::{Array2, Array3};

/// A UV sphere of radius 1 with `n x 2n` quads (`4 n^2` triangles) and a smooth radiance.
fn sphere(n: usize) -> (Array2<f64>, Vec<[u32; 3]>, Array2<f32>) {
    let (rows, cols) = (n + 1, 2 * n + 1);
    let positions = Array2::from_shape_fn((rows * cols, 3), |(k, c)| {
        let (i, j) = (k / cols, k % cols);
        let d = direction(
            std::f64::consts::PI * i as f64 / n as f64,
            std::f64::consts::PI * j as f64 / n as f64,
        );
        d[c]
    });
    let mut tris = Vec::with_capacity(4 * n * n);
    for i in 0..n {
        for j in 0..2 * n {
            let k = (i * cols + j) as u32;
            let c = cols as u32;
            tris.push([k, k + 1, k + c + 1]);
            tris.push([k, k + c + 1, k + c]);
        }
    }
    let radiance = Array2::from_shape_fn((rows * cols, 3), |(k, c)| {
        (0.5 + 0.4 * positions[[k, c]]) as f32
    });
    (positions, tris, radiance)
}

fn map_512() -> LatLongMap<f64> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../testdata/envmaps/rooitou_park_256x128.npy"
    );
    let small: Array3<f32> = ndarray_npy::read_npy(path).expect("test map");
    let big = Array3::from_shape_fn((512, 1024, 3), |(i, j, c)| {
        f64::from(small[[i / 4, j / 4, c]])
    });
    LatLongMap::new(big).expect("a 2:1 map")
}

fn bench(c: &mut Criterion) {
    let (positions, triangles, radiance) = sphere(158);
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: &triangles,
        radiance: radiance.view(),
    };
    let camera = Camera::framing([-1.0; 3], [1.0; 3], DEFAULT_FOV).expect("camera");
    let env = map_512();
    let mut group = c.benchmark_group("relight");
    group.sample_size(10);
    let name = format!("raster_512x512_{}_triangles", triangles.len());
    group.bench_function(format!("{name}/all_threads"), |b| {
        b.iter(|| render(&camera, 512, 512, &mesh, Background::Environment(&env)).expect("renders"))
    });
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    group.bench_function(format!("{name}/one_thread"), |b| {
        b.iter(|| {
            one.install(|| {
                render(&camera, 512, 512, &mesh, Background::Environment(&env)).expect("renders")
            })
        })
    });
    group.bench_function("downsample_512x1024_to_128x256/solid_angle", |b| {
        b.iter(|| downsample_solid_angle(&env, 128).expect("downsamples"))
    });
    group.bench_function("downsample_512x1024_to_128x256/plain_mean", |b| {
        b.iter(|| env.downsample(4).expect("downsamples"))
    });
    let working =
        SphereMap::from_lat_long(&downsample_solid_angle(&env, 128).expect("map")).expect("faces");
    let sh = SphericalHarmonics::new(9).expect("bands");
    group.bench_function("sh_project_128x256_rgb_9_bands", |b| {
        b.iter(|| sh.project(&working))
    });
    group.finish();
}

/// `sum_v bits(v)` over the vertices, in the frame's parallel chunks: a plain read of the
/// transport when `bits` sums a vertex's bytes.
fn plain_read(vertices: usize, bits: impl Fn(usize) -> u64 + Sync + Send) -> u64 {
    (0..vertices)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(bits)
        .sum()
}

/// Prints how many texels `light` lights and what share of the stored coefficients fall on
/// them: the terms a frame visits (`relight::shade::lambert`).
fn report_lit_terms(t: &PreparedTransport<f32>, light: &Lighting) {
    let rows = light.coefficients();
    let lit: Vec<bool> = rows
        .rows()
        .into_iter()
        .map(|r| r.iter().any(|&x| x != 0.0))
        .collect();
    let on_lit: usize = (0..t.vertex_count())
        .map(|v| {
            t.coefficients(v)
                .0
                .iter()
                .filter(|&&i| lit[i as usize])
                .count()
        })
        .sum();
    eprintln!(
        "the lighting lights {} of {} texels; {} of the {} stored coefficients ({:.1}%) fall on them",
        lit.iter().filter(|&&l| l).count(),
        lit.len(),
        on_lit,
        t.coefficient_count(),
        100.0 * on_lit as f64 / t.coefficient_count() as f64
    );
}

/// The time of `iters` runs of `timed`, each followed by an untimed run of `other`.
fn alternate<A, B>(
    iters: u64,
    mut timed: impl FnMut() -> A,
    mut other: impl FnMut() -> B,
) -> Duration {
    let mut total = Duration::ZERO;
    for _ in 0..iters {
        let start = Instant::now();
        std::hint::black_box(timed());
        total += start.elapsed();
        std::hint::black_box(other());
    }
    total
}

/// The Cubes scene's transport at cube 64, 420 coefficients a vertex, ready to shade.
fn cubes_transport(param: Parameterization) -> PreparedTransport<f32> {
    let mesh = Generator::Cubes {
        count: 10,
        cells: 10,
        distance: 1.5,
    }
    .mesh()
    .expect("the cubes scene");
    let mut options = VisibilityOptions::new(param);
    options.keep = Selection::Largest(420);
    options.progress = true;
    let (set, report) = vertex_major(&mesh, &SceneBvh::new(&mesh), &options).expect("precomputes");
    eprintln!(
        "precomputed {} vertices in {:.1} s ({:.1} M rays/s)",
        set.vertex_count(),
        report.seconds,
        report.rays as f64 / report.seconds / 1e6
    );
    let albedo = ndarray::Array2::from_elem((set.vertex_count(), 3), 0.8f32);
    PreparedTransport::new(&set, albedo.view(), &ShadeOptions::default()).expect("prepares")
}

fn bench_relighting(c: &mut Criterion) {
    let param = Parameterization::new(ParamKind::Cube, 64).expect("cube 64");
    let env = Environment::new(map_512());
    let keep = Selection::Largest(200);
    // 37 columns of the 256 of the 128 x 256 working map; and a tilted turn.
    let whole = SphereRotation::from_degrees(37.0 * 360.0 / 256.0, 0.0, 0.0).expect("yaw");
    let general = SphereRotation::from_degrees(30.0, 20.0, 0.0).expect("rotation");
    // Made once, as the animation does: the lat-long-to-cube overlap table.
    let mapping = SphereMapping::new(env.map().height(), param).expect("mapping");
    let transport = OnceLock::new();
    let prepared = || transport.get_or_init(|| cubes_transport(param));
    let mut group = c.benchmark_group("relight_cubes_85860");
    group.sample_size(10);
    group.bench_function("encode_lighting_cube64_keep200/whole_column_yaw", |b| {
        b.iter(|| Lighting::encode(&env, &mapping, &whole, keep).expect("encodes"))
    });
    group.bench_function("encode_lighting_cube64_keep200/general_rotation", |b| {
        b.iter(|| Lighting::encode(&env, &mapping, &general, keep).expect("encodes"))
    });
    // The same at lat-long 64, lat-long 128 and cube 64 with the general rotation applied to
    // the copy prefiltered to twice the working lat-long height (made once, before timing).
    for (kind, size) in [
        (ParamKind::LatLong, 64),
        (ParamKind::LatLong, 128),
        (ParamKind::Cube, 64),
    ] {
        let param = Parameterization::new(kind, size).expect("param");
        let fast = SphereMapping::new(env.map().height(), param)
            .expect("mapping")
            .with_rotation(LightRotation::Prefiltered);
        Lighting::encode(&env, &fast, &general, keep).expect("prepares the copy");
        let name = format!("encode_lighting_{kind}{size}_keep200/prefiltered_general_rotation");
        group.bench_function(name, |b| {
            b.iter(|| Lighting::encode(&env, &fast, &general, keep).expect("encodes"))
        });
    }
    // Each frame alternates with a plain read of the same bytes (the frame's floor: the same
    // offsets, indices and values read once, in the same parallel chunks of vertices, their
    // bits summed as integers, which the compiler vectorises: nothing gathered, nothing
    // waiting on a floating-point add), and each read with a frame, one of the two timed: so
    // that both start from the same cache (278 MiB is about this machine's last-level cache)
    // and are measured under the same neighbours' load.
    let read = |t: &PreparedTransport<f32>| {
        plain_read(t.vertex_count(), |v| {
            let (indices, values) = t.coefficients(v);
            let i = indices.iter().fold(0u32, |s, &i| s.wrapping_add(i));
            let w = values.iter().fold(0u32, |s, x| s.wrapping_add(x.to_bits()));
            u64::from(i ^ w)
        })
    };
    let truncated = || Lighting::encode(&env, &mapping, &whole, keep).expect("encodes");
    let lit_terms = std::sync::Once::new();
    group.bench_function("shade_keep420_f32", |b| {
        let (t, light) = (prepared(), truncated());
        lit_terms.call_once(|| report_lit_terms(t, &light));
        let mut out = ndarray::Array2::zeros((t.vertex_count(), 3));
        b.iter_custom(|n| {
            alternate(
                n,
                || t.shade_into(&light, &mut out).expect("shades"),
                || read(t),
            )
        })
    });
    // Every lighting coefficient kept: its 24,576 rows gathered from the dense table (a
    // truncated lighting's few non-zero rows go through a byte table that stays in L1).
    group.bench_function("shade_keep420_f32_every_light_coefficient", |b| {
        let t = prepared();
        let light = Lighting::encode(&env, &mapping, &whole, Selection::All).expect("encodes");
        let mut out = ndarray::Array2::zeros((t.vertex_count(), 3));
        b.iter_custom(|n| {
            alternate(
                n,
                || t.shade_into(&light, &mut out).expect("shades"),
                || read(t),
            )
        })
    });
    group.bench_function("plain_read_of_the_shaded_bytes", |b| {
        let (t, light) = (prepared(), truncated());
        let mut out = ndarray::Array2::zeros((t.vertex_count(), 3));
        b.iter_custom(|n| {
            alternate(
                n,
                || read(t),
                || t.shade_into(&light, &mut out).expect("shades"),
            )
        })
    });
    // The same transport in 16 bits a coefficient (--precision q16), and its own floor.
    let quantised = OnceLock::new();
    let packed = || quantised.get_or_init(|| QuantisedTransport::new(prepared()));
    let read_q16 = |q: &QuantisedTransport| {
        plain_read(q.vertex_count(), |v| {
            let (gaps, values) = q.entries(v);
            let g = gaps.iter().fold(0u16, |s, &g| s.wrapping_add(g));
            let w = values.iter().fold(0i16, |s, &x| s.wrapping_add(x));
            u64::from(g) ^ w as u64
        })
    };
    group.bench_function("shade_keep420_q16", |b| {
        let (q, light) = (packed(), truncated());
        let mut out = ndarray::Array2::<f32>::zeros((q.vertex_count(), 3));
        b.iter_custom(|n| {
            alternate(
                n,
                || q.shade_into(&light, &mut out).expect("shades"),
                || read_q16(q),
            )
        })
    });
    group.bench_function("plain_read_of_the_q16_bytes", |b| {
        let (q, light) = (packed(), truncated());
        let mut out = ndarray::Array2::<f32>::zeros((q.vertex_count(), 3));
        b.iter_custom(|n| {
            alternate(
                n,
                || read_q16(q),
                || q.shade_into(&light, &mut out).expect("shades"),
            )
        })
    });
    group.bench_function("encode_and_shade/whole_column_yaw", |b| {
        let t = prepared();
        let mut out = ndarray::Array2::zeros((t.vertex_count(), 3));
        b.iter(|| {
            let light = Lighting::encode(&env, &mapping, &whole, keep).expect("encodes");
            t.shade_into(&light, &mut out).expect("shades")
        })
    });
    group.bench_function("encode_and_shade/general_rotation", |b| {
        let t = prepared();
        let mut out = ndarray::Array2::zeros((t.vertex_count(), 3));
        b.iter(|| {
            let light = Lighting::encode(&env, &mapping, &general, keep).expect("encodes");
            t.shade_into(&light, &mut out).expect("shades")
        })
    });
    group.finish();
}

/// The glossy and Lambertian SH shadings of 85,860 vertices, synthetic transfer and lighting.
fn bench_sh(c: &mut Criterion) {
    let vertices = 85_860;
    let mut group = c.benchmark_group("relight_sh_85860");
    group.sample_size(10);
    for bands in [4, 6, 8] {
        let n = bands * bands;
        let transfer = ShTransfer::new(
            bands,
            Array2::from_shape_fn((vertices, n), |(v, i)| {
                (((v * 7 + i * 13) as f64 * 0.37).sin() / (1 + i) as f64) as f32
            }),
        )
        .expect("transfer");
        let albedo = Array2::from_elem((vertices, 3), 0.7f32);
        let lighting = Array2::from_shape_fn((n, 3), |(i, c)| 1.0 / (1 + i + c) as f64);
        let mirror = Array2::from_shape_fn((vertices, 3), |(v, k)| {
            direction(0.1 + 3.0 * (v as f64 * 0.618_034).fract(), v as f64 * 2.4)[k]
        });
        group.bench_function(format!("shade_sh_lambert/bands_{bands}"), |b| {
            b.iter(|| shade_sh(&transfer, albedo.view(), lighting.view()).expect("shades"))
        });
        let phong = PhongSh::new(bands, 50.0).expect("phong");
        group.bench_function(format!("shade_sh_phong50/bands_{bands}"), |b| {
            b.iter(|| {
                phong
                    .shade(
                        &transfer,
                        albedo.view(),
                        lighting.view(),
                        mirror.view(),
                        vertices,
                    )
                    .expect("shades")
            })
        });
        group.bench_function(format!("phong_sh_new/bands_{bands}"), |b| {
            b.iter(|| PhongSh::new(bands, 50.0).expect("phong"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench, bench_relighting, bench_sh);
criterion_main!(benches);
