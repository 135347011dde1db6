//! Flags shared by the `relight` subcommands: the scene, the lighting, the material, the camera
//! and the image.

use std::path::{Path, PathBuf};

use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift_relight::Result;
use haarshift_relight::dynamic::fields::file::FieldStore;
use haarshift_relight::dynamic::{DynamicBudgets, DynamicOptions};
use haarshift_relight::light::environment::{Environment, LightRotation};
use haarshift_relight::material::brdf::DEFAULT_ELEVATIONS;
use haarshift_relight::material::orient::BrdfRotation;
use haarshift_relight::precompute::shard::{Shard, ShardSpec};
use haarshift_relight::render::view::{Backdrop, ViewSpec};
use haarshift_relight::scene::validate::MemoryBudget;
use haarshift_relight::shade::glossy::GlossyOptions;
use haarshift_relight::shade::{LightSpec, Method, Precision, ShadeOptions, ShaderSpec};
use haarshift_relight::{Brdf, EnvironmentSpec, Scene, SceneCache};

pub use haarshift_relight::shade::frame::rotation;

use crate::commands::{choice, names};

/// A mesh or a scene file, and the ground plane.
#[derive(clap::Args, Debug)]
pub struct SceneFlags {
    /// A mesh (.obj, .ply, .gltf, .glb) or a scene file (.json)
    #[arg(value_name = "MESH|SCENE.json")]
    pub input: PathBuf,

    /// Add a ground plane under the scene (a square grid at its lowest y, 4 x its horizontal
    /// extent, of --ground-cells cells per side), unless the scene file has one
    #[arg(long)]
    pub ground_plane: bool,

    /// The ground plane's cells per side (1 to 1024) [default: 32]
    #[arg(long, value_name = "N", requires = "ground_plane", value_parser = ground_cells)]
    pub ground_cells: Option<usize>,

    /// The most memory the scene and its work may take (e.g. 8GiB): a scene file whose
    /// generators, or a precomputation whose transport, would need more is refused before
    /// it starts
    #[arg(long, value_name = "SIZE", default_value = "4GiB", value_parser = memory_size)]
    pub memory_limit: u64,
}

/// `--memory-limit`, read by the library (as Python's `memory_limit` is).
fn memory_size(s: &str) -> std::result::Result<u64, String> {
    haarshift_relight::scene::validate::parse_memory_limit(s).map_err(|e| e.to_string())
}

impl SceneFlags {
    /// The scene, with the ground plane when asked, within the default [`MemoryBudget`]
    /// under `--memory-limit`.
    pub fn load(&self) -> Result<Scene> {
        self.load_within(MemoryBudget {
            limit: self.memory_limit,
            ..MemoryBudget::default()
        })
    }

    /// [`load`](Self::load) within `budget` (its limit is the caller's).
    pub fn load_within(&self, budget: MemoryBudget) -> Result<Scene> {
        let mut scene = Scene::load_within(&self.input, &budget)?;
        // What the mesh files approximated (a glossy glTF material taken as its base colour):
        // one line each, beside the work, not a refusal.
        for warning in &scene.warnings {
            eprintln!("haarshift: warning: {}: {warning}", self.input.display());
        }
        let added = match (self.ground_plane, self.ground_cells) {
            (false, _) => Ok(()),
            (true, None) => scene.add_ground_plane(),
            (true, Some(cells)) => scene.add_ground_plane_of(cells),
        };
        added.map_err(|e| e.in_file(&self.input))?;
        Ok(scene)
    }
}

/// `--ground-cells`, checked by the library.
fn ground_cells(s: &str) -> std::result::Result<usize, String> {
    let cells: usize = s.parse().map_err(|e| format!("{s:?}: {e}"))?;
    haarshift_relight::scene::check_ground_cells(cells).map_err(|e| e.to_string())?;
    Ok(cells)
}

/// Three numbers `x,y,z`.
pub fn triple(s: &str) -> std::result::Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').collect();
    let values: Vec<f64> = parts
        .iter()
        .map(|p| p.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| format!("{s:?}: {e}"))?;
    match values[..] {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok([x, y, z]),
        _ => Err(format!("{s:?}: expected three finite numbers x,y,z")),
    }
}

