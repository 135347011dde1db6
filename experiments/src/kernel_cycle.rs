//! The rotation-cycle experiment run with the library's kernels: [`KernelCycle`] adapts any
//! [`ShiftMethod`] to [`CycleMethod`], [`default_images`] is the fixed image set and
//! [`run_rotation_cycle`] runs every method on every image.

use std::path::Path;

use ndarray::{Array2, ArrayView2};

use super::rotation_cycle::{
    CycleMethod, CycleRecord, CycleRun, MemoryMeter, MethodSpec, luma, run_cycle,
};
use haarshift::kernels::{KernelOptions, ShiftMethod};
use haarshift::patterns;
use haarshift::rotate::{RotateOptions, RotationChain};
use haarshift::{Error, Result};

/// A kernel rotating in f64 through a [`RotationChain`], which keeps its working grid (the
/// retained Haar mode's `2^h`-finer grid, or the `2^supersample`-finer one) across the whole
/// cycle and box-averages back to pixels only at the end.
///
/// ```
/// use haarshift_experiments::kernel_cycle::KernelCycle;
/// use haarshift_experiments::rotation_cycle::{CycleMethod, NoMeter, run_cycle};
/// use haarshift::kernels::{KernelOptions, ShiftMethod};
/// let nearest = KernelCycle::new(ShiftMethod::Nearest, KernelOptions::default(), 0);
/// let plane = haarshift::patterns::zone_plate(16, 16).unwrap();
/// let r = run_cycle("zone", plane.view(), &nearest, 4, &NoMeter).unwrap().record;
/// assert_eq!(r.rms, 0.0); // quarter turns are exact
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KernelCycle {
    /// The kernel.
    pub method: ShiftMethod,
    /// Its parameters (Haar precision and mode, Keys' `a`).
    pub options: KernelOptions,
    /// Rotate on a `2^supersample`-finer grid.
    pub supersample: u32,
}

impl KernelCycle {
    /// A kernel with its options and supersampling exponent.
    pub fn new(method: ShiftMethod, options: KernelOptions, supersample: u32) -> Self {
        KernelCycle {
            method,
            options,
            supersample,
        }
    }

    /// Every built-in kernel with `options`, the Haar method twice (compact and retained).
    ///
    /// ```
    /// use haarshift_experiments::kernel_cycle::KernelCycle;
    /// use haarshift::kernels::KernelOptions;
    /// let all = KernelCycle::every_kernel(KernelOptions::default(), 0);
    /// assert_eq!(all.len(), 10);
    /// ```
    pub fn every_kernel(options: KernelOptions, supersample: u32) -> Vec<KernelCycle> {
        ShiftMethod::ALL
            .iter()
            .flat_map(|&method| {
                let retains: &[bool] = match method {
                    ShiftMethod::Haar => &[false, true],
                    _ => &[false],
                };
                retains.iter().map(move |&retain| {
                    KernelCycle::new(method, KernelOptions { retain, ..options }, supersample)
                })
            })
            .collect()
    }
}

impl CycleMethod for KernelCycle {
    fn spec(&self) -> MethodSpec {
        let haar = self.method == ShiftMethod::Haar;
        MethodSpec {
            method: self.method.name().to_owned(),
            precision: haar.then_some(self.options.precision),
            retain: haar.then_some(self.options.retain),
            supersample: self.supersample,
        }
    }

    fn rotate_repeatedly(
        &self,
        plane: ArrayView2<'_, f64>,
        angle_deg: f64,
        steps: usize,
    ) -> Result<Array2<f64>> {
        let kernel = self.method.kernel_with::<f64>(&self.options)?;
        let options = RotateOptions {
            supersample: self.supersample,
            ..Default::default()
        };
        let mut chain = RotationChain::new(plane, kernel.as_ref(), options)?;
        for _ in 0..steps {
            chain.rotate(angle_deg)?;
        }
        Ok(chain.finish())
    }
}

/// One input of an experiment: a name (file name or pattern) and its luma plane.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedPlane {
    /// File name, or pattern name with its size.
    pub name: String,
    /// The luma plane in 0..255 units.
    pub plane: Array2<f64>,
}

impl NamedPlane {
    /// Reads an image file and converts it to luma by the protocol's weights.
    pub fn read(path: &Path) -> Result<NamedPlane> {
        let image = haarshift::io::read_image::<f64>(path)?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        Ok(NamedPlane {
            name,
            plane: luma(&image),
        })
    }

    /// Decodes the bytes of an image file held in memory (named `name`) and converts it to
    /// luma by the protocol's weights.
    pub fn from_memory(name: &str, bytes: &[u8]) -> Result<NamedPlane> {
        let image = haarshift::io::read_image_from_memory::<f64>(
            bytes,
            name.as_ref(),
            &haarshift::io::ReadOptions::default(),
        )?;
        Ok(NamedPlane {
            name: name.to_owned(),
            plane: luma(&image),
        })
    }

