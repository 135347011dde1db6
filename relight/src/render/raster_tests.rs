//! Tests of the rasteriser.

use super::*;
use crate::render::{srgb_encode, write_render};
use glam::DVec3;
use haarshift::sphere::latlong::angles;
use ndarray::{Array2, Array3, array};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn front_camera() -> Camera {
    Camera::new([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], 60.0).unwrap()
}

/// One triangle's screen-space setup, as `render` makes it.
fn setups(
    camera: &Camera,
    w: usize,
    h: usize,
    positions: &Array2<f64>,
    tris: &[[u32; 3]],
) -> Vec<Setup> {
    let radiance = Array2::<f32>::zeros((positions.nrows(), 3));
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: tris,
        radiance: radiance.view(),
    };
    setup_triangles(camera, w, h, &mesh)
}

/// How many triangles cover each pixel centre.
fn coverage(
    camera: &Camera,
    w: usize,
    h: usize,
    positions: &Array2<f64>,
    tris: &[[u32; 3]],
) -> Array2<u32> {
    let mut count = Array2::<u32>::zeros((h, w));
    for s in setups(camera, w, h, positions, tris) {
        rasterize(&s, 0..h, w, |i, j, _| count[[i, j]] += 1);
    }
    count
}

/// Signed distance in pixels from `p` to the line `a -> b` (positive on the left, y down).
fn side(a: [f64; 3], b: [f64; 3], p: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    (dx * (p[1] - a[1]) - dy * (p[0] - a[0])) / (dx * dx + dy * dy).sqrt()
}

#[test]
fn a_triangle_covers_exactly_the_pixel_centres_inside_it() {
    let camera = front_camera();
    let (w, h) = (64, 48);
    let tris = [
        array![[-1.3, -0.7, 0.2], [1.1, -1.2, -0.4], [0.3, 1.4, 0.1]],
        array![[-2.0, 0.1, -1.0], [0.05, 0.2, 0.5], [-0.4, 0.9, 0.0]],
    ];
    for positions in tris {
        let count = coverage(&camera, w, h, &positions, &[[0, 1, 2]]);
        let v: Vec<[f64; 3]> = (0..3)
            .map(|k| {
                camera
                    .project([0, 1, 2].map(|c| positions[[k, c]]), w, h)
                    .unwrap()
            })
            .collect();
        let orient = side(v[0], v[1], [v[2][0], v[2][1]]).signum();
        let (mut inside, mut ambiguous) = (0, 0);
        for ((i, j), &n) in count.indexed_iter() {
            let p = [j as f64 + 0.5, i as f64 + 0.5];
            let d = [(0, 1), (1, 2), (2, 0)].map(|(a, b)| orient * side(v[a], v[b], p));
            let margin = d.iter().fold(f64::INFINITY, |m, &x| m.min(x));
            if margin.abs() < 0.01 {
                ambiguous += 1; // within the 1/256-pixel snapping of an edge
                continue;
            }
            let want = u32::from(margin > 0.0);
            inside += want;
            assert_eq!(n, want, "pixel ({i}, {j}), margin {margin}");
        }
        assert!(
            inside > 30 && ambiguous < 5,
            "{inside} inside, {ambiguous} ambiguous"
        );
    }
}

/// A grid of `n x n` vertices `vertex(a, b)`, two triangles per quad (alternating diagonals).
fn grid(n: usize, vertex: impl Fn(usize, usize) -> [f64; 3]) -> (Array2<f64>, Vec<[u32; 3]>) {
    let positions = Array2::from_shape_fn((n * n, 3), |(k, c)| vertex(k / n, k % n)[c]);
    let mut tris = Vec::new();
    for a in 0..n - 1 {
        for b in 0..n - 1 {
            let (k, m) = ((a * n + b) as u32, n as u32);
            if (a + b) % 2 == 0 {
                tris.extend([[k, k + 1, k + m + 1], [k, k + m + 1, k + m]]);
            } else {
                tris.extend([[k, k + 1, k + m], [k + 1, k + m + 1, k + m]]);
            }
        }
    }
    (positions, tris)
}

