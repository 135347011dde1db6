//! One way to play a dynamic scene: a [`PlayRequest`] holds what `haarshift relight scene`
//! needs (the scene file, the fields' options and store, the material, lighting, camera, the
//! path to play and the outputs), refuses what cannot be done in one
//! [`check`](PlayRequest::check) before any work, and [`run`](PlayRequest::run)s it: one
//! frame, an animation (numbered images or a GIF), or with a shard only its share of the
//! shapes' field files. What a run did comes back as data ([`PlayOutcome`]); the library
//! prints nothing.

use std::path::{Path, PathBuf};
use std::time::Instant;

use haarshift::faces::Parameterization;
use haarshift::product::Selection;
use haarshift::{PlanarImage, SampleDepth};
use ndarray::{Array2, Array3};

use crate::dynamic::fields::file::FieldStore;
use crate::dynamic::motion::{FrameReport, MotionPath, play};
use crate::dynamic::{BuildReport, DynamicOptions, DynamicScene};
use crate::light::environment::{Environment, LightRotation};
use crate::precompute::shard::{Shard, ShardSpec};
use crate::render::animation::{numbered_path, write_gif};
use crate::render::view::{Frames, ViewSpec};
use crate::render::{Camera, render_format, to_srgb8, write_render};
use crate::shade::dynamic_scene::{DynamicMethod, DynamicShader, glossy_material};
use crate::shade::frame::rotation;
use crate::shade::glossy::GlossyOptions;
use crate::shade::{FrameSpec, LightSpec, Shader, ShaderSpec};
use crate::{Brdf, CameraSpec, Error, Result};

/// Everything `haarshift relight scene` needs, named as its flags are. [`new`](Self::new)
/// gives its defaults.
///
/// ```
/// use haarshift_relight::dynamic::request::PlayRequest;
/// use haarshift_relight::dynamic::{DynamicBudgets, DynamicOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
/// let options = DynamicOptions::from_budgets(&DynamicBudgets::new(param));
/// let mut request = PlayRequest::new("scene.json".into(), options);
/// let err = request.check().unwrap_err().to_string();
/// assert_eq!(err, "invalid output: -o IMAGE is needed to render (only --shard renders nothing)");
/// request.output = Some("frame.gif".into());
/// let err = request.check().unwrap_err().to_string();
/// assert!(err.contains("a .gif needs --animate PATH.json"), "{err}");
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PlayRequest {
    /// The scene file (objects, ground plane, lighting, camera).
    pub scene: PathBuf,
    /// `-o`: the image, or with [`animate`](Self::animate) a `.gif` or numbered images
    /// (`%d`); none with a [`shard`](Self::shard), which only builds fields.
    pub output: Option<PathBuf>,
    /// `--animate PATH.json`: the path to play.
    pub animate: Option<PathBuf>,
    /// `--vertices OUT.npy`: also every vertex's radiance, `(V, 3)` (`(frames, V, 3)`).
    pub vertices: Option<PathBuf>,
    /// `--method`.
    pub method: DynamicMethod,
    /// `--keep-light K`: detail coefficients of the lighting kept (`None`: all).
    pub keep_light: Option<usize>,
    /// How the fields and transports are built.
    pub options: DynamicOptions,
    /// `--fields-dir DIR`: each shape's fields kept in `DIR`.
    pub fields_dir: Option<PathBuf>,
    /// `--shard I/N|auto`: build this share of the shapes' fields into
    /// [`fields_dir`](Self::fields_dir), and render nothing.
    pub shard: Option<ShardSpec>,
    /// `--shards N`: the count of `--shard auto` in a Kubernetes Indexed Job.
    pub shards: Option<usize>,
    /// `--delay MS`: the time each GIF frame is shown.
    pub delay: u32,
    /// `--brdf`: every object's BRDF instead of its material's (`merl:FILE` is read by the
    /// run).
    pub brdf: Option<String>,
    /// How the first glossy material is rotated, truncated and cached (its `brdf` is the
    /// scene's, set by the run).
    pub glossy: GlossyOptions,
    /// `--fill-cache`.
    pub fill_cache: bool,
    /// The environment and its rotation (default the scene file's).
    pub light: LightSpec,
    /// `--light-rotation`.
    pub light_rotation: LightRotation,
    /// The camera and image size.
    pub view: ViewSpec,
    /// `--exposure E`: stops, for 8-bit images.
    pub exposure: f64,
    /// `--force`: replace the outputs (and field files that do not match).
    pub force: bool,
    /// `--bounces B`: refused above 0 (a dynamic scene's interreflections change as its
    /// objects move).
    pub bounces: usize,
}

