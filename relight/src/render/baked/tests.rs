//! Tests of the baked glTF: every array read back through the document's own accessors equals
//! what went in, bit for bit, and the GLB container is laid out as the specification says.

use super::*;
use crate::Generator;
use ndarray::{Array2, array};

/// A sphere with radiance that exercises the clamp: negative, above 1, and in between.
fn lit_sphere() -> (Mesh, Array2<f32>) {
    let mesh = Generator::Sphere { cells: 3 }.mesh().unwrap();
    let radiance = Array2::from_shape_fn((mesh.vertex_count(), 3), |(v, c)| {
        (v as f32 * 0.37 + c as f32 * 0.11).sin() * 1.7
    });
    (mesh, radiance)
}

fn info(exposure: f64) -> BakeInfo {
    BakeInfo {
        exposure,
        environment: Some("park.hdr".into()),
        rotation_degrees: [30.0, -5.0, 0.0],
        shading: "haar, all coefficients".into(),
        cache: Some("sphere.hsr".into()),
    }
}

#[test]
fn every_array_reads_back_bit_for_bit_from_both_containers() {
    let (mesh, radiance) = lit_sphere();
    for container in [GltfContainer::Glb, GltfContainer::Gltf] {
        let bytes = baked_gltf(&mesh, radiance.view(), &info(1.0), container).unwrap();
        let back = BakedGltf::from_bytes(&bytes).unwrap();
        assert_eq!(back.positions, mesh.positions().mapv(|x| x as f32));
        assert_eq!(back.normals, mesh.normals().mapv(|x| x as f32));
        assert_eq!(back.triangles, mesh.triangles());
        assert_eq!(back.radiance, radiance);
        // COLOR_0 = clamp(2 L, 0, 1): doubling is exact in f32.
        for (c, l) in back.colours.iter().zip(radiance.iter()) {
            assert_eq!(*c, (2.0 * l).clamp(0.0, 1.0));
        }
        assert!(back.colours.iter().any(|&c| c == 0.0) && back.colours.iter().any(|&c| c == 1.0));
        let stated = &back.extras["haarshift"];
        assert_eq!(stated["exposure_stops"], 1.0);
        assert_eq!(stated["colour_scale"], 2.0);
        assert_eq!(stated["environment"], "park.hdr");
        assert_eq!(stated["rotation_degrees"]["yaw"], 30.0);
        assert_eq!(stated["rotation_degrees"]["pitch"], -5.0);
    }
}

#[test]
fn the_glb_container_has_its_header_and_padded_chunks() {
    let (mesh, radiance) = lit_sphere();
    let glb = baked_gltf(&mesh, radiance.view(), &info(0.0), GltfContainer::Glb).unwrap();
    let word = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!((&glb[0..4], word(4), word(8)), (&b"glTF"[..], 2, glb.len()));
    let json_length = word(12);
    assert_eq!((json_length % 4, &glb[16..20]), (0, &b"JSON"[..]));
    let text = std::str::from_utf8(&glb[20..20 + json_length]).unwrap();
    // Padded with spaces, which JSON ignores.
    let document: serde_json::Value = serde_json::from_str(text).unwrap();
    let bin_at = 20 + json_length;
    let bin_length = word(bin_at);
    assert_eq!(&glb[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(bin_at + 8 + bin_length, glb.len());
    let v = mesh.vertex_count();
    let content = 4 * 12 * v + 12 * mesh.triangles().len();
    assert_eq!(document["buffers"][0]["byteLength"], content);
    assert!(glb[bin_at + 8 + content..].iter().all(|&b| b == 0));
    // The POSITION accessor's bounds are the f32 positions' own.
    let accessor = &document["accessors"][0];
    let positions = mesh.positions().mapv(|x| x as f32);
    for k in 0..3 {
        let column = positions.column(k);
        let min = column.iter().copied().fold(f32::INFINITY, f32::min);
        let max = column.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        assert_eq!(accessor["min"][k].as_f64().unwrap() as f32, min);
        assert_eq!(accessor["max"][k].as_f64().unwrap() as f32, max);
    }
    assert_eq!(
        document["extensionsUsed"],
        serde_json::json!(["KHR_materials_unlit"])
    );
    assert!(document["materials"][0]["extensions"]["KHR_materials_unlit"].is_object());
}

#[test]
fn a_vertex_without_a_normal_is_written_with_the_stand_in() {
    // Vertex 3 is on no triangle: its mesh normal is zero.
    let positions = array![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [5.0, 5.0, 5.0]
    ];
    let mesh = Mesh::new(positions, vec![[0, 1, 2]], None).unwrap();
    assert_eq!(mesh.normals().row(3).to_vec(), vec![0.0; 3]);
    let radiance = Array2::<f32>::zeros((4, 3));
    let glb = baked_gltf(&mesh, radiance.view(), &info(0.0), GltfContainer::Glb).unwrap();
    let back = BakedGltf::from_bytes(&glb).unwrap();
    assert_eq!(back.normals.row(3).to_vec(), ZERO_NORMAL_STAND_IN.to_vec());
    assert_eq!(back.normals.row(0).to_vec(), vec![0.0, 1.0, 0.0]);
}

#[test]
fn bad_radiance_and_a_bad_name_are_refused() {
    let (mesh, mut radiance) = lit_sphere();
    let wrong = Array2::<f32>::zeros((3, 3));
    let e = baked_gltf(&mesh, wrong.view(), &info(0.0), GltfContainer::Glb).unwrap_err();
    assert!(
        matches!(e, Error::Core(haarshift::Error::InvalidShape { .. })),
        "{e}"
    );
    radiance[[4, 1]] = f32::NAN;
    let e = baked_gltf(&mesh, radiance.view(), &info(0.0), GltfContainer::Glb).unwrap_err();
    assert!(
        matches!(e, Error::Core(haarshift::Error::NonFinite { ref index, .. }) if index == &[4, 1]),
        "{e}"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.obj");
    let e = write_baked_gltf(&path, &mesh, wrong.view(), &info(0.0), false).unwrap_err();
    assert!(
        e.to_string()
            .contains("out.obj: a baked glTF is written as .glb or .gltf"),
        "{e}"
    );
}

#[test]
fn a_truncated_or_foreign_file_is_refused_not_read() {
    let (mesh, radiance) = lit_sphere();
    let glb = baked_gltf(&mesh, radiance.view(), &info(0.0), GltfContainer::Glb).unwrap();
    for cut in [0, 11, 20, glb.len() / 2, glb.len() - 4] {
        let e = BakedGltf::from_bytes(&glb[..cut]).unwrap_err();
        assert!(
            e.starts_with("not a readable mesh: not a valid glTF 2.0 file: "),
            "cut at {cut}: {e}"
        );
    }
    // A count beyond the view.
    let gltf = baked_gltf(&mesh, radiance.view(), &info(0.0), GltfContainer::Gltf).unwrap();
    let mut document: serde_json::Value = serde_json::from_slice(&gltf).unwrap();
    document["accessors"][1]["count"] = serde_json::json!(mesh.vertex_count() + 1);
    let e = BakedGltf::from_bytes(&serde_json::to_vec(&document).unwrap()).unwrap_err();
    assert!(e.contains("beyond its view"), "{e}");
    // A POSITION accessor that is not there (gltf-json's validation would panic on it).
    document["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = serde_json::json!(99);
    let e = BakedGltf::from_bytes(&serde_json::to_vec(&document).unwrap()).unwrap_err();
    assert!(e.contains("POSITION accessor 99 is not among"), "{e}");
}
