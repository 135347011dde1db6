//! [`ShaderSpec`]: how per-vertex radiance is computed, and the one place that chooses the
//! [`Shader`] that computes it.

use std::path::Path;

use ndarray::ArrayView2;

use super::Shader;
use super::ambient::AmbientShader;
use super::glossy::{GlossyHaarShader, GlossyOptions};
use super::lambert::{LambertShader, ShadeOptions};
use super::reference::ReferenceShader;
use super::sh::ShShader;
use crate::light::environment::LightRotation;
use crate::material::brdf::DEFAULT_ELEVATIONS;
use crate::material::orient::BrdfRotation;
use crate::precompute::bounce::BouncedTransport;
use crate::{Error, Result};
use crate::{Mesh, Scene, SceneCache, TransportSet};
use haarshift::named_enum;
use haarshift::product::Selection;

named_enum! {
    /// How the radiance is computed: the names `relight render --basis` takes.
    ///
    /// ```
    /// use haarshift_relight::shade::Method;
    /// assert_eq!("sh".parse::<Method>().unwrap(), Method::Sh);
    /// assert_eq!(Method::ALL.iter().map(|m| m.name()).collect::<Vec<_>>(),
    ///            ["haar", "sh", "reference", "ambient"]);
    /// ```
    pub enum Method ("basis") {
        /// The sparse Haar transport and lighting (all-frequency); glossy BRDFs by the triple
        /// product with the rotated BRDF.
        Haar = "haar",
        /// Spherical harmonics: the transfer stored by `precompute --sh-bands B` and the
        /// lighting projected onto the same bands (low-frequency PRT).
        Sh = "sh",
        /// Direct quadrature over the lighting's texels with ray casting: the ground truth.
        Reference = "reference",
        /// Ambient occlusion: `albedo / pi x` the integral of the transport, whatever the
        /// lighting.
        Ambient = "ambient",
    }
}

named_enum! {
    /// The arithmetic of the Haar shaders (the other methods have their own): the names
    /// `relight render --precision` takes.
    ///
    /// ```
    /// use haarshift_relight::shade::Precision;
    /// assert_eq!(Precision::default(), Precision::F32);
    /// assert_eq!("q16".parse::<Precision>().unwrap(), Precision::Q16);
    /// ```
    #[derive(Default)]
    pub enum Precision ("precision") {
        #[default]
        /// `f32`: the fast path.
        F32 = "f32",
        /// `f64`: for checks and committed tables.
        F64 = "f64",
        /// f32 arithmetic on a transport stored in 16 bits a coefficient with a scale per
        /// vertex ([`QuantisedTransport`](crate::shade::lambert::QuantisedTransport)):
        /// half the bytes a frame streams; Lambertian materials only.
        Q16 = "q16",
    }
}

/// How per-vertex radiance is computed; [`build`](Self::build) makes the [`Shader`].
///
/// ```
/// use haarshift_relight::shade::{Method, ShaderSpec};
/// let spec = ShaderSpec::default();
/// assert_eq!((spec.method, spec.material.brdf.is_lambert(), spec.fill_cache), (Method::Haar, true, false));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ShaderSpec {
    /// The method.
    pub method: Method,
    /// The material: the objects' BRDF (the ground plane stays Lambertian) and, for a glossy
    /// one, how it is brought into each vertex's frame, truncated and cached.
    pub material: GlossyOptions,
    /// Rotate every bin of the rotation cache before the first frame (Phong only).
    pub fill_cache: bool,
    /// The transport's truncation (`keep_visibility`, `depth`), Haar only.
    pub shade: ShadeOptions,
    /// The lighting's truncation, Haar only.
    pub keep_light: Selection,
    /// How a general rotation of the lighting is applied, Haar and spherical harmonics
    /// ([`LightRotation`]).
    pub light_rotation: LightRotation,
    /// The Haar shaders' arithmetic.
    pub precision: Precision,
    /// Spherical harmonics: use the first `B` of the bands stored [default: all].
    pub sh_bands: Option<usize>,
    /// The reference's lat-long height `N` [default: the transport's face size].
    pub reference_resolution: Option<usize>,
    /// The reference reports its progress ([`progress`](haarshift::progress)).
    pub progress: bool,
}

impl Default for ShaderSpec {
    /// Haar, Lambertian, every coefficient, `f32`.
    fn default() -> Self {
        ShaderSpec {
            method: Method::Haar,
            material: GlossyOptions::default(),
            fill_cache: false,
            shade: ShadeOptions::default(),
            keep_light: Selection::All,
            light_rotation: LightRotation::Source,
            precision: Precision::F32,
            sh_bands: None,
            reference_resolution: None,
            progress: false,
        }
    }
}

