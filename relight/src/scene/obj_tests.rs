use super::*;

/// Writes `files` into a fresh folder and reads its `x.obj`.
fn read(files: &[(&str, &[u8])]) -> (Result<MeshAsset>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let path = dir.path().join("x.obj");
    (MeshAsset::load(&path), dir)
}

/// Two triangles sharing the edge 2-3 (positions 1..4), a 2 x 1 texture (black, white).
const SQUARE: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nvt 0.25 0.5\nvt 0.75 0.5\nvt 0.5 0.5\n";

/// A PNG of two pixels, black then white, `width x height` (2 x 1 or 1 x 2).
fn two_pixel_png(width: u32, height: u32) -> Vec<u8> {
    use image::ImageEncoder;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(
            &[0, 0, 0, 255, 255, 255],
            width,
            height,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
    png
}

fn texture_png() -> Vec<u8> {
    two_pixel_png(2, 1)
}

#[test]
fn a_position_with_several_uvs_or_materials_is_split_after_the_file_vertices() {
    let mtl = b"newmtl tex\nKd 1 0.5 1\nmap_Kd t.png\nnewmtl red\nKd 0.9 0 0\nKs 0.5 0.5 0.5\n";
    // Triangle 0 textured: corners 1/1 2/2 3/3; triangle 1: position 3 again with uv 1 (a
    // second vertex), position 4 with uv 2; triangle 2 red: positions 1, 2, 4 (new vertices
    // for 1 and 2, vertex 3 is position 4's first use: it was textured).
    let obj = format!("{SQUARE}usemtl tex\nf 1/1 2/2 3/3\nf 1/1 3/1 4/2\nusemtl red\nf 1 2 4\n");
    let (asset, _dir) = read(&[
        ("x.obj", obj.as_bytes()),
        ("m.mtl", mtl),
        ("t.png", &texture_png()),
    ]);
    let asset = asset.unwrap();
    assert_eq!(asset.mesh.vertex_count(), 5 + 4);
    assert_eq!(asset.mesh.triangles(), &[[0, 1, 2], [0, 5, 3], [6, 7, 8]]);
    let p = asset.mesh.positions();
    for (vertex, position) in [(5, 2), (6, 0), (7, 1), (8, 3)] {
        assert_eq!(p.row(vertex), p.row(position));
        assert_eq!(
            asset.mesh.normals().row(vertex),
            asset.mesh.normals().row(position)
        );
    }
    let a = asset.albedo.unwrap();
    // vt (0.25, 0.5) is texel 0's centre (black), (0.75, 0.5) texel 1's (white), 0.5 half way
    // (linear 0.5: texels are decoded before they are interpolated); times Kd.
    assert_eq!(a.row(0).to_vec(), vec![0.0; 3]);
    assert_eq!(a.row(1).to_vec(), vec![1.0, 0.5, 1.0]);
    assert_eq!(a.row(2).to_vec(), vec![0.5, 0.25, 0.5]);
    assert_eq!(a.row(5).to_vec(), vec![0.0; 3]);
    assert_eq!(a.row(3).to_vec(), vec![1.0, 0.5, 1.0]);
    assert_eq!(a.row(4).to_vec(), vec![0.8; 3]); // used by no face
    assert_eq!(a.row(6).to_vec(), vec![0.9, 0.0, 0.0]);
    assert_eq!(asset.warnings.len(), 1);
    assert!(
        asset.warnings[0].starts_with("material \"red\" has a specular colour (Ks 0.5 0.5 0.5)")
    );
    // Without usemtl the same file keeps vertex k = the k-th v.
    let plain = format!("{SQUARE}f 1/1 2/2 3/3\nf 1/1 3/1 4/2\n");
    let (asset, _dir) = read(&[
        ("x.obj", plain.as_bytes()),
        ("m.mtl", mtl),
        ("t.png", &texture_png()),
    ]);
    let asset = asset.unwrap();
    assert_eq!((asset.mesh.vertex_count(), asset.albedo), (5, None));
}

#[test]
fn libraries_and_textures_outside_the_folder_and_unknown_materials_are_refused() {
    let obj = format!("{SQUARE}usemtl tex\nf 1/1 2/2 3/3\n");
    for (mtl, needle) in [
        (
            &b"newmtl tex\nmap_Kd ../t.png\n"[..],
            "line 2, map_Kd: \"../t.png\" climbs out",
        ),
        (b"newmtl tex\nmap_Kd /etc/t.png\n", "absolute path"),
        (b"newmtl tex\nmap_Kd file:t.png\n", "scheme"),
        (b"newmtl tex\nmap_Kd -s 2 2 t.png\n", "options are not read"),
        (
            b"newmtl tex\nKd 2 0 0\n",
            "Kd needs three numbers in [0, 1]",
        ),
        (b"newmtl other\n", "usemtl \"tex\" names no material"),
        (b"Kd 1 1 1\n", "Kd before any newmtl"),
    ] {
        let (result, dir) = read(&[
            ("x.obj", obj.as_bytes()),
            ("m.mtl", mtl),
            ("t.png", &texture_png()),
        ]);
        let e = result.unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{}: ", dir.path().join("x.obj").display())),
            "{e}"
        );
        assert!(
            e.contains(needle) && e.lines().count() == 1,
            "{e} lacks {needle:?}"
        );
    }
    let outside = SQUARE.replace("mtllib m.mtl", "mtllib ../m.mtl");
    let (result, _dir) = read(&[("x.obj", outside.as_bytes())]);
    assert!(
        result
            .unwrap_err()
            .to_string()
            .contains("mtllib: \"../m.mtl\" climbs out")
    );
}

