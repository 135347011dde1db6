use ndarray::{Array2, s};

use super::picture::false_colour;
use super::*;
use crate::journal::Journal;
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::metrics::RelativeError;
use haarshift::product::Selection;
use haarshift::sphere::LatLongMap;
use haarshift::sphere::SphereRotation;
use haarshift::sphere::harmonics::SphericalHarmonics;
use haarshift_relight::render::Camera;
use haarshift_relight::render::DEFAULT_FOV;
use haarshift_relight::shade::glossy::GlossyOptions;
use haarshift_relight::shade::glossy::GlossyShader;
use haarshift_relight::{Generator, Lighting, PreparedTransport, ShTransfer, reference, shade_sh};
use haarshift_relight::{
    ReferenceOptions, SceneBvh, ShadeOptions, VisibilityOptions, vertex_major,
};

/// A box floating over a plane (shadows), under a sky with a sun, a tiny protocol.
fn setup() -> (Subject, Light, RelightProtocol) {
    let subject = Subject {
        name: "box".into(),
        scene: Scene::from_mesh(
            Generator::PlaneUnderBox { height: 0.5 }.mesh().unwrap(),
            false,
        )
        .unwrap(),
    };
    let sky = LatLongMap::<f64>::from_fn(32, 3, |d, o| {
        let sun = (30.0 * (d[0] * 0.5 + d[1] * 0.8 + d[2] * 0.33 - 1.0)).exp();
        o.copy_from_slice(&[0.3 + 40.0 * sun, 0.4 + 0.3 * d[1].abs(), 0.5 + 20.0 * sun]);
    })
    .unwrap();
    let light = Light {
        name: "sun".into(),
        environment: Environment::new(sky),
    };
    let orient = |rotation| Orienting {
        rotation,
        level: None,
    };
    let protocol = RelightProtocol {
        name: "test".into(),
        truth_resolution: 16,
        scenes: 1,
        lights: 1,
        light_rotations: vec![[0.0; 3]],
        cameras: 1,
        rotation_resolution: 8,
        rotation_materials: vec![Brdf::Phong { exponent: 8.0 }],
        orientings: vec![
            orient(BrdfRotation::Haar),
            orient(BrdfRotation::Spatial),
            orient(BrdfRotation::Direct),
            orient(BrdfRotation::Reference),
        ],
        reference_settings: 0,
        coefficient_material: Brdf::Phong { exponent: 8.0 },
        coefficient_counts: vec![4],
        latlong_resolutions: vec![8, 16],
        cube_resolutions: vec![4],
        ratios: vec![1.0, 0.1],
        resolution_materials: vec![Brdf::Lambert],
        depth_resolution: 8,
        depth_materials: vec![Brdf::Lambert],
        harmonics_resolution: 8,
        sh_bands: vec![2, 3],
        haar_budgets: vec![16],
        harmonics_materials: vec![Brdf::Lambert, Brdf::Phong { exponent: 8.0 }],
        image: (32, 24),
    };
    (subject, light, protocol)
}

fn find(records: &[RelightRecord], f: impl Fn(&RelightRecord) -> bool) -> &RelightRecord {
    let hits: Vec<&RelightRecord> = records.iter().filter(|r| f(r)).collect();
    assert_eq!(hits.len(), 1, "expected one matching record");
    hits[0]
}

/// The truth computed here without the cached bits: `reference` casting its own rays.
fn truth(subject: &Subject, light: &Light, brdf: &Brdf, eye: [f64; 3]) -> Array2<f64> {
    let scene = &subject.scene;
    let lighting = light
        .environment
        .lat_long(16, &SphereRotation::identity())
        .unwrap();
    let options = ReferenceOptions {
        progress: false,
        brdf: brdf.clone(),
        eye: Some(eye),
        object_vertices: Some(scene.object_vertices()),
    };
    reference(
        &scene.mesh,
        &SceneBvh::new(&scene.mesh),
        scene.albedo.view(),
        &lighting,
        &options,
    )
    .unwrap()
    .0
}