/// `--brdf`, its syntax checked by the library; a `merl:FILE` is read later
/// ([`MaterialFlags::brdf`]), so that a bad file is one line naming it, not a usage error.
pub fn brdf(s: &str) -> std::result::Result<String, String> {
    match s.strip_prefix("merl:") {
        Some(path) if !path.is_empty() => Ok(s.to_owned()),
        _ => s
            .parse::<Brdf>()
            .map(|_| s.to_owned())
            .map_err(|e| e.to_string()),
    }
}

/// `--shard I/N|auto` and `--shards N`: one machine's share of a split job.
#[derive(clap::Args, Debug)]
pub struct ShardFlags {
    /// Do shard I of N only (`I/N`, I from 0), or `auto`: from the Slurm array task or the
    /// Kubernetes Indexed Job's completion index
    #[arg(long, value_name = "I/N|auto", value_parser = shard_spec)]
    pub shard: Option<ShardSpec>,

    /// With `--shard auto` in a Kubernetes Indexed Job: the number of shards (the Job's
    /// completions); under Slurm it must equal the array's task count
    #[arg(long, value_name = "N", requires = "shard")]
    pub shards: Option<usize>,
}

impl ShardFlags {
    /// The shard named or read from the scheduler's environment, if any.
    pub fn resolve(&self) -> Result<Option<Shard>> {
        ShardSpec::from_env(self.shard, self.shards)
    }
}

/// `--shard`, parsed by the library.
fn shard_spec(s: &str) -> std::result::Result<ShardSpec, String> {
    s.parse()
        .map_err(|e: haarshift_relight::Error| e.to_string())
}

/// When a looked-up occlusion map is truncated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TruncateWhen {
    /// Each sample's map is stored truncated; the lookup blends them.
    Before,
    /// The stored maps are blended, then the blend is truncated to --keep-field.
    After,
}

/// How a dynamic scene (objects with occlusion fields) is built: `relight scene` and
/// `relight view SCENE.json`.
#[derive(clap::Args, Debug)]
#[command(next_help_heading = "Building a scene file's fields (SCENE.json)")]
pub struct DynamicFlags {
    /// Parameterisation of every map: `latlong` N x 2N (objects can turn) or `cube` 6 x N x N
    #[arg(long, default_value = "latlong", value_parser = choice::<ParamKind>(names!(ParamKind)))]
    pub param: ParamKind,

    /// Resolution N: lat-long N x 2N, cube 6 x N x N
    #[arg(long, value_name = "N", default_value_t = 32)]
    pub resolution: usize,

    /// Detail coefficients of each vertex's own transport kept [default: all]
    #[arg(long, value_name = "K")]
    pub keep_visibility: Option<usize>,

    /// Detail coefficients of each occlusion map kept [default: all]
    #[arg(long, value_name = "K")]
    pub keep_field: Option<usize>,

    /// Detail coefficients of each vertex's fixed product kept (animations) [default: all]
    #[arg(long, value_name = "K")]
    pub keep_product: Option<usize>,

    /// When looked-up occlusion maps are truncated
    #[arg(long, value_enum, default_value = "before")]
    pub truncate: TruncateWhen,

    /// Traversal depth: detail levels 0..D-1 only [default: all]
    #[arg(long, value_name = "D")]
    pub depth: Option<usize>,

    /// Circles of the planar field
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub circles: usize,

    /// Points per circle
    #[arg(long, value_name = "N", default_value_t = 200)]
    pub circle_points: usize,

    /// Shells of the spherical field
    #[arg(long, value_name = "N", default_value_t = 20)]
    pub shells: usize,

    /// Points per face edge of each shell's cube grid
    #[arg(long, value_name = "N", default_value_t = 9)]
    pub shell_grid: usize,

    /// Load each shape's fields from DIR when its file matches; build and write absent ones
    #[arg(long, value_name = "DIR")]
    pub fields_dir: Option<PathBuf>,
}

impl DynamicFlags {
    /// The build options the flags say (progress bars on).
    pub fn options(&self) -> Result<DynamicOptions> {
        Ok(DynamicOptions::from_budgets(&DynamicBudgets {
            param: Parameterization::new(self.param, self.resolution)?,
            keep_visibility: self.keep_visibility,
            keep_field: self.keep_field,
            keep_product: self.keep_product,
            truncate_after: self.truncate == TruncateWhen::After,
            depth: self.depth,
            circles: self.circles,
            circle_points: self.circle_points,
            shells: self.shells,
            shell_grid: self.shell_grid,
            progress: true,
        }))
    }