#[test]
fn shared_edges_are_drawn_once_and_leave_no_cracks() {
    // Vertices on pixel centres, 3 px apart: every edge, horizontal, vertical or diagonal,
    // runs through pixel centres, and only the fill rule decides who draws them. Camera:
    // f = 50 px for 100 x 100, depth 10, so world x goes to 50 + 5 x and y to 50 - 5 y.
    let camera = Camera::new([0.0, 0.0, 10.0], [0.0, 0.0, 0.0], 90.0).unwrap();
    let (positions, tris) = grid(11, |a, b| [0.1 + 0.6 * b as f64, 0.1 + 0.6 * a as f64, 0.0]);
    let count = coverage(&camera, 100, 100, &positions, &tris);
    // The outline spans x in [50.5, 80.5] and y in [19.5, 49.5]: its left and top edges
    // are in, its right and bottom edges out.
    for ((i, j), &c) in count.indexed_iter() {
        let want = u32::from((19..49).contains(&i) && (50..80).contains(&j));
        assert_eq!(c, want, "pixel ({i}, {j})");
    }
    // A jittered grid on a tilted plane: nothing drawn twice, no crack along any row.
    let camera = Camera::new([0.3, 0.2, 4.0], [0.0, 0.0, 0.0], 50.0).unwrap();
    let (positions, tris) = grid(10, |a, b| {
        let jitter = 0.3 * (((a * 10 + b) * 7919 % 13) as f64 / 13.0 - 0.5);
        let (a, b) = (a as f64, b as f64);
        [
            -1.5 + b / 3.0 + 0.2 * jitter,
            -1.5 + a / 3.0 - 0.1 * jitter,
            0.03 * (b - a),
        ]
    });
    let count = coverage(&camera, 96, 96, &positions, &tris);
    assert!(count.iter().all(|&c| c <= 1), "a pixel drawn twice");
    let drawn = count.iter().filter(|&&c| c == 1).count();
    assert!(drawn > 2000, "{drawn}");
    for (i, row) in count.outer_iter().enumerate() {
        let cols: Vec<usize> = (0..96).filter(|&j| row[j] == 1).collect();
        if let (Some(&first), Some(&last)) = (cols.first(), cols.last()) {
            assert_eq!(cols.len(), last - first + 1, "a crack in row {i}");
        }
    }
}

#[test]
fn the_nearer_of_two_overlapping_triangles_wins_in_either_order() {
    let camera = front_camera();
    let positions = array![
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 1.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, -1.0, 1.0],
    ];
    let mut radiance = Array2::<f32>::zeros((6, 3));
    radiance.slice_mut(ndarray::s![..3, 0]).fill(1.0); // far: red
    radiance.slice_mut(ndarray::s![3.., 2]).fill(1.0); // near: blue
    for tris in [[[0, 1, 2], [3, 4, 5]], [[3, 4, 5], [0, 1, 2]]] {
        let mesh = LitMesh {
            positions: positions.view(),
            triangles: &tris,
            radiance: radiance.view(),
        };
        let image = render(&camera, 40, 40, &mesh, Background::Colour([0.0; 3])).unwrap();
        // The centre is covered by both: blue.
        assert_eq!(
            (image.plane(0)[[20, 20]], image.plane(2)[[20, 20]]),
            (0.0, 1.0)
        );
    }
}

