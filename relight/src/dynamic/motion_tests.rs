use std::path::Path;

use super::*;
use crate::SceneFile;
use crate::dynamic::DynamicOptions;
use crate::dynamic::fields::FieldOptions;
use haarshift::faces::param::{ParamKind, Parameterization};
use haarshift::sphere::LatLongMap;

fn two_spheres() -> DynamicScene {
    dynamic_scene_of(
        r#"{"objects": [
            {"name": "a", "generator": {"sphere": {"cells": 2}}},
            {"name": "b", "generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.5, 0, 0]}}
        ], "ground_plane": true}"#,
    )
}

/// A glossy sphere beside a Lambertian one, seen by a camera.
fn glossy_scene() -> DynamicScene {
    dynamic_scene_of(
        r#"{"objects": [
            {"name": "a", "generator": {"sphere": {"cells": 2}},
             "material": {"brdf": "phong", "exponent": 20, "albedo": [0.9, 0.8, 0.7]}},
            {"name": "b", "generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.5, 0, 0]}}
        ], "ground_plane": true, "camera": {"position": [0, 1, 5], "look_at": [1, 0, 0]}}"#,
    )
}

fn dynamic_scene_of(json: &str) -> DynamicScene {
    let file: SceneFile = serde_json::from_str(json).unwrap();
    let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    let mut o = DynamicOptions::new(param);
    o.field = FieldOptions {
        circles: 6,
        circle_points: 16,
        shells: 5,
        shell_grid: 3,
        ..o.field
    };
    DynamicScene::build(&file, Path::new("."), &o).unwrap()
}

/// A played frame (f32) against the full product integrals of its state, to 1e-4 of the RMS.
fn assert_is_the_full_product_integral(
    scene: &DynamicScene,
    env: &Environment,
    radiance: &Array2<f32>,
    turn: &SphereRotation,
    report: &FrameReport,
) -> Result<()> {
    let mapping = SphereMapping::new(16, scene.param())?;
    let lighting = Lighting::encode(env, &mapping, turn, Selection::All)?;
    let want = scene.shade::<f64>(&lighting)?;
    let rms = (want.iter().map(|x| x * x).sum::<f64>() / want.len() as f64).sqrt();
    let worst = radiance
        .iter()
        .zip(&want)
        .map(|(a, b)| (f64::from(*a) - b).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-4 * rms,
        "frame {}: {worst} of {rms}",
        report.index
    );
    Ok(())
}

fn path(json: &str) -> MotionPath {
    serde_json::from_str(json).unwrap()
}

#[test]
fn states_interpolate_each_segment_from_where_the_last_left_off() {
    let s = two_spheres();
    let p = path(
        r#"{"segments": [
            {"frames": 4, "object": "b", "to": {"translate": [0.5, 0, 2.5], "yaw": 90}},
            {"frames": 2, "light_yaw": 60},
            {"frames": 2, "object": "b", "to": {"translate": [0.5, 0, 0.5]}}]}"#,
    );
    let states = p.states(&s).unwrap();
    assert_eq!(states.len(), 9);
    assert_eq!(states[0].placement, Some(s.placement(1)));
    let mid = states[2].placement.unwrap();
    assert_eq!((mid.translate, mid.turn), ([1.5, 0.0, 1.25], 2)); // half of 4 columns
    assert_eq!(states[4].placement.unwrap().turn, 4);
    assert_eq!((states[5].light_yaw, states[6].light_yaw), (30.0, 60.0));
    assert_eq!(states[5].change, Change::Lighting);
    // The last segment starts where the first ended, turn kept, lighting kept.
    let last = states[8].placement.unwrap();
    assert_eq!(
        (last.translate, last.turn, states[8].light_yaw),
        ([0.5, 0.0, 0.5], 0, 60.0)
    );
    let seventh = states[7].placement.unwrap();
    assert_eq!((seventh.translate[2], seventh.turn), (1.5, 2));
}

#[test]
fn an_eye_segment_orbits_the_camera_about_its_look_at_point() {
    let s = glossy_scene();
    let p = path(
        r#"{"segments": [
            {"frames": 2, "eye_yaw": 90},
            {"frames": 1, "light_yaw": 10}]}"#,
    );
    let states = p.states(&s).unwrap();
    assert_eq!(states[0].change, Change::View);
    assert_eq!(states[0].eye, Some([0.0, 1.0, 5.0]));
    // About (1, y, 0): the eye (-1, 5) from the axis turns +Z toward +X, 45 degrees a frame.
    let h = 26.0f64.sqrt();
    let half = 45.0f64.to_radians() + (-1.0f64).atan2(5.0);
    let want = [[1.0 + h * half.sin(), 1.0, h * half.cos()], [6.0, 1.0, 1.0]];
    for (state, want) in states[1..3].iter().zip(want) {
        let got = state.eye.unwrap();
        assert!(
            (0..3).all(|k| (got[k] - want[k]).abs() < 1e-12),
            "{got:?} {want:?}"
        );
    }
    // The eye stays where the segment left it.
    assert_eq!(states[3].eye, states[2].eye);
    // Without a camera there is nothing to orbit.
    let message = p.states(&two_spheres()).unwrap_err().to_string();
    assert!(
        message.contains("segment 0") && message.contains("camera"),
        "{message}"
    );
}

