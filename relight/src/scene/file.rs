//! The JSON scene file ([`SceneFile`]) and its parts; the [module docs](super) give the
//! schema.

use std::path::{Path, PathBuf};

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use crate::scene::validate::{self, MemoryBudget};
use crate::scene::{MeshAsset, Scene};
use crate::{Brdf, Generator, Mesh, SceneError};
use crate::{Error, Result};
use haarshift::sphere::SphereRotation;

/// Scale, rotation and translation of an object; see the [module docs](super).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    /// Added last.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Uniform scale, applied first.
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// Degrees about Y.
    #[serde(default)]
    pub yaw: f64,
    /// Degrees about X.
    #[serde(default)]
    pub pitch: f64,
    /// Degrees about Z.
    #[serde(default)]
    pub roll: f64,
}

/// A transform's default scale.
fn unit_scale() -> f64 {
    1.0
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            translate: [0.0; 3],
            scale: 1.0,
            yaw: 0.0,
            pitch: 0.0,
            roll: 0.0,
        }
    }
}

impl Transform {
    /// `mesh` transformed: positions `R (s p) + t`, normals `R n` (a uniform scale keeps them).
    pub fn apply(&self, mesh: &Mesh) -> Result<Mesh> {
        if !(self.scale.is_finite() && self.scale > 0.0)
            || self.translate.iter().any(|t| !t.is_finite())
        {
            return Err(Error::parameter(
                "transform",
                "scale must be positive and finite, translate finite",
            ));
        }
        let r = SphereRotation::from_degrees(self.yaw, self.pitch, self.roll)?;
        mesh.mapped(
            |p| {
                let q = r.apply(p.map(|x| x * self.scale));
                std::array::from_fn(|k| q[k] + self.translate[k])
            },
            |n| r.apply(n),
        )
    }
}

/// The albedo of the default material.
pub(crate) const DEFAULT_ALBEDO: [f32; 3] = [0.8, 0.8, 0.8];

/// A surface's material: its BRDF (the `brdf` tag, [`Brdf`]'s `--brdf` names) and its RGB
/// albedo, the diffuse colour of a Lambertian surface and the specular colour of a glossy one.
/// Glossy materials are shaded in dynamic scenes ([`DynamicScene`](crate::dynamic::DynamicScene));
/// a static scene ([`Scene`]) takes its BRDF from `--brdf` and refuses them.
///
/// ```
/// use haarshift_relight::{Brdf, Material};
/// let m: Material = serde_json::from_str(
///     r#"{"brdf": "phong", "exponent": 20, "albedo": [0.9, 0.9, 0.9]}"#).unwrap();
/// assert_eq!(m.brdf().unwrap(), Brdf::Phong { exponent: 20.0 });
/// let bad = Material::Phong { albedo: [1.0; 3], exponent: -1.0 };
/// assert!(bad.brdf().unwrap_err().to_string().contains("from 0"));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "brdf", rename_all = "snake_case", deny_unknown_fields)]
pub enum Material {
    /// Lambertian: reflects `albedo / pi` of the irradiance, per channel.
    Lambert {
        /// RGB albedo, each in `[0, 1]`.
        albedo: [f32; 3],
    },
    /// Energy-normalised Phong ([`Brdf::Phong`]).
    Phong {
        /// RGB specular albedo, each in `[0, 1]`.
        albedo: [f32; 3],
        /// Shininess, `0..=`[`MAX_EXPONENT`](crate::material::brdf::MAX_EXPONENT).
        exponent: f64,
    },
    /// Energy-normalised Blinn-Phong ([`Brdf::BlinnPhong`]).
    Blinn {
        /// RGB specular albedo, each in `[0, 1]`.
        albedo: [f32; 3],
        /// Shininess, `0..=`[`MAX_EXPONENT`](crate::material::brdf::MAX_EXPONENT).
        exponent: f64,
    },
}

impl Default for Material {
    fn default() -> Self {
        Material::Lambert {
            albedo: DEFAULT_ALBEDO,
        }
    }
}

