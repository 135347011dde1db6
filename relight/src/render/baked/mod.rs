//! Lighting out: a relit mesh written as glTF 2.0 (Khronos 2017, the specification 2.0.1) with
//! its per-vertex radiance baked in, for any viewer to show as it is.
//!
//! **What the file holds.** One node with one triangle primitive: `POSITION` (f32, with the
//! `min`/`max` the specification requires), `NORMAL` (f32, unit), `COLOR_0` (f32 RGB),
//! `_RADIANCE` (f32 RGB, an application-specific attribute: the specification's names start
//! with an underscore) and `u32` indices, the vertices in the order of the mesh (a scene cache's
//! vertex order, the ground plane's last) and the triangles as the mesh winds them
//! (counter-clockwise seen from outside, as glTF's front faces are). The material is
//! `KHR_materials_unlit` (Khronos 2019): a viewer shows the vertex colour as it is instead of
//! lighting it again; its fallback for a viewer without the extension is the specification's
//! default material with `metallicFactor` 0, as the extension's text recommends, which a
//! renderer lights as a white diffuse surface tinted by the vertex colour.
//!
//! **Colours.** glTF's `COLOR_0` is a *linear* multiplier, and a float colour must lie in
//! `[0, 1]` (the Khronos validator's `ACCESSOR_NON_CLAMPED` is an error). Radiance is neither
//! bounded by 1 nor, after a truncated Haar product, always non-negative, so `COLOR_0` is
//! `clamp(2^E L, 0, 1)` per channel, `E` the exposure in stops, computed in f32 (a power of two
//! scales exactly, short of overflow), and `_RADIANCE` is `L` itself, the f32 radiance as
//! rendered, bit for bit. The asset's `extras` say so under `"haarshift"` (a
//! [`BakeInfo`]): the exposure, the scale `2^E`, the environment and its rotation, how the
//! radiance was shaded.
//!
//! **Normals.** A mesh vertex on no triangle of non-zero area has the normal `(0, 0, 0)` (it
//! receives no light; see [`Mesh`]); glTF requires unit normals, so such a vertex is written
//! with `(0, 1, 0)`. Under the unlit material no viewer uses the normals for shading.
//!
//! **Containers.** `.glb` is the binary container (specification section 4.4): a 12-byte
//! header, a JSON chunk padded with spaces and a BIN chunk padded with zeros to 4 bytes,
//! written by the `gltf` crate's `Glb`; `.gltf` is the JSON alone with its one buffer embedded
//! as a base64 `data:` URI, so that either is one self-contained file. Either is written
//! atomically and replaces an existing file only with `force`.
//!
//! **What the Khronos glTF Validator says** (`tools/gltf-validate`, version 2.0.0-dev.3.10, run
//! on every file the command-line tests bake, `.glb` and `.gltf`): no error, no warning, no
//! information and no hint. The underscore attribute is one the specification allows; a mesh
//! with zero-area triangles (kept, as the mesh keeps them) would draw the information
//! `ACCESSOR_INDEX_TRIANGLE_DEGENERATE`, and a clamp left out the error `ACCESSOR_NON_CLAMPED`.
//!
//! ```
//! use haarshift_relight::Mesh;
//! use haarshift_relight::render::baked::{BakeInfo, baked_gltf, GltfContainer};
//! use ndarray::array;
//! let mesh = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]], vec![[0, 1, 2]], None).unwrap();
//! let radiance = array![[0.5f32, 0.25, 2.0], [0.0, 0.0, 0.0], [-0.1, 1.0, 0.5]];
//! let glb = baked_gltf(&mesh, radiance.view(), &BakeInfo::default(), GltfContainer::Glb).unwrap();
//! assert_eq!(&glb[..4], b"glTF");
//! assert_eq!(glb.len() % 4, 0);
//! ```

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::Path;

use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use ndarray::ArrayView2;
use serde::Serialize;

use crate::Mesh;
use crate::{Error, Result};

mod read;

pub use read::BakedGltf;

/// The normal written for a vertex whose mesh normal is zero (see the [module docs](self)).
pub const ZERO_NORMAL_STAND_IN: [f32; 3] = [0.0, 1.0, 0.0];

/// How the baked colours were made, stated in the asset's `extras` under `"haarshift"`.
///
/// ```
/// use haarshift_relight::render::baked::BakeInfo;
/// let info = BakeInfo { exposure: 1.0, ..BakeInfo::default() };
/// assert_eq!(info.colour_scale(), 2.0);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BakeInfo {
    /// The exposure `E`, stops: `COLOR_0 = clamp(2^E L, 0, 1)`.
    pub exposure: f64,
    /// The environment map (its file name), if known.
    pub environment: Option<String>,
    /// The lighting's rotation `[yaw, pitch, roll]`, degrees (`g(p) = f(R p)`).
    pub rotation_degrees: [f64; 3],
    /// How the radiance was shaded (the shader's description).
    pub shading: String,
    /// The scene cache the radiance came from (its file name), if any.
    pub cache: Option<String>,
}

