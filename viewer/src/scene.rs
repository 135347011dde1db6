//! What the viewer shows: a precomputed scene or a dynamic scene, the environment that lights
//! it, and what the page is sent once (the mesh, the background, the description of both).

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use serde_json::json;

use haarshift::faces::Parameterization;
use haarshift::product::Selection;
use haarshift::sphere::SphereRotation;
use haarshift_relight::dynamic::motion::{FrameState, MotionPath};
use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
use haarshift_relight::light::environment::Environment;
use haarshift_relight::render::camera::Camera;
use haarshift_relight::render::view::ViewSpec;
use haarshift_relight::shade::LightSpec;
use haarshift_relight::{Brdf, Mesh, SceneCache};
use haarshift_relight::{Error, Result};

use crate::protocol::{PacketKind, SampleFormat, packet, sample_bytes};

/// The background's lat-long height on the page: the environment brought down to at most this
/// many rows by solid-angle-weighted means (sharper than a 640-pixel view needs of a 60-degree
/// field of view, a fraction of the bytes of a 1k map).
pub const BACKGROUND_HEIGHT: usize = 256;

/// What is relit: a scene cache, or a dynamic scene whose objects the page moves.
#[derive(Debug)]
pub enum Source {
    /// A precomputed scene (`relight precompute -o SCENE.hsr`), its transport read in place
    /// from the file.
    Cache(Box<SceneCache>),
    /// A scene file built into occlusion fields (`relight scene`'s build), as the file places
    /// its objects; each page's session moves its own copy.
    Dynamic(Box<DynamicScene>),
}

impl Source {
    fn mesh(&self) -> Cow<'_, Mesh> {
        match self {
            Source::Cache(cache) => Cow::Borrowed(&cache.mesh),
            Source::Dynamic(scene) => Cow::Owned(scene.mesh()),
        }
    }
}

/// A scene with its lighting, loaded once and shared by every page's session.
///
/// ```no_run
/// use haarshift_relight::shade::LightSpec;
/// use haarshift_viewer::ViewedScene;
/// let light = LightSpec { env: Some("park.hdr".into()), ..LightSpec::default() };
/// let scene = ViewedScene::load("bunny.hsr".as_ref(), &light).unwrap();
/// println!("{} vertices", scene.mesh().vertex_count());
/// ```
#[derive(Debug)]
pub struct ViewedScene {
    /// What is relit.
    pub source: Source,
    /// The file it was read from, as given.
    pub path: PathBuf,
    /// A dynamic scene's motion path, frame by frame (`relight scene --animate`'s file): the
    /// page plays it.
    pub motion: Option<Vec<FrameState>>,
    /// The environment map's file, as given (or the scene file's).
    pub env_path: PathBuf,
    /// The environment at its source resolution.
    pub environment: Environment,
    /// The rotation the page starts at, `[yaw, pitch, roll]` degrees (the flags', else the
    /// scene's).
    pub angles: [f64; 3],
    /// The camera the page starts at: `relight render`'s default for this scene.
    pub camera: Camera,
    /// Measured BRDFs the page may choose (`relight view --merl FILE`), read once: the page
    /// names them by file stem (`merl:STEM`), never by path.
    pub measured: Vec<(String, Brdf)>,
}

impl ViewedScene {
    /// Reads the scene cache at `path` and the lighting `light` names (else the cache's).
    pub fn load(path: &Path, light: &LightSpec) -> Result<ViewedScene> {
        let cache = SceneCache::read(path)?;
        let environment = cache.environment.clone();
        let camera = cache.camera.clone();
        let source = Source::Cache(Box::new(cache));
        ViewedScene::new(source, path, None, light, environment, camera)
    }

    /// A dynamic scene built from `path` (see [`DynamicScene::load_with`]), the motion path
    /// file `motion` checked against it, and the lighting `light` names (else the file's).
    ///
    /// ```no_run
    /// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift_relight::shade::LightSpec;
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// use haarshift_viewer::ViewedScene;
    /// let path = std::path::Path::new("bunny_and_ball.json");
    /// let options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 32).unwrap());
    /// let built = DynamicScene::load_with(path, &options, None).unwrap();
    /// let scene = ViewedScene::dynamic(built, path, Some("ball_path.json".as_ref()),
    ///                                  &LightSpec::default()).unwrap();
    /// assert_eq!(scene.motion.map(|m| m.len()), Some(25));
    /// ```
    pub fn dynamic(
        scene: DynamicScene,
        path: &Path,
        motion: Option<&Path>,
        light: &LightSpec,
    ) -> Result<ViewedScene> {
        let motion = motion
            .map(|m| {
                MotionPath::load(m)?
                    .states(&scene)
                    .map_err(|e| e.in_file(m))
            })
            .transpose()?;
        let environment = scene.environment.clone();
        let camera = scene.camera.clone();
        let source = Source::Dynamic(Box::new(scene));
        ViewedScene::new(source, path, motion, light, environment, camera)
    }

