//! `haarshift relight precompute --shard` and `relight merge`: shards run as separate
//! processes merge into the unsharded cache byte for byte (of a scene file of generators, and
//! of mesh files and a scene file naming one), `--shard auto` reads Slurm's and
//! Kubernetes' variables, a complete shard is skipped, and every bad set of shards is refused
//! with one line naming the file.

use std::path::{Path, PathBuf};

use crate::common::{
    fails_cleanly, fails_cleanly_scheduled, p, run_scheduled, succeeds_with_stdout, testdata, text,
};

/// A sphere resting on the ground plane (96 + 1089 = 1185 vertices): the ground's shadow
/// comes from vertices in other shards.
fn ball_scene(dir: &Path, name: &str, height: f64) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            r#"{{"objects": [{{"generator": {{"sphere": {{"cells": 3}}}},
                "transform": {{"translate": [0, {height}, 0]}}}}],
                "ground_plane": true}}"#
        ),
    )
    .unwrap();
    path
}

/// Options small enough for eleven processes, with jittered rays (2 x 2 a texel).
const OPTIONS: [&str; 6] = [
    "--param",
    "cube",
    "--resolution",
    "4",
    "--visibility-samples",
    "2",
];

/// `relight precompute SCENE OPTIONS EXTRA -o OUT`; returns standard output.
fn precompute_with_options(scene: &Path, out: &Path, extra: &[&str]) -> String {
    let mut args = vec!["relight", "precompute", p(scene), "-o", p(out)];
    args.extend(OPTIONS);
    args.extend(extra);
    succeeds_with_stdout(&args)
}

/// Shards `0..count` of `scene` as separate processes, `DIR/part-I.hsr`.
fn shards(scene: &Path, dir: &Path, count: usize) -> Vec<PathBuf> {
    (0..count)
        .map(|i| {
            let out = dir.join(format!("part-{i}.hsr"));
            let stdout =
                precompute_with_options(scene, &out, &["--shard", &format!("{i}/{count}")]);
            assert!(
                stdout.contains(&format!("(shard {i}/{count}: vertices ")),
                "{stdout}"
            );
            out
        })
        .collect()
}

fn merge(parts: &[PathBuf], out: &Path) -> String {
    let mut args = vec!["relight", "merge"];
    args.extend(parts.iter().map(|x| p(x)));
    args.extend(["-o", p(out)]);
    succeeds_with_stdout(&args)
}

/// `relight merge PARTS -o OUT` refused with one line naming `culprit` and holding `needle`.
fn merge_refused(parts: &[&PathBuf], out: &Path, culprit: &Path, needle: &str) -> String {
    let mut args = vec!["relight", "merge"];
    args.extend(parts.iter().map(|x| p(x)));
    args.extend(["-o", p(out)]);
    let line = fails_cleanly(&args, &[needle]);
    assert!(
        line.starts_with(&format!("haarshift: {}: ", culprit.display())),
        "{line}"
    );
    assert!(!out.exists());
    line
}

#[test]
fn one_three_and_seven_shards_merge_into_the_unsharded_cache_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let scene = ball_scene(dir.path(), "ball.json", 1.0);
    let whole = dir.path().join("whole.hsr");
    precompute_with_options(&scene, &whole, &[]);
    let expected = std::fs::read(&whole).unwrap();
    for count in [1, 3, 7] {
        let sub = dir.path().join(format!("n{count}"));
        std::fs::create_dir(&sub).unwrap();
        let mut parts = shards(&scene, &sub, count);
        parts.reverse();
        let out = sub.join("merged.hsr");
        let stdout = merge(&parts, &out);
        assert!(
            stdout.contains(&format!("{count} shards merged, 1185 vertices")),
            "{stdout}"
        );
        assert!(std::fs::read(&out).unwrap() == expected, "{count} shards");
        if count == 7 {
            // A shard is no cache to render.
            let mut args = vec!["relight", "render", p(&parts[0]), "-o"];
            let png = sub.join("x.png");
            args.push(p(&png));
            fails_cleanly(&args, &["is shard 6/7 of a scene cache", "relight merge"]);
        }
    }
}

