//! Wavefront OBJ meshes, with MTL materials ([`super::mtl`]).
//!
//! Statements read: `v x y z [w]`, `vn x y z`, `vt u [v [w]]`, `f` with `a`, `a/t`, `a/t/n`
//! or `a//n` corners (1-based, or negative for relative; polygons triangulated as fans),
//! `mtllib FILE...` (each a library in the OBJ's folder, confined to it by
//! [`super::asset_path`]) and `usemtl NAME` (the material of the faces after it, looked up in
//! every library the file names). Objects and groups are merged; every other statement is
//! ignored. File normals are used only when every corner's normal index equals its position
//! index (the only way they can be per-vertex normals).
//!
//! **Vertex order.** A file whose faces use no material (no `usemtl`, or none before any face)
//! is read as geometry only, `vt` ignored: vertex `k` is the file's `k`-th `v`, exactly as
//! before materials were read. A file whose faces use materials carries colour, and a
//! position may then need several vertices: one per (position, texture coordinate, material)
//! its corners use (the texture coordinate counts only for a material with a `map_Kd`). Vertex
//! `k < V` (`V` the file's `v` count) is still position `k`, with the first such triple a
//! corner gives it (in face order); every further triple of a position is a new vertex after
//! those, in the order faces first use it. All vertices of one position share the normal the
//! position has in the geometry-only reading (file or area-weighted over all its faces), so
//! splitting adds no seam to the shading.
//!
//! **Albedo.** A corner's material's `Kd` times its `map_Kd` sampled at `(u, 1 - v)` (OBJ's
//! `v` points up, the texture's rows down; [`super::texture`]); a textured material's corner
//! without `vt` takes `Kd` alone; a face before any `usemtl`, and a position no face uses,
//! takes haarshift's default 0.8.

use std::collections::HashMap;
use std::path::Path;

use ndarray::Array2;

use crate::Result;
use crate::scene::asset::MeshAsset;
use crate::scene::asset_path::{AssetSource, read_limited, resolve};
use crate::scene::file::DEFAULT_ALBEDO;
use crate::scene::mesh::corrupt;
use crate::scene::mtl::{MtlMaterial, read_mtl};
use crate::scene::texture::{Filter, Wrap};
use crate::scene::validate::MemoryBudget;
use crate::{Mesh, SceneError};

/// Reads an OBJ file (and the libraries it names) within `budget`'s byte limit.
pub(crate) fn read_obj(path: &Path, budget: &MemoryBudget) -> Result<MeshAsset> {
    let text = read_limited(path, None, budget.limit)?;
    // A UTF-8 byte-order mark would otherwise hide the first statement.
    let text = text.strip_prefix("\u{feff}".as_bytes()).unwrap_or(&text);
    let dir = path.parent().unwrap_or(Path::new(""));
    parse_obj(&String::from_utf8_lossy(text), dir, budget.limit)
}

/// One face corner: its position, texture coordinate and material (indices).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct Corner {
    position: u32,
    uv: Option<u32>,
    material: Option<u32>,
}