#[test]
fn ply_colours_are_srgb_as_bytes_and_linear_as_floats() {
    let header = |ty: &str| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty {ty} red\nproperty {ty} green\nproperty {ty} blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        )
    };
    let dir = tempfile::tempdir().unwrap();
    let bytes = dir.path().join("b.ply");
    std::fs::write(
        &bytes,
        format!(
            "{}0 0 0 0 128 255\n1 0 0 10 20 30\n0 1 0 255 255 255\n3 0 1 2\n",
            header("uchar")
        ),
    )
    .unwrap();
    let a = MeshAsset::load(&bytes).unwrap().albedo.unwrap();
    let lin = |k: f64| crate::scene::texture::srgb_to_linear(k / 255.0) as f32;
    assert_eq!(a.row(0).to_vec(), vec![0.0, lin(128.0), 1.0]);
    assert_eq!(a.row(1).to_vec(), vec![lin(10.0), lin(20.0), lin(30.0)]);
    let floats = dir.path().join("f.ply");
    std::fs::write(
        &floats,
        format!(
            "{}0 0 0 0 0.5 1\n1 0 0 0.25 0.125 0\n0 1 0 1 1 1\n3 0 1 2\n",
            header("float")
        ),
    )
    .unwrap();
    let a = MeshAsset::load(&floats).unwrap().albedo.unwrap();
    assert_eq!(a.row(0).to_vec(), vec![0.0, 0.5, 1.0]);
    assert_eq!(a.row(1).to_vec(), vec![0.25, 0.125, 0.0]);
    std::fs::write(
        &floats,
        format!(
            "{}0 0 0 0 1.5 1\n1 0 0 0 0 0\n0 1 0 1 1 1\n3 0 1 2\n",
            header("float")
        ),
    )
    .unwrap();
    let e = MeshAsset::load(&floats).unwrap_err().to_string();
    assert!(e.contains("vertex 0: a float green outside [0, 1]"), "{e}");
}

#[test]
fn a_texture_coordinate_s_v_is_read_and_points_up() {
    // A 1 x 2 texture: row 0 (the image's top) black, row 1 white.
    let png = two_pixel_png(1, 2);
    let mtl = b"newmtl tex\nKd 1 1 1\nmap_Kd t.png\n";
    // v = 0.75 is the top row's centre, v = 0.25 the bottom's; `vt u` alone has v = 0, the
    // bottom edge, half way between the bottom row and the top one it wraps to.
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.75\nvt 0.5 0.25 0.9\nvt 0.5\n\
               usemtl tex\nf 1/1 2/2 3/3\n";
    let (asset, _dir) = read(&[("x.obj", obj.as_bytes()), ("m.mtl", mtl), ("t.png", &png)]);
    let a = asset.unwrap().albedo.unwrap();
    assert_eq!(a.column(0).to_vec(), vec![0.0, 1.0, 0.5]);
}
