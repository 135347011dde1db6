use std::path::{Path, PathBuf};

use ndarray::Array2;

use super::glossy::{GlossyOptions, GlossyShader};
use super::*;
use crate::light::environment::Environment;
use crate::material::orient::mirror_directions;
use crate::{
    Brdf, Generator, PhongSh, ReferenceOptions, Scene, SceneBvh, TransportSet, VisibilityOptions,
    reference, shade_sh, vertex_major,
};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::sphere::harmonics::SphericalHarmonics;
use haarshift::sphere::{LatLongMap, SphereRotation};

/// A sphere on the ground plane precomputed at lat-long 8 with 3 bands of harmonics.
fn sphere_with_harmonics() -> (Scene, TransportSet) {
    let scene = Scene::from_mesh(Generator::Sphere { cells: 3 }.mesh().unwrap(), true).unwrap();
    let mut options = VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
    options.sh_bands = Some(3);
    let (set, _) = vertex_major(&scene.mesh, &SceneBvh::new(&scene.mesh), &options).unwrap();
    (scene, set)
}

fn coloured_sky() -> Environment {
    Environment::new(
        LatLongMap::<f64>::from_fn(16, 3, |d, o| {
            o[0] = 1.0 + d[1].max(0.0) * 4.0;
            o[1] = 0.5 + 0.5 * d[0];
            o[2] = 0.2 + (3.0 * d[2]).sin().abs();
        })
        .unwrap(),
    )
}

const EYE: [f64; 3] = [0.5, 2.0, 6.0];

fn shade_with(spec: &ShaderSpec, scene: &Scene, set: &TransportSet) -> Shading {
    let input = ShadingInput::new(
        &scene.mesh,
        scene.albedo.view(),
        Some(set),
        scene.object_vertices(),
    );
    spec.build(&input)
        .unwrap()
        .shade(&FrameSpec {
            environment: &coloured_sky(),
            rotation: SphereRotation::from_degrees(30.0, 10.0, 0.0).unwrap(),
            eye: Some(EYE),
        })
        .unwrap()
}

fn turn() -> SphereRotation {
    SphereRotation::from_degrees(30.0, 10.0, 0.0).unwrap()
}

#[test]
fn every_shader_returns_what_its_numeric_code_returns_bit_for_bit() {
    let (scene, set) = sphere_with_harmonics();
    let env = coloured_sky();
    let param = set.param();
    let objects = scene.object_vertices();
    let albedo = scene.albedo.view();
    let keep = haarshift::product::Selection::Largest(40);
    let lighting = Lighting::new(&env, param, &turn(), keep).unwrap();

    // Lambert Haar, f32 and f64.
    let spec = ShaderSpec {
        keep_light: keep,
        ..ShaderSpec::default()
    };
    let want = PreparedTransport::<f32>::new(&set, albedo, &ShadeOptions::default())
        .unwrap()
        .shade(&lighting)
        .unwrap();
    assert_eq!(
        shade_with(&spec, &scene, &set).radiance,
        Radiance::F32(want)
    );
    let f64_spec = ShaderSpec {
        precision: Precision::F64,
        ..spec.clone()
    };
    let want = PreparedTransport::<f64>::new(&set, albedo, &ShadeOptions::default())
        .unwrap()
        .shade(&lighting)
        .unwrap();
    assert_eq!(
        shade_with(&f64_spec, &scene, &set).radiance,
        Radiance::F64(want)
    );

    // Glossy Haar with a rotation cache.
    let material = GlossyOptions {
        brdf: Brdf::Phong { exponent: 20.0 },
        cache_bins: Some(8),
        ..GlossyOptions::default()
    };
    let glossy = ShaderSpec {
        material: material.clone(),
        ..spec.clone()
    };
    let shader = GlossyShader::<f32>::new(
        &set,
        &scene.mesh,
        albedo,
        &ShadeOptions::default(),
        &material,
        objects,
    )
    .unwrap();
    let (want, report) = shader.shade(&lighting, EYE).unwrap();
    let got = shade_with(&glossy, &scene, &set);
    assert_eq!(got.radiance, Radiance::F32(want));
    assert_eq!(
        got.maps.map(|m| (m.maps, m.rotated)),
        Some((report.maps, report.rotated))
    );

    // Spherical harmonics, Lambert and Phong.
    let transfer = set.sh().unwrap();
    let sh_light = SphericalHarmonics::new(3)
        .unwrap()
        .project(&env.sphere_map(param, &turn()).unwrap());
    let sh = ShaderSpec {
        method: Method::Sh,
        ..ShaderSpec::default()
    };
    let want = shade_sh(transfer, albedo, sh_light.view()).unwrap();
    assert_eq!(shade_with(&sh, &scene, &set).radiance, Radiance::F32(want));
    let phong = ShaderSpec {
        material: GlossyOptions {
            brdf: Brdf::Phong { exponent: 20.0 },
            ..GlossyOptions::default()
        },
        ..sh
    };
    let mirror = mirror_directions(&scene.mesh, EYE);
    let want = PhongSh::new(3, 20.0)
        .unwrap()
        .shade(transfer, albedo, sh_light.view(), mirror.view(), objects)
        .unwrap();
    assert_eq!(
        shade_with(&phong, &scene, &set).radiance,
        Radiance::F64(want)
    );

    // The reference at the transport's resolution.
    let truth = ShaderSpec {
        method: Method::Reference,
        ..ShaderSpec::default()
    };
    let (want, _) = reference(
        &scene.mesh,
        &SceneBvh::new(&scene.mesh),
        albedo,
        &env.lat_long(8, &turn()).unwrap(),
        &ReferenceOptions {
            object_vertices: Some(objects),
            ..ReferenceOptions::default()
        },
    )
    .unwrap();
    assert_eq!(
        shade_with(&truth, &scene, &set).radiance,
        Radiance::F64(want)
    );
}