    fn new(
        source: Source,
        path: &Path,
        motion: Option<Vec<FrameState>>,
        light: &LightSpec,
        environment: Option<haarshift_relight::EnvironmentSpec>,
        camera: Option<haarshift_relight::CameraSpec>,
    ) -> Result<ViewedScene> {
        let (env_path, angles) = light.resolve(environment.as_ref())?;
        let environment = Environment::load(&env_path)?;
        let camera = ViewSpec::default().camera(camera.as_ref(), &source.mesh())?;
        Ok(ViewedScene {
            source,
            path: path.to_path_buf(),
            motion,
            env_path,
            environment,
            angles,
            camera,
            measured: Vec::new(),
        })
    }

    /// The scene with the MERL tables `files` offered as materials, each read now (a bad file
    /// is an error naming it, before the server starts). A dynamic scene's materials are its
    /// scene file's: it takes none.
    ///
    /// ```no_run
    /// use haarshift_relight::shade::LightSpec;
    /// use haarshift_viewer::ViewedScene;
    /// let light = LightSpec { env: Some("park.hdr".into()), ..LightSpec::default() };
    /// let scene = ViewedScene::load("bunny.hsr".as_ref(), &light).unwrap()
    ///     .with_measured(&["gold-metallic-paint.binary".into()]).unwrap();
    /// assert_eq!(scene.measured[0].0, "gold-metallic-paint");
    /// ```
    pub fn with_measured(mut self, files: &[PathBuf]) -> Result<ViewedScene> {
        if !files.is_empty() && matches!(self.source, Source::Dynamic(_)) {
            return Err(Error::parameter(
                "merl",
                "a scene file's materials are its own: measured BRDFs go in its objects' \"brdf\"",
            ));
        }
        for file in files {
            let name = file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            if self.measured.iter().any(|(n, _)| *n == name) {
                return Err(Error::parameter(
                    "merl",
                    format!("{}: a second table named {name:?}", file.display()),
                ));
            }
            let brdf = format!("merl:{}", file.display()).parse::<Brdf>()?;
            self.measured.push((name, brdf));
        }
        Ok(self)
    }