impl Material {
    /// The RGB albedo, checked to be in `[0, 1]`.
    ///
    /// ```
    /// use haarshift_relight::Material;
    /// assert_eq!(Material::default().albedo().unwrap(), [0.8; 3]);
    /// assert!(Material::Lambert { albedo: [2.0, 0.0, 0.0] }.albedo().is_err());
    /// ```
    pub fn albedo(&self) -> Result<[f32; 3]> {
        let (Material::Lambert { albedo }
        | Material::Phong { albedo, .. }
        | Material::Blinn { albedo, .. }) = self;
        if albedo.iter().any(|a| !(0.0..=1.0).contains(a)) {
            return Err(SceneError::SceneFile(format!(
                "albedo {albedo:?}: every channel must be in [0, 1]"
            ))
            .into());
        }
        Ok(*albedo)
    }

    /// The BRDF, its exponent checked as `--brdf` checks it (the same grammar: `phong:EXP`).
    ///
    /// ```
    /// use haarshift_relight::{Brdf, Material};
    /// let m = Material::Blinn { albedo: [0.5; 3], exponent: 12.0 };
    /// assert_eq!(m.brdf().unwrap(), Brdf::BlinnPhong { exponent: 12.0 });
    /// assert!(Material::Phong { albedo: [0.5; 3], exponent: f64::NAN }.brdf().is_err());
    /// ```
    pub fn brdf(&self) -> Result<Brdf> {
        let spec = match self {
            Material::Lambert { .. } => return Ok(Brdf::Lambert),
            Material::Phong { exponent, .. } => format!("phong:{exponent}"),
            Material::Blinn { exponent, .. } => format!("blinn:{exponent}"),
        };
        spec.parse::<Brdf>()
            .map_err(|e| SceneError::SceneFile(format!("material: {e}")).into())
    }
}

/// One object of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneObject {
    /// A name an animation path can refer to (dynamic scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// A mesh file (OBJ, PLY, glTF or GLB), relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// A procedural mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generator: Option<Generator>,
    /// Placement.
    #[serde(default)]
    pub transform: Transform,
    /// Material.
    #[serde(default)]
    pub material: Material,
}

impl SceneObject {
    /// The object's mesh in its own frame (before its transform): its mesh file, relative to
    /// `dir`, or its generator's; `k` is its place in the scene file, for the message.
    pub fn shape(&self, dir: &Path, k: usize) -> Result<Mesh> {
        self.asset(dir, k, &MemoryBudget::default()).map(|a| a.mesh)
    }

    /// [`shape`](Self::shape) with the colour its mesh file carries ([`MeshAsset`]; a
    /// generator's carries none), read within `budget`. The object's albedo is
    /// [`albedo`](Self::albedo).
    pub fn asset(&self, dir: &Path, k: usize, budget: &MemoryBudget) -> Result<MeshAsset> {
        match (&self.mesh, &self.generator) {
            (Some(path), None) => MeshAsset::load_within(&dir.join(path), budget),
            (None, Some(generator)) => generator.mesh().map(MeshAsset::plain),
            _ => Err(SceneError::SceneFile(format!(
                "object {k} must have exactly one of \"mesh\" and \"generator\""
            ))
            .into()),
        }
    }
}

impl SceneObject {
    /// The object's albedo per vertex of `asset` (its [`asset`](Self::asset)): the material's
    /// albedo times the asset's own where the file carries colour, else the material's alone.
    ///
    /// ```
    /// use haarshift_relight::{Mesh, SceneObject};
    /// use haarshift_relight::scene::MeshAsset;
    /// use ndarray::array;
    /// let mesh = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    ///                      vec![[0, 1, 2]], None).unwrap();
    /// let object: SceneObject = serde_json::from_str(
    ///     r#"{"mesh": "x.ply", "material": {"brdf": "lambert", "albedo": [0.5, 1, 1]}}"#).unwrap();
    /// let mut asset = MeshAsset::plain(mesh);
    /// assert_eq!(object.albedo(&asset).unwrap().row(0).to_vec(), vec![0.5, 1.0, 1.0]);
    /// asset.albedo = Some(array![[0.2, 0.4, 0.6], [1.0; 3], [1.0; 3]]);
    /// assert_eq!(object.albedo(&asset).unwrap().row(0).to_vec(), vec![0.1, 0.4, 0.6]);
    /// ```
    pub fn albedo(&self, asset: &MeshAsset) -> Result<Array2<f32>> {
        let a = self.material.albedo()?;
        Ok(match &asset.albedo {
            Some(own) => Array2::from_shape_fn(own.raw_dim(), |(v, c)| a[c] * own[[v, c]]),
            None => Array2::from_shape_fn((asset.mesh.vertex_count(), 3), |(_, c)| a[c]),
        })
    }
}