impl PlayRequest {
    /// A request for `scene`, its fields and transports built with `options`, with
    /// `relight scene`'s defaults and no output.
    pub fn new(scene: PathBuf, options: DynamicOptions) -> Self {
        PlayRequest {
            scene,
            options,
            output: None,
            animate: None,
            vertices: None,
            method: DynamicMethod::Haar,
            keep_light: None,
            fields_dir: None,
            shard: None,
            shards: None,
            delay: 100,
            brdf: None,
            glossy: GlossyOptions::default(),
            fill_cache: false,
            light: LightSpec::default(),
            light_rotation: LightRotation::Source,
            view: ViewSpec::default(),
            exposure: 0.0,
            force: false,
            bounces: 0,
        }
    }

    /// Refuses, before any scene is built: bounces; a shard without a fields directory; no
    /// output (unless a shard); a `.gif` without a path to play; an image format not known;
    /// an output that is an input or exists (unless [`force`](Self::force)); a prefiltered
    /// light rotation in an animation. Reads the path file (to count its frames).
    pub fn check(&self) -> Result<()> {
        self.plan().map(drop)
    }

    /// The outputs, after every refusal of [`check`](Self::check).
    fn plan(&self) -> Result<Plan> {
        if self.bounces > 0 {
            return Err(Error::parameter(
                "bounces",
                "a dynamic scene's objects move, so their interreflections are not \
                 precomputed: --bounces is for static scenes (relight precompute --bounces)",
            ));
        }
        if let Some(shard) = ShardSpec::from_env(self.shard, self.shards)? {
            if self.output.is_some() || self.animate.is_some() || self.vertices.is_some() {
                return Err(Error::parameter(
                    "shard",
                    "--shard only builds fields and renders nothing: no -o, --animate or \
                     --vertices",
                ));
            }
            let dir = self.fields_dir.clone().ok_or_else(|| {
                Error::parameter(
                    "shard",
                    "--shard builds fields into a directory: add --fields-dir DIR",
                )
            })?;
            return Ok(Plan::Fields { shard, dir });
        }
        let output = self.output.clone().ok_or_else(|| {
            Error::parameter(
                "output",
                "-o IMAGE is needed to render (only --shard renders nothing)",
            )
        })?;
        let gif = output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("gif"));
        let path = self.animate.as_deref().map(MotionPath::load).transpose()?;
        if path.is_none() && gif {
            return Err(Error::parameter(
                "output",
                "a .gif needs --animate PATH.json; one frame is .png or .exr",
            ));
        }
        let frame_count = path.as_ref().map_or(1, MotionPath::frame_count);
        let frame_paths: Vec<PathBuf> = match (&path, gif) {
            (Some(_), false) => (0..frame_count)
                .map(|k| numbered_path(&output, k))
                .collect::<Result<_>>()?,
            _ => Vec::new(),
        };
        match frame_paths.first() {
            Some(first) => render_format(first).map(drop)?,
            None if !gif => render_format(&output).map(drop)?,
            None => {}
        }
        self.check_outputs(&output, &frame_paths)?;
        if self.light_rotation != LightRotation::Source && path.is_some() {
            return Err(Error::parameter(
                "light-rotation",
                "--light-rotation prefiltered applies to one frame; an animation's lighting \
                 is rotated at the source's resolution",
            ));
        }
        Ok(Plan::Frames {
            output,
            gif,
            path,
            frame_paths,
        })
    }

    /// Refuses an output that is an input, or that exists unless [`force`](Self::force).
    fn check_outputs(&self, output: &Path, frame_paths: &[PathBuf]) -> Result<()> {
        let mut outputs: Vec<&Path> = if frame_paths.is_empty() {
            vec![output]
        } else {
            frame_paths.iter().map(PathBuf::as_path).collect()
        };
        outputs.extend(self.vertices.as_deref());
        let merl = (self.brdf.as_deref()).and_then(|b| b.strip_prefix("merl:"));
        let inputs = [Some(self.scene.as_path()), self.animate.as_deref()]
            .into_iter()
            .chain([self.light.env.as_deref(), merl.map(Path::new)]);
        for input in inputs.flatten() {
            for output in &outputs {
                haarshift::io::ensure_distinct_paths(input, output)?;
            }
        }
        match outputs.iter().find(|p| !self.force && p.exists()) {
            Some(path) => Err(haarshift::Error::OutputExists {
                path: path.to_path_buf(),
            }
            .into()),
            None => Ok(()),
        }
    }

    /// Runs the request: [`check`](Self::check)s, then builds the fields of a shard's shapes,
    /// or builds the scene and renders its frame or plays its path, writing the images, the
    /// GIF and the vertices' radiance.
    pub fn run(&self) -> Result<PlayOutcome> {
        match self.plan()? {
            Plan::Fields { shard, dir } => {
                let mut store = FieldStore::new(&dir, self.force);
                store.prepare()?;
                let start = Instant::now();
                let report =
                    DynamicScene::build_fields(&self.scene, &self.options, &mut store, shard)?;
                Ok(PlayOutcome::Fields {
                    shard,
                    dir,
                    report,
                    seconds: start.elapsed().as_secs_f64(),
                })
            }
            Plan::Frames {
                output,
                gif,
                path,
                frame_paths,
            } => self
                .frames(&output, gif, path.as_ref(), &frame_paths)
                .map(|r| PlayOutcome::Frames(Box::new(r))),
        }
    }

    /// The scene built, its material, lighting and camera set, and its frames rendered and
    /// written.
    fn frames(
        &self,
        output: &Path,
        gif: bool,
        path: Option<&MotionPath>,
        frame_paths: &[PathBuf],
    ) -> Result<PlayReport> {
        let mut store = self
            .fields_dir
            .as_ref()
            .map(|dir| FieldStore::new(dir, self.force));
        store.as_ref().map(FieldStore::prepare).transpose()?;
        let start = Instant::now();
        let mut scene = DynamicScene::load_with(&self.scene, &self.options, store.as_mut())?;
        let build_seconds = start.elapsed().as_secs_f64();
        let (env, angles) = self.light.load(scene.environment.as_ref())?;
        let camera = self.view.camera(scene.camera.as_ref(), &scene.mesh())?;
        self.set_material(&mut scene)?;
        scene.set_eye(camera.position())?;
        // The camera as resolved from the request and the file: eye segments orbit its
        // look-at point.
        scene.camera = Some(CameraSpec {
            position: camera.position(),
            look_at: camera.look_at(),
            fov: camera.fov(),
        });
        let mut report = PlayReport {
            objects: scene.object_count(),
            shapes: scene.shape_count(),
            vertices: scene.vertex_count(),
            param: scene.param(),
            field_samples: self.options.field.samples(),
            build: *scene.report(),
            build_seconds,
            fields_dir: self.fields_dir.clone(),
            frames: Vec::new(),
        };
        let mut writer = FrameWriter {
            request: self,
            output,
            gif,
            frame_paths,
            frames: Frames::new(self.view),
            env: &env,
            radiance: Vec::new(),
            gif_frames: Vec::new(),
        };
        let keep_light = self.keep_light.map_or(Selection::All, Selection::Largest);
        match path {
            None => {
                let turn = rotation(angles)?;
                let shading = DynamicShader::new(&scene, self.method, keep_light)
                    .with_light_rotation(self.light_rotation)
                    .shade(&FrameSpec {
                        environment: &env,
                        rotation: turn,
                        eye: None,
                    })?;
                let radiance = shading.radiance.to_f32();
                let raster_seconds = writer.draw(&scene, &camera, &radiance, &turn, 0)?;
                report.frames.push(FrameLine {
                    played: None,
                    description: shading.description,
                    shade_seconds: shading.timing.total_seconds(),
                    raster_seconds,
                });
            }
            Some(path) => {
                play(
                    &mut scene,
                    &env,
                    angles,
                    keep_light,
                    path,
                    |scene, radiance, turn, r| {
                        let shading =
                            self.method
                                .played(scene, radiance, r.shade_seconds, &env, turn)?;
                        let eye = scene.eye().unwrap_or(camera.position());
                        let seen_from = match scene.eye() {
                            Some(eye) if eye != camera.position() => {
                                Camera::new(eye, camera.look_at(), camera.fov())?
                            }
                            _ => camera,
                        };
                        let radiance = shading.radiance.to_f32();
                        let raster_seconds =
                            writer.draw(scene, &seen_from, &radiance, turn, r.index)?;
                        report.frames.push(FrameLine {
                            played: Some(PlayedFrame {
                                report: r.clone(),
                                eye,
                            }),
                            description: shading.description,
                            shade_seconds: shading.timing.total_seconds(),
                            raster_seconds,
                        });
                        Ok(())
                    },
                )?;
            }
        }
        writer.finish()?;
        Ok(report)
    }

    /// `--brdf` on every object, and the glossy options on the first glossy material (any
    /// other is rotated alike), checked as a shader checks them.
    fn set_material(&self, scene: &mut DynamicScene) -> Result<()> {
        if let Some(spec) = &self.brdf {
            let brdf: Brdf = spec.parse()?;
            for k in 0..scene.object_count() {
                scene.set_brdf(k, brdf.clone())?;
            }
        }
        let glossy = GlossyOptions {
            brdf: glossy_material(scene)?,
            ..self.glossy.clone()
        };
        ShaderSpec {
            material: glossy.clone(),
            fill_cache: self.fill_cache,
            ..ShaderSpec::default()
        }
        .check()?;
        scene.set_glossy(&glossy)
    }
}

