//! Hostile glTF, OBJ and MTL assets (`testdata/hostile/`, written by
//! `scripts/make_hostile_assets.py`): each is refused by `relight precompute` in one line
//! naming the file and the broken part, within the limits, before anything is cast.

use super::*;

/// Every asset of `testdata/hostile/` and what its refusal must say.
const CASES: [(&str, &[&str]); 16] = [
    (
        "missing_buffer.gltf",
        &["buffer 0", "\"missing.bin\"", "No such file"],
    ),
    (
        "accessor_past_its_view.gltf",
        &[
            "POSITION (accessor 0)",
            "run past its buffer view's 36 bytes",
        ],
    ),
    (
        "view_past_its_buffer.gltf",
        &["buffer view 1", "runs past its buffer's 44 bytes"],
    ),
    (
        "index_beyond_the_vertices.gltf",
        &["refers to vertex 7 but there are 3 vertices"],
    ),
    (
        "index_beyond_the_vertices.glb",
        &["refers to vertex 7 but there are 3 vertices"],
    ),
    ("nan_position.gltf", &["vertex 2 has a non-finite position"]),
    (
        "transform_overflows.gltf",
        &["node 1", "coordinates must be finite"],
    ),
    (
        "texture_beyond_the_budget.gltf",
        &["image 0", "60000x60000", "more than the memory limit"],
    ),
    (
        "buffer_climbs_out.gltf",
        &["buffer 0", "\"../x.bin\" climbs out"],
    ),
    ("buffer_absolute.gltf", &["buffer 0", "is an absolute path"]),
    ("buffer_file_uri.gltf", &["buffer 0", "a URI with a scheme"]),
    ("image_climbs_out.gltf", &["image 0", "climbs out"]),
    ("truncated.glb", &["not a valid glTF 2.0 file"]),
    (
        "map_kd_climbs_out.obj",
        &["map_kd_climbs_out.mtl, line 3, map_Kd", "climbs out"],
    ),
    (
        "map_kd_absolute.obj",
        &["map_kd_absolute.mtl, line 3, map_Kd", "is an absolute path"],
    ),
    (
        "map_kd_file_uri.obj",
        &["map_kd_file_uri.mtl, line 3, map_Kd", "a URI with a scheme"],
    ),
];

#[test]
fn hostile_assets_are_refused_in_one_line_naming_the_part() {
    let folder = testdata("hostile");
    // Every asset in the folder has its case (an MTL is read through its OBJ).
    let mut on_disk: Vec<String> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|name| !name.ends_with(".mtl"))
        .collect();
    on_disk.sort();
    let mut named: Vec<String> = CASES.iter().map(|(name, _)| name.to_string()).collect();
    named.sort();
    assert_eq!(on_disk, named);
    let out = tempfile::tempdir().unwrap();
    for (name, needles) in CASES {
        let input = folder.join(name);
        let line = refused(out.path(), &precompute_args(p(&input), &[]), needles);
        assert!(
            line.starts_with(&format!("haarshift: {}: ", input.display())),
            "{line}"
        );
    }
    assert_eq!(std::fs::read_dir(out.path()).unwrap().count(), 0);
}