    /// The field files of `--fields-dir`, the directory made ready (created if absent);
    /// `force` replaces files that do not match.
    pub fn field_store(&self, force: bool) -> Result<Option<FieldStore>> {
        let store = self
            .fields_dir
            .as_ref()
            .map(|dir| FieldStore::new(dir, force));
        store.as_ref().map(FieldStore::prepare).transpose()?;
        Ok(store)
    }
}

/// The lighting: the environment map and its rotation.
#[derive(clap::Args, Debug)]
pub struct LightFlags {
    /// Environment map: lat-long (2:1) .hdr, .exr or .npy [default: the scene file's]
    #[arg(long, value_name = "ENV")]
    pub env: Option<PathBuf>,

    /// Rotation of the lighting about +Y, degrees (g(p) = f(R p), R = Rz(roll) Ry(yaw) Rx(pitch))
    /// [default: the scene file's]
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub yaw: Option<f64>,

    /// Rotation of the lighting about +X, degrees [default: the scene file's]
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub pitch: Option<f64>,

    /// Rotation of the lighting about +Z, degrees [default: the scene file's]
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub roll: Option<f64>,

    /// How a rotation other than a yaw by whole columns of the working map is applied (bases
    /// haar and sh): `source` rotates the map at its own resolution, then downsamples (the
    /// sharpest; costs what the source has texels: about 0.1 s per frame for a 1024 x 512 map
    /// on two cores); `prefiltered` rotates a copy brought down once (solid-angle means) to
    /// twice the working lat-long height (2 to 8 ms per frame up to lat-long 128 or cube 64;
    /// blurrier: a sun spreads into the neighbouring texels)
    #[arg(long, value_name = "HOW", default_value = "source",
          value_parser = choice::<LightRotation>(names!(LightRotation)))]
    pub light_rotation: LightRotation,
}

impl LightFlags {
    /// The lighting asked for.
    pub fn spec(&self) -> LightSpec {
        LightSpec {
            env: self.env.clone(),
            yaw: self.yaw,
            pitch: self.pitch,
            roll: self.roll,
        }
    }

    /// The environment (read) and its rotation angles `[yaw, pitch, roll]`, degrees: the
    /// flags, else the scene file's `environment`.
    pub fn load(&self, scene: Option<&EnvironmentSpec>) -> Result<(Environment, [f64; 3])> {
        self.spec().load(scene)
    }
}

/// The material: the BRDF and its albedo.
#[derive(clap::Args, Debug)]
pub struct MaterialFlags {
    /// The BRDF: lambert, phong:EXP (a lobe about the mirror direction), blinn:EXP (Blinn-Phong,
    /// of the half vector), merl:FILE (a measured BRDF, MERL binary format); glossy and measured
    /// ones apply to the scene's objects, the ground plane stays Lambertian
    #[arg(long, value_name = "BRDF", default_value = "lambert", value_parser = brdf)]
    pub brdf: String,

    /// Lambertian albedo r,g,b (each 0 to 1) for every vertex [default: the scene's, 0.8 for
    /// a mesh and the ground plane]
    #[arg(long, value_name = "R,G,B", value_parser = triple)]
    pub albedo: Option<[f64; 3]>,
}

impl MaterialFlags {
    /// The BRDF of `--brdf`, a measured one read from its file.
    pub fn brdf(&self) -> Result<Brdf> {
        self.brdf.parse()
    }

    /// The file `--brdf merl:FILE` names, an input.
    pub fn brdf_file(&self) -> Option<&Path> {
        self.brdf.strip_prefix("merl:").map(Path::new)
    }

    /// `albedo` `(V, 3)` with every row replaced by `--albedo` when given (checked to be in
    /// `[0, 1]`).
    pub fn apply(&self, albedo: &mut ndarray::Array2<f32>) -> Result<()> {
        if let Some(a) = self.albedo {
            if a.iter().any(|x| !(0.0..=1.0).contains(x)) {
                return Err(haarshift_relight::Error::from(
                    haarshift::Error::InvalidParameter {
                        name: "albedo",
                        reason: format!("{a:?}: every channel must be from 0 to 1"),
                    },
                ));
            }
            for mut row in albedo.rows_mut() {
                row.assign(&ndarray::arr1(&a.map(|x| x as f32)));
            }
        }
        Ok(())
    }
}

