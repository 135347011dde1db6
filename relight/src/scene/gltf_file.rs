//! glTF 2.0 scenes in (`.gltf` with external or `data:` buffers, and `.glb`), per the
//! Khronos glTF 2.0 specification (2021): the document is parsed and validated by the `gltf`
//! crate ([`gltf::Gltf::from_slice`]), and everything it names is resolved here, so that
//! every path is checked ([`super::asset_path`]) and every count budgeted before anything is
//! opened or allocated.
//!
//! * **What is read.** The default scene (`scene`, else scene 0): its nodes depth first in
//!   the order listed (a node, then its children), and of each node's mesh every primitive
//!   in order. A mesh used by several nodes is read once per node. Vertex order is that
//!   order: a primitive's vertices in accessor order, primitives one after another. Primitives
//!   must be triangle lists (mode 4, the default); any other mode is refused. Skins, morph
//!   targets, cameras and animations are not read (the rest pose). Nodes must form trees,
//!   as the spec requires: a node with two parents, or a root that has a parent, is refused,
//!   so the traversal ends.
//! * **Transforms.** Each node's `matrix` or TRS (`gltf`'s [`gltf::scene::Transform::matrix`])
//!   composed down the hierarchy in f64, parent times child: positions by `M p + t`, normals
//!   by the cofactor matrix of `M`'s 3 x 3 part (its inverse transpose times `det M`) times
//!   `sign(det M)`, then normalised; a negative determinant (a mirrored node) reverses every
//!   triangle's winding so that triangles stay counter-clockwise seen from the (transformed)
//!   outside. A non-finite matrix is refused.
//! * **Normals.** `NORMAL` as stored; absent (or zero at a vertex), the area-weighted normals
//!   of [`super::mesh`], computed in the primitive's own frame and transformed like stored
//!   ones.
//! * **Albedo** (linear RGB per vertex): `baseColorFactor` x `baseColorTexture` (sampled as
//!   [`super::texture`] says at the texture's `TEXCOORD_n`, with its sampler's wrap modes and
//!   `magFilter`) x `COLOR_0` (linear, spec section 3.7.2.1; alpha dropped). A primitive
//!   without a material takes the spec's default material: factor 1, no texture. A material
//!   that is metallic (`metallicFactor > 0`) or glossy (`roughnessFactor < 1`) is reported
//!   once as approximated by its base colour: a static cache is Lambertian. (The spec's
//!   default material is fully metallic too; it has no colour to lose and is not reported.)
//! * **Accessors.** `POSITION` and `NORMAL` are float VEC3; `TEXCOORD_n` float, or
//!   normalised unsigned byte or short, VEC2; `COLOR_0` float or normalised unsigned byte or
//!   short, VEC3 or VEC4; indices unsigned byte, short or int. Sparse accessors and accessors
//!   without a buffer view are refused. Every accessor's last byte is checked against its view
//!   and every view against its buffer with checked arithmetic; an index at or beyond the
//!   primitive's vertex count, and a NaN or infinite position, are refused.
//! * **Budget.** The file, each buffer's `byteLength` and each texture's decoded size are
//!   checked against the [`MemoryBudget`]'s limit before they are read, and the vertices of
//!   all instances (and half their triangles, counted as vertices: the budget's per-vertex
//!   bytes assume about two triangles a vertex) before any accessor is read.

use std::collections::HashMap;
use std::path::Path;

use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use gltf::texture::{MagFilter, WrappingMode};
use ndarray::Array2;

use crate::Mesh;
use crate::SceneError;
use crate::scene::asset::MeshAsset;
use crate::scene::asset_path::{AssetSource, read_limited, resolve};
use crate::scene::texture::{Filter, Texture, Wrap};
use crate::scene::validate::MemoryBudget;
use crate::{Error, Result};

/// An error about `part` of the asset.
fn asset_error(part: impl Into<String>, reason: impl std::fmt::Display) -> Error {
    SceneError::Asset {
        part: part.into(),
        reason: reason.to_string(),
    }
    .into()
}

