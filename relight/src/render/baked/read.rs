//! Reading a baked glTF back: the arrays a file holds, found through its JSON document's
//! accessors and buffer views (not through the writer's layout), for the tests that check a
//! bake bit for bit and for anyone who wants the exact radiance out of a file.

use std::path::Path;

use gltf::Semantic;
use gltf::accessor::{DataType, Dimensions};
use ndarray::Array2;

use crate::Result;
use crate::scene::asset_path::decode_data_uri;
use crate::scene::gltf_file::parse;

/// A baked glTF's first primitive, as stored: every attribute f32 `(V, 3)`, the triangles
/// from its `u32` indices, and the asset's `extras`.
///
/// Only what [`baked_gltf`](super::baked_gltf) writes is read: f32 VEC3 attributes and
/// `u32` indices, tightly packed, in the GLB's BIN chunk or a base64 `data:` URI. Anything
/// else (another layout, an external buffer, an accessor beyond its view) is refused in one
/// line naming the file.
///
/// ```
/// use haarshift_relight::Generator;
/// use haarshift_relight::render::baked::{BakeInfo, BakedGltf, write_baked_gltf};
/// let dir = tempfile::tempdir().unwrap();
/// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let radiance = ndarray::Array2::<f32>::from_elem((mesh.vertex_count(), 3), 3.0);
/// let path = dir.path().join("sphere.gltf");
/// write_baked_gltf(&path, &mesh, radiance.view(), &BakeInfo::default(), false).unwrap();
/// let back = BakedGltf::read(&path).unwrap();
/// assert_eq!(back.radiance, radiance);
/// assert!(back.colours.iter().all(|&c| c == 1.0)); // clamped
/// assert_eq!(back.triangles, mesh.triangles());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct BakedGltf {
    /// `POSITION`, `(V, 3)`.
    pub positions: Array2<f32>,
    /// `NORMAL`, `(V, 3)`.
    pub normals: Array2<f32>,
    /// `COLOR_0`, `(V, 3)`, linear.
    pub colours: Array2<f32>,
    /// `_RADIANCE`, `(V, 3)`, linear.
    pub radiance: Array2<f32>,
    /// The triangles, three indices each.
    pub triangles: Vec<[u32; 3]>,
    /// The asset's `extras` (`null` when it has none).
    pub extras: serde_json::Value,
}

impl BakedGltf {
    /// Reads `path` (`.glb` or `.gltf`, by its first bytes).
    pub fn read(path: &Path) -> Result<Self> {
        let bytes =
            std::fs::read(path).map_err(|source| crate::Error::io(path.to_path_buf(), source))?;
        Self::from_bytes(&bytes).map_err(|reason| {
            crate::Error::from(haarshift::Error::Format {
                path: path.to_path_buf(),
                reason,
            })
        })
    }

    /// Reads a file's bytes; the error says what is wrong.
    ///
    /// ```
    /// use haarshift_relight::render::baked::BakedGltf;
    /// assert!(BakedGltf::from_bytes(b"glTF\x02\0\0\0\x0c\0\0\0").is_err());
    /// ```
    pub fn from_bytes(bytes: &[u8]) -> std::result::Result<Self, String> {
        let file = parse(bytes).map_err(|e| e.to_string())?;
        let buffer = match (file.buffers().next(), file.blob.as_deref()) {
            (Some(buffer), blob) => match buffer.source() {
                gltf::buffer::Source::Bin => blob
                    .map(<[u8]>::to_vec)
                    .ok_or("the buffer names a BIN chunk the file does not have")?,
                gltf::buffer::Source::Uri(uri) => uri
                    .strip_prefix("data:")
                    .and_then(decode_data_uri)
                    .ok_or("the buffer is not embedded (a base64 data: URI)")?,
            },
            (None, _) => return Err("no buffer".into()),
        };
        let primitive = file
            .meshes()
            .next()
            .and_then(|m| m.primitives().next())
            .ok_or("no mesh primitive")?;
        let attribute = |semantic: Semantic| {
            let name = format!("{semantic:?}");
            let accessor = primitive
                .get(&semantic)
                .ok_or_else(|| format!("no {name} attribute"))?;
            let values = floats(&accessor, &buffer, DataType::F32, Dimensions::Vec3)
                .map_err(|e| format!("{name}: {e}"))?;
            Array2::from_shape_vec((accessor.count(), 3), values).map_err(|e| e.to_string())
        };
        let indices = primitive.indices().ok_or("no indices")?;
        let flat = read_words(&indices, &buffer, DataType::U32, Dimensions::Scalar)
            .map_err(|e| format!("indices: {e}"))?;
        if flat.len() % 3 != 0 {
            return Err(format!("{} indices: not whole triangles", flat.len()));
        }
        let extras = match &file.as_json().asset.extras {
            Some(raw) => serde_json::from_str(raw.get()).map_err(|e| format!("extras: {e}"))?,
            None => serde_json::Value::Null,
        };
        Ok(BakedGltf {
            positions: attribute(Semantic::Positions)?,
            normals: attribute(Semantic::Normals)?,
            colours: attribute(Semantic::Colors(0))?,
            radiance: attribute(Semantic::Extras("RADIANCE".into()))?,
            triangles: flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
            extras,
        })
    }
}

/// An f32 accessor's values.
fn floats(
    accessor: &gltf::Accessor<'_>,
    buffer: &[u8],
    data_type: DataType,
    dimensions: Dimensions,
) -> std::result::Result<Vec<f32>, String> {
    Ok(read_words(accessor, buffer, data_type, dimensions)?
        .into_iter()
        .map(f32::from_bits)
        .collect())
}

/// The 4-byte little-endian words of a tightly packed accessor of `data_type` and
/// `dimensions`, bounds-checked against its view and the buffer.
fn read_words(
    accessor: &gltf::Accessor<'_>,
    buffer: &[u8],
    data_type: DataType,
    dimensions: Dimensions,
) -> std::result::Result<Vec<u32>, String> {
    if accessor.data_type() != data_type || accessor.dimensions() != dimensions {
        return Err(format!(
            "{:?} {:?}, expected {data_type:?} {dimensions:?}",
            accessor.data_type(),
            accessor.dimensions()
        ));
    }
    let view = accessor.view().ok_or("no buffer view")?;
    let element = 4 * dimensions.multiplicity();
    if view.stride().is_some_and(|s| s != element) {
        return Err("not tightly packed".into());
    }
    let length = accessor
        .count()
        .checked_mul(element)
        .ok_or("too many elements")?;
    let start = view.offset().saturating_add(accessor.offset());
    let end = start.saturating_add(length);
    if accessor.offset().saturating_add(length) > view.length() || end > buffer.len() {
        return Err(format!(
            "bytes {start}..{end} beyond its view or the buffer ({} bytes)",
            buffer.len()
        ));
    }
    Ok(buffer[start..end]
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect())
}