#[test]
fn the_records_agree_with_their_methods_computed_independently() {
    let (subject, light, protocol) = setup();
    let results = run(
        std::slice::from_ref(&subject),
        std::slice::from_ref(&light),
        &protocol,
        &mut Journal::in_memory(),
        |_| {},
    )
    .unwrap();
    let records = &results.records;
    // rotation 3; coefficients 2 + 1; resolution: lat-long 2 x (1 + 2), cube 2; depth 3;
    // harmonics 2 materials x (2 SH + 3 Haar).
    assert_eq!(records.len(), 3 + 3 + 8 + 3 + 10);
    assert_eq!(results.grids.len(), 1);
    let scene = &subject.scene;
    let eye = Camera::framing(
        scene.mesh.bounds().min,
        scene.mesh.bounds().max,
        DEFAULT_FOV,
    )
    .unwrap()
    .position();
    let lambert = truth(&subject, &light, &Brdf::Lambert, eye);

    // The reference method at the truth's resolution is the truth: 0 exactly.
    let floor = find(records, |r| r.method == "reference" && r.resolution == 16);
    assert_eq!((floor.rms, floor.max, floor.image_rms), (0.0, 0.0, 0.0));
    // At a coarser resolution it is not.
    let coarse = find(records, |r| r.method == "reference" && r.resolution == 8);
    assert!(coarse.rms_relative > 1e-3, "{}", coarse.rms_relative);

    // Ratio 1 keeps everything: the unpruned figure, which the depth axis's full depth and
    // a shading computed here give too.
    let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    let bvh = SceneBvh::new(&scene.mesh);
    let (set, _) = vertex_major(&scene.mesh, &bvh, &VisibilityOptions::new(param)).unwrap();
    let identity = SphereRotation::identity();
    let shade = |keep: Option<usize>| {
        let options = ShadeOptions {
            keep_visibility: keep.map(Selection::Largest),
            depth: None,
        };
        let prepared = PreparedTransport::<f32>::new(&set, scene.albedo.view(), &options).unwrap();
        let select = keep.map_or(Selection::All, Selection::Largest);
        let lighting = Lighting::new(&light.environment, param, &identity, select).unwrap();
        let got = prepared.shade(&lighting).unwrap().mapv(f64::from);
        RelativeError::between(got.view(), lambert.view()).unwrap()
    };
    let all = shade(None);
    let unpruned = find(records, |r| {
        r.axis == "resolution"
            && r.param == "latlong"
            && r.resolution == 8
            && r.kept_ratio == Some(1.0)
    });
    assert_eq!(unpruned.rms, all.rms);
    assert_eq!(unpruned.max_relative, all.max_relative);
    let deepest = find(records, |r| r.axis == "depth" && r.depth == 3);
    assert_eq!(deepest.rms, all.rms);
    assert!(
        all.rms_relative > 0.0 && all.rms_relative < 0.5,
        "{}",
        all.rms_relative
    );

    // Ratio 0.1: 13 of the 126 details of the lighting and of each transport.
    let pruned = shade(Some(13));
    let r = find(records, |r| {
        r.axis == "resolution"
            && r.param == "latlong"
            && r.resolution == 8
            && r.kept_ratio == Some(0.1)
    });
    assert_eq!(r.light_coefficients, 13 + 2);
    assert!(
        (r.rms - pruned.rms).abs() <= 1e-12 * pruned.rms,
        "{} {}",
        r.rms,
        pruned.rms
    );
    assert!(r.rms > all.rms);

    // A glossy record: Phong 8 evaluated directly in each frame, triple product with every
    // coefficient, against the glossy truth.
    let phong = Brdf::Phong { exponent: 8.0 };
    let glossy_truth = truth(&subject, &light, &phong, eye);
    let options = GlossyOptions {
        brdf: phong.clone(),
        rotation: BrdfRotation::Direct,
        ..GlossyOptions::default()
    };
    let shader = GlossyShader::<f32>::new(
        &set,
        &scene.mesh,
        scene.albedo.view(),
        &ShadeOptions::default(),
        &options,
        scene.object_vertices(),
    )
    .unwrap();
    let lighting = Lighting::new(&light.environment, param, &identity, Selection::All).unwrap();
    let (got, _) = shader.shade(&lighting, eye).unwrap();
    let want = RelativeError::between(got.mapv(f64::from).view(), glossy_truth.view()).unwrap();
    let direct = find(records, |r| r.axis == "rotation" && r.method == "direct");
    assert!((direct.rms - want.rms).abs() <= 1e-12 * want.rms);
    // The thesis's metric: the spatial render against itself is 0; others differ from it.
    let spatial = find(records, |r| r.axis == "rotation" && r.method == "spatial");
    assert_eq!(spatial.spatial_difference, Some(0.0));
    assert!(direct.spatial_difference.unwrap() > 0.0);

    // Spherical harmonics of 2 bands, projected here.
    let sh = find(records, |r| {
        r.axis == "harmonics"
            && r.method == "sh"
            && r.sh_bands == Some(2)
            && r.material == "lambert"
    });
    let (set, _) = vertex_major(
        &scene.mesh,
        &bvh,
        &VisibilityOptions {
            sh_bands: Some(3),
            ..VisibilityOptions::new(param)
        },
    )
    .unwrap();
    let stored = set.sh().unwrap();
    let transfer = ShTransfer::new(2, stored.coefficients().slice(s![.., ..4]).to_owned()).unwrap();
    let projected = SphericalHarmonics::new(2)
        .unwrap()
        .project(&light.environment.sphere_map(param, &identity).unwrap());
    let got = shade_sh(&transfer, scene.albedo.view(), projected.view())
        .unwrap()
        .mapv(f64::from);
    let want = RelativeError::between(got.view(), lambert.view()).unwrap();
    assert!((sh.rms - want.rms).abs() <= 1e-12 * want.rms);
    assert_eq!(sh.light_coefficients, 4);
}

