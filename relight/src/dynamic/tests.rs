use ndarray::{Array3, Axis};

use std::path::Path;

use super::shading::tree;
use super::*;
use crate::Occlusion;
use crate::dynamic::fields::FieldOptions;
use crate::precompute::visibility::{VisibilityOptions, ray_offset, vertex_major};
use crate::shade::{PreparedTransport, ShadeOptions};
use crate::{SceneBvh, SceneFile};
use haarshift::faces::param::SphereMap;
use haarshift::metrics;

pub(super) fn param() -> Parameterization {
    Parameterization::new(ParamKind::LatLong, 8).unwrap()
}

pub(super) fn options() -> DynamicOptions {
    let mut o = DynamicOptions::new(param());
    o.field = FieldOptions {
        circles: 6,
        circle_points: 16,
        shells: 5,
        shell_grid: 3,
        ..o.field
    };
    o
}

pub(super) fn scene_file(json: &str) -> SceneFile {
    serde_json::from_str(json).unwrap()
}

pub(super) fn build(json: &str) -> DynamicScene {
    DynamicScene::build(&scene_file(json), Path::new("."), &options()).unwrap()
}

/// A sky with a bright patch, so that shadows matter.
pub(super) fn lighting(turn: f64) -> Lighting {
    let sky = SphereMap::<f64>::from_fn(param(), 3, |d, out| {
        let sun = (d[0] * turn.cos() + d[2] * turn.sin() + 0.5 * d[1])
            .max(0.0)
            .powi(8);
        out[0] = 0.3 + 4.0 * sun;
        out[1] = 0.4 + 3.0 * sun + 0.1 * d[1];
        out[2] = 0.5 + 2.0 * sun;
    })
    .unwrap();
    Lighting::from_map(&sky, Selection::All).unwrap()
}

/// Largest difference relative to the RMS of `want`.
pub(super) fn relative(got: &Array2<f64>, want: &Array2<f64>) -> f64 {
    assert_eq!(got.dim(), want.dim());
    let worst = got
        .iter()
        .zip(want)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    worst / metrics::rms(want.view())
}

pub(super) const THREE: &str = r#"{"objects": [
    {"name": "a", "generator": {"sphere": {"cells": 2}}},
    {"name": "b", "generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.4, 0, 0.5]}},
    {"name": "c", "generator": {"sphere": {"cells": 2}},
     "transform": {"translate": [0.8, 0.4, 2.3], "scale": 0.7}}
  ], "ground_plane": true}"#;

#[test]
fn one_object_alone_is_shaded_as_the_static_path_shades_it() {
    let json = r#"{"objects": [{"generator": {"plane_under_box": {"height": 0.4}},
        "transform": {"translate": [0.3, 0, -0.2], "scale": 1.5}}]}"#;
    let scene = build(json);
    let file = scene_file(json);
    let fixed = file.build(Path::new(".")).unwrap();
    let visibility = VisibilityOptions::new(param());
    let (set, _) = vertex_major(&fixed.mesh, &SceneBvh::new(&fixed.mesh), &visibility).unwrap();
    let prepared =
        PreparedTransport::<f64>::new(&set, fixed.albedo.view(), &ShadeOptions::default()).unwrap();
    let light = lighting(0.3);
    let want = prepared.shade(&light).unwrap();
    // The box shadows the plane: the comparison is not of unshadowed vertices only.
    assert!(
        want.column(0).iter().fold(f64::INFINITY, |a, &b| a.min(b))
            < 0.5 * metrics::rms(want.view())
    );
    assert!(relative(&scene.shade::<f64>(&light).unwrap(), &want) < 1e-12);
    let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Lighting).unwrap();
    let turned = lighting(1.9);
    let want = prepared.shade(&turned).unwrap();
    assert!(relative(&jrt.frame_lit(&scene, &turned).unwrap(), &want) < 1e-12);
}