    /// The centred `side x side` crop (each axis cropped only where it is longer than
    /// `side`), under the same name: the rotation-cycle protocol then works on a crop of side
    /// `min(side, height, width)`, the cheaper run the trade-off experiment makes by default.
    ///
    /// ```
    /// use haarshift_experiments::kernel_cycle::NamedPlane;
    /// use ndarray::Array2;
    /// let p = NamedPlane { name: "p".into(), plane: Array2::from_shape_fn((4, 6), |(i, j)| (10 * i + j) as f64) };
    /// let c = p.centre_crop(2).unwrap();
    /// assert_eq!(c.plane, ndarray::array![[12.0, 13.0], [22.0, 23.0]]);
    /// assert_eq!(p.centre_crop(5).unwrap().plane.dim(), (4, 5));
    /// ```
    pub fn centre_crop(&self, side: usize) -> Result<NamedPlane> {
        if side == 0 {
            return Err(Error::parameter("crop size", "must be at least 1"));
        }
        let (h, w) = self.plane.dim();
        let (ch, cw) = (h.min(side), w.min(side));
        let (top, left) = ((h - ch) / 2, (w - cw) / 2);
        Ok(NamedPlane {
            name: self.name.clone(),
            plane: self
                .plane
                .slice(ndarray::s![top..top + ch, left..left + cw])
                .to_owned(),
        })
    }
}

/// The synthetic images of the default set: a 300x200 zone plate (non-square, rising to
/// Nyquist at the crop's edge) and a 256x256 Siemens star with 32 spokes.
///
/// ```
/// let p = haarshift_experiments::kernel_cycle::synthetic_images().unwrap();
/// assert_eq!(p[0].plane.dim(), (200, 300));
/// ```
pub fn synthetic_images() -> Result<Vec<NamedPlane>> {
    Ok(vec![
        NamedPlane {
            name: "zone-plate-300x200".into(),
            plane: patterns::zone_plate(200, 300)?,
        },
        NamedPlane {
            name: "siemens-star-256x256".into(),
            plane: patterns::siemens_star(256, 256, 32)?,
        },
    ])
}

/// The photographs of the default image set, embedded in the library so that the
/// experiments run from any directory (`testdata/SOURCES.md` has their sources and licences).
pub const PHOTOGRAPHS: [(&str, &[u8]); 6] = [
    (
        "astronaut.png",
        include_bytes!("../../testdata/astronaut.png"),
    ),
    ("brick.png", include_bytes!("../../testdata/brick.png")),
    ("camera.png", include_bytes!("../../testdata/camera.png")),
    ("chelsea.png", include_bytes!("../../testdata/chelsea.png")),
    ("coins.png", include_bytes!("../../testdata/coins.png")),
    ("text.png", include_bytes!("../../testdata/text.png")),
];

/// The default image set: the six [`PHOTOGRAPHS`] (sorted by name) followed by
/// [`synthetic_images`].
///
/// ```
/// let images = haarshift_experiments::kernel_cycle::default_images().unwrap();
/// let names: Vec<&str> = images.iter().map(|i| i.name.as_str()).collect();
/// assert_eq!(names[..3], ["astronaut.png", "brick.png", "camera.png"]);
/// assert_eq!(images[2].plane.dim(), (512, 512));
/// assert_eq!(images.len(), 8);
/// ```
pub fn default_images() -> Result<Vec<NamedPlane>> {
    let mut images = PHOTOGRAPHS
        .iter()
        .map(|&(name, bytes)| NamedPlane::from_memory(name, bytes))
        .collect::<Result<Vec<_>>>()?;
    images.extend(synthetic_images()?);
    Ok(images)
}

/// One of the embedded [`PHOTOGRAPHS`] by file name.
///
/// ```
/// let camera = haarshift_experiments::kernel_cycle::default_photograph("camera.png").unwrap();
/// assert_eq!(camera.plane.dim(), (512, 512));
/// let cat = haarshift_experiments::kernel_cycle::default_photograph("cat.png");
/// assert!(matches!(cat, Err(haarshift::Error::InvalidParameter { name: "image", .. })));
/// ```
pub fn default_photograph(name: &str) -> Result<NamedPlane> {
    let (name, bytes) = PHOTOGRAPHS
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| {
            let known: Vec<&str> = PHOTOGRAPHS.iter().map(|(n, _)| *n).collect();
            Error::parameter(
                "image",
                format!(
                    "{name} is not an embedded photograph ({})",
                    known.join(", ")
                ),
            )
        })?;
    NamedPlane::from_memory(name, bytes)
}

/// Runs the protocol for every image and method, images outermost; `progress` is called after
/// each run with the whole run (record and canvases), whose record is kept. Runs one at a
/// time so that the wall time and peak memory of each are its own.
pub fn run_rotation_cycle(
    images: &[NamedPlane],
    methods: &[KernelCycle],
    steps: usize,
    meter: &dyn MemoryMeter,
    mut progress: impl FnMut(&CycleRun),
) -> Result<Vec<CycleRecord>> {
    let mut records = Vec::with_capacity(images.len() * methods.len());
    for image in images {
        for method in methods {
            let run = run_cycle(&image.name, image.plane.view(), method, steps, meter)?;
            progress(&run);
            records.push(run.record);
        }
    }
    Ok(records)
}
