use ndarray::Array2;

use super::*;
use crate::light::environment::Environment;
use crate::shade::{Method, ShaderSpec, ShadingInput};
use crate::{
    Generator, ReferenceOptions, Scene, SceneBvh, VisibilityOptions, reference, vertex_major,
};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::sphere::{LatLongMap, SphereRotation};

/// A sphere on the ground plane, precomputed at lat-long `n`: the sphere shadows the plane
/// and the plane the sphere's lower half.
fn sphere_on_ground(n: usize) -> (Scene, crate::TransportSet) {
    let scene = Scene::from_mesh(Generator::Sphere { cells: 4 }.mesh().unwrap(), true).unwrap();
    let param = Parameterization::new(ParamKind::LatLong, n).unwrap();
    let (set, _) = vertex_major(
        &scene.mesh,
        &SceneBvh::new(&scene.mesh),
        &VisibilityOptions::new(param),
    )
    .unwrap();
    (scene, set)
}

fn ambient(scene: &Scene, set: &crate::TransportSet) -> Box<dyn Shader> {
    let spec = ShaderSpec {
        method: Method::Ambient,
        ..ShaderSpec::default()
    };
    let input = ShadingInput::new(
        &scene.mesh,
        scene.albedo.view(),
        Some(set),
        scene.object_vertices(),
    );
    spec.build(&input).unwrap()
}

fn map(n: usize, f: impl Fn([f64; 3]) -> f64 + Sync) -> LatLongMap<f64> {
    LatLongMap::from_fn(n, 1, |d, o| o[0] = f(d)).unwrap()
}

#[test]
fn ambient_occlusion_is_the_quadrature_of_the_transport_under_a_white_sky() {
    // The oracle: albedo / pi x sum_t V(v, t) max(0, n . w_t) dOmega_t, the integral of the
    // transport, by the reference's direct quadrature under radiance 1 at the same texels (no
    // Haar transform; the same rays).
    let n = 16;
    let (scene, set) = sphere_on_ground(n);
    let got = ambient(&scene, &set)
        .shade(&FrameSpec {
            environment: &Environment::new(map(n, |_| 1.0)),
            rotation: SphereRotation::identity(),
            eye: None,
        })
        .unwrap()
        .radiance
        .to_f64();
    let (want, _) = reference(
        &scene.mesh,
        &SceneBvh::new(&scene.mesh),
        scene.albedo.view(),
        &map(n, |_| 1.0),
        &ReferenceOptions::default(),
    )
    .unwrap();
    let worst = got
        .iter()
        .zip(&want)
        .fold(0.0f64, |a, (g, w)| a.max((g - w).abs()));
    assert!(worst < 1e-6, "{worst}");
    // Occlusion is seen: the plane under the sphere and the sphere's underside are darker
    // than an open vertex's albedo (0.8), by more than the quadrature error.
    let darkest = want.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    assert!(darkest < 0.5, "{darkest}");
}

#[test]
fn ambient_occlusion_ignores_the_lighting() {
    let n = 8;
    let (scene, set) = sphere_on_ground(n);
    let mut shader = ambient(&scene, &set);
    let bright = Environment::new(map(n, |d| 2.0 + d[1]));
    let dark = Environment::new(map(2 * n, |d| 0.1 * d[0].abs()));
    let a = shader
        .shade(&FrameSpec {
            environment: &bright,
            rotation: SphereRotation::identity(),
            eye: None,
        })
        .unwrap();
    let b = shader
        .shade(&FrameSpec {
            environment: &dark,
            rotation: SphereRotation::from_degrees(40.0, 10.0, 0.0).unwrap(),
            eye: Some([0.0, 1.0, 5.0]),
        })
        .unwrap();
    assert_eq!(a.radiance, b.radiance);
}

#[test]
fn an_open_upward_vertex_reflects_its_albedo() {
    // <T, 1> = int max(0, y) dOmega = pi for a vertex that sees the whole sky.
    let mesh = crate::Mesh::new(
        ndarray::array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
        vec![[0, 1, 2]],
        None,
    )
    .unwrap();
    let param = Parameterization::new(ParamKind::LatLong, 32).unwrap();
    let (set, _) =
        vertex_major(&mesh, &SceneBvh::new(&mesh), &VisibilityOptions::new(param)).unwrap();
    let albedo = Array2::from_shape_fn((3, 3), |(_, c)| [0.25f32, 0.5, 0.75][c]);
    let spec = ShaderSpec {
        method: Method::Ambient,
        ..ShaderSpec::default()
    };
    let mut shader = spec
        .build(&ShadingInput::new(&mesh, albedo.view(), Some(&set), 3))
        .unwrap();
    let r = shader
        .shade(&FrameSpec {
            environment: &Environment::new(map(8, |_| 0.0)),
            rotation: SphereRotation::identity(),
            eye: None,
        })
        .unwrap()
        .radiance
        .to_f64();
    for v in 0..3 {
        for c in 0..3 {
            let a = f64::from(albedo[[v, c]]);
            // The lat-long midpoint quadrature of the cosine at N = 32: within 1.5e-3.
            assert!(
                (r[[v, c]] / a - 1.0).abs() < 1.5e-3,
                "{v} {c}: {}",
                r[[v, c]]
            );
        }
    }
}

#[test]
fn a_glossy_material_or_a_scene_without_transport_is_refused() {
    let (scene, set) = sphere_on_ground(8);
    let mut spec = ShaderSpec {
        method: Method::Ambient,
        ..ShaderSpec::default()
    };
    let e = spec
        .build(&ShadingInput::scene(&scene))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("needs a precomputed transport"), "{e}");
    spec.material.brdf = "phong:20".parse().unwrap();
    let input = ShadingInput::new(&scene.mesh, scene.albedo.view(), Some(&set), 1);
    let e = spec.build(&input).err().unwrap().to_string();
    assert!(e.contains("ambient occlusion is Lambertian"), "{e}");
}