#[test]
fn mesh_files_scene_files_and_generators_merge_byte_for_byte() {
    // Each input's normals are normalised once (computed, read from a file or moved by a
    // transform), in ways that a second normalisation of the shard read back moved by a
    // unit in the last place: the merge must keep the bits the shards were written with.
    let dir = tempfile::tempdir().unwrap();
    let (ply, obj) = (testdata("meshes/bunny.ply"), testdata("meshes/bunny.obj"));
    let named = dir.path().join("named.json");
    let object = serde_json::json!({
        "mesh": ply,
        "transform": {"scale": 0.5, "yaw": 30, "translate": [0, 0.2, 0]},
    });
    let scene = serde_json::json!({"objects": [object], "ground_plane": true});
    std::fs::write(&named, scene.to_string()).unwrap();
    let generated = dir.path().join("generated.json");
    std::fs::write(
        &generated,
        r#"{"objects": [{"generator": {"cylinder_and_bump": {"cells": 8}}},
                        {"generator": {"sphere": {"cells": 3}},
                         "transform": {"translate": [2, 1, 0], "yaw": 30, "pitch": 10}}]}"#,
    )
    .unwrap();
    let inputs: [(&Path, &[&str], usize); 5] = [
        (&ply, &[], 1839),
        (&ply, &["--ground-plane"], 1839 + 1089),
        (&obj, &[], 1839),
        (&named, &[], 1839 + 1089),
        (&generated, &[], 1475),
    ];
    for (k, (input, extra, vertices)) in inputs.into_iter().enumerate() {
        let what = format!("{} {extra:?}", input.display());
        let sub = dir.path().join(k.to_string());
        std::fs::create_dir(&sub).unwrap();
        let whole = sub.join("whole.hsr");
        precompute_with_options(input, &whole, extra);
        let parts: Vec<_> = ["1/2", "0/2"]
            .iter()
            .map(|shard| {
                let out = sub.join(format!("part-{}.hsr", &shard[..1]));
                precompute_with_options(input, &out, &[extra, &["--shard", shard]].concat());
                out
            })
            .collect();
        let merged = sub.join("merged.hsr");
        let stdout = merge(&parts, &merged);
        let counted = format!("2 shards merged, {vertices} vertices");
        assert!(stdout.contains(&counted), "{what}: {stdout}");
        assert!(
            std::fs::read(&merged).unwrap() == std::fs::read(&whole).unwrap(),
            "{what}: the merged cache is not the unsharded one"
        );
        // A shard read back is its scene's, so a rerun skips it.
        let again =
            precompute_with_options(input, &parts[1], &[extra, &["--shard", "0/2"]].concat());
        assert!(again.ends_with("is complete: skipped\n"), "{what}: {again}");
    }
}

#[test]
fn bad_sets_of_shards_are_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = ball_scene(dir.path(), "ball.json", 1.0);
    let parts = shards(&scene, dir.path(), 3); // 0..395, 395..790, 790..1185
    let out = dir.path().join("merged.hsr");
    let [a, b, c] = [&parts[0], &parts[1], &parts[2]];
    merge_refused(&[a, c], &out, c, "vertices 395..790 are in no shard");
    merge_refused(&[a, b], &out, b, "vertices 790..1185 are in no shard");
    merge_refused(
        &[a, b, b, c],
        &out,
        b,
        "vertices 395..790 of shard 1/3 are also in",
    );
    let copy = dir.path().join("copy-of-part-2.hsr");
    std::fs::copy(c, &copy).unwrap();
    merge_refused(
        &[a, b, c, &copy],
        &out,
        &copy,
        "vertices 790..1185 of shard 2/3",
    );

    // Another scene (the ball higher up) and other options (another seed).
    let higher = ball_scene(dir.path(), "higher.json", 1.5);
    let stranger = dir.path().join("other-scene.hsr");
    precompute_with_options(&higher, &stranger, &["--shard", "1/3"]);
    merge_refused(&[a, &stranger, c], &out, &stranger, "has another mesh");
    let reseeded = dir.path().join("other-options.hsr");
    precompute_with_options(&scene, &reseeded, &["--shard", "1/3", "--seed", "9"]);
    merge_refused(
        &[a, &reseeded, c],
        &out,
        &reseeded,
        "other options (seed 9, not 0)",
    );
    let banded = dir.path().join("other-bands.hsr");
    precompute_with_options(&scene, &banded, &["--shard", "1/3", "--sh-bands", "2"]);
    merge_refused(
        &[a, &banded, c],
        &out,
        &banded,
        "other options (sh_bands 2, not null)",
    );

    // A truncated shard, and a file that is no shard.
    let cut = dir.path().join("cut.hsr");
    let bytes = std::fs::read(b).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    merge_refused(&[a, &cut, c], &out, &cut, "scene cache is damaged");
    let whole = dir.path().join("whole.hsr");
    precompute_with_options(&scene, &whole, &[]);
    merge_refused(
        &[a, &whole],
        &out,
        &whole,
        "is a whole scene cache, not a shard",
    );

    // The output is checked before any work.
    std::fs::write(&out, b"keep").unwrap();
    let args = ["relight", "merge", p(a), p(b), p(c), "-o", p(&out)];
    fails_cleanly(&args, &[p(&out), "already exists"]);
    assert_eq!(std::fs::read(&out).unwrap(), b"keep");
    fails_cleanly(&["relight", "merge", p(a), "-o", p(a), "--force"], &[p(a)]);
}