#[test]
fn bad_segments_are_refused_with_their_number() {
    let s = two_spheres();
    for (json, reason) in [
        (r#"{"segments": []}"#, "at least one segment"),
        (
            r#"{"segments": [{"frames": 0, "light_yaw": 1}]}"#,
            "segment 0: frames",
        ),
        (
            r#"{"segments": [{"frames": 1, "light_yaw": 1}, {"frames": 1, "object": "z", "to": {}}]}"#,
            "segment 1: no object",
        ),
        (
            r#"{"segments": [{"frames": 1, "object": "a", "to": {}, "light_yaw": 1}]}"#,
            "either",
        ),
        (
            r#"{"segments": [{"frames": 1, "object": "a", "to": {"pitch": 3}}]}"#,
            "vertical",
        ),
        (
            r#"{"segments": [{"frames": 4000, "light_yaw": 1}]}"#,
            "frames in all",
        ),
        (
            r#"{"segments": [{"frames": 1, "light_yaw": 1, "eye_yaw": 2}]}"#,
            "either",
        ),
        (
            r#"{"segments": [{"frames": 1, "eye_yaw": 1e300}]}"#,
            "finite",
        ),
    ] {
        let message = path(json).states(&s).unwrap_err().to_string();
        assert!(message.contains(reason), "{json}: {message}");
    }
}

#[test]
fn every_played_frame_is_the_full_product_integral_of_its_state() {
    let mut s = two_spheres();
    let sky = LatLongMap::<f64>::from_fn(16, 3, |d, out| {
        let sun = (0.8 * d[0] + 0.6 * d[1]).max(0.0).powi(6);
        out.fill(0.2 + 3.0 * sun + 0.1 * d[2]);
    })
    .unwrap();
    let env = Environment::new(sky);
    let p = path(
        r#"{"segments": [
            {"frames": 2, "object": "b", "to": {"translate": [1.2, 0, 1.5], "yaw": 45}},
            {"frames": 2, "light_yaw": 100},
            {"frames": 1, "object": "a", "to": {"translate": [-0.5, 0, 0]}}]}"#,
    );
    let mut reformed = Vec::new();
    let mut checked = 0;
    play(
        &mut s,
        &env,
        [10.0, 0.0, 0.0],
        Selection::All,
        &p,
        |scene, radiance, turn, report| {
            assert_is_the_full_product_integral(scene, &env, radiance, turn, report)?;
            reformed.push(report.reformed.is_some());
            checked += 1;
            Ok(())
        },
    )
    .unwrap();
    assert_eq!(checked, 6);
    // Formed at frame 0, re-formed as the turning object's turn changes (two columns a
    // frame), when the lighting starts turning and when the other object starts moving.
    assert_eq!(reformed, vec![true, true, true, true, false, true]);
}

#[test]
fn a_played_eye_segment_reshades_glossy_vertices_as_the_full_product_integral() {
    let mut s = glossy_scene();
    let env = Environment::new(
        LatLongMap::<f64>::from_fn(16, 3, |d, out| {
            out.fill(0.2 + 3.0 * (0.8 * d[0] + 0.6 * d[1]).max(0.0).powi(6))
        })
        .unwrap(),
    );
    let p = path(
        r#"{"segments": [
            {"frames": 1, "object": "b", "to": {"translate": [1.5, 0, 1.0]}},
            {"frames": 2, "eye_yaw": 120}]}"#,
    );
    let glossy = s.object_vertices(0);
    let mut first: Option<Array2<f32>> = None;
    let mut moved = 0.0f64;
    let mut changes = Vec::new();
    play(
        &mut s,
        &env,
        [0.0; 3],
        Selection::All,
        &p,
        |scene, radiance, turn, report| {
            assert_is_the_full_product_integral(scene, &env, radiance, turn, report)?;
            assert_eq!(scene.eye(), report.state.eye);
            changes.push((report.state.change, report.reformed.is_some()));
            let rows = radiance.slice(ndarray::s![glossy.clone(), ..]).to_owned();
            match &first {
                None => first = Some(rows),
                Some(f) => {
                    moved = moved.max(
                        (&rows - f)
                            .mapv(f32::abs)
                            .fold(0.0f32, |m, &x| m.max(x))
                            .into(),
                    )
                }
            }
            Ok(())
        },
    )
    .unwrap();
    // Re-formed for the change of view, then one dot a vertex per frame; the glossy sphere's
    // radiance moved with the eye.
    assert_eq!(
        changes,
        [
            (Change::Object(1), true),
            (Change::Object(1), false),
            (Change::View, true),
            (Change::View, false)
        ]
    );
    assert!(moved > 1e-3, "{moved}");
}