#[test]
fn at_a_sample_point_two_objects_unpruned_maps_multiply_to_the_visibility_against_both() {
    // b sits at twice the radius of circle 3 along +X, so the point of circle 3 at angle 0
    // of a is also b's sample of circle 3 at angle pi.
    let probe = build(r#"{"objects": [{"generator": {"sphere": {"cells": 3}}}]}"#);
    let f = probe.field(0);
    let x = f.sample_points()[3 * 16];
    let rho = x[0] - f.frame().centre[0];
    let json = format!(
        r#"{{"objects": [{{"generator": {{"sphere": {{"cells": 3}}}}}},
            {{"generator": {{"sphere": {{"cells": 3}}}}, "transform": {{"translate": [{}, 0, 0]}}}}]}}"#,
        2.0 * rho
    );
    let scene = build(&json);
    let depth = 3;
    let mut scratch = Scratch::new(param());
    let maps: Vec<_> = (0..2)
        .map(|k| {
            let (i, v) = scene.occlusion(k, x, depth, &mut scratch).unwrap();
            (i.to_vec(), v.to_vec())
        })
        .collect();
    let trees: Vec<HaarTree<f64, 3>> = maps
        .iter()
        .map(|(i, v)| tree(param(), i, v.iter().copied()).unwrap())
        .collect();
    let both = product(&[&trees[0], &trees[1]])
        .unwrap()
        .to_pixels()
        .unwrap();
    let mesh = scene.mesh();
    let bvh = SceneBvh::new(&mesh);
    let lift = ray_offset(probe.shapes.first().unwrap());
    let from = [x[0] as f32, (x[1] + lift) as f32, x[2] as f32];
    let want = Array3::from_shape_fn((2, 8, 8), |(face, i, j)| {
        let d = param().texel_direction(face, i, j).map(|v| v as f32);
        if bvh.occluded(from, d, f32::INFINITY) {
            0.0
        } else {
            1.0
        }
    });
    let got = both.index_axis(Axis(3), 0);
    let blocked = want.iter().filter(|&&v| v == 0.0).count();
    let differ = got
        .iter()
        .zip(&want)
        .filter(|(a, b)| (*a - *b).abs() > 1e-9)
        .count();
    assert!(
        blocked >= 20,
        "{blocked} texels blocked: the point sees both objects"
    );
    assert_eq!(differ, 0, "{differ} texels differ");
}

#[test]
fn moving_an_object_beyond_its_field_renders_as_removing_it() {
    let two = r#"{"objects": [
        {"generator": {"plane_under_box": {"height": 0.4}}},
        {"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [0.5, 2.2, 0.3]}}]}"#;
    let mut scene = build(two);
    let alone = build(r#"{"objects": [{"generator": {"plane_under_box": {"height": 0.4}}}]}"#);
    let light = lighting(0.7);
    let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Object(1)).unwrap();
    let with = scene.shade::<f64>(&light).unwrap();
    let far = Placement {
        translate: [1000.0, 0.0, 0.0],
        ..scene.placement(1)
    };
    scene.place(1, far).unwrap();
    let want = alone.shade::<f64>(&light).unwrap();
    let range = scene.object_vertices(0);
    let first = |a: &Array2<f64>| a.slice(ndarray::s![range.clone(), ..]).to_owned();
    // The sphere shadowed the plane before it left.
    assert!(relative(&first(&with), &want) > 0.01);
    assert!(relative(&first(&scene.shade::<f64>(&light).unwrap()), &want) < 1e-12);
    assert!(relative(&first(&jrt.frame_moved(&scene).unwrap()), &want) < 1e-12);
}

/// Moves each object of `scene` in turn (translated and scaled) after forming JRT for it:
/// every frame must equal the full product integrals to 1e-9 relative.
pub(super) fn each_moved_object_is_the_full_product_integral(
    scene: &mut DynamicScene,
    light: &Lighting,
) {
    for moving in 0..scene.object_count() {
        let jrt = JustInTimeTransfer::<f64>::form(scene, light, Change::Object(moving)).unwrap();
        let mut p = scene.placement(moving);
        p.translate[0] += 0.35;
        p.translate[2] -= 0.2;
        p.scale *= 1.1;
        scene.place(moving, p).unwrap();
        let want = scene.shade::<f64>(light).unwrap();
        let err = relative(&jrt.frame_moved(scene).unwrap(), &want);
        assert!(err < 1e-9, "object {moving}: {err:e}");
    }
}

#[test]
fn just_in_time_transfer_equals_the_full_product_integral_with_unpruned_factors() {
    let mut scene = build(THREE);
    let light = lighting(0.4);
    each_moved_object_is_the_full_product_integral(&mut scene, &light);
    let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Lighting).unwrap();
    let turned = lighting(2.5);
    let want = scene.shade::<f64>(&turned).unwrap();
    assert!(relative(&jrt.frame_lit(&scene, &turned).unwrap(), &want) < 1e-9);
    // The wrong frame for the change is refused, and so is a turn since formation.
    assert_err!(
        jrt.frame_moved(&scene),
        InvalidParameter { name: "change", .. },
        "use frame_lit"
    );
    let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Object(1)).unwrap();
    let turned = Placement {
        turn: 3,
        ..scene.placement(1)
    };
    scene.place(1, turned).unwrap();
    let message = jrt.frame_moved(&scene).unwrap_err().to_string();
    assert!(message.contains("re-form"), "{message}");
}