/// What [`PlayRequest::plan`] found.
enum Plan {
    /// A shard of the fields, built into `dir`.
    Fields { shard: Shard, dir: PathBuf },
    /// Frames rendered to `output` (or `frame_paths`, numbered), a GIF when `gif`.
    Frames {
        output: PathBuf,
        gif: bool,
        path: Option<MotionPath>,
        frame_paths: Vec<PathBuf>,
    },
}

/// Draws and writes each frame, keeping what is written at the end (the GIF's frames, the
/// vertices' radiance).
struct FrameWriter<'a> {
    request: &'a PlayRequest,
    output: &'a Path,
    gif: bool,
    frame_paths: &'a [PathBuf],
    /// Each pixel's place in the environment, prepared with the first frame and kept while
    /// the camera stays.
    frames: Frames,
    env: &'a Environment,
    radiance: Vec<Array2<f32>>,
    gif_frames: Vec<PlanarImage<f32>>,
}

impl FrameWriter<'_> {
    /// Frame `index` drawn and written (or kept for the GIF); the seconds rasterising took.
    fn draw(
        &mut self,
        scene: &DynamicScene,
        camera: &Camera,
        radiance: &Array2<f32>,
        turn: &haarshift::sphere::SphereRotation,
        index: usize,
    ) -> Result<f64> {
        let start = Instant::now();
        let image = (self.frames).draw(camera, &scene.mesh(), radiance.view(), self.env, turn)?;
        let seconds = start.elapsed().as_secs_f64();
        let (exposure, force) = (self.request.exposure, self.request.force);
        match (self.frame_paths.get(index), self.gif) {
            (Some(p), _) => write_render(&image, p, exposure, force)?,
            (None, true) => self.gif_frames.push(to_srgb8(&image, exposure)?),
            (None, false) => write_render(&image, self.output, exposure, force)?,
        }
        if self.request.vertices.is_some() {
            self.radiance.push(radiance.clone());
        }
        Ok(seconds)
    }

    /// The GIF and the vertices' radiance written.
    fn finish(self) -> Result<()> {
        let request = self.request;
        if self.gif {
            write_gif(&self.gif_frames, self.output, request.delay, request.force)?;
        }
        let Some(out) = &request.vertices else {
            return Ok(());
        };
        match (&request.animate, self.radiance.as_slice()) {
            (None, [one]) => Ok(haarshift::io::write_npy(
                one.view(),
                SampleDepth::F32,
                out,
                request.force,
            )?),
            _ => {
                let v = self.radiance.first().map_or(0, |r| r.nrows());
                let mut stack = Array3::<f32>::zeros((self.radiance.len(), v, 3));
                for (k, r) in self.radiance.iter().enumerate() {
                    stack.index_axis_mut(ndarray::Axis(0), k).assign(r);
                }
                Ok(haarshift::io::write_npy(
                    stack.view(),
                    SampleDepth::F32,
                    out,
                    request.force,
                )?)
            }
        }
    }
}

