//! What the viewer shows: a precomputed scene, the environment that lights it, and what the
//! page is sent once (the mesh, the background, the description of both).

use std::path::{Path, PathBuf};

use serde_json::json;

use haarshift::Result;
use haarshift::relight::SceneCache;
use haarshift::relight::light::environment::Environment;
use haarshift::relight::shade::LightSpec;
use haarshift::render::camera::Camera;
use haarshift::render::view::ViewSpec;
use haarshift::sphere::SphereRotation;

use crate::protocol::{PacketKind, SampleFormat, packet, sample_bytes};

/// The background's lat-long height on the page: the environment brought down to at most this
/// many rows by solid-angle-weighted means (sharper than a 640-pixel view needs of a 60-degree
/// field of view, a fraction of the bytes of a 1k map).
pub const BACKGROUND_HEIGHT: usize = 256;

/// A scene cache with its lighting, loaded once and shared by every page's session.
///
/// ```no_run
/// use haarshift::relight::shade::LightSpec;
/// use haarshift_viewer::ViewedScene;
/// let light = LightSpec { env: Some("park.hdr".into()), ..LightSpec::default() };
/// let scene = ViewedScene::load("bunny.hsr".as_ref(), &light).unwrap();
/// println!("{} vertices", scene.cache.mesh.vertex_count());
/// ```
#[derive(Debug)]
pub struct ViewedScene {
    /// The scene cache, its transport read in place from the file.
    pub cache: SceneCache,
    /// The file it was read from, as given.
    pub cache_path: PathBuf,
    /// The environment map's file, as given (or the scene file's).
    pub env_path: PathBuf,
    /// The environment at its source resolution.
    pub environment: Environment,
    /// The rotation the page starts at, `[yaw, pitch, roll]` degrees (the flags', else the
    /// scene's).
    pub angles: [f64; 3],
    /// The camera the page starts at: `relight render`'s default for this scene.
    pub camera: Camera,
}

impl ViewedScene {
    /// Reads the scene cache at `path` and the lighting `light` names (else the cache's).
    pub fn load(path: &Path, light: &LightSpec) -> Result<ViewedScene> {
        let cache = SceneCache::read(path)?;
        let (env_path, angles) = light.resolve(cache.environment.as_ref())?;
        let environment = Environment::load(&env_path)?;
        let camera = ViewSpec::default().camera(cache.camera.as_ref(), &cache.mesh)?;
        Ok(ViewedScene {
            cache,
            cache_path: path.to_path_buf(),
            env_path,
            environment,
            angles,
            camera,
        })
    }

    /// The scene packet: the description in the header, positions `(V, 3)` f32 and triangles
    /// `(T, 3)` u32 in the payload.
    pub fn scene_packet(&self, max_sessions: usize) -> Result<Vec<u8>> {
        let mesh = &self.cache.mesh;
        let param = self.cache.transport.param();
        let bounds = mesh.bounds();
        let header = json!({
            "vertices": mesh.vertex_count(),
            "triangles": mesh.triangles().len(),
            "object_vertices": self.cache.object_vertices(),
            "param": param.kind().to_string(),
            "resolution": param.face_size(),
            "texels": param.texels(),
            "levels": param.face_size().trailing_zeros(),
            "stored_coefficients": self.cache.transport.coefficient_count(),
            "sh_bands": self.cache.params.sh_bands,
            "cache": self.cache_path,
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
        let positions: Vec<f32> = mesh.positions().iter().map(|&v| v as f32).collect();
        let mut payload = sample_bytes(&positions, SampleFormat::F32);
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