    /// The material the page names `name`: `lambert`, `phong:EXP`, `blinn:EXP`, or
    /// `merl:STEM` of a table given with [`with_measured`](Self::with_measured) (a page never
    /// makes the server read a file).
    pub fn brdf(&self, name: &str) -> Result<Brdf> {
        let Some(stem) = name.strip_prefix("merl:") else {
            return name.parse();
        };
        match self.measured.iter().find(|(n, _)| n == stem) {
            Some((_, brdf)) => Ok(brdf.clone()),
            None => Err(Error::parameter(
                "brdf",
                format!(
                    "{name}: the viewer offers the measured BRDFs given with --merl ({})",
                    if self.measured.is_empty() {
                        "none".to_owned()
                    } else {
                        self.measured
                            .iter()
                            .map(|(n, _)| format!("merl:{n}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                ),
            )),
        }
    }

    /// The mesh as the scene is loaded (a dynamic scene's objects where its file puts them).
    pub fn mesh(&self) -> Cow<'_, Mesh> {
        self.source.mesh()
    }

    /// The parameterisation of the scene's maps.
    pub fn param(&self) -> Parameterization {
        match &self.source {
            Source::Cache(cache) => cache.transport.param(),
            Source::Dynamic(scene) => scene.param(),
        }
    }

    /// The scene cache, or the one-line reason a dynamic scene has none for `what`.
    pub fn cache(&self, what: &str) -> Result<&SceneCache> {
        match &self.source {
            Source::Cache(cache) => Ok(cache),
            Source::Dynamic(_) => Err(Error::parameter(
                "scene",
                format!("{what}: a dynamic scene is shaded by Haar product integrals only"),
            )),
        }
    }

    /// The scene packet: the description in the header, positions `(V, 3)` f32 and triangles
    /// `(T, 3)` u32 in the payload.
    pub fn scene_packet(&self, max_sessions: usize) -> Result<Vec<u8>> {
        let mesh = self.mesh();
        let param = self.param();
        let bounds = mesh.bounds();
        let bounces = match &self.source {
            Source::Cache(cache) => cache.params.bounces,
            Source::Dynamic(_) => 0,
        };
        let (object_vertices, stored, sh_bands, dynamic) = match &self.source {
            Source::Cache(cache) => (
                cache.object_vertices(),
                Some(cache.transport.coefficient_count()),
                cache.params.sh_bands,
                None,
            ),
            Source::Dynamic(scene) => {
                let objects: Vec<_> = (0..scene.object_count())
                    .map(|k| {
                        let p = scene.placement(k);
                        json!({
                            "name": scene.object_name(k),
                            "vertices": [scene.object_vertices(k).start, scene.object_vertices(k).end],
                            "translate": p.translate,
                            "scale": p.scale,
                        })
                    })
                    .collect();
                let ends = (0..scene.object_count()).map(|k| scene.object_vertices(k).end);
                let frames = self.motion.as_ref().map(Vec::len);
                let dynamic = json!({
                    "objects": objects,
                    "path_frames": frames,
                    "build_flags": build_flags(scene.options()),
                });
                (ends.max().unwrap_or(0), None, None, Some(dynamic))
            }
        };
        let header = json!({
            "vertices": mesh.vertex_count(),
            "triangles": mesh.triangles().len(),
            "object_vertices": object_vertices,
            "param": param.kind().to_string(),
            "resolution": param.face_size(),
            "texels": param.texels(),
            "levels": param.face_size().trailing_zeros(),
            "stored_coefficients": stored,
            "sh_bands": sh_bands,
            "bounces": bounces,
            "dynamic": dynamic,
            "measured": self.measured.iter().map(|(name, brdf)| json!({
                "name": name,
                "path": brdf.to_string().trim_start_matches("merl:"),
            })).collect::<Vec<_>>(),
            "cache": self.path,
            "env": self.env_path,
            "angles": self.angles,
            "camera": {
                "position": self.camera.position(),
                "look_at": self.camera.look_at(),
                "fov": self.camera.fov(),
            },
            "bounds": { "min": bounds.min, "max": bounds.max },
            "max_sessions": max_sessions,
        });
        let mut payload = positions_bytes(&mesh);
        payload.extend(
            mesh.triangles()
                .iter()
                .flatten()
                .flat_map(|i| i.to_le_bytes()),
        );
        packet(PacketKind::Scene, &header, &payload)
    }

    /// The environment packet: the unrotated map at most [`BACKGROUND_HEIGHT`] rows high,
    /// `(H, 2H, 3)` f32 (a grey map broadcast to RGB); the page rotates it per pixel.
    pub fn environment_packet(&self) -> Result<Vec<u8>> {
        let height = self.environment.map().height().min(BACKGROUND_HEIGHT);
        let map = self
            .environment
            .lat_long(height, &SphereRotation::identity())?;
        let a = map.as_array();
        let (h, w, c) = a.dim();
        let rgb: Vec<f32> = (0..h * w)
            .flat_map(|k| (0..3).map(move |ch| (k, ch)))
            .map(|(k, ch)| a[[k / w, k % w, ch.min(c - 1)]] as f32)
            .collect();
        let header = json!({ "height": h, "width": w });
        packet(
            PacketKind::Environment,
            &header,
            &sample_bytes(&rgb, SampleFormat::F32),
        )
    }
}

/// `mesh`'s positions `(V, 3)` as little-endian f32: the scene packet's first payload, and a
/// positions packet's.
pub(crate) fn positions_bytes(mesh: &Mesh) -> Vec<u8> {
    let positions: Vec<f32> = mesh.positions().iter().map(|&v| v as f32).collect();
    sample_bytes(&positions, SampleFormat::F32)
}

/// The `relight scene` flags that build a scene as `options` say (its fields and own
/// transport), for the command the page copies.
///
/// ```
/// use haarshift_relight::dynamic::DynamicOptions;
/// use haarshift::faces::param::{ParamKind, Parameterization};
/// use haarshift::product::Selection;
/// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::Cube, 16).unwrap());
/// options.field.keep = Selection::Largest(70);
/// assert_eq!(haarshift_viewer::scene::build_flags(&options).join(" "),
///     "--param cube --resolution 16 --circles 100 --circle-points 200 --shells 20 --shell-grid 9 --keep-field 70");
/// ```
pub fn build_flags(options: &DynamicOptions) -> Vec<String> {
    let f = &options.field;
    let mut flags: Vec<String> = [
        ("param", f.param.kind().to_string()),
        ("resolution", f.param.face_size().to_string()),
        ("circles", f.circles.to_string()),
        ("circle-points", f.circle_points.to_string()),
        ("shells", f.shells.to_string()),
        ("shell-grid", f.shell_grid.to_string()),
    ]
    .into_iter()
    .map(|(name, value)| format!("--{name} {value}"))
    .collect();
    for (name, keep) in [
        ("keep-field", f.keep),
        ("keep-visibility", options.keep_visibility),
        ("keep-product", options.keep_product),
    ] {
        if let Selection::Largest(k) = keep {
            flags.push(format!("--{name} {k}"));
        }
    }
    if let Some(d) = options.depth {
        flags.push(format!("--depth {d}"));
    }
    flags
}