/// What a [`PlayRequest`] did.
#[derive(Clone, Debug, PartialEq)]
pub enum PlayOutcome {
    /// A shard's share of the shapes' fields, built or found in `dir`.
    Fields {
        /// The shard.
        shard: Shard,
        /// The fields directory.
        dir: PathBuf,
        /// What building them did.
        report: BuildReport,
        /// Seconds in all.
        seconds: f64,
    },
    /// Frames rendered.
    Frames(Box<PlayReport>),
}

/// The scene built and the frames rendered.
#[derive(Clone, Debug, PartialEq)]
pub struct PlayReport {
    /// Objects in the scene.
    pub objects: usize,
    /// Their distinct shapes.
    pub shapes: usize,
    /// Vertices, the ground plane's included.
    pub vertices: usize,
    /// The parameterisation of every map.
    pub param: Parameterization,
    /// Sample points of a shape's fields.
    pub field_samples: usize,
    /// Rays, seconds and bytes of the fields and the own transport.
    pub build: BuildReport,
    /// Seconds building the scene in all.
    pub build_seconds: f64,
    /// The fields directory, when one was used.
    pub fields_dir: Option<PathBuf>,
    /// Each frame, in order.
    pub frames: Vec<FrameLine>,
}

/// One frame rendered.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameLine {
    /// What the path did for it (`None`: the one frame of a scene not played).
    pub played: Option<PlayedFrame>,
    /// The shading's own description (method, factors, coefficients).
    pub description: String,
    /// Seconds shading.
    pub shade_seconds: f64,
    /// Seconds rasterising.
    pub raster_seconds: f64,
}

