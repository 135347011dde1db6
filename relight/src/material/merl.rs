//! Measured BRDFs in the MERL binary format (Matusik et al. 2003, the materials of Alnasser 2008's
//! renders).
//!
//! **The file**: three little-endian `i32` dimensions `90, 90, 180`, then `3 x 1,458,000`
//! little-endian `f64`, the red, green and blue blocks, each indexed
//! `phi_diff + 180 (theta_diff + 90 theta_half)` ([`MerlBrdf::index`]): 34,992,012 bytes
//! exactly. Entries are scaled per channel by `1/1500`, `1.15/1500` and `1.66/1500`
//! ([`CHANNEL_SCALES`]). A negative entry means "not measured": it reads as 0 (the count is
//! kept, [`MerlBrdf::unmeasured`]). Only these dimensions are accepted: the database has no
//! other, and a reader that took others would accept tables no other MERL tool reads. Tests
//! therefore write full tables (35 MB) with [`MerlBrdf::from_fn`] and [`MerlBrdf::write`].
//!
//! **The lookup** is the reference `BRDFRead.cpp`'s (checked against it): the directions, in
//! the local frame (`z` the normal), become Rusinkiewicz's half/difference angles
//! `(theta_half, theta_diff, phi_diff)` (the half vector `h`; the incoming direction rotated
//! about `z` by `-phi_half`, then about `y` by `-theta_half`, so that `h` becomes `z`), and
//! each angle picks a bin by rounding down:
//! * `theta_half`: `floor(sqrt(theta_half / (pi/2)) x 90)`, finer near the specular peak;
//! * `theta_diff`: `floor(theta_diff / (pi/2) x 90)`;
//! * `phi_diff`: reciprocity makes the BRDF `pi`-periodic in it, so a negative `phi_diff`
//!   gains `pi`; then `floor(phi_diff / pi x 180)`;
//!
//! each clamped to its last bin. Bin `(i, j, k)` is thus the value at its lower corner, the
//! grid point `theta_half = (i / 90)^2 pi/2`, `theta_diff = j pi/180`, `phi_diff = k pi/180`
//! ([`MerlBrdf::from_fn`] samples there), and a lookup is that corner's value: no
//! interpolation, as in the reference.
//!
//! Directions below the surface (`z <= 0`) give 0: the table covers the upper hemisphere
//! only, and the half/difference angles of a lower direction would fold it onto an upper one.

use std::f64::consts::{FRAC_PI_2, PI};
use std::io::Read;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::{Error, Result};

/// Bins of `theta_half`, `theta_diff` and `phi_diff`, the order of the file's dimensions.
pub const DIMENSIONS: [usize; 3] = [90, 90, 180];

/// Entries per channel: `90 x 90 x 180`.
pub const SAMPLES: usize = DIMENSIONS[0] * DIMENSIONS[1] * DIMENSIONS[2];

/// The size of a MERL file in bytes: the header and three blocks of `f64`.
pub const FILE_BYTES: u64 = 12 + 3 * 8 * SAMPLES as u64;

/// What a file's entry is multiplied by to give the BRDF, per channel (red, green, blue).
pub const CHANNEL_SCALES: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

const CHANNEL_NAMES: [&str; 3] = ["red", "green", "blue"];

/// What can be wrong with a MERL file's content ([`crate::Error::Merl`] adds the file).
///
/// ```
/// use haarshift_relight::material::merl::MerlError;
/// let e = MerlError::Truncated { bytes: 12 };
/// assert_eq!(e.to_string(), "truncated: 12 bytes where a MERL table has 34992012");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MerlError {
    /// The file is shorter than a MERL table.
    #[error("truncated: {bytes} bytes where a MERL table has {FILE_BYTES}")]
    Truncated {
        /// The file's size.
        bytes: u64,
    },
    /// The file is longer than a MERL table.
    #[error("too large: {bytes} bytes where a MERL table has {FILE_BYTES}")]
    TooLarge {
        /// The file's size.
        bytes: u64,
    },
    /// The header's dimensions are not `90, 90, 180`.
    #[error("dimensions {} x {} x {} where a MERL table is 90 x 90 x 180", .found[0], .found[1], .found[2])]
    Dimensions {
        /// The header's three dimensions.
        found: [i32; 3],
    },
    /// An entry is NaN or infinite.
    #[error(
        "non-finite entry {value} in the {channel} block at theta_half bin {}, theta_diff bin {}, phi_diff bin {}",
        .bin[0], .bin[1], .bin[2]
    )]
    NonFinite {
        /// `red`, `green` or `blue`.
        channel: &'static str,
        /// `[theta_half, theta_diff, phi_diff]` bins.
        bin: [usize; 3],
        /// The entry.
        value: f64,
    },
}