#[test]
fn interpolation_is_perspective_correct() {
    // A triangle steep in depth with radiance linear in the position: at every pixel centre
    // the value must be the linear function at the point where the ray meets the plane.
    let camera = Camera::new([0.2, 0.4, 3.0], [0.0, 0.0, 0.0], 70.0).unwrap();
    let positions = array![[-1.5, -1.0, 1.5], [1.5, -0.8, 1.2], [0.0, 1.2, -6.0]];
    let f = |p: [f64; 3]| {
        [
            1.0 + 0.3 * p[0],
            2.0 - 0.2 * p[1] + 0.1 * p[2],
            0.5 + 0.05 * p[2],
        ]
    };
    let radiance = Array2::from_shape_fn((3, 3), |(k, c)| {
        f([0, 1, 2].map(|i| positions[[k, i]]))[c] as f32
    });
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: &[[0, 1, 2]],
        radiance: radiance.view(),
    };
    let (w, h) = (80, 60);
    let image = render(&camera, w, h, &mesh, Background::Colour([-1.0; 3])).unwrap();
    let corner = |k: usize| DVec3::new(positions[[k, 0]], positions[[k, 1]], positions[[k, 2]]);
    let p0 = corner(0);
    let normal = (corner(1) - p0).cross(corner(2) - p0);
    let mut checked = 0;
    for i in 0..h {
        for j in 0..w {
            if image.plane(0)[[i, j]] == -1.0 {
                continue;
            }
            let d = camera.ray(j as f64 + 0.5, i as f64 + 0.5, w, h);
            let t = (p0 - DVec3::from(camera.position())).dot(normal) / DVec3::from(d).dot(normal);
            let hit = [0, 1, 2].map(|k| camera.position()[k] + t * d[k]);
            for (c, want) in f(hit).iter().enumerate() {
                let got = image.plane(c)[[i, j]] as f64;
                assert!(
                    (got - want).abs() < 2e-6 * want.abs(),
                    "({i}, {j}) {c}: {got} vs {want}"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 500, "{checked}");
}

#[test]
fn a_known_point_projects_to_its_pixel() {
    // Looking along -Z from (0, 0, 10), fov 90: f = H / 2 = 50 for 100 x 100.
    let camera = Camera::new([0.0, 0.0, 10.0], [0.0, 0.0, 9.0], 90.0).unwrap();
    let [x, y, z] = camera.project([2.0, -3.0, 0.0], 100, 100).unwrap();
    assert!((x - (50.0 + 50.0 * 2.0 / 10.0)).abs() < 1e-12);
    assert!((y - (50.0 + 50.0 * 3.0 / 10.0)).abs() < 1e-12);
    assert!((z - 10.0).abs() < 1e-12);
    assert!(camera.project([0.0, 0.0, 11.0], 100, 100).is_none());
    // A triangle 0.2 px wide around the point seen at the centre (59.5, 64.5) of pixel
    // (row 64, column 59) lights that pixel and no other.
    let (x, y, e) = (1.9, -2.9, 0.02);
    let positions = array![[x - e, y - e, 0.0], [x + e, y - e, 0.0], [x, y + e, 0.0]];
    let count = coverage(&camera, 100, 100, &positions, &[[0, 1, 2]]);
    let lit: Vec<(usize, usize)> = count
        .indexed_iter()
        .filter(|(_, c)| **c > 0)
        .map(|(p, _)| p)
        .collect();
    assert_eq!(lit, vec![(64, 59)]);
}

#[test]
fn the_background_of_a_constant_environment_is_the_constant() {
    let env =
        LatLongMap::<f64>::from_fn(16, 3, |_, o| o.copy_from_slice(&[0.3, 0.6, 0.9])).unwrap();
    let camera = Camera::new([1.0, 2.0, 3.0], [0.0, 0.5, 0.0], 75.0).unwrap();
    let positions = Array2::<f64>::zeros((0, 3));
    let radiance = Array2::<f32>::zeros((0, 3));
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: &[],
        radiance: radiance.view(),
    };
    let image = render(&camera, 33, 21, &mesh, Background::Environment(&env)).unwrap();
    for (c, want) in [0.3f32, 0.6, 0.9].iter().enumerate() {
        assert!(image.plane(c).iter().all(|v| (v - want).abs() < 1e-6));
    }
    // The direction convention: the env holds its own direction; the centre pixel of a
    // camera looking along -X sees about (-1, 0, 0).
    let dirs = LatLongMap::<f64>::from_fn(64, 3, |d, o| o.copy_from_slice(&d)).unwrap();
    let camera = Camera::new([0.0; 3], [-1.0, 0.0, 0.0], 60.0).unwrap();
    let image = render(&camera, 11, 11, &mesh, Background::Environment(&dirs)).unwrap();
    let centre = [0, 1, 2].map(|c| image.plane(c)[[5, 5]]);
    assert!(
        (centre[0] + 1.0).abs() < 1e-2 && centre[1].abs() < 1e-2 && centre[2].abs() < 1e-2,
        "{centre:?}"
    );
}

#[test]
fn srgb_matches_the_standard_at_known_values() {
    // IEC 61966-2-1: 12.92 v below 0.0031308, else 1.055 v^(1/2.4) - 0.055.
    for (v, want) in [
        (0.0, 0.0),
        (0.002, 0.02584),
        (0.003_130_8, 0.040_449_936),
        (0.18, 0.461_356_129_500_441_6),
        (0.5, 0.735_356_983_052_449_5),
        (1.0, 1.0),
        (4.0, 1.0),
    ] {
        assert!(
            (srgb_encode(v) - want).abs() < 1e-8,
            "{v}: {}",
            srgb_encode(v)
        );
    }
}

#[test]
fn renders_are_written_as_srgb_png_and_linear_exr() {
    let planes = Array3::from_shape_fn((3, 2, 2), |(c, i, j)| {
        [0.0f32, 0.18, 0.5, 2.0][(c + i + 2 * j) % 4]
    });
    let image = PlanarImage::new(planes.clone(), Channels::Rgb, SampleDepth::F32).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("r.png");
    write_render(&image, &png, 0.0, false).unwrap();
    let back = haarshift::io::read_image::<f32>(&png).unwrap();
    for (&v, &b) in planes.iter().zip(back.planes().iter()) {
        assert_eq!(b, (srgb_encode(v as f64) * 255.0).round() as f32);
    }
    assert_err!(
        write_render(&image, &png, 0.0, false),
        OutputExists { .. },
        "already exists"
    );
    write_render(&image, &png, 1.0, true).unwrap();
    let exr = dir.path().join("r.exr");
    write_render(&image, &exr, 5.0, false).unwrap(); // the exposure does not touch EXR
    assert_eq!(
        haarshift::io::read_image::<f32>(&exr).unwrap().planes(),
        planes.view()
    );
}

#[test]
fn bad_meshes_and_cameras_are_errors() {
    let camera = front_camera();
    let positions = array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0]];
    let radiance = Array2::<f32>::zeros((3, 3));
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: &[[0, 1, 2]],
        radiance: radiance.view(),
    };
    assert_err!(
        render(&camera, 8, 8, &mesh, Background::Colour([0.0; 3])),
        NonFinite { .. },
        "NaN"
    );
    let positions = Array2::<f64>::zeros((3, 3));
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: &[[0, 1, 3]],
        radiance: radiance.view(),
    };
    let err = render(&camera, 8, 8, &mesh, Background::Colour([0.0; 3])).unwrap_err();
    assert!(err.to_string().contains("triangle 0"), "{err}");
    let short = Array2::<f32>::zeros((2, 3));
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: &[],
        radiance: short.view(),
    };
    assert_err!(
        render(&camera, 8, 8, &mesh, Background::Colour([0.0; 3])),
        InvalidShape { .. },
        "positions (V, 3) and radiance (V, 3)"
    );
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: &[],
        radiance: radiance.view(),
    };
    assert_err!(
        render(&camera, 0, 8, &mesh, Background::Colour([0.0; 3])),
        InvalidShape { .. },
        "1 to 32768 pixels"
    );
    let two = LatLongMap::<f64>::from_fn(4, 2, |_, o| o.fill(1.0)).unwrap();
    assert_err!(
        render(&camera, 8, 8, &mesh, Background::Environment(&two)),
        InvalidParameter {
            name: "background",
            ..
        },
        "2 channels"
    );
    assert_err!(
        Camera::new([0.0; 3], [0.0, 0.0, -1.0], 180.0),
        InvalidParameter { name: "fov", .. },
        "180 degrees"
    );
    assert_err!(
        Camera::new([0.0, f64::INFINITY, 0.0], [0.0; 3], 40.0),
        InvalidParameter { name: "camera", .. },
        "must be finite"
    );
    // Looking straight down is allowed: the image's up is -Z.
    let down = Camera::new([0.0, 5.0, 0.0], [0.0; 3], 40.0).unwrap();
    let [_, y, _] = down.project([0.0, 0.0, -1.0], 10, 10).unwrap();
    assert!(y < 5.0);
}