impl Default for BakeInfo {
    /// Exposure 0, no environment named, no rotation, no shading stated.
    fn default() -> Self {
        BakeInfo {
            exposure: 0.0,
            environment: None,
            rotation_degrees: [0.0; 3],
            shading: String::new(),
            cache: None,
        }
    }
}

impl BakeInfo {
    /// `2^exposure`, the factor from radiance to `COLOR_0` before clamping.
    pub fn colour_scale(&self) -> f64 {
        self.exposure.exp2()
    }

    /// Refuses an exposure that is not a finite number from -64 to 64 stops (as
    /// [`to_srgb8`](crate::render::to_srgb8) does).
    ///
    /// ```
    /// use haarshift_relight::render::baked::BakeInfo;
    /// assert!(BakeInfo { exposure: f64::NAN, ..BakeInfo::default() }.check().is_err());
    /// ```
    pub fn check(&self) -> Result<()> {
        if self.exposure.is_finite() && self.exposure.abs() <= 64.0 {
            return Ok(());
        }
        Err(Error::parameter(
            "exposure",
            format!(
                "{} stops (expected a finite number from -64 to 64)",
                self.exposure
            ),
        ))
    }

    /// The `extras` object: this info, the scale and what each attribute holds.
    fn extras(&self) -> serde_json::Value {
        serde_json::json!({
            "haarshift": {
                "exposure_stops": self.exposure,
                "colour_scale": self.colour_scale(),
                "environment": self.environment,
                "rotation_degrees": {
                    "yaw": self.rotation_degrees[0],
                    "pitch": self.rotation_degrees[1],
                    "roll": self.rotation_degrees[2],
                },
                "shading": self.shading,
                "cache": self.cache,
                "COLOR_0": "linear RGB: clamp(colour_scale x radiance, 0, 1) per channel, f32",
                "_RADIANCE": "linear RGB radiance as rendered, f32, unscaled and unclamped",
            }
        })
    }
}

/// The two glTF containers.
///
/// ```
/// use haarshift_relight::render::baked::GltfContainer;
/// assert_eq!(GltfContainer::from_path("a/b.GLB".as_ref()).unwrap(), GltfContainer::Glb);
/// assert_eq!(GltfContainer::from_path("b.gltf".as_ref()).unwrap(), GltfContainer::Gltf);
/// assert!(GltfContainer::from_path("b.obj".as_ref()).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GltfContainer {
    /// Binary glTF (`.glb`): JSON and BIN chunks.
    Glb,
    /// JSON glTF (`.gltf`) with its buffer embedded as a base64 `data:` URI.
    Gltf,
}

impl GltfContainer {
    /// The container a file name asks for (`.glb` or `.gltf`, any case); other names are
    /// refused naming the file.
    pub fn from_path(path: &Path) -> Result<Self> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("glb") => Ok(GltfContainer::Glb),
            Some("gltf") => Ok(GltfContainer::Gltf),
            _ => Err(crate::Error::from(haarshift::Error::Format {
                path: path.to_path_buf(),
                reason: "a baked glTF is written as .glb or .gltf".into(),
            })),
        }
    }
}

/// The baked glTF of `mesh` with `radiance` `(V, 3)` (linear RGB, one row per vertex), in
/// `container`'s bytes; see the [module docs](self) for what it holds.
///
/// Refused: `radiance` with another shape than `(V, 3)`, a NaN or infinite radiance, and a
/// mesh too large for glTF's 32-bit GLB length.
///
/// ```
/// use haarshift_relight::Generator;
/// use haarshift_relight::render::baked::{BakeInfo, baked_gltf, GltfContainer};
/// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let radiance = ndarray::Array2::<f32>::from_elem((mesh.vertex_count(), 3), 0.5);
/// let gltf = baked_gltf(&mesh, radiance.view(), &BakeInfo::default(), GltfContainer::Gltf).unwrap();
/// assert!(String::from_utf8(gltf).unwrap().contains("KHR_materials_unlit"));
/// assert!(baked_gltf(&mesh, radiance.slice(ndarray::s![1.., ..]), &BakeInfo::default(), GltfContainer::Glb).is_err());
/// ```
pub fn baked_gltf(
    mesh: &Mesh,
    radiance: ArrayView2<'_, f32>,
    info: &BakeInfo,
    container: GltfContainer,
) -> Result<Vec<u8>> {
    info.check()?;
    let vertices = mesh.vertex_count();
    if radiance.dim() != (vertices, 3) {
        return Err(crate::Error::from(haarshift::Error::InvalidShape {
            shape: radiance.shape().to_vec(),
            reason: format!("the radiance must be (V, 3) for the mesh's {vertices} vertices"),
        }));
    }
    if let Some(((row, channel), value)) = radiance.indexed_iter().find(|(_, v)| !v.is_finite()) {
        return Err(crate::Error::from(haarshift::Error::NonFinite {
            value: f64::from(*value),
            index: vec![row, channel],
        }));
    }
    let (bin, layout) = pack(mesh, radiance, info)?;
    let root = document(
        &layout,
        vertices,
        mesh.triangles().len(),
        info,
        container,
        &bin,
    )?;
    let text = json::serialize::to_string(&root).map_err(json_error)?;
    match container {
        GltfContainer::Gltf => Ok(text.into_bytes()),
        GltfContainer::Glb => glb(text.into_bytes(), bin),
    }
}