/// The environment lighting of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// The lat-long map (HDR, EXR or `.npy`), relative to the scene file.
    pub path: PathBuf,
    /// Degrees.
    #[serde(default)]
    pub yaw: f64,
    /// Degrees.
    #[serde(default)]
    pub pitch: f64,
    /// Degrees.
    #[serde(default)]
    pub roll: f64,
}

/// The camera of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position.
    pub position: [f64; 3],
    /// The point the camera looks at.
    pub look_at: [f64; 3],
    /// Vertical field of view, degrees.
    #[serde(default = "default_fov")]
    pub fov: f64,
}

impl CameraSpec {
    /// Checks the position and the point looked at against
    /// [`MAX_COORDINATE`](super::validate::MAX_COORDINATE), as a scene file is read.
    ///
    /// ```
    /// use haarshift_relight::CameraSpec;
    /// let far = CameraSpec { position: [0.0, 2.0, 5.0], look_at: [0.0, 1e308, 0.0], fov: 40.0 };
    /// assert!(matches!(far.check(), Err(haarshift_relight::Error::Scene { .. })));
    /// ```
    pub fn check(&self) -> Result<()> {
        validate::check_point("the camera's position", self.position)?;
        validate::check_point("the camera's look_at", self.look_at)
    }
}

fn default_fov() -> f64 {
    45.0
}

/// A scene file's content; see the [module docs](super) for the schema.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// The objects, merged in order.
    pub objects: Vec<SceneObject>,
    /// Whether to add the ground plane.
    #[serde(default)]
    pub ground_plane: bool,
    /// The ground plane's cells per side (only with `ground_plane`; default
    /// [`GROUND_CELLS`](super::GROUND_CELLS)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ground_cells: Option<usize>,
    /// The lighting.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<EnvironmentSpec>,
    /// The camera.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraSpec>,
}

/// Reads a JSON file of the scene family (scene files, motion paths) into `T`; a bad file is
/// a [`SceneError::SceneFile`] naming it.
pub(crate) fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| crate::Error::io(path.to_path_buf(), source))?;
    serde_json::from_str(&text)
        .map_err(|e| Error::from(SceneError::SceneFile(e.to_string())).in_file(path))
}

impl SceneFile {
    /// Reads a JSON scene file; returns it with the directory its relative paths start from.
    pub fn read(path: &Path) -> Result<(SceneFile, &Path)> {
        Ok((read_json(path)?, path.parent().unwrap_or(Path::new(""))))
    }

    /// Refuses a file whose generated objects would not fit in `budget`, from their
    /// settings alone ([`Generator::vertex_count`]), before any of them is built; the error
    /// names the object at which the running sum of their vertices passes the limit.
    ///
    /// ```
    /// use haarshift_relight::SceneFile;
    /// use haarshift_relight::scene::validate::MemoryBudget;
    /// let file: SceneFile = serde_json::from_str(r#"{"objects": [{"mesh": "bunny.ply"},
    ///     {"generator": {"sphere": {"cells": 3000}}}]}"#).unwrap();
    /// let err = file.check_memory(&MemoryBudget::default()).unwrap_err().to_string();
    /// assert!(err.starts_with(r#"object 1, {"sphere":{"cells":3000}}, with the generators before it (54036006 vertices) needs"#));
    /// ```
    pub fn check_memory(&self, budget: &MemoryBudget) -> Result<()> {
        let mut vertices: u128 = 0;
        for (k, object) in self.objects.iter().enumerate() {
            let Some(generator) = &object.generator else {
                continue;
            };
            // A count past usize is at least 2^64 vertices: refused as that. The sum of at
            // most 2^64 objects of at most 2^64 vertices each stays inside u128.
            vertices += generator.vertex_count().map_or(1 << 64, |v| v as u128);
            let settings = serde_json::to_string(generator).expect("a generator serialises");
            budget.check(
                &format!("object {k}, {settings}, with the generators before it"),
                vertices,
            )?;
        }
        Ok(())
    }