#[test]
fn pruning_the_fixed_product_trades_coefficients_for_error() {
    let scene = build(THREE);
    let light = lighting(0.4);
    let full = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Object(1)).unwrap();
    let want = full.frame_moved(&scene).unwrap();
    let mut errors = Vec::new();
    for k in [8, 32] {
        let mut pruned = scene.clone();
        pruned.options.keep_product = Selection::Largest(k);
        let jrt = JustInTimeTransfer::<f64>::form(&pruned, &light, Change::Object(1)).unwrap();
        assert!(jrt.report().coefficients < full.report().coefficients);
        errors.push(relative(&jrt.frame_moved(&pruned).unwrap(), &want));
    }
    assert!(errors[0] > errors[1] && errors[1] > 0.0, "{errors:?}");
}

#[test]
fn turning_an_object_at_run_time_matches_turning_it_in_the_file() {
    let file_turn = build(
        r#"{"objects": [{"generator": {"plane_under_box": {"height": 0.4}}, "transform": {"yaw": 45}},
            {"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.5, 0.2, 0]}}]}"#,
    );
    let mut run_turn = build(
        r#"{"objects": [{"generator": {"plane_under_box": {"height": 0.4}}},
            {"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.5, 0.2, 0]}}]}"#,
    );
    let p = Placement {
        turn: 2, // 45 degrees at 16 columns
        ..run_turn.placement(0)
    };
    assert_eq!(file_turn.placement(0).turn, 2);
    run_turn.place(0, p).unwrap();
    let light = lighting(1.1);
    let want = file_turn.shade::<f64>(&light).unwrap();
    let got = run_turn.shade::<f64>(&light).unwrap();
    assert!(relative(&got, &want) < 1e-3, "{}", relative(&got, &want));
}

#[test]
fn bad_scene_files_are_refused_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let cases = [
        (r#"{"objects": [{"mesh": "missing.ply"}]}"#, "missing.ply"),
        (
            r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "colour": 1}]}"#,
            "unknown field",
        ),
        (
            r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "transform": {"scale": -1}}]}"#,
            "scale",
        ),
        (
            r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "transform": {"pitch": 10}}]}"#,
            "vertical",
        ),
        (
            r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [NaN, 0, 0]}}]}"#,
            "expected value",
        ),
        (
            r#"{"objects": [{"name": "x", "generator": {"sphere": {"cells": 2}}}, {"name": "x", "generator": {"sphere": {"cells": 2}}}]}"#,
            "named",
        ),
        (r#"{"objects": []}"#, "at least one object"),
    ];
    for (k, (text, reason)) in cases.iter().enumerate() {
        let path = write(&format!("s{k}.json"), text);
        let message = match DynamicScene::load(&path, &options()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("case {k} was accepted"),
        };
        assert!(message.contains(reason), "case {k}: {message}");
    }
    let path = write(
        "ok.json",
        r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "transform": {"yaw": 30}}]}"#,
    );
    let mut cube = options();
    cube.field.param = Parameterization::new(ParamKind::Cube, 4).unwrap();
    let refused = DynamicScene::load(&path, &cube);
    assert!(refused.unwrap_err().to_string().contains("latlong"));
    let mut scene = build(THREE);
    assert_err!(
        scene.place(7, scene.placement(0)),
        InvalidParameter { name: "object", .. },
        "the scene has 3 objects"
    );
    let bad = Placement {
        scale: f64::NAN,
        ..scene.placement(0)
    };
    assert_err!(
        scene.place(0, bad),
        InvalidParameter {
            name: "placement",
            ..
        },
        "scale must be positive"
    );
    let far = Placement {
        translate: [-1e30, 0.0, 0.0],
        ..scene.placement(0)
    };
    assert_err!(scene.place(0, far), Scene { .. }, "placed object", "1e15");
}