/// Parses OBJ text whose libraries are relative to `dir`; see the [module docs](self).
fn parse_obj(text: &str, dir: &Path, memory_limit: u64) -> Result<MeshAsset> {
    let mut positions: Vec<f64> = Vec::new();
    let mut file_normals: Vec<f64> = Vec::new();
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    let mut corners: Vec<[Corner; 3]> = Vec::new();
    let mut normals_per_vertex = true;
    let mut polygon: Vec<Corner> = Vec::new();
    let mut materials: Vec<MtlMaterial> = Vec::new();
    let mut warnings = Vec::new();
    // usemtl names in order of first use; a corner's material indexes this list.
    let mut used: Vec<(String, usize)> = Vec::new();
    let mut current: Option<u32> = None;
    for (line_no, line) in text.lines().enumerate() {
        let bad = |what: &str| corrupt(format!("line {}: {what}", line_no + 1));
        let mut words = line.split_whitespace();
        // The next `least` to `most` numbers of the line (the rest is left).
        let numbers = |words: std::str::SplitWhitespace<'_>, least: usize, most: usize| {
            let parsed: Vec<f64> = words
                .take(most)
                .map(|w| w.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| bad("a coordinate is not a number"))?;
            if parsed.len() < least {
                return Err(bad("too few coordinates"));
            }
            Ok::<_, crate::Error>(parsed)
        };
        match words.next() {
            Some("v") => positions.extend(numbers(words, 3, 3)?),
            Some("vn") => file_normals.extend(numbers(words, 3, 3)?),
            Some("vt") => {
                // `vt u [v [w]]`: v defaults to 0, w (a 3D texture's) is ignored.
                let mut uv = numbers(words, 1, 2)?;
                if uv.iter().any(|x| !x.is_finite()) {
                    return Err(bad("a texture coordinate is not finite"));
                }
                uv.resize(2, 0.0);
                uvs.push([uv[0], uv[1]]);
            }
            Some("mtllib") => {
                for name in words {
                    let part = format!("line {}: mtllib", line_no + 1);
                    let AssetSource::File(library) = resolve(&part, name, dir)? else {
                        return Err(bad("an MTL library must be a file"));
                    };
                    let (read, notes) = read_mtl(&library, name, memory_limit)?;
                    materials.extend(read);
                    warnings.extend(notes);
                }
            }
            Some("usemtl") => {
                let name = line.trim_start()["usemtl".len()..].trim().to_owned();
                let index = match used.iter().position(|(n, _)| *n == name) {
                    Some(i) => i,
                    None => {
                        used.push((name, line_no + 1));
                        used.len() - 1
                    }
                };
                current = Some(index as u32);
            }
            Some("f") => {
                polygon.clear();
                let v = (positions.len() / 3) as i64;
                for corner in words {
                    let mut parts = corner.split('/');
                    let index = |part: Option<&str>, count: i64| -> Result<Option<i64>> {
                        match part {
                            None | Some("") => Ok(None),
                            Some(p) => match p.parse::<i64>() {
                                Ok(0) => Err(bad("face index 0 (OBJ counts vertices from 1)")),
                                Ok(i) => Ok(Some(if i < 0 { count + i } else { i - 1 })),
                                Err(_) => Err(bad("a face index is not an integer")),
                            },
                        }
                    };
                    let position =
                        index(parts.next(), v)?.ok_or_else(|| bad("empty face corner"))?;
                    let uv = index(parts.next(), uvs.len() as i64)?;
                    let normal = index(parts.next(), v)?;
                    normals_per_vertex &= normal == Some(position);
                    let position = match u32::try_from(position) {
                        Ok(p) if position < v => p,
                        _ => {
                            return Err(SceneError::IndexOutOfRange {
                                triangle: corners.len(),
                                index: position as u64,
                                vertices: v as usize,
                            }
                            .into());
                        }
                    };
                    let uv = match uv {
                        None => None,
                        Some(t) if (0..uvs.len() as i64).contains(&t) => Some(t as u32),
                        Some(_) => {
                            return Err(bad(
                                "a texture coordinate index beyond the vt read so far",
                            ));
                        }
                    };
                    polygon.push(Corner {
                        position,
                        uv,
                        material: current,
                    });
                }
                if polygon.len() < 3 {
                    return Err(bad("a face needs at least three corners"));
                }
                for k in 1..polygon.len() - 1 {
                    corners.push([polygon[0], polygon[k], polygon[k + 1]]);
                }
            }
            _ => {}
        }
    }
    let v = positions.len() / 3;
    let positions = Array2::from_shape_vec((v, 3), positions).map_err(corrupt)?;
    let triangles: Vec<[u32; 3]> = corners.iter().map(|t| t.map(|c| c.position)).collect();
    let normals = (normals_per_vertex && !triangles.is_empty() && file_normals.len() == 3 * v)
        .then(|| Array2::from_shape_vec((v, 3), file_normals))
        .transpose()
        .map_err(corrupt)?;
    let geometry = Mesh::new(positions, triangles, normals)?;
    if corners.iter().flatten().all(|c| c.material.is_none()) {
        return Ok(MeshAsset {
            mesh: geometry,
            albedo: None,
            warnings,
        });
    }
    // The used names as materials of the libraries.
    let library: Vec<&MtlMaterial> = used
        .iter()
        .map(|(name, line)| {
            materials.iter().find(|m| m.name == *name).ok_or_else(|| {
                corrupt(format!(
                    "line {line}: usemtl {name:?} names no material of the file's libraries"
                ))
            })
        })
        .collect::<Result<_>>()?;
    split_by_material(&geometry, &corners, &uvs, &library, warnings)
}

/// The mesh with one vertex per (position, texture coordinate, material) and its albedo;
/// see the [module docs](self) for the order.
fn split_by_material(
    geometry: &Mesh,
    corners: &[[Corner; 3]],
    uvs: &[[f64; 2]],
    library: &[&MtlMaterial],
    warnings: Vec<String>,
) -> Result<MeshAsset> {
    let v = geometry.vertex_count();
    // A texture coordinate matters only where the material has a texture.
    let key = |c: Corner| Corner {
        uv: c.uv.filter(|_| {
            c.material
                .is_some_and(|m| library[m as usize].texture.is_some())
        }),
        ..c
    };
    let mut vertices: Vec<Corner> = (0..v as u32)
        .map(|position| Corner {
            position,
            uv: None,
            material: None,
        })
        .collect();
    let mut first_used = vec![false; v];
    let mut index: HashMap<Corner, u32> = HashMap::new();
    let mut triangles = Vec::with_capacity(corners.len());
    for t in corners {
        triangles.push(t.map(|c| {
            let c = key(c);
            *index.entry(c).or_insert_with(|| {
                let p = c.position as usize;
                if !std::mem::replace(&mut first_used[p], true) {
                    vertices[p] = c;
                    c.position
                } else {
                    vertices.push(c);
                    (vertices.len() - 1) as u32
                }
            })
        }));
    }
    let (positions, normals) = (geometry.positions(), geometry.normals());
    let split = |a: ndarray::ArrayView2<'_, f64>| {
        Array2::from_shape_fn((vertices.len(), 3), |(k, c)| {
            a[[vertices[k].position as usize, c]]
        })
    };
    let mesh = Mesh::new(split(positions), triangles, Some(split(normals)))?;
    let albedo = Array2::from_shape_fn((vertices.len(), 3), |(k, c)| {
        let corner = vertices[k];
        let Some(material) = corner.material.map(|m| library[m as usize]) else {
            return DEFAULT_ALBEDO[c];
        };
        let texel = match (&material.texture, corner.uv) {
            (Some(texture), Some(t)) => {
                let [u, w] = uvs[t as usize];
                texture.sample([u, 1.0 - w], [Wrap::Repeat; 2], Filter::Linear)[c]
            }
            _ => 1.0,
        };
        material.kd[c] * texel
    });
    Ok(MeshAsset {
        mesh,
        albedo: Some(albedo),
        warnings,
    })
}

#[cfg(test)]
#[path = "obj_tests.rs"]
mod tests;
