use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use super::*;
use crate::scene::MeshAsset;

fn meshes(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../testdata/meshes")
        .join(name)
}

/// A one-triangle glTF (positions `(0,0,0), (1,0,0), (0,1,0)` in f32, indices u16, then the
/// bytes of `extra` f32s), its buffer a data: URI; `patch` edits the document.
fn triangle(extra: &[f32], patch: impl FnOnce(&mut Value)) -> Value {
    let mut bytes = Vec::new();
    for x in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    for x in extra {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        data_encoding::BASE64.encode(&bytes)
    );
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bytes.len(), "uri": uri}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6},
            {"buffer": 0, "byteOffset": 44, "byteLength": 4 * extra.len()}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ]
    });
    if extra.is_empty() {
        doc["bufferViews"].as_array_mut().unwrap().pop();
    }
    patch(&mut doc);
    doc
}

/// Writes `doc` as `x.gltf` in a fresh folder and reads it within `budget`.
fn load(doc: &Value, budget: &MemoryBudget) -> (Result<MeshAsset>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.gltf");
    std::fs::write(&path, serde_json::to_vec(doc).unwrap()).unwrap();
    (MeshAsset::load_within(&path, budget), dir)
}

/// The one-line refusal of `doc`, which must name the file.
fn gltf_refusal(doc: &Value) -> String {
    let (result, dir) = load(doc, &MemoryBudget::default());
    let e = result.unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{}: ", dir.path().join("x.gltf").display())),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1, "{e}");
    e
}

#[test]
fn the_glb_and_the_gltf_read_the_same_mesh_and_albedo_as_the_ply_oracle() {
    let glb = MeshAsset::load(&meshes("bunny_boxes.glb")).unwrap();
    let gltf = MeshAsset::load(&meshes("bunny_boxes.gltf")).unwrap();
    assert_eq!(glb, gltf);
    assert_eq!(glb.mesh.vertex_count(), 1839 + 48);
    assert!(glb.warnings.is_empty(), "{:?}", glb.warnings);
    let albedo = glb.albedo.as_ref().unwrap();
    // The boxes: their factors alone. The bunny: the script's own sRGB decoding and bilinear
    // sampling of the checker, written as float colours.
    assert_eq!(albedo.row(1839).to_vec(), vec![0.8, 0.1, 0.1]);
    assert_eq!(albedo.row(1839 + 24).to_vec(), vec![0.1, 0.7, 0.15]);
    let ply = MeshAsset::load(&meshes("bunny_boxes_colours.ply")).unwrap();
    assert_eq!(ply.mesh.positions(), glb.mesh.positions());
    assert_eq!(ply.mesh.triangles(), glb.mesh.triangles());
    let normals = (&ply.mesh.normals() - &glb.mesh.normals())
        .iter()
        .fold(0.0f64, |m, d| m.max(d.abs()));
    assert!(normals < 1e-15, "{normals}");
    let oracle = ply.albedo.unwrap();
    let worst = (&oracle - albedo)
        .iter()
        .fold(0.0f32, |m, d| m.max(d.abs()));
    assert!(worst < 1e-6, "{worst}");
    // The texture varies: the bunny is not one colour.
    let spread = albedo
        .column(2)
        .iter()
        .take(1839)
        .fold((1.0f32, 0.0f32), |(lo, hi), &a| (lo.min(a), hi.max(a)));
    assert!(spread.1 - spread.0 > 0.3, "{spread:?}");
}

/// `m` (column-major) applied to a point.
fn apply(m: &[[f64; 4]; 4], p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| (0..3).map(|c| m[c][r] * p[c]).sum::<f64>() + m[3][r])
}