/// Writes [`baked_gltf`] to `path`, the container chosen by its extension
/// ([`GltfContainer::from_path`]), atomically; an existing file is replaced only with `force`.
///
/// ```
/// use haarshift_relight::Generator;
/// use haarshift_relight::render::baked::{BakeInfo, write_baked_gltf};
/// let dir = tempfile::tempdir().unwrap();
/// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let radiance = ndarray::Array2::<f32>::zeros((mesh.vertex_count(), 3));
/// let path = dir.path().join("sphere.glb");
/// write_baked_gltf(&path, &mesh, radiance.view(), &BakeInfo::default(), false).unwrap();
/// assert!(write_baked_gltf(&path, &mesh, radiance.view(), &BakeInfo::default(), false).is_err());
/// ```
pub fn write_baked_gltf(
    path: &Path,
    mesh: &Mesh,
    radiance: ArrayView2<'_, f32>,
    info: &BakeInfo,
    force: bool,
) -> Result<()> {
    let container = GltfContainer::from_path(path)?;
    let bytes = baked_gltf(mesh, radiance, info, container)?;
    Ok(haarshift::io::write_file_atomically(path, force, |w| {
        w.write_all(&bytes)
    })?)
}

/// Where each array lies in the BIN buffer: `(offset, length)` in bytes.
struct Layout {
    positions: (usize, usize),
    normals: (usize, usize),
    colours: (usize, usize),
    radiance: (usize, usize),
    indices: (usize, usize),
    /// The positions' per-axis minimum and maximum, as f32.
    min: [f32; 3],
    max: [f32; 3],
}