#[test]
fn triangles_through_the_near_plane_are_clipped_not_dropped() {
    // A floor running from behind the camera to far in front fills the lower half.
    let camera = Camera::new([0.0, 1.0, 0.0], [0.0, 1.0, -1.0], 90.0).unwrap();
    let positions = array![
        [-50.0, 0.0, 50.0],
        [50.0, 0.0, 50.0],
        [50.0, 0.0, -50.0],
        [-50.0, 0.0, -50.0]
    ];
    let count = coverage(&camera, 20, 20, &positions, &[[0, 1, 2], [0, 2, 3]]);
    for i in 0..20 {
        for j in 0..20 {
            // The horizon of a floor 50 units away is about 1/50 of the half-height below
            // the centre line: rows from 11 on are floor, rows up to 9 are sky.
            if i >= 11 {
                assert_eq!(count[[i, j]], 1, "({i}, {j})");
            }
            if i <= 9 {
                assert_eq!(count[[i, j]], 0, "({i}, {j})");
            }
        }
    }
}

/// The image by brute force: every pixel centre against every set-up triangle in the mesh's
/// order, coverage from the edge functions evaluated at the centre itself (top-left rule), the
/// nearest fragment kept (the earlier of two at the same depth), its radiance interpolated
/// there; `background(i, j)` elsewhere. No bands, no bounding boxes, no stepping, no threads.
fn raster_by_brute_force(
    camera: &Camera,
    w: usize,
    h: usize,
    mesh: &LitMesh<'_>,
    background: impl Fn(usize, usize) -> [f32; 3],
) -> Array3<f32> {
    let setups = setup_triangles(camera, w, h, mesh);
    let mut image = Array3::<f32>::zeros((3, h, w));
    for i in 0..h {
        for j in 0..w {
            let p = [256 * j as i64 + 128, 256 * i as i64 + 128];
            let (x, y) = (j as f64 + 0.5, i as f64 + 0.5);
            let mut nearest: Option<(f64, [f32; 3])> = None;
            for s in &setups {
                let [a, b, c] = s.snapped;
                let inside = [(b, c), (c, a), (a, b)].iter().all(|&(u, v)| {
                    let e = (v[0] - u[0]) * (p[1] - u[1]) - (v[1] - u[1]) * (p[0] - u[0]);
                    let (dx, dy) = (v[0] - u[0], v[1] - u[1]);
                    e > 0 || (e == 0 && (dy < 0 || (dy == 0 && dx > 0)))
                });
                if !inside {
                    continue;
                }
                let plane = |q: usize| s.planes[q][0] * x + s.planes[q][1] * y + s.planes[q][2];
                let depth = plane(0);
                if nearest.is_none_or(|(d, _)| depth > d) {
                    let z = 1.0 / depth;
                    let rgb = [1, 2, 3].map(|q| (plane(q) * z) as f32);
                    nearest = Some((depth, rgb));
                }
            }
            let rgb = nearest.map_or_else(|| background(i, j), |(_, rgb)| rgb);
            for c in 0..3 {
                image[[c, i, j]] = rgb[c];
            }
        }
    }
    image
}