/// A measured isotropic BRDF: a MERL table, RGB ([module docs](self)).
///
/// ```
/// use haarshift_relight::material::merl::MerlBrdf;
/// // A constant table of 1 / pi: Lambertian.
/// let m = MerlBrdf::from_fn(|_, _, _| [std::f64::consts::FRAC_1_PI; 3]).unwrap();
/// let (wi, wo) = ([0.6, 0.0, 0.8], [0.0, 0.28, 0.96]);
/// assert!(m.evaluate(wi, wo).iter().all(|v| (v - std::f64::consts::FRAC_1_PI).abs() < 1e-15));
/// assert_eq!(m.evaluate([0.6, 0.0, -0.8], wo), [0.0; 3]); // below the surface
/// ```
#[derive(Clone, PartialEq)]
pub struct MerlBrdf {
    /// The file it was read from, if any.
    path: Option<PathBuf>,
    /// The file's entries, negatives as 0: red, green, blue blocks of [`SAMPLES`].
    entries: Vec<f64>,
    /// Negative ("not measured") entries read as 0.
    unmeasured: usize,
}

impl std::fmt::Debug for MerlBrdf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Not the 4.4 million entries.
        f.debug_struct("MerlBrdf")
            .field("path", &self.path)
            .field("unmeasured", &self.unmeasured)
            .finish_non_exhaustive()
    }
}

/// The Rusinkiewicz angles `(theta_half, theta_diff, phi_diff)` of `wi` and `wo` (unit, local
/// frame, `z` the normal), `phi_diff` in `(-pi, pi]`; `None` when `wi = -wo`.
fn half_diff(wi: [f64; 3], wo: [f64; 3]) -> Option<(f64, f64, f64)> {
    let h: [f64; 3] = std::array::from_fn(|k| wi[k] + wo[k]);
    let len = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    if len == 0.0 {
        return None;
    }
    let h = h.map(|x| x / len);
    let sin_h = h[0].hypot(h[1]);
    let cos_h = h[2];
    let (cos_phi, sin_phi) = if sin_h > 0.0 {
        (h[0] / sin_h, h[1] / sin_h)
    } else {
        (1.0, 0.0)
    };
    // wi about z by -phi_half, then about y by -theta_half: h goes to z.
    let x = cos_phi * wi[0] + sin_phi * wi[1];
    let y = -sin_phi * wi[0] + cos_phi * wi[1];
    let z = wi[2];
    let d = [x * cos_h - z * sin_h, y, x * sin_h + z * cos_h];
    let theta_half = cos_h.clamp(-1.0, 1.0).acos();
    let theta_diff = d[2].clamp(-1.0, 1.0).acos();
    Some((theta_half, theta_diff, d[1].atan2(d[0])))
}

/// `floor(x)` clamped to `0..bins`.
fn bin(x: f64, bins: usize) -> usize {
    if x <= 0.0 {
        0
    } else {
        (x as usize).min(bins - 1)
    }
}

impl MerlBrdf {
    /// The entry of bins `[theta_half, theta_diff, phi_diff]` within a channel's block.
    ///
    /// ```
    /// use haarshift_relight::material::merl::MerlBrdf;
    /// assert_eq!(MerlBrdf::index([0, 0, 1]), 1);
    /// assert_eq!(MerlBrdf::index([0, 1, 0]), 180);
    /// assert_eq!(MerlBrdf::index([1, 0, 0]), 180 * 90);
    /// ```
    pub fn index([i, j, k]: [usize; 3]) -> usize {
        k + DIMENSIONS[2] * (j + DIMENSIONS[1] * i)
    }