    /// The scene, relative paths resolved against `dir`, within the default
    /// [`MemoryBudget`].
    pub fn build(&self, dir: &Path) -> Result<Scene> {
        self.build_within(dir, &MemoryBudget::default())
    }

    /// [`build`](Self::build), refused first when its generators do not fit in `budget`
    /// ([`check_memory`](Self::check_memory)).
    pub fn build_within(&self, dir: &Path, budget: &MemoryBudget) -> Result<Scene> {
        self.check_memory(budget)?;
        let ground_cells = self.ground_cells()?;
        if self.objects.is_empty() {
            return Err(SceneError::SceneFile("a scene needs at least one object".into()).into());
        }
        if let Some(camera) = &self.camera {
            camera.check()?;
        }
        let mut mesh: Option<Mesh> = None;
        let mut albedo = Array2::<f32>::zeros((0, 3));
        let mut warnings = Vec::new();
        for (k, object) in self.objects.iter().enumerate() {
            let asset = object.asset(dir, k, budget)?;
            let shape = object.transform.apply(&asset.mesh)?;
            let rows = object.albedo(&asset)?;
            warnings.extend(asset.warnings.iter().map(|w| format!("object {k}: {w}")));
            if !object.material.brdf()?.is_lambert() {
                return Err(SceneError::SceneFile(format!(
                    "object {k}: a glossy material is shaded in dynamic scenes (relight scene); \
                     a static scene takes its BRDF from --brdf"
                ))
                .into());
            }
            albedo
                .append(ndarray::Axis(0), rows.view())
                .expect("(V, 3)");
            match &mut mesh {
                None => mesh = Some(shape),
                Some(m) => m.append(&shape),
            }
        }
        let mut scene = Scene {
            mesh: mesh.expect("at least one object"),
            albedo,
            environment: self.environment.clone().map(|mut e| {
                e.path = dir.join(&e.path);
                e
            }),
            camera: self.camera.clone(),
            ground_plane: false,
            ground_cells: None,
            ground_vertices: 0,
            warnings,
        };
        if let Some(cells) = ground_cells {
            scene.add_ground_plane_of(cells)?;
        }
        Ok(scene)
    }

    /// The ground plane's cells per side, `None` without one; refuses `ground_cells` without
    /// `"ground_plane": true` and a count outside
    /// [`check_ground_cells`](super::check_ground_cells)'s range.
    ///
    /// ```
    /// use haarshift_relight::SceneFile;
    /// let file = |json: &str| serde_json::from_str::<SceneFile>(json).unwrap();
    /// let objects = r#""objects": [{"generator": {"sphere": {"cells": 2}}}]"#;
    /// assert_eq!(file(&format!("{{{objects}, \"ground_plane\": true}}")).ground_cells().unwrap(), Some(32));
    /// let dense = file(&format!("{{{objects}, \"ground_plane\": true, \"ground_cells\": 64}}"));
    /// assert_eq!(dense.ground_cells().unwrap(), Some(64));
    /// assert!(file(&format!("{{{objects}, \"ground_cells\": 64}}")).ground_cells().is_err());
    /// assert!(file(&format!("{{{objects}, \"ground_plane\": true, \"ground_cells\": 0}}")).ground_cells().is_err());
    /// ```
    pub fn ground_cells(&self) -> Result<Option<usize>> {
        match (self.ground_plane, self.ground_cells) {
            (false, None) => Ok(None),
            (false, Some(cells)) => Err(SceneError::SceneFile(format!(
                "\"ground_cells\": {cells} needs \"ground_plane\": true"
            ))
            .into()),
            (true, cells) => {
                let cells = cells.unwrap_or(super::GROUND_CELLS);
                super::check_ground_cells(cells)
                    .map_err(|e| SceneError::SceneFile(format!("\"ground_cells\": {e}")))?;
                Ok(Some(cells))
            }
        }
    }
}