/// The document in `bytes` (`.glb` by its magic, else JSON), validated by the `gltf` crate
/// after what its validation would panic on is refused; every glTF the crate reads (assets
/// here, baked files in `render::baked`) comes through this.
pub(crate) fn parse(bytes: &[u8]) -> Result<gltf::Gltf> {
    let invalid = |e: gltf::Error| SceneError::Corrupt(format!("not a valid glTF 2.0 file: {e}"));
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(invalid)?;
    // gltf-json 1.4.1's validation indexes a primitive's POSITION accessor before checking
    // that it exists (mesh.rs, `primitive_validate_hook`), and panics on one that does not:
    // found by the gltf fuzz target, so checked first. Then the images, as below.
    let json = document.into_json();
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = gltf_json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(index) = primitive.attributes.get(&position)
                && index.value() >= accessors
            {
                return Err(SceneError::Corrupt(format!(
                    "mesh {m}, primitive {p}: its POSITION accessor {} is not among the file's {accessors}",
                    index.value()
                ))
                .into());
            }
        }
    }
    // gltf 1.4.1's `Image::source` unwraps a uri where there is no bufferView, and a mimeType
    // where there is one (the spec's rule for both, which its validation does not check):
    // also found by the fuzz target.
    for (k, image) in json.images.iter().enumerate() {
        let why = match (&image.uri, &image.buffer_view, &image.mime_type) {
            (None, None, _) => "names neither a uri nor a bufferView",
            (Some(_), Some(_), _) => "names both a uri and a bufferView",
            (None, Some(_), None) => "is in a bufferView but has no mimeType",
            _ => continue,
        };
        return Err(SceneError::Corrupt(format!("image {k} {why}")).into());
    }
    let document = gltf::Document::from_json(json).map_err(invalid)?;
    Ok(gltf::Gltf { document, blob })
}

/// Reads a `.gltf` or `.glb` file; see the [module docs](self).
pub(crate) fn read_gltf(path: &Path, budget: &MemoryBudget) -> Result<MeshAsset> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let bytes = read_limited(path, None, budget.limit)?;
    let gltf = parse(&bytes)?;
    let buffers = load_buffers(&gltf, dir, budget)?;
    let instances = instances(&gltf.document)?;
    check_counts(&instances, budget)?;
    let mut reader = Reader {
        buffers: &buffers,
        dir,
        budget,
        textures: HashMap::new(),
        warned: Vec::new(),
        warnings: Vec::new(),
    };
    let mut mesh: Option<Mesh> = None;
    let mut albedo = Array2::<f32>::zeros((0, 3));
    for instance in &instances {
        for primitive in instance.mesh.primitives() {
            let part = format!(
                "node {}, mesh {}, primitive {}",
                instance.node,
                instance.mesh.index(),
                primitive.index()
            );
            let (shape, colour) = reader
                .primitive(&primitive, &instance.matrix)
                .map_err(|e| within(&part, e))?;
            albedo
                .append(ndarray::Axis(0), colour.view())
                .expect("(V, 3)");
            match &mut mesh {
                None => mesh = Some(shape),
                Some(m) => m.append(&shape),
            }
        }
    }
    let mesh = mesh.ok_or(SceneError::NoFaces)?;
    Ok(MeshAsset {
        mesh,
        albedo: Some(albedo),
        warnings: reader.warnings,
    })
}

/// `e` as an asset error of `part` (a scene error without a file gets the part in front;
/// others, such as a memory budget's or a file's, keep their own message).
fn within(part: &str, e: Error) -> Error {
    match e {
        Error::Scene { path: None, source } => asset_error(part, source),
        other => other,
    }
}