/// A frame of a path played.
#[derive(Clone, Debug, PartialEq)]
pub struct PlayedFrame {
    /// Its state and what re-forming cost.
    pub report: FrameReport,
    /// Where the eye was.
    pub eye: [f64; 3],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamic::DynamicBudgets;
    use haarshift::faces::ParamKind;

    fn request(output: Option<&Path>) -> PlayRequest {
        let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
        PlayRequest {
            output: output.map(Path::to_path_buf),
            ..PlayRequest::new(
                "scene.json".into(),
                DynamicOptions::from_budgets(&DynamicBudgets::new(param)),
            )
        }
    }

    /// The refusal's whole message.
    fn refusal(request: &PlayRequest) -> String {
        request.check().unwrap_err().to_string()
    }

    #[test]
    fn every_refusal_comes_before_the_scene_is_read() {
        // scene.json does not exist: each refusal is made before anything reads it.
        let bounced = PlayRequest {
            bounces: 1,
            ..request(Some(Path::new("f.png")))
        };
        assert!(refusal(&bounced).starts_with("invalid bounces: a dynamic scene's objects move"));
        let shard = Some(ShardSpec::Given(Shard::new(0, 2).unwrap()));
        let no_dir = PlayRequest {
            shard,
            ..request(None)
        };
        assert_eq!(
            refusal(&no_dir),
            "invalid shard: --shard builds fields into a directory: add --fields-dir DIR"
        );
        let rendering = PlayRequest {
            shard,
            ..request(Some(Path::new("f.png")))
        };
        assert_eq!(
            refusal(&rendering),
            "invalid shard: --shard only builds fields and renders nothing: no -o, --animate \
             or --vertices"
        );
        assert_eq!(
            refusal(&request(None)),
            "invalid output: -o IMAGE is needed to render (only --shard renders nothing)"
        );
        assert_eq!(
            refusal(&request(Some(Path::new("f.gif")))),
            "invalid output: a .gif needs --animate PATH.json; one frame is .png or .exr"
        );
        assert!(refusal(&request(Some(Path::new("f.bmp")))).contains("f.bmp"));
        let dir = tempfile::tempdir().unwrap();
        let taken = dir.path().join("taken.png");
        std::fs::write(&taken, b"mine").unwrap();
        match request(Some(&taken)).check() {
            Err(Error::Core(haarshift::Error::OutputExists { path })) => assert_eq!(path, taken),
            other => panic!("expected the output refused, got {other:?}"),
        }
        let forced = PlayRequest {
            force: true,
            ..request(Some(&taken))
        };
        forced.check().unwrap();
        assert_eq!(std::fs::read(&taken).unwrap(), b"mine");
    }
}