impl ShaderSpec {
    /// Refuses options that would change nothing for this method and material, with a
    /// message naming the `relight` flags.
    ///
    /// ```
    /// use haarshift_relight::shade::ShaderSpec;
    /// let mut spec = ShaderSpec::default(); // Lambertian
    /// spec.material.cache_bins = Some(16);
    /// assert!(spec.check().is_err()); // a rotation cache rotates glossy BRDFs only
    /// use haarshift_relight::light::environment::LightRotation;
    /// use haarshift_relight::shade::Method;
    /// let fast = ShaderSpec { light_rotation: LightRotation::Prefiltered, ..ShaderSpec::default() };
    /// assert!(fast.check().is_ok());
    /// assert!(ShaderSpec { method: Method::Reference, ..fast }.check().is_err()); // the ground truth
    /// use haarshift_relight::shade::Precision;
    /// let q16 = ShaderSpec { precision: Precision::Q16, ..ShaderSpec::default() };
    /// assert!(q16.check().is_ok()); // Lambertian Haar
    /// let mut glossy = q16.clone();
    /// glossy.material.brdf = "phong:20".parse().unwrap();
    /// assert!(glossy.check().unwrap_err().to_string().contains("q16"));
    /// assert!(ShaderSpec { method: Method::Sh, ..q16 }.check().is_err());
    /// ```
    pub fn check(&self) -> Result<()> {
        let m = &self.material;
        let glossy_set = m.rotation != BrdfRotation::default()
            || m.level.is_some()
            || m.keep_brdf.is_some()
            || m.brdf_levels.is_some()
            || m.cache_bins.is_some()
            || m.elevations != DEFAULT_ELEVATIONS
            || self.fill_cache;
        if glossy_set && m.brdf.is_lambert() {
            return Err(crate::Error::from(haarshift::Error::InvalidParameter {
                name: "brdf-rotation",
                reason: "--brdf-rotation, --level, --keep-brdf, --brdf-levels, --rotation-cache, \
                         --elevations and --fill-cache apply to glossy BRDFs; the BRDF is lambert"
                    .into(),
            }));
        }
        if self.fill_cache && m.cache_bins.is_none() {
            return Err(crate::Error::from(haarshift::Error::InvalidParameter {
                name: "fill-cache",
                reason: "--fill-cache fills the rotation cache: give --rotation-cache N".into(),
            }));
        }
        let truncated = self.keep_light != Selection::All
            || self.shade.keep_visibility.is_some()
            || self.shade.depth.is_some();
        if self.method == Method::Sh && truncated {
            return Err(crate::Error::from(haarshift::Error::InvalidParameter {
                name: "basis",
                reason: "--keep-light, --keep-visibility and --depth truncate the Haar \
                         basis; --basis sh uses every band stored"
                    .into(),
            }));
        }
        if self.precision == Precision::Q16 && (self.method != Method::Haar || !m.brdf.is_lambert())
        {
            return Err(crate::Error::from(haarshift::Error::InvalidParameter {
                name: "precision",
                reason: format!(
                    "--precision q16 quantises the Lambertian Haar transport; this is --basis {} \
                     with --brdf {}",
                    self.method, m.brdf
                ),
            }));
        }
        if self.light_rotation != LightRotation::Source
            && matches!(self.method, Method::Reference | Method::Ambient)
        {
            return Err(crate::Error::from(haarshift::Error::InvalidParameter {
                name: "light-rotation",
                reason: format!(
                    "--light-rotation {} applies to the haar and sh bases; --basis {} rotates \
                     the lighting at the source's resolution (reference) or not at all (ambient)",
                    self.light_rotation, self.method
                ),
            }));
        }
        Ok(())
    }

    /// The method's short name as tables and records print it: the basis (`haar`, `sh`,
    /// `reference`, `ambient`), except that a glossy Haar shader is named by how it brings
    /// the BRDF into each frame (`haar`, `haar-cubic`, `spatial`, `reference`, `direct`).
    ///
    /// ```
    /// use haarshift_relight::material::orient::BrdfRotation;
    /// use haarshift_relight::shade::{Method, ShaderSpec};
    /// let mut spec = ShaderSpec::default();
    /// assert_eq!(spec.label(), "haar");
    /// spec.material.brdf = "phong:20".parse().unwrap();
    /// spec.material.rotation = BrdfRotation::Spatial;
    /// assert_eq!(spec.label(), "spatial");
    /// spec.method = Method::Sh;
    /// assert_eq!(spec.label(), "sh");
    /// ```
    pub fn label(&self) -> String {
        match self.method {
            Method::Haar if !self.material.brdf.is_lambert() => self.material.rotation.to_string(),
            method => method.to_string(),
        }
    }

