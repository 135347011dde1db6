use std::path::Path;

use super::*;
use crate::SceneBvh;
use crate::dynamic::tests::{
    THREE, build, each_moved_object_is_the_full_product_integral, lighting, options, param,
    relative, scene_file,
};
use crate::material::orient::BrdfRotation;
use crate::precompute::visibility::{VisibilityOptions, vertex_major};
use crate::shade::ShadeOptions;
use crate::shade::glossy::GlossyShader;
use haarshift::faces::param::SphereMap;
use haarshift::sphere::LatLongMap;

const CAMERA: &str = r#""camera": {"position": [1.5, 2.5, 4.0], "look_at": [0, 0, 0]}"#;

/// A box over a plane, one object (its own transport is all its visibility), with `material`.
fn box_alone(material: &str) -> String {
    format!(
        r#"{{"objects": [{{"generator": {{"plane_under_box": {{"height": 0.4}}}},
            "transform": {{"translate": [0.3, 0, -0.2], "scale": 1.5}}, "material": {material}}}],
            {CAMERA}}}"#
    )
}

/// THREE with a camera and materials for objects a, b and c.
fn three(materials: [&str; 3]) -> String {
    let mut json = THREE.to_string();
    for (name, m) in ["a", "b", "c"].iter().zip(materials) {
        let at = json.find(&format!(r#""name": "{name}", "#)).unwrap();
        json.insert_str(at, &format!(r#""material": {m}, "#));
    }
    json.replacen(
        r#""ground_plane": true"#,
        &format!(r#""ground_plane": true, {CAMERA}"#),
        1,
    )
}

const PHONG: &str = r#"{"brdf": "phong", "exponent": 30, "albedo": [0.9, 0.8, 0.7]}"#;
const BLINN: &str = r#"{"brdf": "blinn", "exponent": 20, "albedo": [0.6, 0.7, 0.9]}"#;
const LAMBERT: &str = r#"{"brdf": "lambert", "albedo": [0.5, 0.6, 0.7]}"#;

fn direct(scene: &mut DynamicScene) {
    let options = GlossyOptions {
        rotation: BrdfRotation::Direct,
        ..GlossyOptions::default()
    };
    scene.set_glossy(&options).unwrap();
}

/// A sky with a sun, as the shading's lighting and as the reference's lat-long map.
fn sunny_sky() -> (Lighting, LatLongMap<f64>) {
    let map = SphereMap::<f64>::from_fn(param(), 3, |d, o| {
        let sun = (8.0 * (d[0] * 0.6 + d[1] * 0.8 - 1.0)).exp();
        o.copy_from_slice(&[1.0 + 20.0 * sun, 0.5 + d[2].abs(), 0.2 + 10.0 * sun]);
    })
    .unwrap();
    (
        Lighting::from_map(&map, Selection::All).unwrap(),
        map.to_lat_long().unwrap(),
    )
}

#[test]
fn with_every_coefficient_and_direct_evaluation_the_shading_equals_the_reference() {
    let (light, map) = sunny_sky();
    for material in [PHONG, BLINN] {
        let mut scene = build(&box_alone(material));
        direct(&mut scene);
        let want = scene.reference(&map).unwrap();
        let got = scene.shade::<f64>(&light).unwrap();
        // The own transport is stored in f32 (measured 3.3e-7 Phong, 5.1e-7 Blinn-Phong).
        let err = relative(&got, &want);
        assert!(err < 1e-6, "{material}: {err:e}");
        // The material matters: the Lambertian radiance of the same albedo is far from it.
        let mut lambert = scene.clone();
        lambert.set_brdf(0, Brdf::Lambert).unwrap();
        let apart = relative(&lambert.shade::<f64>(&light).unwrap(), &want);
        assert!(apart > 0.1, "{material}: {apart}");
    }
}

#[test]
fn the_reference_gives_each_object_its_own_material() {
    let (_, map) = sunny_sky();
    let mixed = build(&three([PHONG, BLINN, LAMBERT]));
    let got = mixed.reference(&map).unwrap();
    for (k, brdf) in ["phong:30", "blinn:20", "lambert"].iter().enumerate() {
        let mut alike = mixed.clone();
        for j in 0..3 {
            alike.set_brdf(j, brdf.parse().unwrap()).unwrap();
        }
        let want = alike.reference(&map).unwrap();
        let rows = ndarray::s![mixed.object_vertices(k), ..];
        assert_eq!(got.slice(rows), want.slice(rows), "object {k}");
    }
    // The ground plane stays Lambertian.
    let ground = ndarray::s![mixed.object_vertices(2).end.., ..];
    let mut lambert = mixed.clone();
    (0..2).for_each(|j| lambert.set_brdf(j, Brdf::Lambert).unwrap());
    assert_eq!(
        got.slice(ground),
        lambert.reference(&map).unwrap().slice(ground)
    );
}

#[test]
fn phong_zero_is_lambert_with_albedo_one() {
    let light = lighting(0.8);
    let white = r#"{"brdf": "lambert", "albedo": [1, 1, 1]}"#;
    let flat = r#"{"brdf": "phong", "exponent": 0, "albedo": [1, 1, 1]}"#;
    let want = build(&three([white; 3])).shade::<f64>(&light).unwrap();
    for rotation in [BrdfRotation::Haar, BrdfRotation::Direct] {
        let mut scene = build(&three([flat; 3]));
        scene
            .set_glossy(&GlossyOptions {
                rotation,
                ..GlossyOptions::default()
            })
            .unwrap();
        let err = relative(&scene.shade::<f64>(&light).unwrap(), &want);
        assert!(err < 1e-12, "{rotation}: {err:e}");
    }
}

#[test]
fn a_change_of_view_equals_the_full_product_integral() {
    let light = lighting(0.4);
    let mut scene = build(&three([PHONG, BLINN, LAMBERT]));
    let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::View).unwrap();
    let mut frames = Vec::new();
    for eye in [[1.5, 2.5, 4.0], [-4.0, 1.0, 2.0], [0.5, 6.0, -3.0]] {
        scene.set_eye(eye).unwrap();
        let want = scene.shade::<f64>(&light).unwrap();
        let got = jrt.frame_view(&scene).unwrap();
        let err = relative(&got, &want);
        assert!(err < 1e-9, "{eye:?}: {err:e}");
        frames.push(got);
    }
    // The view matters on the glossy objects, not on the Lambertian one and the ground.
    let (glossy, rest) = (
        ndarray::s![0..scene.object_vertices(1).end, ..],
        ndarray::s![scene.object_vertices(2).start.., ..],
    );
    let part = |a: &Array2<f64>, s| a.slice(s).to_owned();
    assert!(relative(&part(&frames[1], glossy), &part(&frames[0], glossy)) > 0.05);
    assert!(relative(&part(&frames[1], rest), &part(&frames[0], rest)) < 1e-12);
    // Another kind of frame is refused, and so is a frame after a move.
    assert_err!(
        jrt.frame_lit(&scene, &light),
        InvalidParameter { name: "change", .. },
        "use frame_view"
    );
    let mut p = scene.placement(1);
    p.translate[0] += 0.1;
    scene.place(1, p).unwrap();
    let message = jrt.frame_view(&scene).unwrap_err().to_string();
    assert!(message.contains("re-form"), "{message}");
}

#[test]
fn moving_objects_and_lighting_hold_the_brdf_in_the_fixed_product() {
    let mut scene = build(&three([PHONG, BLINN, LAMBERT]));
    let light = lighting(0.4);
    each_moved_object_is_the_full_product_integral(&mut scene, &light);
    let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Lighting).unwrap();
    let turned = lighting(2.5);
    let want = scene.shade::<f64>(&turned).unwrap();
    let err = relative(&jrt.frame_lit(&scene, &turned).unwrap(), &want);
    assert!(err < 1e-9, "lighting: {err:e}");
}

#[test]
fn one_glossy_object_alone_is_shaded_as_the_static_glossy_path_shades_it() {
    let scene = build(&box_alone(PHONG));
    // The static scene of the same file, Lambertian (a static scene takes --brdf).
    let fixed = scene_file(&box_alone(LAMBERT))
        .build(Path::new("."))
        .unwrap();
    let visibility = VisibilityOptions::new(param());
    let (set, _) = vertex_major(&fixed.mesh, &SceneBvh::new(&fixed.mesh), &visibility).unwrap();
    let albedo = Array2::from_shape_fn((fixed.mesh.vertex_count(), 3), |(_, c)| {
        [0.9f32, 0.8, 0.7][c]
    });
    let glossy = GlossyOptions {
        brdf: Brdf::Phong { exponent: 30.0 },
        ..GlossyOptions::default()
    };
    let shader = GlossyShader::<f64>::new(
        &set,
        &fixed.mesh,
        albedo.view(),
        &ShadeOptions::default(),
        &glossy,
        fixed.mesh.vertex_count(),
    )
    .unwrap();
    let light = lighting(0.3);
    let (want, _) = shader.shade(&light, scene.eye().unwrap()).unwrap();
    // The same lobes and the same integral, summed in another order (measured 6.8e-15).
    let err = relative(&scene.shade::<f64>(&light).unwrap(), &want);
    assert!(err < 1e-12, "{err:e}");
}

#[test]
fn bad_materials_are_refused_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            r#"{"brdf": "chrome", "albedo": [1, 1, 1]}"#,
            "unknown variant",
        ),
        (
            r#"{"brdf": "phong", "exponent": -1, "albedo": [1, 1, 1]}"#,
            "from 0",
        ),
        (
            r#"{"brdf": "phong", "exponent": 1e9, "albedo": [1, 1, 1]}"#,
            "from 0",
        ),
        (
            r#"{"brdf": "blinn", "exponent": 5, "albedo": [1, 1, 1], "ior": 1.5}"#,
            "unknown field",
        ),
        (r#"{"brdf": "phong", "albedo": [1, 1, 1]}"#, "exponent"),
    ];
    for (k, (material, reason)) in cases.iter().enumerate() {
        let path = dir.path().join(format!("s{k}.json"));
        std::fs::write(&path, box_alone(material)).unwrap();
        let message = match DynamicScene::load(&path, &options()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("case {k} was accepted"),
        };
        assert!(message.contains(reason), "case {k}: {message}");
        assert!(!message.contains('\n'), "case {k}: {message}");
    }
    let mut scene = build(&box_alone(PHONG));
    for bad in [f64::NAN, -1.0, f64::INFINITY] {
        let e = scene.set_brdf(0, Brdf::Phong { exponent: bad });
        assert!(e.unwrap_err().to_string().contains("exponent"), "{bad}");
    }
    assert_eq!(scene.brdf(0).unwrap(), &Brdf::Phong { exponent: 30.0 });
    // A glossy scene without a camera cannot be shaded: its radiance depends on the view.
    let blind = build(&box_alone(PHONG).replace(CAMERA, r#""ground_plane": false"#));
    let message = blind.shade::<f64>(&lighting(0.3)).unwrap_err().to_string();
    assert!(message.contains("camera"), "{message}");
}