#[test]
fn the_hierarchy_composes_transforms_and_the_mirrored_node_keeps_outward_normals() {
    let asset = MeshAsset::load(&meshes("hierarchy.gltf")).unwrap();
    let box_ = Mesh::load(&meshes("hierarchy.gltf")).unwrap();
    assert_eq!(asset.mesh, box_);
    assert_eq!(asset.mesh.vertex_count(), 48);
    // By hand: root = T(1, 2, 3) Ry(90), middle = S(2, 1, 0.5), leaf = T(0, 1, 0).
    // Ry(90) takes x to -z and z to x. World = T Ry S T'.
    let world = |p: [f64; 3]| {
        let q = [p[0], p[1] + 1.0, p[2]];
        let s = [2.0 * q[0], q[1], 0.5 * q[2]];
        let r = [s[2], s[1], -s[0]];
        [r[0] + 1.0, r[1] + 2.0, r[2] + 3.0]
    };
    // Normals by the inverse transpose: S^-1 then Ry, normalised.
    let normal = |n: [f64; 3]| {
        let s = [n[0] / 2.0, n[1], n[2] / 0.5];
        let r = [s[2], s[1], -s[0]];
        let len = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        r.map(|x| x / len)
    };
    let mirror = [
        [-1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [-3.0, 0.0, 0.0, 1.0],
    ];
    // The stored box: 24 vertices, faces +X, -X, +Y, -Y, +Z, -Z with their normals.
    let face_normals = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let local = asset.mesh.positions();
    let (p, n) = (asset.mesh.positions(), asset.mesh.normals());
    // Recover the local box from the mirrored copy (its own inverse) and check both copies.
    for k in 0..24 {
        let mirrored = [p[[24 + k, 0]], p[[24 + k, 1]], p[[24 + k, 2]]];
        let original = [-(mirrored[0] + 3.0), mirrored[1], mirrored[2]];
        assert!(
            original.iter().all(|x| (x.abs() - 0.5).abs() < 1e-12),
            "{original:?}"
        );
        let expected = world(original);
        for c in 0..3 {
            assert!((local[[k, c]] - expected[c]).abs() < 1e-6, "vertex {k}");
            assert_eq!(p[[24 + k, c]], apply(&mirror, original)[c]);
        }
        let stored = face_normals[k / 4];
        let expected = normal(stored);
        for c in 0..3 {
            assert!(
                (n[[k, c]] - expected[c]).abs() < 1e-6,
                "normal {k}: {:?}",
                n.row(k)
            );
        }
        // Mirrored: x negated (the inverse transpose of a reflection is itself).
        assert_eq!(
            [n[[24 + k, 0]], n[[24 + k, 1]], n[[24 + k, 2]]],
            [-stored[0], stored[1], stored[2]]
        );
    }
    // Both copies' triangles are counter-clockwise seen from outside: the geometric normal
    // agrees with the vertex normals and points away from the box's centre.
    let centres = [world([0.0; 3]), [-3.0, 0.0, 0.0]];
    for (t, tri) in asset.mesh.triangles().iter().enumerate() {
        let at = |i: u32| [p[[i as usize, 0]], p[[i as usize, 1]], p[[i as usize, 2]]];
        let (a, b, c) = (at(tri[0]), at(tri[1]), at(tri[2]));
        let g =
            crate::scene::mesh::cross(crate::scene::mesh::sub(b, a), crate::scene::mesh::sub(c, a));
        let vertex_normal = [
            n[[tri[0] as usize, 0]],
            n[[tri[0] as usize, 1]],
            n[[tri[0] as usize, 2]],
        ];
        let outward = crate::scene::mesh::sub(a, centres[t / 12]);
        assert!(
            crate::scene::mesh::dot(g, vertex_normal) > 0.0,
            "triangle {t}"
        );
        assert!(crate::scene::mesh::dot(g, outward) > 0.0, "triangle {t}");
    }
    // Without its stored normals the mirrored box's computed normals point outward too.
    let mut doc: Value =
        serde_json::from_slice(&std::fs::read(meshes("hierarchy.gltf")).unwrap()).unwrap();
    doc["meshes"][0]["primitives"][0]["attributes"]
        .as_object_mut()
        .unwrap()
        .remove("NORMAL");
    let (computed, _dir) = load(&doc, &MemoryBudget::default());
    let computed = computed.unwrap();
    for k in 0..48 {
        let row = computed.mesh.normals().row(k).to_vec();
        let centre = centres[k / 24];
        let out = crate::scene::mesh::sub([p[[k, 0]], p[[k, 1]], p[[k, 2]]], centre);
        assert!(
            crate::scene::mesh::dot([row[0], row[1], row[2]], out) > 0.0,
            "vertex {k}"
        );
    }
}

#[test]
fn the_default_material_factor_texture_and_colour_multiply() {
    // No material: the spec's default, factor 1 (not haarshift's 0.8).
    let (bare, _d) = load(&triangle(&[], |_| {}), &MemoryBudget::default());
    let bare = bare.unwrap();
    assert_eq!(bare.albedo.unwrap().row(0).to_vec(), vec![1.0; 3]);
    assert!(bare.warnings.is_empty());
    // A factor times COLOR_0 (float VEC4, alpha dropped), and a metallic material reported.
    let colours = [0.5, 1.0, 0.25, 0.1, 1.0, 1.0, 1.0, 1.0, 0.0, 0.5, 1.0, 1.0];
    let doc = triangle(&colours, |d| {
        d["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = json!(2);
        d["meshes"][0]["primitives"][0]["material"] = json!(0);
        d["materials"] = json!([{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 1, 1],
            "metallicFactor": 0.5}}]);
        d["accessors"]
            .as_array_mut()
            .unwrap()
            .push(json!({"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"}));
    });
    let (asset, _d) = load(&doc, &MemoryBudget::default());
    let asset = asset.unwrap();
    let albedo = asset.albedo.unwrap();
    assert_eq!(albedo.row(0).to_vec(), vec![0.25, 0.5, 0.25]);
    assert_eq!(albedo.row(2).to_vec(), vec![0.0, 0.25, 1.0]);
    assert_eq!(asset.warnings.len(), 1);
    assert!(
        asset.warnings[0].starts_with(
            "material 0 is metallic or glossy (metallicFactor 0.5, roughnessFactor 1)"
        ),
        "{:?}",
        asset.warnings
    );
}