/// Every buffer's bytes, cut to its `byteLength`: the GLB's BIN chunk, a `data:` URI, or a
/// file in the asset's folder.
fn load_buffers(gltf: &gltf::Gltf, dir: &Path, budget: &MemoryBudget) -> Result<Vec<Vec<u8>>> {
    gltf.document
        .buffers()
        .map(|buffer| {
            let part = format!("buffer {}", buffer.index());
            let length = buffer.length();
            let mut data = match buffer.source() {
                gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                    asset_error(&part, "names the GLB's BIN chunk, which the file lacks")
                })?,
                gltf::buffer::Source::Uri(uri) => match resolve(&part, uri, dir)? {
                    AssetSource::Data(bytes) => bytes,
                    AssetSource::File(file) => {
                        read_limited(&file, Some(length as u64), budget.limit)
                            .map_err(|e| asset_error(&part, e))?
                    }
                },
            };
            if data.len() < length {
                return Err(asset_error(
                    &part,
                    format!("holds {} bytes, its byteLength says {length}", data.len()),
                ));
            }
            data.truncate(length);
            Ok(data)
        })
        .collect()
}

/// One node of the default scene that has a mesh, with its world matrix.
struct Instance<'a> {
    node: usize,
    mesh: gltf::Mesh<'a>,
    matrix: [[f64; 4]; 4],
}

/// The default scene's nodes with meshes, depth first, their matrices composed; refuses
/// nodes that are not trees and non-finite matrices.
fn instances(document: &gltf::Document) -> Result<Vec<Instance<'_>>> {
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| SceneError::Corrupt("the glTF has no scene".into()))?;
    let mut parents = vec![0usize; document.nodes().len()];
    for node in document.nodes() {
        for child in node.children() {
            parents[child.index()] += 1;
        }
    }
    if let Some(node) = parents.iter().position(|&p| p > 1) {
        return Err(asset_error(
            format!("node {node}"),
            "has more than one parent (glTF nodes form trees)",
        ));
    }
    let mut out = Vec::new();
    let mut roots_seen = vec![false; parents.len()];
    let identity = std::array::from_fn(|c| std::array::from_fn(|r| f64::from(u8::from(r == c))));
    let mut stack = Vec::new();
    for root in scene.nodes().collect::<Vec<_>>().into_iter().rev() {
        let k = root.index();
        if parents[k] > 0 || std::mem::replace(&mut roots_seen[k], true) {
            return Err(asset_error(
                format!("node {k}"),
                "is a root of the scene and has a parent or is listed twice (glTF nodes form trees)",
            ));
        }
        stack.push((root, identity));
    }
    while let Some((node, parent)) = stack.pop() {
        let local = node.transform().matrix().map(|c| c.map(f64::from));
        let matrix = multiply(&parent, &local);
        if matrix.iter().flatten().any(|x| !x.is_finite()) {
            return Err(asset_error(
                format!("node {}", node.index()),
                "has a transform that is not finite (NaN or beyond f32) once composed",
            ));
        }
        if let Some(mesh) = node.mesh() {
            out.push(Instance {
                node: node.index(),
                mesh,
                matrix,
            });
        }
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, matrix));
        }
    }
    Ok(out)
}

/// `a b` of column-major 4 x 4 matrices (`m[column][row]`, glTF's layout).
fn multiply(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    std::array::from_fn(|c| std::array::from_fn(|r| (0..4).map(|k| a[k][r] * b[c][k]).sum()))
}

/// Refuses the instances' vertices (and half their triangles) past the budget, from the
/// accessors' counts alone.
fn check_counts(instances: &[Instance<'_>], budget: &MemoryBudget) -> Result<()> {
    let (mut vertices, mut corners) = (0u128, 0u128);
    for instance in instances {
        for primitive in instance.mesh.primitives() {
            let count = primitive
                .get(&Semantic::Positions)
                .map_or(0, |a| a.count() as u128);
            vertices += count;
            corners += primitive.indices().map_or(count, |a| a.count() as u128);
        }
    }
    budget.check(
        "the glTF's primitives, every instance counted",
        vertices.max(corners / 6),
    )
}

/// Reads primitives; decoded textures are kept by image index.
struct Reader<'a> {
    buffers: &'a [Vec<u8>],
    dir: &'a Path,
    budget: &'a MemoryBudget,
    textures: HashMap<usize, Texture>,
    warned: Vec<usize>,
    warnings: Vec<String>,
}