impl MaterialFlags {
    /// [`apply`](Self::apply) to a cache read from `path`, refusing `--albedo` when the cache
    /// holds bounced light (its albedo is baked into the bounced sum; `relight render
    /// --direct-only` drops the sum first).
    pub fn apply_to_cache(&self, cache: &mut SceneCache, path: &Path) -> Result<()> {
        if let (Some(_), Some(b)) = (self.albedo, &cache.bounced) {
            return Err(haarshift_relight::Error::from(haarshift::Error::Format {
                path: path.to_path_buf(),
                reason: format!(
                    "it holds {} bounces of light made with its own albedo, so --albedo cannot \
                     change it (--direct-only shows the direct light alone)",
                    b.bounces()
                ),
            }));
        }
        self.apply(&mut cache.albedo)
    }
}

/// How a glossy BRDF is brought into each vertex's frame and truncated.
#[derive(clap::Args, Debug)]
pub struct GlossyFlags {
    /// How each vertex's BRDF is rotated into its frame: `haar` (the chain rule on the Haar
    /// coefficients), `spatial` (bilinear in pixels, then transformed), `reference` (solid-angle
    /// integration), `direct` (the BRDF evaluated at every texel, no rotation)
    #[arg(long, value_name = "METHOD", default_value = "haar",
          value_parser = choice::<BrdfRotation>(names!(BrdfRotation)))]
    pub brdf_rotation: BrdfRotation,

    /// Rotate from detail level L (the thesis's level L+1: faces 2^(L+1) texels wide; finer
    /// levels are zero) [default: the finest]
    #[arg(long, value_name = "L")]
    pub level: Option<usize>,

    /// Detail coefficients of each rotated BRDF map kept (the largest), plus each face's
    /// scaling coefficient [default: all]
    #[arg(long, value_name = "K", value_parser = positive)]
    pub keep_brdf: Option<usize>,

    /// Keep only the detail levels 0..L of each rotated BRDF map, 4^L coefficients per face
    /// (the thesis's coarse-to-fine cutoff: 4, 16, 64, 256 coefficients are L = 1 to 4)
    /// [default: every level]
    #[arg(long, value_name = "L")]
    pub brdf_levels: Option<usize>,

    /// Rotate one BRDF map per bin of an N x 2N grid of directions (the mirror direction for
    /// Phong, blended over the 4 nearest bins; the normal for view-dependent BRDFs) and keep it
    /// for every view [default: one rotation per vertex]
    #[arg(long, value_name = "N")]
    pub rotation_cache: Option<usize>,

    /// Outgoing elevations tabulated above the surface for a view-dependent BRDF (Blinn-Phong,
    /// MERL), as many again below it for vertices seen from behind
    #[arg(long, value_name = "E", default_value_t = DEFAULT_ELEVATIONS)]
    pub elevations: usize,

    /// Before shading, rotate every bin of the rotation cache (N x 2N maps, Phong only), timed
    /// on its own, so that every view finds its maps there
    #[arg(long)]
    pub fill_cache: bool,
}

impl GlossyFlags {
    /// The material: `brdf` and how it is rotated, truncated and cached.
    pub fn options(&self, brdf: &Brdf) -> GlossyOptions {
        GlossyOptions {
            brdf: brdf.clone(),
            rotation: self.brdf_rotation,
            level: self.level,
            keep_brdf: self.keep_brdf,
            brdf_levels: self.brdf_levels,
            cache_bins: self.rotation_cache,
            elevations: self.elevations,
        }
    }
}

/// The camera and the image.
#[derive(clap::Args, Debug)]
pub struct CameraFlags {
    /// Camera position x,y,z [default: the scene file's camera, else one that frames the
    /// scene from 20 degrees above the horizon on the +Z side]
    #[arg(long, value_name = "X,Y,Z", value_parser = triple, allow_hyphen_values = true, requires = "look_at")]
    pub camera: Option<[f64; 3]>,

    /// The point the camera looks at, x,y,z
    #[arg(long, value_name = "X,Y,Z", value_parser = triple, allow_hyphen_values = true, requires = "camera")]
    pub look_at: Option<[f64; 3]>,

    /// Vertical field of view, degrees [default: the scene file's, else 40]
    #[arg(long, value_name = "DEG")]
    pub fov: Option<f64>,

    /// Image width, pixels
    #[arg(long, value_name = "W", default_value_t = 640)]
    pub width: usize,