    /// The shader of this spec for `input`, prepared (and with
    /// [`fill_cache`](Self::fill_cache), its rotation cache filled).
    ///
    /// An input with a bounced sum ([`ShadingInput::bounced`]) is shaded with it by the
    /// Lambertian Haar and spherical-harmonic shaders, `albedo / pi x <T0 + S_c, L_c>`, and
    /// refused by every other method and material: its albedo and BRDF are baked into it.
    pub fn build(&self, input: &ShadingInput<'_>) -> Result<Box<dyn Shader>> {
        self.check()?;
        if let Some(b) = input.bounced
            && !(self.material.brdf.is_lambert()
                && matches!(self.method, Method::Haar | Method::Sh))
        {
            return Err(input.refusal(&format!(
                "it holds {} bounces of light baked with its albedo and a Lambertian BRDF, which \
                 --basis {} with --brdf {} cannot show; --direct-only shows the direct light alone",
                b.bounces(),
                self.method,
                self.material.brdf
            )));
        }
        Ok(match (self.method, self.precision) {
            (Method::Haar, precision) if self.material.brdf.is_lambert() => match precision {
                Precision::F32 | Precision::Q16 => {
                    Box::new(LambertShader::<f32>::new(self, input)?)
                }
                Precision::F64 => Box::new(LambertShader::<f64>::new(self, input)?),
            },
            (Method::Haar, Precision::F64) => Box::new(GlossyHaarShader::<f64>::new(self, input)?),
            (Method::Haar, _) => Box::new(GlossyHaarShader::<f32>::new(self, input)?),
            (Method::Sh, _) => Box::new(ShShader::new(self, input)?),
            (Method::Reference, _) => Box::new(ReferenceShader::new(self, input)?),
            (Method::Ambient, _) => Box::new(AmbientShader::new(self, input)?),
        })
    }
}

/// What a shader is built from: the mesh, its albedo, the precomputed transport (absent for a
/// scene that was not precomputed: only the reference shades it), and where the objects'
/// vertices end (the ground plane's, after them, stay Lambertian).
///
/// ```
/// use haarshift_relight::shade::ShadingInput;
/// use haarshift_relight::{Generator, Scene};
/// let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), true).unwrap();
/// let input = ShadingInput::scene(&scene);
/// assert!(input.transport.is_none());
/// assert_eq!(input.object_vertices, scene.object_vertices());
/// ```
#[derive(Clone, Copy, Debug)]
pub struct ShadingInput<'a> {
    /// The mesh, objects first.
    pub mesh: &'a Mesh,
    /// RGB albedo per vertex, `(V, 3)`.
    pub albedo: ArrayView2<'a, f32>,
    /// Every vertex's transport, when precomputed.
    pub transport: Option<&'a TransportSet>,
    /// Every vertex's bounced sum, to shade with the transport (a cache precomputed with
    /// bounces; `None` shows the direct light alone).
    pub bounced: Option<&'a BouncedTransport>,
    /// Vertices `0..object_vertices` carry the material's BRDF.
    pub object_vertices: usize,
    /// The file the input came from, named by errors about its contents.
    pub origin: Option<&'a Path>,
}

impl<'a> ShadingInput<'a> {
    /// An input from its parts.
    pub fn new(
        mesh: &'a Mesh,
        albedo: ArrayView2<'a, f32>,
        transport: Option<&'a TransportSet>,
        object_vertices: usize,
    ) -> Self {
        ShadingInput {
            mesh,
            albedo,
            transport,
            bounced: None,
            object_vertices,
            origin: None,
        }
    }

    /// A scene cache's mesh, albedo, transport and bounced sum (when it has one).
    pub fn cache(cache: &'a SceneCache) -> Self {
        ShadingInput {
            bounced: cache.bounced.as_ref(),
            ..Self::new(
                &cache.mesh,
                cache.albedo.view(),
                Some(&cache.transport),
                cache.object_vertices(),
            )
        }
    }

    /// A scene without a transport (for the reference).
    pub fn scene(scene: &'a Scene) -> Self {
        Self::new(
            &scene.mesh,
            scene.albedo.view(),
            None,
            scene.object_vertices(),
        )
    }

    /// This input, read from `path`.
    pub fn from_file(self, path: &'a Path) -> Self {
        ShadingInput {
            origin: Some(path),
            ..self
        }
    }

    /// The transport, or the refusal of `method` without one.
    pub(crate) fn transport(&self, method: Method) -> Result<&'a TransportSet> {
        self.transport.ok_or_else(|| {
            Error::parameter(
                "basis",
                format!("{method} needs a precomputed transport: give a scene cache (.hsr)"),
            )
        })
    }

    /// A refusal of the input's contents: naming its file when it has one.
    pub(crate) fn refusal(&self, reason: &str) -> Error {
        match self.origin {
            Some(path) => crate::Error::from(haarshift::Error::Format {
                path: path.to_path_buf(),
                reason: reason.into(),
            }),
            None => Error::parameter("scene", reason),
        }
    }
}