impl Reader<'_> {
    /// A primitive's mesh in world space and its albedo, `(V, 3)`.
    fn primitive(
        &mut self,
        primitive: &gltf::Primitive<'_>,
        matrix: &[[f64; 4]; 4],
    ) -> Result<(Mesh, Array2<f32>)> {
        if primitive.mode() != Mode::Triangles {
            return Err(SceneError::Corrupt(format!(
                "mode {:?}: only triangle lists (mode 4) are read",
                primitive.mode()
            ))
            .into());
        }
        let positions = primitive
            .get(&Semantic::Positions)
            .ok_or_else(|| SceneError::Corrupt("no POSITION attribute".into()))?;
        let positions = Elements::of(&positions, "POSITION", self.buffers, FLOAT, &[3])?;
        let v = positions.count;
        let per_vertex = |accessor: Option<gltf::Accessor<'_>>,
                          name: &str,
                          kinds: &[Kind],
                          dims: &[usize]|
         -> Result<Option<Elements<'_>>> {
            let Some(accessor) = accessor else {
                return Ok(None);
            };
            let e = Elements::of(&accessor, name, self.buffers, kinds, dims)?;
            if e.count != v {
                return Err(asset_error(
                    e.part.clone(),
                    format!("has {} elements for {v} vertices", e.count),
                ));
            }
            Ok(Some(e))
        };
        let normals = per_vertex(primitive.get(&Semantic::Normals), "NORMAL", FLOAT, &[3])?;
        let colours = per_vertex(
            primitive.get(&Semantic::Colors(0)),
            "COLOR_0",
            COLOUR,
            &[3, 4],
        )?;
        let triangles = match primitive.indices() {
            None if v % 3 == 0 => (0..v as u32 / 3)
                .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect(),
            None => {
                return Err(SceneError::Corrupt(format!(
                    "{v} vertices without indices is not a list of triangles"
                ))
                .into());
            }
            Some(indices) => {
                let e = Elements::of(&indices, "indices", self.buffers, INDEX, &[1])?;
                if e.count % 3 != 0 {
                    return Err(asset_error(
                        e.part,
                        format!("{} indices is not a list of triangles", e.count),
                    ));
                }
                let mut triangles = Vec::with_capacity(e.count / 3);
                for t in 0..e.count / 3 {
                    let mut tri = [0u32; 3];
                    for (c, slot) in tri.iter_mut().enumerate() {
                        let i = e.get(3 * t + c, 0);
                        if i >= v as f64 {
                            return Err(SceneError::IndexOutOfRange {
                                triangle: t,
                                index: i as u64,
                                vertices: v,
                            }
                            .into());
                        }
                        *slot = i as u32;
                    }
                    triangles.push(tri);
                }
                triangles
            }
        };
        let to_array = |e: &Elements<'_>| Array2::from_shape_fn((v, 3), |(k, c)| e.get(k, c));
        let local = Mesh::new(
            to_array(&positions),
            triangles,
            normals.as_ref().map(to_array),
        )?;
        let linear: [[f64; 3]; 3] = std::array::from_fn(|c| std::array::from_fn(|r| matrix[c][r]));
        let cofactor = cofactor(&linear);
        let det: f64 = (0..3).map(|r| linear[0][r] * cofactor[0][r]).sum();
        let sign = if det < 0.0 { -1.0 } else { 1.0 };
        let world = local.mapped(
            |p| {
                std::array::from_fn(|r| {
                    (0..3).map(|c| linear[c][r] * p[c]).sum::<f64>() + matrix[3][r]
                })
            },
            |n| std::array::from_fn(|r| sign * (0..3).map(|c| cofactor[c][r] * n[c]).sum::<f64>()),
        )?;
        let world = if det < 0.0 { world.reversed() } else { world };
        let albedo = self.albedo(primitive, v, colours.as_ref())?;
        Ok((world, albedo))
    }

    /// The primitive's albedo: factor x texture x `COLOR_0`.
    fn albedo(
        &mut self,
        primitive: &gltf::Primitive<'_>,
        v: usize,
        colours: Option<&Elements<'_>>,
    ) -> Result<Array2<f32>> {
        let material = primitive.material();
        let pbr = material.pbr_metallic_roughness();
        if let Some(m) = material.index() {
            let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
            if (metallic > 0.0 || roughness < 1.0) && !self.warned.contains(&m) {
                self.warned.push(m);
                self.warnings.push(format!(
                    "material {m} is metallic or glossy (metallicFactor {metallic}, roughnessFactor {roughness}): approximated by its base colour (a static cache is Lambertian)"
                ));
            }
        }
        let factor = pbr.base_color_factor();
        let mut albedo = Array2::from_shape_fn((v, 3), |(_, c)| factor[c]);
        if let Some(info) = pbr.base_color_texture() {
            let set = info.tex_coord();
            let accessor = primitive.get(&Semantic::TexCoords(set)).ok_or_else(|| {
                SceneError::Corrupt(format!(
                    "its material's baseColorTexture reads TEXCOORD_{set}, which it lacks"
                ))
            })?;
            let name = format!("TEXCOORD_{set}");
            let uv = Elements::of(&accessor, &name, self.buffers, TEXCOORD, &[2])?;
            if uv.count != v {
                return Err(asset_error(
                    uv.part,
                    format!("has {} elements for {v} vertices", uv.count),
                ));
            }
            let texture = info.texture();
            let sampler = texture.sampler();
            let wrap = [sampler.wrap_s(), sampler.wrap_t()].map(|w| match w {
                WrappingMode::ClampToEdge => Wrap::ClampToEdge,
                WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
                WrappingMode::Repeat => Wrap::Repeat,
            });
            let filter = match sampler.mag_filter() {
                Some(MagFilter::Nearest) => Filter::Nearest,
                _ => Filter::Linear,
            };
            let image = self.texture(texture.source())?;
            for (k, mut row) in albedo.outer_iter_mut().enumerate() {
                let t = image.sample([uv.get(k, 0), uv.get(k, 1)], wrap, filter);
                for c in 0..3 {
                    row[c] *= t[c];
                }
            }
        }
        if let Some(colours) = colours {
            for (k, mut row) in albedo.outer_iter_mut().enumerate() {
                for c in 0..3 {
                    row[c] *= colours.get(k, c) as f32;
                }
            }
        }
        Ok(albedo)
    }

    /// Image `image` decoded (once).
    fn texture(&mut self, image: gltf::Image<'_>) -> Result<&Texture> {
        let k = image.index();
        if !self.textures.contains_key(&k) {
            let part = format!("image {k}");
            let bytes = match image.source() {
                gltf::image::Source::View { view, .. } => {
                    view_bytes(&view, self.buffers, &part)?.to_vec()
                }
                gltf::image::Source::Uri { uri, .. } => match resolve(&part, uri, self.dir)? {
                    AssetSource::Data(bytes) => bytes,
                    AssetSource::File(file) => read_limited(&file, None, self.budget.limit)
                        .map_err(|e| asset_error(&part, e))?,
                },
            };
            let texture =
                Texture::decode(&bytes, Path::new(&part), self.budget.limit).map_err(|e| {
                    asset_error(
                        &part,
                        e.to_string().trim_start_matches(&format!("{part}: ")),
                    )
                })?;
            self.textures.insert(k, texture);
        }
        Ok(&self.textures[&k])
    }
}