    /// The bins `[theta_half, theta_diff, phi_diff]` a lookup of these angles uses.
    ///
    /// ```
    /// use haarshift_relight::material::merl::MerlBrdf;
    /// use std::f64::consts::{FRAC_PI_2, PI};
    /// // theta_half on a square-root scale: a quarter of pi/2 is bin 45.
    /// assert_eq!(MerlBrdf::bins(FRAC_PI_2 / 4.0 + 1e-9, 0.0, 0.0), [45, 0, 0]);
    /// // phi_diff modulo pi: -pi/2 is pi/2, bin 90.
    /// assert_eq!(MerlBrdf::bins(0.0, 0.5 * PI / 180.0, -FRAC_PI_2 + 1e-9), [0, 0, 90]);
    /// ```
    pub fn bins(theta_half: f64, theta_diff: f64, phi_diff: f64) -> [usize; 3] {
        let [nh, nd, np] = DIMENSIONS;
        let phi = if phi_diff < 0.0 {
            phi_diff + PI
        } else {
            phi_diff
        };
        [
            bin((theta_half.max(0.0) / FRAC_PI_2).sqrt() * nh as f64, nh),
            bin(theta_diff / FRAC_PI_2 * nd as f64, nd),
            bin(phi / PI * np as f64, np),
        ]
    }

    /// The grid point of bins `[theta_half, theta_diff, phi_diff]`: its lower corner, where
    /// [`from_fn`](Self::from_fn) samples.
    pub fn grid_point([i, j, k]: [usize; 3]) -> (f64, f64, f64) {
        let [nh, nd, np] = DIMENSIONS.map(|n| n as f64);
        (
            (i as f64 / nh).powi(2) * FRAC_PI_2,
            j as f64 / nd * FRAC_PI_2,
            k as f64 / np * PI,
        )
    }

    /// A table sampled from `f(theta_half, theta_diff, phi_diff) -> RGB BRDF` at every bin's
    /// grid point ([`grid_point`](Self::grid_point)); negative values are "not measured", as in
    /// a file. A non-finite value is refused.
    ///
    /// ```
    /// use haarshift_relight::material::merl::MerlBrdf;
    /// let m = MerlBrdf::from_fn(|th, _, _| [th, 0.0, -1.0]).unwrap();
    /// assert_eq!(m.unmeasured(), 1_458_000);
    /// assert!(MerlBrdf::from_fn(|_, _, _| [f64::NAN; 3]).is_err());
    /// ```
    pub fn from_fn(f: impl Fn(f64, f64, f64) -> [f64; 3] + Sync) -> Result<MerlBrdf> {
        let [_, nd, np] = DIMENSIONS;
        let mut entries = vec![0.0; 3 * SAMPLES];
        let (red, rest) = entries.split_at_mut(SAMPLES);
        let (green, blue) = rest.split_at_mut(SAMPLES);
        let per_row = nd * np;
        red.par_chunks_mut(per_row)
            .zip(green.par_chunks_mut(per_row))
            .zip(blue.par_chunks_mut(per_row))
            .enumerate()
            .for_each(|(i, ((r, g), b))| {
                for j in 0..nd {
                    for k in 0..np {
                        let (th, td, pd) = Self::grid_point([i, j, k]);
                        let v = f(th, td, pd);
                        let at = k + np * j;
                        r[at] = v[0] / CHANNEL_SCALES[0];
                        g[at] = v[1] / CHANNEL_SCALES[1];
                        b[at] = v[2] / CHANNEL_SCALES[2];
                    }
                }
            });
        Self::from_entries(None, entries).map_err(|e| Error::parameter("MERL table", e.to_string()))
    }

    /// Checks raw entries (finite) and reads negatives as 0.
    fn from_entries(
        path: Option<PathBuf>,
        mut entries: Vec<f64>,
    ) -> std::result::Result<MerlBrdf, MerlError> {
        if let Some(at) = entries.iter().position(|v| !v.is_finite()) {
            let within = at % SAMPLES;
            let [_, nd, np] = DIMENSIONS;
            return Err(MerlError::NonFinite {
                channel: CHANNEL_NAMES[at / SAMPLES],
                bin: [within / (nd * np), within / np % nd, within % np],
                value: entries[at],
            });
        }
        let mut unmeasured = 0;
        for v in entries.iter_mut().filter(|v| **v < 0.0) {
            *v = 0.0;
            unmeasured += 1;
        }
        Ok(MerlBrdf {
            path,
            entries,
            unmeasured,
        })
    }

