//! Wavefront MTL material libraries, as OBJ files name them (`mtllib`): each material's
//! diffuse colour `Kd` and texture `map_Kd`, the part of a material a Lambertian cache keeps.
//!
//! Statements read: `newmtl NAME`, `Kd r g b` (taken as linear RGB, each in `[0, 1]`; the
//! default when absent is 0.8, haarshift's and the common exporters'), `map_Kd FILE` (the rest
//! of the line is the file name, relative to the library's folder and confined to it by
//! [`super::asset_path`]; options such as `-s` are refused, not misread as names), and
//! `Ks r g b`: a material with a specular colour other than black is reported as
//! approximated by its diffuse colour. Every other statement (`Ka`, `Ns`, `illum`, `d`, ...)
//! is ignored. A `map_Kd` texture is decoded once per library ([`super::texture`]); OBJ's
//! texture coordinates wrap (REPEAT), sampled bilinearly.

use std::path::Path;

use crate::SceneError;
use crate::scene::asset_path::{AssetSource, read_limited, resolve};
use crate::scene::texture::Texture;
use crate::{Error, Result};

/// One material of a library.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MtlMaterial {
    /// Its `newmtl` name.
    pub name: String,
    /// `Kd`, linear RGB.
    pub kd: [f32; 3],
    /// `map_Kd` decoded, if any.
    pub texture: Option<Texture>,
}

/// A library's materials and what was approximated, read from `path` (named `part` in
/// errors), its textures decoded within `memory_limit` bytes each.
pub(crate) fn read_mtl(
    path: &Path,
    part: &str,
    memory_limit: u64,
) -> Result<(Vec<MtlMaterial>, Vec<String>)> {
    let bad = |line: usize, reason: String| -> Error {
        SceneError::Asset {
            part: format!("{part}, line {line}"),
            reason,
        }
        .into()
    };
    let text = read_limited(path, None, memory_limit)?;
    let text = String::from_utf8_lossy(text.strip_prefix("\u{feff}".as_bytes()).unwrap_or(&text))
        .into_owned();
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut materials: Vec<MtlMaterial> = Vec::new();
    let mut warnings = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line_no = k + 1;
        let line = line.trim();
        let (keyword, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let rest = rest.trim();
        if keyword == "newmtl" {
            if rest.is_empty() {
                return Err(bad(line_no, "newmtl without a name".into()));
            }
            materials.push(MtlMaterial {
                name: rest.to_owned(),
                kd: [0.8; 3],
                texture: None,
            });
            continue;
        }
        if !matches!(keyword, "Kd" | "Ks" | "map_Kd") {
            continue;
        }
        let Some(material) = materials.last_mut() else {
            return Err(bad(line_no, format!("{keyword} before any newmtl")));
        };
        match keyword {
            "Kd" | "Ks" => {
                let rgb = colour(rest).ok_or_else(|| {
                    bad(line_no, format!("{keyword} needs three numbers in [0, 1]"))
                })?;
                if keyword == "Kd" {
                    material.kd = rgb;
                } else if rgb.iter().any(|&c| c > 0.0) {
                    warnings.push(format!(
                        "material {:?} has a specular colour (Ks {} {} {}): approximated by its diffuse colour (a static cache is Lambertian)",
                        material.name, rgb[0], rgb[1], rgb[2]
                    ));
                }
            }
            _ => {
                if rest.starts_with('-') || rest.is_empty() {
                    return Err(bad(
                        line_no,
                        "map_Kd takes one file name; its options are not read".into(),
                    ));
                }
                let texture_part = format!("{part}, line {line_no}, map_Kd");
                let bytes = match resolve(&texture_part, rest, dir)? {
                    AssetSource::Data(bytes) => bytes,
                    AssetSource::File(file) => read_limited(&file, None, memory_limit)?,
                };
                let texture =
                    Texture::decode(&bytes, Path::new(rest), memory_limit).map_err(|e| {
                        Error::from(SceneError::Asset {
                            part: texture_part.clone(),
                            reason: e.to_string(),
                        })
                    })?;
                material.texture = Some(texture);
            }
        }
    }
    Ok((materials, warnings))
}

/// Three numbers in `[0, 1]` (a colour statement's), or `None`.
fn colour(rest: &str) -> Option<[f32; 3]> {
    let v: Vec<f32> = rest
        .split_whitespace()
        .map(|w| w.parse::<f32>().ok().filter(|x| (0.0..=1.0).contains(x)))
        .collect::<Option<_>>()?;
    match v[..] {
        [r, g, b] => Some([r, g, b]),
        [x] => Some([x; 3]),
        _ => None,
    }
}