/// The cofactor matrix of a column-major 3 x 3 `m` (`m[column][row]`): `det(m) m^-T`, defined
/// for every `m`.
fn cofactor(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    // Column c of the cofactor matrix is the cross product of m's other two columns.
    let cross = super::mesh::cross;
    [cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1])]
}

/// The bytes of a buffer view, checked against its buffer.
fn view_bytes<'b>(
    view: &gltf::buffer::View<'_>,
    buffers: &'b [Vec<u8>],
    part: &str,
) -> Result<&'b [u8]> {
    let buffer = &buffers[view.buffer().index()];
    view.offset()
        .checked_add(view.length())
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            asset_error(
                part,
                format!(
                    "buffer view {} (bytes {} + {}) runs past its buffer's {} bytes",
                    view.index(),
                    view.offset(),
                    view.length(),
                    buffer.len()
                ),
            )
        })
}

/// A component type an attribute may have, and whether it must be normalised.
type Kind = (DataType, bool);
const FLOAT: &[Kind] = &[(DataType::F32, false)];
const TEXCOORD: &[Kind] = &[
    (DataType::F32, false),
    (DataType::U8, true),
    (DataType::U16, true),
];
const COLOUR: &[Kind] = TEXCOORD;
const INDEX: &[Kind] = &[
    (DataType::U8, false),
    (DataType::U16, false),
    (DataType::U32, false),
];

