use super::*;
use haarshift::sphere::LatLongMap;

/// A box over a plane and a small ball that moves, under a sky brighter overhead.
fn scenario() -> (Scenario, Environment) {
    let file: SceneFile = serde_json::from_str(
        r#"{"objects": [
                {"name": "a", "generator": {"plane_under_box": {"height": 0.5}}},
                {"name": "b", "generator": {"sphere": {"cells": 2}},
                 "transform": {"translate": [0.4, 2.0, 0.2], "scale": 0.5}}]}"#,
    )
    .unwrap();
    let scenario = Scenario {
        name: "t".into(),
        file,
        dir: PathBuf::from("."),
        moving: "b".into(),
        to: Transform {
            translate: [-0.6, 2.2, 0.3],
            scale: 0.5,
            ..Transform::default()
        },
    };
    let env = Environment::new(
        LatLongMap::<f64>::from_fn(16, 3, |d, o| o.fill(0.2 + 2.0 * d[1].max(0.0).powi(4)))
            .unwrap(),
    );
    (scenario, env)
}

#[test]
fn a_record_is_the_error_of_the_moved_frame_against_the_ray_cast_truth() {
    let (scenario, env) = scenario();
    let protocol = DynamicProtocol {
        resolutions: vec![8],
        densities: vec![1.0],
        base_resolution: 8,
        budgets: vec![Budget::ALL],
        base_budget: Budget::ALL,
        reference_resolution: 8,
    };
    let mut journal = Journal::in_memory();
    let records = run(&scenario, &env, [0.0; 3], &protocol, &mut journal, |_| {}).unwrap();
    // resolution, budget (all: before only), depths 1 to 3, the lighting change, static.
    assert_eq!(records.len(), 1 + 1 + 3 + 1 + 1);
    // Independently: the scene moved, shaded by the n-function product integral, against
    // the reference at the working resolution.
    let built = Built::new(&scenario, 8, 1.0).unwrap();
    let mut moved = built.scene.clone();
    moved.place(built.moving, built.target).unwrap();
    let rotation = SphereRotation::identity();
    let lighting = Lighting::new(&env, moved.param(), &rotation, Selection::All).unwrap();
    let got = moved.shade::<f64>(&lighting).unwrap().mapv(|x| x as f32);
    let truth = moved
        .reference(&env.lat_long(8, &rotation).unwrap())
        .unwrap();
    // By hand: the RMS and largest difference, the truth's RMS.
    let d: Vec<f64> = got
        .iter()
        .zip(&truth)
        .map(|(a, b)| f64::from(*a) - b)
        .collect();
    let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
    let max = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let scale = (truth.iter().map(|x| x * x).sum::<f64>() / truth.len() as f64).sqrt();
    let r = &records[0];
    assert!(
        (r.rms - rms).abs() <= 1e-6 * rms.max(1e-12),
        "{} {rms}",
        r.rms
    );
    assert!((r.max_relative - max / scale).abs() < 1e-6);
    // The fields interpolate: an error, but a small one.
    assert!(
        r.rms_relative > 0.0 && r.rms_relative < 0.2,
        "{}",
        r.rms_relative
    );
    // Depth 0 would be face means; depth 3 is every level: the unlimited figure.
    let full_depth = records
        .iter()
        .find(|r| r.axis == "depth" && r.depth == 3)
        .unwrap();
    assert!((full_depth.rms - records[1].rms).abs() <= 1e-6 * rms);
    let coarse = records
        .iter()
        .find(|r| r.axis == "depth" && r.depth == 1)
        .unwrap();
    assert!(coarse.rms > full_depth.rms);
}

#[test]
fn a_truncated_journal_resumes_to_the_records_of_an_uninterrupted_run() {
    let (scenario, env) = scenario();
    let protocol = DynamicProtocol {
        resolutions: vec![4, 8],
        densities: vec![0.5, 1.0],
        base_resolution: 8,
        budgets: vec![Budget::ALL, Budget::of(10, 5, 5)],
        base_budget: Budget::of(10, 5, 5),
        reference_resolution: 8,
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dynamic.journal");
    let mut journal = Journal::create(&path, "protocol", false).unwrap();
    let whole = run(&scenario, &env, [0.0; 3], &protocol, &mut journal, |_| {}).unwrap();
    drop(journal);
    // Killed while the second setup was being written: the header, the truth and the
    // first setup are whole, the next line is cut short.
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 1 + 3);
    let cut = format!(
        "{}\n{}",
        lines[..3].join("\n"),
        &lines[3][..lines[3].len() / 2]
    );
    std::fs::write(&path, cut).unwrap();
    let mut journal = Journal::resume(&path, "protocol").unwrap();
    let mut seen = 0;
    let resumed = run(&scenario, &env, [0.0; 3], &protocol, &mut journal, |_| {
        seen += 1
    });
    assert_eq!((journal.resumed(), seen), (2, whole.len()));
    let machine_free = |records: Vec<DynamicRecord>| -> Vec<DynamicRecord> {
        records
            .into_iter()
            .map(|r| DynamicRecord {
                field_seconds: 0.0,
                reform_seconds: 0.0,
                frame_seconds: 0.0,
                ..r
            })
            .collect()
    };
    assert_eq!(machine_free(resumed.unwrap()), machine_free(whole));
}