#[test]
fn a_glossy_shader_keeps_its_rotation_cache_from_frame_to_frame() {
    let (scene, set) = sphere_with_harmonics();
    let spec = ShaderSpec {
        material: GlossyOptions {
            brdf: Brdf::Phong { exponent: 20.0 },
            cache_bins: Some(8),
            ..GlossyOptions::default()
        },
        ..ShaderSpec::default()
    };
    let input = ShadingInput::new(
        &scene.mesh,
        scene.albedo.view(),
        Some(&set),
        scene.object_vertices(),
    );
    let mut shader = spec.build(&input).unwrap();
    let env = coloured_sky();
    let frame = FrameSpec {
        environment: &env,
        rotation: turn(),
        eye: Some(EYE),
    };
    let first = shader.shade(&frame).unwrap();
    let second = shader.shade(&frame).unwrap();
    let (a, b) = (first.maps.unwrap(), second.maps.unwrap());
    assert!(a.rotated > 0 && b.rotated == 0, "{a:?} {b:?}");
    assert_eq!(first.radiance, second.radiance);
    // Filled ahead: the first frame rotates nothing, and the fill is reported.
    let filled = ShaderSpec {
        fill_cache: true,
        ..spec
    }
    .build(&input)
    .unwrap();
    assert_eq!(filled.preparation().filled.map(|f| f.maps), Some(8 * 16));
    // A glossy shader needs the eye.
    let blind = FrameSpec { eye: None, ..frame };
    let e = shader.shade(&blind).err().unwrap().to_string();
    assert!(e.contains("needs the camera's position"), "{e}");
}

#[test]
fn specs_that_would_change_nothing_or_cannot_be_built_are_refused() {
    let (scene, set) = sphere_with_harmonics();
    let input = ShadingInput::new(
        &scene.mesh,
        scene.albedo.view(),
        Some(&set),
        scene.object_vertices(),
    );
    let refusal = |spec: ShaderSpec, input: &ShadingInput<'_>| {
        spec.build(input).err().expect("refused").to_string()
    };
    let mut cached = ShaderSpec::default();
    cached.material.cache_bins = Some(4);
    assert!(refusal(cached, &input).contains("apply to glossy BRDFs; the BRDF is lambert"));
    let mut fill = ShaderSpec::default();
    fill.material.brdf = Brdf::Phong { exponent: 5.0 };
    fill.fill_cache = true;
    assert!(refusal(fill, &input).contains("give --rotation-cache N"));
    let truncated_sh = ShaderSpec {
        method: Method::Sh,
        keep_light: haarshift::product::Selection::Largest(10),
        ..ShaderSpec::default()
    };
    assert!(refusal(truncated_sh, &input).contains("uses every band stored"));
    let mut blinn = ShaderSpec {
        method: Method::Sh,
        ..ShaderSpec::default()
    };
    blinn.material.brdf = "blinn:20".parse().unwrap();
    assert!(refusal(blinn, &input).contains("sh shades zonal lobes only"));
    let too_many = ShaderSpec {
        method: Method::Sh,
        sh_bands: Some(4),
        ..ShaderSpec::default()
    };
    assert!(refusal(too_many, &input).contains("the transfer stores 3 bands"));
    // Without harmonics: the file is named.
    let bare = TransportSet::new(set.param(), haarshift::product::Selection::All);
    let path = Path::new("bare.hsr");
    let empty = Array2::<f32>::zeros((0, 3));
    let bare_input = ShadingInput::new(&scene.mesh, empty.view(), Some(&bare), 0).from_file(path);
    let sh = ShaderSpec {
        method: Method::Sh,
        ..ShaderSpec::default()
    };
    assert_eq!(
        refusal(sh.clone(), &bare_input),
        format!(
            "{}: the cache holds no spherical-harmonic transfer: precompute it with --sh-bands B",
            path.display()
        )
    );
    // Haar and harmonics need a transport; the reference of a scene needs its resolution.
    assert!(refusal(ShaderSpec::default(), &ShadingInput::scene(&scene)).contains("transport"));
    assert!(refusal(sh, &ShadingInput::scene(&scene)).contains("transport"));
    let truth = ShaderSpec {
        method: Method::Reference,
        ..ShaderSpec::default()
    };
    assert!(refusal(truth, &ShadingInput::scene(&scene)).contains("lat-long height"));
}