#[test]
fn hostile_documents_are_refused_in_one_line_naming_the_part() {
    let cases: Vec<(Value, &[&str])> = vec![
        (
            triangle(&[], |d| d["meshes"][0]["primitives"][0]["mode"] = json!(1)),
            &["primitive 0", "mode Lines", "only triangle lists"],
        ),
        (
            triangle(&[], |d| d["accessors"][0]["count"] = json!(4)),
            &[
                "POSITION (accessor 0)",
                "run past its buffer view's 36 bytes",
            ],
        ),
        (
            triangle(&[], |d| d["bufferViews"][1]["byteLength"] = json!(600)),
            &["buffer view 1", "runs past its buffer's 44 bytes"],
        ),
        (
            triangle(&[], |d| d["accessors"][1]["count"] = json!(2)),
            &["2 indices is not a list of triangles"],
        ),
        (
            triangle(&[], |d| d["accessors"][0]["componentType"] = json!(5121)),
            &[
                "POSITION (accessor 0)",
                "not a type this attribute may have",
            ],
        ),
        (
            // gltf-json's own validation panics on this one (checked before it runs).
            triangle(&[], |d| {
                d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(2)
            }),
            &[
                "mesh 0, primitive 0",
                "POSITION accessor 2 is not among the file's 2",
            ],
        ),
        (
            // And gltf's `Image::source` on an image of neither uri nor bufferView.
            triangle(&[], |d| d["images"] = json!([{"name": "nothing"}])),
            &["image 0 names neither a uri nor a bufferView"],
        ),
        (
            triangle(&[], |d| d["images"] = json!([{"bufferView": 0}])),
            &["image 0 is in a bufferView but has no mimeType"],
        ),
        (
            triangle(&[], |d| d["buffers"][0]["uri"] = json!("missing.bin")),
            &["buffer 0", "missing.bin"],
        ),
        (
            triangle(&[], |d| d["buffers"][0]["uri"] = json!("../x.bin")),
            &["buffer 0", "climbs out"],
        ),
        (
            triangle(&[], |d| {
                d["buffers"][0]["uri"] = json!("file:///etc/passwd")
            }),
            &["buffer 0", "scheme"],
        ),
        (
            triangle(&[], |d| d["buffers"][0]["byteLength"] = json!(1000)),
            &["buffer 0", "holds 44 bytes, its byteLength says 1000"],
        ),
        (
            triangle(
                &[],
                |d| d["nodes"] = json!([{"scale": [3e38, 1, 1], "children": [1]}, {"scale": [3e38, 1, 1], "mesh": 0}]),
            ),
            &["node 1", "coordinates must be finite"],
        ),
        (
            triangle(&[], |d| {
                d["nodes"] = json!([{"mesh": 0, "children": [1]}, {"children": [0]}])
            }),
            &["node 0", "is a root of the scene and has a parent"],
        ),
        (
            triangle(&[], |d| {
                d["nodes"] = json!([{"children": [2]}, {"children": [2]}, {"mesh": 0}])
            }),
            &["node 2", "more than one parent"],
        ),
        (
            triangle(&[], |d| {
                d.as_object_mut().unwrap().remove("scenes");
            }),
            &["no scene"],
        ),
        (
            triangle(&[], |d| d["accessors"] = json!("x")),
            &["not a valid glTF 2.0 file"],
        ),
    ];
    for (doc, needles) in cases {
        let e = gltf_refusal(&doc);
        for needle in needles {
            assert!(e.contains(needle), "{e} lacks {needle:?}");
        }
    }
}

