//! What a mesh asset may name: the files of its own folder, and data embedded as `data:` URIs.
//!
//! A glTF buffer or image URI and an MTL `map_Kd` name files relative to the asset. Such a
//! name is refused, before anything is opened, when it is absolute (`/x`, `\x`, `C:\x`),
//! climbs out through a `..` component, carries a URI scheme other than `data:` (`file:`,
//! `http:`; any `scheme:` prefix, as RFC 3986 section 3.1 defines one), or holds a NUL. The
//! name is percent-decoded first (glTF 2.0 section 2.8: URIs are RFC 3986 references), so
//! `%2e%2e/` is `../`. What passes is then resolved through the file system, and a path whose
//! canonical form leaves the canonical folder (a symbolic link out of it) is refused too. A
//! scene file's own paths (`"mesh": "../meshes/x.glb"`) are not asset names and keep working.

use std::path::{Component, Path, PathBuf};

use crate::SceneError;
use crate::{Error, Result};

/// What an asset's URI names once checked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum AssetSource {
    /// A file inside the asset's folder.
    File(PathBuf),
    /// The bytes of a base64 `data:` URI.
    Data(Vec<u8>),
}

/// The error of an asset name refused or unreadable: `part` names it (`buffer 0`).
fn refused(part: &str, reason: impl Into<String>) -> Error {
    SceneError::Asset {
        part: part.to_owned(),
        reason: reason.into(),
    }
    .into()
}

/// `uri` (named by `part` in errors) resolved against `dir`, the asset's folder, under the
/// rule of the [module docs](self). Nothing is opened; the file must exist (its canonical
/// path is checked).
pub(crate) fn resolve(part: &str, uri: &str, dir: &Path) -> Result<AssetSource> {
    if let Some(rest) = uri.strip_prefix("data:") {
        return decode_data_uri(rest).map(AssetSource::Data).ok_or_else(|| {
            refused(
                part,
                "a data: URI that is not base64 (data:[TYPE];base64,DATA)",
            )
        });
    }
    let name =
        percent_decode(uri).ok_or_else(|| refused(part, format!("{uri:?} is not a valid URI")))?;
    let leaves = |why: &str| {
        refused(
            part,
            format!("{uri:?} {why}: an asset may name only files in its own folder"),
        )
    };
    if name.is_empty() {
        return Err(refused(part, "an empty URI"));
    }
    if name.contains('\0') {
        return Err(leaves("holds a NUL"));
    }
    if has_scheme(&name) {
        return Err(leaves("is a URI with a scheme"));
    }
    if name.starts_with('/') || name.starts_with('\\') {
        return Err(leaves("is an absolute path"));
    }
    // Backslashes separate components on Windows: `..\x` climbs there too.
    let relative = Path::new(&name);
    if name.split(['/', '\\']).any(|c| c == "..")
        || relative
            .components()
            .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err(leaves("climbs out of the folder"));
    }
    let path = dir.join(relative);
    let unreadable = |e: std::io::Error| refused(part, format!("{uri:?}: {e}"));
    let folder = std::fs::canonicalize(if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    })
    .map_err(unreadable)?;
    let target = std::fs::canonicalize(&path).map_err(unreadable)?;
    if !target.starts_with(&folder) {
        return Err(leaves("resolves (through a link) outside the folder"));
    }
    Ok(AssetSource::File(path))
}

/// The bytes of `path`, at most `length` of them (all when `None`), refused before reading
/// when they exceed `limit` bytes.
pub(crate) fn read_limited(path: &Path, length: Option<u64>, limit: u64) -> Result<Vec<u8>> {
    use std::io::Read;
    let io = |source| crate::Error::io(path.to_path_buf(), source);
    let file = std::fs::File::open(path).map_err(io)?;
    let size = length.unwrap_or(file.metadata().map_err(io)?.len());
    if size > limit {
        return Err(crate::Error::from(haarshift::Error::MemoryBudget {
            what: format!("{} ({size} bytes)", path.display()),
            needed: size.into(),
            budget: limit.into(),
        }));
    }
    let mut bytes = Vec::new();
    file.take(size).read_to_end(&mut bytes).map_err(io)?;
    Ok(bytes)
}

/// Whether `name` starts with an RFC 3986 scheme: a letter, then letters, digits, `+`, `-`
/// or `.`, then `:` (so `C:\x` counts, and is refused as the absolute path it is).
fn has_scheme(name: &str) -> bool {
    let Some((scheme, _)) = name.split_once(':') else {
        return false;
    };
    let mut chars = scheme.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
}

/// `%XX` sequences decoded (RFC 3986 section 2.1); `None` for a broken escape or bytes that
/// are not UTF-8.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        if bytes[k] == b'%' {
            let hex = std::str::from_utf8(bytes.get(k + 1..k + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            k += 3;
        } else {
            out.push(bytes[k]);
            k += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The bytes of a `data:` URI's remainder `[MEDIATYPE][;base64],DATA` (RFC 2397); only
/// base64 data is accepted, as glTF writers emit.
pub(crate) fn decode_data_uri(rest: &str) -> Option<Vec<u8>> {
    let (header, data) = rest.split_once(',')?;
    if !header.ends_with(";base64") {
        return None;
    }
    data_encoding::BASE64.decode(data.as_bytes()).ok()
}

#[cfg(test)]
#[path = "asset_path_tests.rs"]
mod tests;