/// The source files under `dir` (`.rs`), recursively.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs")
            && path
                .file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n != "tests.rs" && !n.ends_with("_tests.rs"))
        {
            out.push(path);
        }
    }
}

/// Text that dispatches on the shading method, the basis or the material, or reaches past
/// the [`Shader`] to a concrete shader or its numeric code.
fn dispatch(line: &str) -> Option<String> {
    const REACHES: [&str; 12] = [
        "PreparedTransport",
        "GlossyShader",
        "LambertShader",
        "ShShader",
        "PhongSh",
        "shade_sh",
        "ReferenceShader",
        "AmbientShader",
        "non_zonal_material",
        "mirror_directions",
        ".is_lambert()",
        "Basis::",
    ];
    if let Some(found) = REACHES.iter().find(|r| line.contains(*r)) {
        return Some((*found).to_owned());
    }
    // A method or a material named in a match arm, a comparison or a pattern (naming one to
    // build a spec or a protocol is not dispatch).
    let methods = Method::ALL.iter().map(|m| format!("Method::{m:?}")).chain(
        dynamic_scene::DynamicMethod::ALL
            .iter()
            .map(|m| format!("DynamicMethod::{m:?}")),
    );
    let materials = ["Lambert", "Phong", "Blinn", "Merl"].map(|v| format!("Brdf::{v}"));
    for variant in methods.chain(materials) {
        let named = line
            .match_indices(&variant)
            .any(|(at, _)| !line[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_'));
        if named
            && ["=>", "==", "!=", "if let", "matches!"]
                .iter()
                .any(|t| line.contains(t))
        {
            return Some(variant);
        }
    }
    None
}

#[test]
fn no_caller_dispatches_on_the_shading_method() {
    // The command line, the Python bindings and the experiments build a ShaderSpec (or a
    // DynamicShader of a DynamicMethod) and loop; only this module chooses between methods.
    // Test files (`tests.rs`, `*_tests.rs`), which check the shaders against their numeric
    // code, are not searched.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in ["cli/src", "python/src", "experiments/src"] {
        sources(&root.join(dir), &mut files);
    }
    assert!(files.len() > 20, "{} files", files.len());
    let mut found = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            if let Some(what) = dispatch(line) {
                found.push(format!(
                    "{}:{}: {what}: {}",
                    file.display(),
                    n + 1,
                    line.trim()
                ));
            }
        }
    }
    assert!(
        found.is_empty(),
        "dispatch outside relight::shade:\n{}",
        found.join("\n")
    );
    // The search finds what it looks for.
    assert_eq!(
        dispatch("    Method::Sh => shade(),").as_deref(),
        Some("Method::Sh")
    );
    assert_eq!(
        dispatch("if brdf.is_lambert() {").as_deref(),
        Some(".is_lambert()")
    );
    assert_eq!(dispatch("let s = spec(Method::Haar);"), None);
    assert_eq!(
        dispatch("DynamicMethod::Reference => truth(),").as_deref(),
        Some("DynamicMethod::Reference")
    );
    assert_eq!(
        dispatch("if let Brdf::Phong { exponent } = brdf {").as_deref(),
        Some("Brdf::Phong")
    );
    assert_eq!(
        dispatch("materials: vec![Brdf::Lambert, phong(10.0)],"),
        None
    );
    assert_eq!(dispatch("ShiftMethod::Haar => {"), None);
}