/// The BIN buffer: positions, normals, colours, radiance (f32 x 3 each) and indices (u32),
/// little-endian, each array starting at a multiple of 4 (they all are 4-byte elements).
fn pack(mesh: &Mesh, radiance: ArrayView2<'_, f32>, info: &BakeInfo) -> Result<(Vec<u8>, Layout)> {
    let vertices = mesh.vertex_count();
    let attribute = vertices * 12;
    let index_bytes = mesh.triangles().len() * 12;
    let total = 4 * attribute + index_bytes;
    // The GLB length field is 32-bit: header, two chunk headers and the JSON come on top.
    if total > (u32::MAX as usize) / 2 {
        return Err(Error::parameter(
            "mesh",
            format!("{vertices} vertices are too many for one glTF buffer ({total} bytes)"),
        ));
    }
    let mut bin = Vec::with_capacity(total);
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in mesh.positions().outer_iter() {
        for k in 0..3 {
            let x = p[k] as f32;
            min[k] = min[k].min(x);
            max[k] = max[k].max(x);
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    for n in mesh.normals().outer_iter() {
        let n = [n[0] as f32, n[1] as f32, n[2] as f32];
        let n = if n == [0.0; 3] {
            ZERO_NORMAL_STAND_IN
        } else {
            n
        };
        bin.extend(n.iter().flat_map(|x| x.to_le_bytes()));
    }
    let scale = info.colour_scale() as f32;
    bin.extend(
        radiance
            .iter()
            .flat_map(|&x| (x * scale).clamp(0.0, 1.0).to_le_bytes()),
    );
    bin.extend(radiance.iter().flat_map(|x| x.to_le_bytes()));
    bin.extend(
        mesh.triangles()
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes()),
    );
    let layout = Layout {
        positions: (0, attribute),
        normals: (attribute, attribute),
        colours: (2 * attribute, attribute),
        radiance: (3 * attribute, attribute),
        indices: (4 * attribute, index_bytes),
        min,
        max,
    };
    Ok((bin, layout))
}

/// The glTF document of a baked mesh whose BIN buffer is `bin` laid out as `layout`.
// The material's extensions name every field under this crate's features, but another crate
// of the build may turn on more of gltf-json's (other KHR extensions), which add fields: the
// struct update keeps this compiling then.
#[allow(clippy::needless_update)]
fn document(
    layout: &Layout,
    vertices: usize,
    triangles: usize,
    info: &BakeInfo,
    container: GltfContainer,
    bin: &[u8],
) -> Result<json::Root> {
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("haarshift {}", env!("CARGO_PKG_VERSION"))),
            extras: Some(raw(&info.extras())?),
            ..json::Asset::default()
        },
        extensions_used: vec!["KHR_materials_unlit".into()],
        ..json::Root::default()
    };
    let uri = match container {
        GltfContainer::Glb => None,
        GltfContainer::Gltf => Some(format!(
            "data:application/octet-stream;base64,{}",
            data_encoding::BASE64.encode(bin)
        )),
    };
    let buffer = root.push(json::Buffer {
        byte_length: USize64::from(bin.len()),
        name: None,
        uri,
        extensions: None,
        extras: None,
    });
    let mut view = |(offset, length): (usize, usize), target| {
        root.push(json::buffer::View {
            buffer,
            byte_length: USize64::from(length),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: Some(Valid(target)),
            extensions: None,
            extras: None,
        })
    };
    let vertex_views = [
        layout.positions,
        layout.normals,
        layout.colours,
        layout.radiance,
    ]
    .map(|range| view(range, json::buffer::Target::ArrayBuffer));
    let index_view = view(layout.indices, json::buffer::Target::ElementArrayBuffer);
    let bounds = |b: [f32; 3]| Some(json::Value::from(b.to_vec()));
    let accessor = |view, count, component, type_, min, max| json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64::from(count),
        component_type: Valid(json::accessor::GenericComponentType(component)),
        extensions: None,
        extras: None,
        type_: Valid(type_),
        min,
        max,
        name: None,
        normalized: false,
        sparse: None,
    };
    use json::accessor::{ComponentType, Type};
    let [positions, normals, colours, radiance] = [
        (vertex_views[0], bounds(layout.min), bounds(layout.max)),
        (vertex_views[1], None, None),
        (vertex_views[2], None, None),
        (vertex_views[3], None, None),
    ]
    .map(|(view, min, max)| {
        root.push(accessor(
            view,
            vertices,
            ComponentType::F32,
            Type::Vec3,
            min,
            max,
        ))
    });
    let indices = root.push(accessor(
        index_view,
        3 * triangles,
        ComponentType::U32,
        Type::Scalar,
        None,
        None,
    ));
    let material = root.push(json::Material {
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            metallic_factor: json::material::StrengthFactor(0.0),
            ..Default::default()
        },
        extensions: Some(json::extensions::material::Material {
            unlit: Some(json::extensions::material::Unlit {}),
            ..Default::default()
        }),
        name: Some("baked radiance (unlit)".into()),
        ..Default::default()
    });
    use json::mesh::Semantic;
    let attributes = BTreeMap::from([
        (Valid(Semantic::Positions), positions),
        (Valid(Semantic::Normals), normals),
        (Valid(Semantic::Colors(0)), colours),
        (Valid(Semantic::Extras("RADIANCE".into())), radiance),
    ]);
    let mesh = root.push(json::Mesh {
        primitives: vec![json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: None,
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }],
        name: Some("relit".into()),
        extensions: None,
        extras: None,
        weights: None,
    });
    let node = root.push(json::Node {
        mesh: Some(mesh),
        ..Default::default()
    });
    let scene = root.push(json::Scene {
        nodes: vec![node],
        name: None,
        extensions: None,
        extras: None,
    });
    root.scene = Some(scene);
    Ok(root)
}

/// `value` as the raw JSON an `extras` field holds.
fn raw(value: &serde_json::Value) -> Result<Box<serde_json::value::RawValue>> {
    serde_json::value::to_raw_value(value).map_err(json_error)
}

/// The GLB container of `json` and `bin` (the `gltf` crate pads the JSON with spaces and the
/// BIN chunk with zeros).
fn glb(json: Vec<u8>, bin: Vec<u8>) -> Result<Vec<u8>> {
    let padded = |n: usize| n.div_ceil(4) * 4;
    let length = 12 + 8 + padded(json.len()) + 8 + padded(bin.len());
    let length = u32::try_from(length).map_err(|_| {
        Error::parameter(
            "mesh",
            format!("{length} bytes exceed the GLB's 32-bit length"),
        )
    })?;
    let file = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length,
        },
        json: Cow::Owned(json),
        bin: Some(Cow::Owned(bin)),
    };
    file.to_vec()
        .map_err(|e| Error::parameter("glTF", format!("the GLB container: {e}")))
}

/// A serialisation failure (none is expected: every value is finite).
fn json_error(e: impl std::fmt::Display) -> Error {
    Error::parameter("glTF", format!("the JSON document: {e}"))
}

#[cfg(test)]
mod tests;