    /// Image height, pixels
    #[arg(long, value_name = "H", default_value_t = 480)]
    pub height: usize,

    /// Exposure for PNG output, stops (the linear radiance is multiplied by 2^E before sRGB)
    #[arg(
        long,
        value_name = "E",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub exposure: f64,

    /// What uncovered pixels show: `env` (the rotated environment) or a linear colour r,g,b
    #[arg(long, value_name = "env|R,G,B", default_value = "env")]
    pub background: String,
}

impl CameraFlags {
    /// The view these flags ask for (`--background` parsed).
    pub fn view(&self) -> Result<ViewSpec> {
        Ok(ViewSpec {
            camera: self.camera.zip(self.look_at),
            fov: self.fov,
            width: self.width,
            height: self.height,
            backdrop: self.backdrop()?,
        })
    }

    /// `--background`, parsed.
    fn backdrop(&self) -> Result<Backdrop> {
        if self.background == "env" {
            return Ok(Backdrop::Environment);
        }
        triple(&self.background)
            .ok()
            .filter(|c| c.iter().all(|&x| x >= 0.0))
            .map(|c| Backdrop::Colour(c.map(|x| x as f32)))
            .ok_or_else(|| {
                haarshift_relight::Error::from(haarshift::Error::InvalidParameter {
                    name: "background",
                    reason: format!(
                        "{:?}: expected `env` or a linear colour r,g,b (non-negative)",
                        self.background
                    ),
                })
            })
    }
}

/// A byte count as people read it (`812 B`, `3.4 KiB`, `51.2 MiB`, `1.07 GiB`).
pub fn bytes(n: u64) -> String {
    const UNITS: [&str; 4] = ["B", "KiB", "MiB", "GiB"];
    let mut value = n as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{n} B")
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

/// A whole number of at least 1.
fn positive(s: &str) -> std::result::Result<usize, String> {
    match s.parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(k) => Ok(k),
        Err(e) => Err(e.to_string()),
    }
}

/// How the per-vertex radiance is computed: the basis and the truncations.
#[derive(clap::Args, Debug)]
pub struct ShadingFlags {
    /// Detail coefficients of the lighting kept (the largest by RGB magnitude, orthonormal),
    /// plus each face's scaling coefficient [default: all]
    #[arg(long, value_name = "K", value_parser = positive)]
    pub keep_light: Option<usize>,

    /// Detail coefficients of each vertex's transport kept at render time (the largest of
    /// those stored), plus each face's scaling coefficient [default: all stored]
    #[arg(long, value_name = "K", value_parser = positive)]
    pub keep_visibility: Option<usize>,

    /// Traversal depth: detail levels 0..D-1 only (0: each face's mean alone; the thesis's
    /// level D, faces 2^D texels wide) [default: all]
    #[arg(long, value_name = "D")]
    pub depth: Option<usize>,

    /// The Haar shading's arithmetic: `f32`; `f64` (slower, for checks); `q16`, f32 on the
    /// Lambertian transport stored in 16 bits a coefficient with a scale per vertex (half the
    /// bytes a frame reads; 7e-6 to 2.3e-4 of the radiance's RMS off, results/relight/quantised.md)
    #[arg(long, value_name = "P", default_value = "f32",
          value_parser = choice::<Precision>(names!(Precision)))]
    pub precision: Precision,
}

impl ShadingFlags {
    /// The lighting's truncation.
    pub fn light_selection(&self) -> Selection {
        self.keep_light.map_or(Selection::All, Selection::Largest)
    }

    /// The transport's truncation.
    pub fn options(&self) -> ShadeOptions {
        ShadeOptions {
            keep_visibility: self.keep_visibility.map(Selection::Largest),
            depth: self.depth,
        }
    }

    /// The shader these flags, `method`, the material (`brdf` under `glossy`) and the
    /// lighting's `--light-rotation` ask for.
    pub fn spec(
        &self,
        method: Method,
        brdf: &Brdf,
        glossy: &GlossyFlags,
        light: &LightFlags,
    ) -> ShaderSpec {
        ShaderSpec {
            method,
            material: glossy.options(brdf),
            fill_cache: glossy.fill_cache,
            shade: self.options(),
            keep_light: self.light_selection(),
            light_rotation: light.light_rotation,
            precision: self.precision,
            progress: true,
            ..ShaderSpec::default()
        }
    }
}

/// Milliseconds since `start`.
pub fn ms(start: std::time::Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}