#[test]
fn a_clone_shares_its_shape_and_shadows_like_the_original() {
    let mut scene = build(THREE);
    let light = lighting(0.4);
    let before = scene.vertex_count();
    let p = Placement {
        translate: [-2.0, 0.0, -1.0],
        ..scene.placement(0)
    };
    let k = scene.clone_object(0, p).unwrap();
    assert_eq!((k, scene.shape_count()), (3, 1));
    assert_eq!(scene.vertex_count(), before + 54);
    let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Object(k)).unwrap();
    assert!(
        relative(
            &jrt.frame_moved(&scene).unwrap(),
            &scene.shade::<f64>(&light).unwrap()
        ) < 1e-9
    );
    // A transfer formed before the clone is refused after it.
    let mut grown = scene.clone();
    grown.clone_object(1, scene.placement(1)).unwrap();
    assert_err!(
        jrt.frame_moved(&grown),
        InvalidParameter { name: "scene", .. },
        "re-form it after cloning"
    );
}

/// A sphere with three others around it: two within whose fields it lies, and one whose
/// outermost shell (6 R = 5.4) passes through it once it has moved to `[0.3, 0.1, 0.2]`, so
/// that its vertices see two maps or three.
const FOUR: &str = r#"{"objects": [
    {"name": "middle", "generator": {"sphere": {"cells": 2}}},
    {"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.2, 0, 0.3]}},
    {"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [-0.4, 0.2, 2.1], "scale": 0.8}},
    {"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [-4.02, 0.1, -3.04], "scale": 0.9}}
  ], "ground_plane": true}"#;

#[test]
fn both_ways_of_a_vertex_product_give_the_quadtree_product() {
    use super::products::{Method, SharedFactor, VertexProduct};
    let mut scene = build(FOUR);
    let light = lighting(0.4);
    let jrt = JustInTimeTransfer::<f64>::form(&scene, &light, Change::Object(0)).unwrap();
    let mut p = scene.placement(0);
    p.translate = [0.3, 0.1, 0.2];
    scene.place(0, p).unwrap();
    let (param, depth) = (param(), 3);
    let (li, lv) = light_sparse::<f64>(&light, depth);
    let light_tree = light_tree::<f64>(&light, depth).unwrap();
    let mut scratch = Scratch::new(param);
    let mut dense = vec![[0.0f64; 3]; param.texels()];
    let methods = [Method::Texels, Method::Trees];
    let mut products = methods.map(|m| VertexProduct::<f64>::new(param, m).unwrap());
    let shared = methods.map(|m| SharedFactor::new(param, m, &li, &lv).unwrap());
    let mut seen = [0usize; 4];
    let mut effect = 0.0f64;
    let close = |got: [f64; 3], want: [f64; 3]| {
        (0..3).all(|c| (got[c] - want[c]).abs() <= 1e-12 * want[c].abs().max(1e-3))
    };
    for r in scene.receivers().iter().filter(|r| r.owner == Some(0)) {
        // A moving vertex's fixed product: its own transport times the lighting, both ways.
        let (i, v) = scene.own_transport(r, depth).unwrap();
        let own = tree::<f64>(param, &i, v.iter().map(|&x| f64::from(x))).unwrap();
        let (ti, tv) = product(&[&own, &light_tree]).unwrap().sparse_coefficients();
        let want_t =
            HaarTree::from_sparse(param.faces(), param.face_size(), layout(param), &ti, &tv)
                .unwrap()
                .to_coefficients();
        for (vp, sh) in products.iter_mut().zip(&shared) {
            vp.reset();
            vp.multiply(&i, &v).unwrap();
            let (gi, gv) = vp.coefficients(Some(sh)).unwrap();
            let got =
                HaarTree::from_sparse(param.faces(), param.face_size(), layout(param), &gi, &gv)
                    .unwrap()
                    .to_coefficients();
            let err = (&got - &want_t).iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(err < 1e-12, "{err:e}");
        }
        let maps: Vec<(Vec<u32>, Vec<f64>)> = (1..4)
            .filter_map(|k| {
                let (i, v) = scene.occlusion(k, r.point, depth, &mut scratch)?;
                Some((i.to_vec(), v.to_vec()))
            })
            .collect();
        seen[maps.len()] += 1;
        if maps.len() < 2 {
            continue;
        }
        // The oracle: the maps' product tree, then one dot with `T`.
        let trees: Vec<HaarTree<f64, 3>> = maps
            .iter()
            .map(|(i, v)| tree(param, i, v.iter().copied()).unwrap())
            .collect();
        let refs: Vec<&HaarTree<f64, 3>> = trees.iter().collect();
        let (pi, pv) = product(&refs).unwrap().sparse_coefficients();
        let pv: Vec<f64> = pv.iter().map(|c| c[0]).collect();
        let want = super::jrt::dot_dense(&mut dense, &ti, &tv, &pi, &pv);
        for vp in &mut products {
            let mut dot = |maps: &[(Vec<u32>, Vec<f64>)]| {
                vp.reset();
                for (i, v) in maps {
                    vp.multiply(i, v).unwrap();
                }
                vp.dot(&ti, &tv).unwrap()
            };
            let got = dot(&maps);
            assert!(close(got, want), "{got:?} {want:?}");
            // Without the last map the value moves (below): every map takes part.
            let fewer = dot(&maps[..maps.len() - 1]);
            effect = effect.max(
                (0..3)
                    .map(|c| (fewer[c] - want[c]).abs() / want[c].abs().max(1e-3))
                    .fold(0.0, f64::max),
            );
        }
    }
    assert!(effect > 0.05, "dropping a map changes at most {effect}");
    // Both traversals of the quadtree way are exercised: two maps (the triple product) and
    // three.
    assert!(seen[2] >= 10 && seen[3] >= 10, "{seen:?}");
    let want = scene.shade::<f64>(&light).unwrap();
    assert!(relative(&jrt.frame_moved(&scene).unwrap(), &want) < 1e-9);
}

#[test]
fn a_mesh_file_s_colours_are_each_vertex_s_albedo_times_the_material_s() {
    // A tetrahedron with a float colour per vertex (linear), over a plane: shaded as the
    // static path shades the same scene file, whose per-vertex albedo is tested on its own.
    let dir = tempfile::tempdir().unwrap();
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
               property float z\nproperty float red\nproperty float green\nproperty float blue\n\
               element face 4\nproperty list uchar int vertex_indices\nend_header\n\
               0 0.2 0 1 0 0\n1 0.2 0 0 1 0\n0 0.2 1 0 0 1\n0.3 1 0.3 0.5 0.5 0.5\n\
               3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
    std::fs::write(dir.path().join("t.ply"), ply).unwrap();
    let json = r#"{"objects": [{"mesh": "t.ply", "material": {"brdf": "lambert", "albedo": [0.5, 1, 0.8]}}]}"#;
    let file = scene_file(json);
    let scene = DynamicScene::build(&file, dir.path(), &options()).unwrap();
    let albedo = scene.albedo();
    assert_eq!(albedo.row(0).to_vec(), vec![0.5, 0.0, 0.0]);
    assert_eq!(albedo.row(1).to_vec(), vec![0.0, 1.0, 0.0]);
    assert_eq!(albedo.row(3).to_vec(), vec![0.25, 0.5, 0.4]);
    let fixed = file.build(dir.path()).unwrap();
    assert_eq!(albedo, fixed.albedo);
    let visibility = VisibilityOptions::new(param());
    let (set, _) = vertex_major(&fixed.mesh, &SceneBvh::new(&fixed.mesh), &visibility).unwrap();
    let prepared =
        PreparedTransport::<f64>::new(&set, fixed.albedo.view(), &ShadeOptions::default()).unwrap();
    let light = lighting(0.3);
    assert!(
        relative(
            &scene.shade::<f64>(&light).unwrap(),
            &prepared.shade(&light).unwrap()
        ) < 1e-12
    );
}