#[test]
fn a_complete_shard_is_skipped_and_another_file_kept() {
    let dir = tempfile::tempdir().unwrap();
    let scene = ball_scene(dir.path(), "ball.json", 1.0);
    let part = dir.path().join("part-1.hsr");
    precompute_with_options(&scene, &part, &["--shard", "1/3"]);
    let first = std::fs::read(&part).unwrap();
    let again = precompute_with_options(&scene, &part, &["--shard", "1/3"]);
    assert_eq!(
        again,
        format!(
            "{}: shard 1/3 (vertices 395..790) is complete: skipped\n",
            p(&part)
        )
    );
    // Another shard's, options' or damaged file at the same path is not replaced without
    // --force.
    let mut args = vec!["relight", "precompute", p(&scene), "-o", p(&part)];
    args.extend(OPTIONS);
    let other = [args.clone(), vec!["--shard", "2/3"]].concat();
    fails_cleanly(&other, &[p(&part), "holds shard 1/3, not 2/3", "--force"]);
    let seeded = [args.clone(), vec!["--shard", "1/3", "--seed", "3"]].concat();
    fails_cleanly(&seeded, &[p(&part), "other options (seed 0, not 3)"]);
    std::fs::write(&part, &first[..100]).unwrap();
    let shard = [args.clone(), vec!["--shard", "1/3"]].concat();
    fails_cleanly(&shard, &[p(&part), "damaged"]);
    let forced = [shard, vec!["--force"]].concat();
    succeeds_with_stdout(&forced);
    assert!(std::fs::read(&part).unwrap() == first);
    // An unsharded output is refused as before.
    fails_cleanly(&args, &[p(&part), "already exists"]);
}

#[test]
fn shard_auto_reads_slurm_and_kubernetes_and_refuses_without_them() {
    let dir = tempfile::tempdir().unwrap();
    let scene = ball_scene(dir.path(), "ball.json", 1.0);
    let mut args = vec!["relight", "precompute", p(&scene)];
    args.extend(OPTIONS);
    let run = |vars: &[(&str, &str)], name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let all = [
            args.clone(),
            vec!["--shard", "auto", "-o", p(&out)],
            extra.to_vec(),
        ]
        .concat();
        let result = run_scheduled(vars, &all);
        assert!(result.status.success(), "{}", text(&result.stderr));
        text(&result.stdout)
    };
    // --array=3-15:4 has tasks 3, 7, 11, 15: task 11 is shard 2 of 4.
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "11"),
        ("SLURM_ARRAY_TASK_MIN", "3"),
        ("SLURM_ARRAY_TASK_MAX", "15"),
        ("SLURM_ARRAY_TASK_STEP", "4"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ];
    let stdout = run(&slurm, "slurm.hsr", &[]);
    assert!(
        stdout.contains("(shard 2/4: vertices 592..888)"),
        "{stdout}"
    );
    let stdout = run(
        &[("JOB_COMPLETION_INDEX", "6")],
        "k8s.hsr",
        &["--shards", "7"],
    );
    assert!(
        stdout.contains("(shard 6/7: vertices 1015..1185)"),
        "{stdout}"
    );
    // The same bits as the shard named by hand.
    let named = dir.path().join("named.hsr");
    precompute_with_options(&scene, &named, &["--shard", "6/7"]);
    assert!(std::fs::read(&named).unwrap() == std::fs::read(dir.path().join("k8s.hsr")).unwrap());

    let out = dir.path().join("refused.hsr");
    let refused = [args.clone(), vec!["--shard", "auto", "-o", p(&out)]].concat();
    fails_cleanly_scheduled(
        &[],
        &refused,
        &["neither SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"],
    );
    fails_cleanly_scheduled(&[("JOB_COMPLETION_INDEX", "1")], &refused, &["--shards N"]);
    let gaps = [
        ("SLURM_ARRAY_TASK_ID", "2"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "5"),
        ("SLURM_ARRAY_TASK_STEP", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    fails_cleanly_scheduled(&gaps, &refused, &["has gaps"]);
    let direction = [
        args,
        vec!["--shard", "1/2", "--order", "direction", "-o", p(&out)],
    ]
    .concat();
    fails_cleanly(
        &direction,
        &["invalid order", "cannot be sharded", "--order vertex"],
    );
    assert!(!out.exists());
}