/// A random scene in front of (and around, and behind) `camera`'s view: small and large
/// triangles, many crossing the bands' borders, some off screen or behind the camera, some
/// through the near plane, some degenerate (a repeated vertex, three collinear points), and
/// exact duplicates of others (equal depths: the earlier wins).
fn random_scene(rng: &mut StdRng) -> (Array2<f64>, Vec<[u32; 3]>, Array2<f32>) {
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut tris = Vec::new();
    for t in 0..40 {
        let centre = [
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            rng.random_range(-4.0..4.5),
        ];
        let size = if t % 5 == 0 { 4.0 } else { 0.6 };
        let k = points.len() as u32;
        for _ in 0..3 {
            points.push(std::array::from_fn(|c| {
                centre[c] + size * rng.random_range(-1.0..1.0)
            }));
        }
        match t % 10 {
            3 => points[k as usize + 2] = points[k as usize], // a repeated vertex
            4 => {
                let (a, b) = (points[k as usize], points[k as usize + 1]);
                points[k as usize + 2] = std::array::from_fn(|c| 0.5 * (a[c] + b[c]));
            }
            _ => {}
        }
        tris.push([k, k + 1, k + 2]);
        if t % 7 == 2 {
            tris.push([k + 1, k + 2, k]); // the same triangle again, later
        }
    }
    let positions = Array2::from_shape_fn((points.len(), 3), |(v, c)| points[v][c]);
    let radiance = Array2::from_shape_fn((points.len(), 3), |_| rng.random_range(0.0..2.0f32));
    (positions, tris, radiance)
}