    /// Reads a MERL file ([module docs](self)); every error names `path`.
    pub fn read(path: &Path) -> Result<MerlBrdf> {
        let io = |source| crate::Error::io(path.to_path_buf(), source);
        let bad = |source| Error::Merl {
            path: path.to_path_buf(),
            source,
        };
        let mut file = std::fs::File::open(path).map_err(io)?;
        let bytes = file.metadata().map_err(io)?.len();
        let mut header = [0u8; 12];
        if bytes < 12 {
            return Err(bad(MerlError::Truncated { bytes }));
        }
        file.read_exact(&mut header).map_err(io)?;
        let found: [i32; 3] = std::array::from_fn(|k| {
            i32::from_le_bytes(header[4 * k..4 * k + 4].try_into().expect("4 bytes"))
        });
        if found != DIMENSIONS.map(|d| d as i32) {
            return Err(bad(MerlError::Dimensions { found }));
        }
        if bytes < FILE_BYTES {
            return Err(bad(MerlError::Truncated { bytes }));
        }
        if bytes > FILE_BYTES {
            return Err(bad(MerlError::TooLarge { bytes }));
        }
        let mut raw = vec![0u8; (FILE_BYTES - 12) as usize];
        file.read_exact(&mut raw).map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                // Shortened since its size was taken.
                bad(MerlError::Truncated { bytes })
            } else {
                io(e)
            }
        })?;
        let entries = raw
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect();
        Self::from_entries(Some(path.to_path_buf()), entries).map_err(bad)
    }

    /// Writes the table as a MERL file, atomically; an existing `path` is replaced only with
    /// `force`. Unmeasured entries are written as 0.
    ///
    /// ```
    /// use haarshift_relight::material::merl::{FILE_BYTES, MerlBrdf};
    /// let dir = tempfile::tempdir().unwrap();
    /// let path = dir.path().join("grey.binary");
    /// let m = MerlBrdf::from_fn(|_, _, _| [0.25; 3]).unwrap();
    /// m.write(&path, false).unwrap();
    /// assert_eq!(std::fs::metadata(&path).unwrap().len(), FILE_BYTES);
    /// let back = MerlBrdf::read(&path).unwrap();
    /// assert_eq!(back.evaluate([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]), [0.25; 3]);
    /// assert_eq!(back.path(), Some(path.as_path()));
    /// ```
    pub fn write(&self, path: &Path, force: bool) -> Result<()> {
        Ok(haarshift::io::write_file_atomically(path, force, |w| {
            for d in DIMENSIONS {
                w.write_all(&(d as i32).to_le_bytes())?;
            }
            let mut bytes = Vec::with_capacity(8 * self.entries.len());
            for v in &self.entries {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            w.write_all(&bytes)
        })?)
    }

    /// The file the table was read from (`None` for [`from_fn`](Self::from_fn)'s).
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// How many entries were negative ("not measured") and read as 0.
    pub fn unmeasured(&self) -> usize {
        self.unmeasured
    }

    /// The RGB BRDF at bins `[theta_half, theta_diff, phi_diff]`, scaled.
    pub fn at(&self, bins: [usize; 3]) -> [f64; 3] {
        let at = Self::index(bins);
        std::array::from_fn(|c| self.entries[at + c * SAMPLES] * CHANNEL_SCALES[c])
    }

    /// `rho(w_i, w_o)` per RGB channel for unit directions in the local frame (`z` the
    /// normal): the table's value at their bins ([module docs](self)); 0 below the surface.
    pub fn evaluate(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            return [0.0; 3];
        }
        match half_diff(wi, wo) {
            Some((th, td, pd)) => self.at(Self::bins(th, td, pd)),
            None => [0.0; 3],
        }
    }
}

#[cfg(test)]
#[path = "merl_tests.rs"]
pub(crate) mod tests;
