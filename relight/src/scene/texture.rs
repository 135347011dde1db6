//! Colour textures of mesh assets (a glTF `baseColorTexture`, an MTL `map_Kd`): decoded to
//! linear RGB once, then sampled at each vertex's texture coordinate.
//!
//! * **Decoding.** PNG or JPEG through [`haarshift::io::read_image_from_memory`] (its memory limit
//!   checked from the header before decoding); 8- and 16-bit samples are divided by 255 or
//!   65535, then taken from sRGB to linear by the IEC 61966-2-1 (1999) transfer function
//!   ([`srgb_to_linear`]), as glTF 2.0 (section 3.9.2) says of base colour textures and as
//!   MTL's `map_Kd` images are stored. A grey image gives grey; alpha is dropped.
//! * **Coordinates.** `(u, v) = (0, 0)` is the image's first (top-left) texel's corner, `u`
//!   right and `v` down, glTF's convention; texel `(i, j)`'s centre is `((i + 0.5) / w,
//!   (j + 0.5) / h)`. OBJ's `vt` has `v` up and is passed here as `1 - v`.
//! * **Sampling** ([`Texture::sample`]): bilinear between the four nearest texel centres, each
//!   texel decoded to linear first (what a GPU's sRGB texture does), or the nearest texel when
//!   the [`Filter`] is `Nearest` (a glTF sampler's `magFilter` NEAREST). Mipmaps and
//!   `minFilter` are not used: one value per vertex is taken at the full resolution.
//!   Coordinates beyond `[0, 1]` wrap by each axis's [`Wrap`] (glTF's three modes; REPEAT is
//!   the default, and OBJ's).

use std::path::Path;

use crate::{Error, Result};
use haarshift::io::{ReadOptions, read_image_from_memory};

/// The sRGB transfer function's inverse (IEC 61966-2-1, 1999): an encoded value in `[0, 1]`
/// to linear light.
///
/// ```
/// use haarshift_relight::scene::texture::srgb_to_linear;
/// assert_eq!(srgb_to_linear(0.0), 0.0);
/// assert_eq!(srgb_to_linear(1.0), 1.0);
/// assert!((srgb_to_linear(0.5) - 0.214041).abs() < 1e-6);
/// ```
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// How coordinates beyond `[0, 1]` map back onto the texture (glTF 2.0's sampler `wrapS`,
/// `wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// The texture tiles: `u` and `u + 1` sample the same point.
    Repeat,
    /// Texel indices are clamped to the edge.
    ClampToEdge,
    /// The texture tiles mirrored every other period.
    MirroredRepeat,
}

impl Wrap {
    /// Texel index `i` (of any sign) folded into `0..n` (`n > 0`).
    fn index(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        let folded = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::ClampToEdge => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let r = i.rem_euclid(2 * n);
                if r < n { r } else { 2 * n - 1 - r }
            }
        };
        folded as usize
    }
}

/// How a texture is read between texel centres.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    /// Bilinear between the four nearest texel centres.
    Linear,
    /// The texel the coordinate falls in.
    Nearest,
}

/// A linear-RGB texture, row-major from the top row; see the [module docs](self).
///
/// ```
/// use haarshift_relight::scene::texture::{Filter, Texture, Wrap};
/// // 2 x 1: black then white (already linear).
/// let t = Texture::from_linear(2, 1, vec![[0.0; 3], [1.0; 3]]).unwrap();
/// let wrap = [Wrap::ClampToEdge; 2];
/// assert_eq!(t.sample([0.25, 0.5], wrap, Filter::Linear), [0.0; 3]); // texel 0's centre
/// assert_eq!(t.sample([0.5, 0.5], wrap, Filter::Linear), [0.5; 3]); // half way
/// assert_eq!(t.sample([0.6, 0.5], wrap, Filter::Nearest), [1.0; 3]);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<[f32; 3]>,
}

impl Texture {
    /// A texture of `width x height` linear texels (row-major, top row first); an error
    /// unless there are `width * height > 0` of them.
    pub fn from_linear(width: usize, height: usize, texels: Vec<[f32; 3]>) -> Result<Texture> {
        if width == 0 || height == 0 || width.checked_mul(height) != Some(texels.len()) {
            return Err(Error::shape(
                &[height, width],
                format!("{} texels for a {width} x {height} texture", texels.len()),
            ));
        }
        Ok(Texture {
            width,
            height,
            texels,
        })
    }

    /// Decodes a PNG or JPEG `bytes` (named `name` in errors) within `memory_limit` bytes
    /// and takes it to linear RGB; see the [module docs](self).
    ///
    /// ```
    /// use haarshift_relight::scene::texture::Texture;
    /// let png = include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/coins.png"));
    /// let t = Texture::decode(png, "coins.png".as_ref(), 1 << 30).unwrap();
    /// assert_eq!((t.width(), t.height()), (384, 303));
    /// assert!(Texture::decode(png, "coins.png".as_ref(), 1000).is_err());
    /// ```
    pub fn decode(bytes: &[u8], name: &Path, memory_limit: u64) -> Result<Texture> {
        let image = read_image_from_memory::<f32>(bytes, name, &ReadOptions { memory_limit })?;
        let scale = image.depth().integer_max().unwrap_or(1.0);
        let planes = image.color_planes();
        let (channels, height, width) = planes.dim();
        let texels = (0..height * width)
            .map(|k| {
                let (row, col) = (k / width, k % width);
                std::array::from_fn(|c| {
                    let encoded = f64::from(planes[[c.min(channels - 1), row, col]]) / scale;
                    srgb_to_linear(encoded.clamp(0.0, 1.0)) as f32
                })
            })
            .collect();
        Texture::from_linear(width, height, texels)
    }

    /// Texels across.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Texels down.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The linear RGB at texture coordinate `uv` (`u` right, `v` down, `[0, 1]` across the
    /// image), wrapped by `wrap` (`[s, t]`) and read by `filter`. A non-finite coordinate
    /// reads texel `(0, 0)`.
    pub fn sample(&self, uv: [f64; 2], wrap: [Wrap; 2], filter: Filter) -> [f32; 3] {
        let uv = uv.map(|x| if x.is_finite() { x } else { 0.0 });
        let size = [self.width, self.height];
        // Texel-centre coordinates; clamped far beyond any wrap period so that the casts
        // below stay exact integers.
        let x: [f64; 2] =
            std::array::from_fn(|a| (uv[a] * size[a] as f64 - 0.5).clamp(-1e15, 1e15));
        let texel = |i: i64, j: i64| {
            let (i, j) = (wrap[0].index(i, self.width), wrap[1].index(j, self.height));
            self.texels[j * self.width + i]
        };
        if filter == Filter::Nearest {
            return texel((x[0] + 0.5).floor() as i64, (x[1] + 0.5).floor() as i64);
        }
        let base = x.map(f64::floor);
        let f = [x[0] - base[0], x[1] - base[1]];
        let (i, j) = (base[0] as i64, base[1] as i64);
        let (a, b, c, d) = (
            texel(i, j),
            texel(i + 1, j),
            texel(i, j + 1),
            texel(i + 1, j + 1),
        );
        std::array::from_fn(|k| {
            let top = f64::from(a[k]) * (1.0 - f[0]) + f64::from(b[k]) * f[0];
            let bottom = f64::from(c[k]) * (1.0 - f[0]) + f64::from(d[k]) * f[0];
            (top * (1.0 - f[1]) + bottom * f[1]) as f32
        })
    }
}

#[cfg(test)]
#[path = "texture_tests.rs"]
mod tests;