#[test]
fn a_bad_protocol_or_no_input_is_refused() {
    let (subject, light, mut protocol) = setup();
    assert_err!(
        run(
            &[],
            std::slice::from_ref(&light),
            &protocol,
            &mut Journal::in_memory(),
            |_| {}
        ),
        InvalidParameter {
            name: "relight experiment",
            ..
        },
        "at least one scene"
    );
    protocol.coefficient_counts = vec![8];
    assert_err!(
        run(
            std::slice::from_ref(&subject),
            std::slice::from_ref(&light),
            &protocol,
            &mut Journal::in_memory(),
            |_| {}
        ),
        InvalidParameter {
            name: "coefficient counts",
            ..
        },
        "power of 4"
    );
}

/// The records with the columns that depend on the machine (seconds, memory) cleared.
fn measured(records: &[RelightRecord]) -> Vec<RelightRecord> {
    records
        .iter()
        .map(|r| RelightRecord {
            precompute_seconds: 0.0,
            relight_seconds: 0.0,
            peak_mib: 0.0,
            ..r.clone()
        })
        .collect()
}

#[test]
fn a_run_stopped_after_some_units_resumes_to_the_same_records_and_grids() {
    let (subject, light, protocol) = setup();
    let go = |journal: &mut Journal| {
        run(
            std::slice::from_ref(&subject),
            std::slice::from_ref(&light),
            &protocol,
            journal,
            |_| {},
        )
        .unwrap()
    };
    let whole = go(&mut Journal::in_memory());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("relight.journal");
    let options = format!("{protocol:?}");
    go(&mut Journal::create(&path, &options, false).unwrap());
    // Killed after the truth, the rotation axis's one condition (and its grid) and the
    // coefficient axis: the header and three units stay.
    let text = std::fs::read_to_string(&path).unwrap();
    let kept: Vec<&str> = text.lines().take(4).collect();
    assert!(
        kept[2].starts_with(r#"{"unit":"0 box/rotation 0""#),
        "{}",
        kept[2]
    );
    std::fs::write(&path, kept.join("\n") + "\n").unwrap();
    let mut journal = Journal::resume(&path, &options).unwrap();
    let resumed = go(&mut journal);
    assert_eq!(journal.resumed(), 3);
    assert_eq!(measured(&resumed.records), measured(&whole.records));
    assert_eq!(resumed.grids.len(), 1);
    assert_eq!(resumed.grids[0].image, whole.grids[0].image);
    assert_eq!(resumed.grids[0].caption, whole.grids[0].caption);
    assert_eq!(resumed.truth_seconds.len(), 1);
    journal.finish().unwrap();
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn false_colour_is_white_at_zero_and_saturates() {
    let e = Array2::from_shape_vec((1, 4), vec![0.0, 1.0, -1.0, 9.0]).unwrap();
    let c = false_colour(&e, 1.0);
    let px = |j: usize| [c[[0, 0, j]], c[[1, 0, j]], c[[2, 0, j]]];
    assert_eq!(px(0), [255.0; 3]);
    assert_eq!(px(1), [255.0, 0.0, 0.0]);
    assert_eq!(px(2), [0.0, 0.0, 255.0]);
    assert_eq!(px(3), px(1));
}