#[test]
fn the_banded_parallel_image_equals_brute_force_bit_for_bit() {
    let mut rng = StdRng::seed_from_u64(34);
    let env = LatLongMap::<f64>::from_fn(16, 3, |d, o| {
        o.copy_from_slice(&[1.0 + d[0], 2.0 - d[1], 1.5 + d[0] * d[2]])
    })
    .unwrap();
    // 37 x 43: the last band is partial and no border falls on a multiple of 8.
    let (w, h) = (37, 43);
    for scene in 0..12 {
        let camera =
            Camera::new([0.3, 0.2, 5.0], [0.0, 0.0, 0.0], 40.0 + 5.0 * scene as f64).unwrap();
        let (positions, tris, radiance) = random_scene(&mut rng);
        let mesh = LitMesh {
            positions: positions.view(),
            triangles: &tris,
            radiance: radiance.view(),
        };
        let colour = [0.25, 0.5, 0.75];
        let got = render(&camera, w, h, &mesh, Background::Colour(colour)).unwrap();
        let want = raster_by_brute_force(&camera, w, h, &mesh, |_, _| colour);
        assert_eq!(got.planes(), want, "scene {scene}");
        // Some pixels drawn, some left to the background.
        let background = (0..h * w)
            .filter(|&p| want[[0, p / w, p % w]] == 0.25)
            .count();
        assert!(
            background > 0 && background < w * h,
            "scene {scene}: {background}"
        );
        let got = render(&camera, w, h, &mesh, Background::Environment(&env)).unwrap();
        let want = raster_by_brute_force(&camera, w, h, &mesh, |i, j| {
            let (theta, phi) = angles(camera.ray(j as f64 + 0.5, i as f64 + 0.5, w, h));
            let mut v = [0.0; 3];
            env.bilinear(theta, phi, &mut v);
            v.map(|x| x as f32)
        });
        assert_eq!(got.planes(), want, "scene {scene}, environment");
        // Threads do not change a bit.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let alone = one.install(|| render(&camera, w, h, &mesh, Background::Environment(&env)));
        assert_eq!(alone.unwrap(), got, "scene {scene}, one thread");
    }
}