#[test]
fn indices_beyond_the_vertices_and_nan_positions_are_refused() {
    // Index 7 in a triangle of 3 vertices; a NaN as the second vertex's y.
    let mut doc = triangle(&[], |_| {});
    let uri = doc["buffers"][0]["uri"].as_str().unwrap().to_owned();
    let mut bytes = data_encoding::BASE64
        .decode(uri.split_once(',').unwrap().1.as_bytes())
        .unwrap();
    let mut bad_index = bytes.clone();
    bad_index[38..40].copy_from_slice(&7u16.to_le_bytes());
    bytes[16..20].copy_from_slice(&f32::NAN.to_le_bytes());
    for (data, needle) in [
        (bad_index, "refers to vertex 7 but there are 3 vertices"),
        (bytes, "vertex 1 has a non-finite position"),
    ] {
        doc["buffers"][0]["uri"] = json!(format!(
            "data:application/octet-stream;base64,{}",
            data_encoding::BASE64.encode(&data)
        ));
        let e = gltf_refusal(&doc);
        assert!(
            e.contains("node 0, mesh 0, primitive 0: ") && e.contains(needle),
            "{e}"
        );
    }
}

#[test]
fn counts_and_textures_beyond_the_budget_are_refused_before_they_are_read() {
    // A 1 KiB budget refuses the file itself; a larger one the vertices of many instances.
    let doc = triangle(&[], |d| {
        let nodes: Vec<Value> = (0..200).map(|_| json!({"mesh": 0})).collect();
        d["nodes"] = json!(nodes);
        d["scenes"] = json!([{"nodes": (0..200).collect::<Vec<_>>()}]);
    });
    let small = MemoryBudget {
        limit: 100_000,
        ..MemoryBudget::default()
    };
    let (result, _d) = load(&doc, &small);
    let e = result.unwrap_err().to_string();
    assert!(
        e.contains(
            "the glTF's primitives, every instance counted (600 vertices) needs 384000 bytes"
        ),
        "{e}"
    );
    // A PNG whose header claims 60000 x 60000 RGB: refused from the header.
    let mut png = Vec::new();
    png.extend_from_slice(b"\x89PNG\r\n\x1a\n");
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend_from_slice(&60000u32.to_be_bytes());
    ihdr.extend_from_slice(&60000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    png.extend_from_slice(&13u32.to_be_bytes());
    png.extend_from_slice(&ihdr);
    png.extend_from_slice(&crc32fast::hash(&ihdr).to_be_bytes());
    for chunk in [&b"IDAT\x78\x9c\x03\x00\x00\x00\x00\x01"[..], b"IEND"] {
        png.extend_from_slice(&(chunk.len() as u32 - 4).to_be_bytes());
        png.extend_from_slice(chunk);
        png.extend_from_slice(&crc32fast::hash(chunk).to_be_bytes());
    }
    let textured = |image: Value| {
        triangle(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], |d| {
            d["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(2);
            d["meshes"][0]["primitives"][0]["material"] = json!(0);
            d["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
            d["textures"] = json!([{"source": 0}]);
            d["images"] = json!([image]);
            d["accessors"]
                .as_array_mut()
                .unwrap()
                .push(json!({"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}));
        })
    };
    let huge = textured(
        json!({"uri": format!("data:image/png;base64,{}", data_encoding::BASE64.encode(&png))}),
    );
    let e = gltf_refusal(&huge);
    assert!(e.contains("image 0: ") && e.contains("memory limit"), "{e}");
    let outside = gltf_refusal(&textured(json!({"uri": "../checker.png"})));
    assert!(
        outside.contains("image 0: \"../checker.png\" climbs out"),
        "{outside}"
    );
    let missing_uv = triangle(&[], |d| {
        d["meshes"][0]["primitives"][0]["material"] = json!(0);
        d["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
        d["textures"] = json!([{"source": 0}]);
        d["images"] = json!([{"uri": "x.png"}]);
    });
    assert!(gltf_refusal(&missing_uv).contains("reads TEXCOORD_0, which it lacks"));
}

#[test]
fn the_obj_with_mtl_reads_the_glb_s_albedo() {
    let glb = MeshAsset::load(&meshes("bunny_boxes.glb")).unwrap();
    let albedo = glb.albedo.as_ref().unwrap();
    let obj = MeshAsset::load(&meshes("bunny_boxes.obj")).unwrap();
    assert_eq!(obj.mesh.triangles(), glb.mesh.triangles());
    let obj_albedo = obj.albedo.unwrap();
    let worst = (0..albedo.nrows())
        .map(|v| {
            let d = (0..3).fold(0.0f32, |m, c| {
                m.max((obj_albedo[[v, c]] - albedo[[v, c]]).abs())
            });
            (d, v)
        })
        .fold((0.0f32, 0), |m, x| if x.0 > m.0 { x } else { m });
    assert!(
        worst.0 < 1e-6,
        "{worst:?}: obj {:?} glb {:?} of {}",
        obj_albedo.row(worst.1),
        albedo.row(worst.1),
        albedo.nrows()
    );
}