/// An accessor's elements, bounds checked once: element `k`'s component `c` is read from
/// `bytes[k * stride + c * size..]`.
struct Elements<'b> {
    part: String,
    bytes: &'b [u8],
    count: usize,
    stride: usize,
    data_type: DataType,
    normalized: bool,
}

impl<'b> Elements<'b> {
    /// `accessor` (the attribute `name`) checked to be of one of `kinds` with one of `dims`
    /// components and to lie inside its view and buffer.
    fn of(
        accessor: &gltf::Accessor<'_>,
        name: &str,
        buffers: &'b [Vec<u8>],
        kinds: &[Kind],
        dims: &[usize],
    ) -> Result<Elements<'b>> {
        let part = format!("{name} (accessor {})", accessor.index());
        let bad = |reason: String| asset_error(&part, reason);
        let (data_type, normalized) = (accessor.data_type(), accessor.normalized());
        let components = match accessor.dimensions() {
            Dimensions::Scalar => 1,
            Dimensions::Vec2 => 2,
            Dimensions::Vec3 => 3,
            Dimensions::Vec4 => 4,
            _ => 0,
        };
        if !kinds.contains(&(data_type, normalized)) || !dims.contains(&components) {
            return Err(bad(format!(
                "{:?} x {:?}{} is not a type this attribute may have",
                accessor.dimensions(),
                data_type,
                if normalized { " (normalized)" } else { "" }
            )));
        }
        if accessor.sparse().is_some() {
            return Err(bad("is sparse; sparse accessors are not read".into()));
        }
        let view = accessor
            .view()
            .ok_or_else(|| bad("has no bufferView; such accessors are not read".into()))?;
        let bytes = view_bytes(&view, buffers, &part)?;
        let size = data_type.size();
        let element = size * components;
        let stride = view.stride().unwrap_or(element);
        let count = accessor.count();
        let end = count.checked_sub(1).map_or(Some(0), |last| {
            last.checked_mul(stride)?
                .checked_add(element)?
                .checked_add(accessor.offset())
        });
        match end {
            Some(end) if stride >= element && end <= bytes.len() => Ok(Elements {
                bytes: &bytes[accessor.offset().min(bytes.len())..],
                part,
                count,
                stride,
                data_type,
                normalized,
            }),
            _ => Err(bad(format!(
                "{count} elements of {element} bytes every {stride} from byte {} run past its buffer view's {} bytes",
                accessor.offset(),
                bytes.len()
            ))),
        }
    }

    /// Element `k`'s component `c` (`k < count`, `c <` the components: checked in `of`), a
    /// normalised integer divided by its maximum.
    fn get(&self, k: usize, c: usize) -> f64 {
        let at = k * self.stride + c * self.data_type.size();
        let b = &self.bytes[at..];
        let (value, max) = match self.data_type {
            DataType::U8 => (f64::from(b[0]), 255.0),
            DataType::U16 => (f64::from(u16::from_le_bytes([b[0], b[1]])), 65535.0),
            DataType::U32 => (f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])), 1.0),
            DataType::F32 => (f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])), 1.0),
            DataType::I8 | DataType::I16 => (0.0, 1.0),
        };
        if self.normalized { value / max } else { value }
    }
}

#[cfg(test)]
#[path = "gltf_file_tests.rs"]
mod tests;
