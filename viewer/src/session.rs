//! One page's session: its shader, its frames and its reference in the background.
//!
//! The session reads every request queued on its socket before it starts a frame and keeps
//! only the latest state, so a drag faster than the frames costs no backlog: the frame
//! computed is always the newest view's. A state equal to the last one drawn (but for its
//! number, or the eye when nothing depends on it) computes nothing.

use std::io::ErrorKind;
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::{Duration, Instant};

use ndarray::Array2;
use serde_json::json;
use tungstenite::{Message, WebSocket};

use haarshift::product::Selection;
use haarshift::sphere::SphereRotation;
use haarshift_relight::dynamic::{Change, DynamicScene, Placement};
use haarshift_relight::light::environment::LightRotation;
use haarshift_relight::material::orient::BrdfRotation;
use haarshift_relight::render::baked::{BakeInfo, GltfContainer, baked_gltf};
use haarshift_relight::render::output::write_render;
use haarshift_relight::render::view::{Backdrop, ViewSpec};
use haarshift_relight::shade::dynamic_scene::{DynamicMethod, DynamicShader, glossy_material};
use haarshift_relight::shade::glossy::GlossyOptions;
use haarshift_relight::shade::{
    FrameSpec, Method, ShadeOptions, Shader, ShaderSpec, Shading, ShadingInput,
};
use haarshift_relight::{Error, Result};

use crate::progress::{Counter, watch};
use crate::protocol::{
    GlbRequest, Notice, PacketKind, PictureRequest, Request, SampleFormat, ViewState, packet,
    sample_bytes,
};
use crate::scene::{Source, ViewedScene, positions_bytes};

/// How long an idle session waits on its socket before it looks at its reference again.
const IDLE_WAIT: Duration = Duration::from_millis(50);
/// How long a busy session waits for one more queued request before it computes.
const DRAIN_WAIT: Duration = Duration::from_millis(1);

/// What the reference of a frame depends on: the lighting's rotation, the material and, for a
/// view-dependent one, the eye.
#[derive(Clone, Debug, PartialEq)]
struct ReferenceKey {
    angles: [f64; 3],
    brdf: String,
    eye: Option<[f64; 3]>,
    /// A dynamic scene's placements (none for a scene cache).
    placements: Vec<Placement>,
}

/// A reference being computed on its own thread.
struct ReferenceJob {
    key: ReferenceKey,
    counter: Arc<Counter>,
    result: Receiver<Result<Shading>>,
    start: Instant,
}

/// One page's state between frames.
pub(crate) struct Session {
    scene: Arc<ViewedScene>,
    shader: Option<(ShaderSpec, Box<dyn Shader>)>,
    /// The state of the last frame sent, its number cleared.
    drawn: Option<ViewState>,
    /// The last frame's radiance, rotation and eye, for a picture of it.
    last: Option<(Array2<f32>, SphereRotation, [f64; 3])>,
    /// A dynamic scene's copy, placed as the last frame asked: each page moves its own.
    placed: Option<Placed>,
    /// The reference sent last, or being computed.
    reference: Option<ReferenceKey>,
    job: Option<ReferenceJob>,
    /// The latest state with the error view on: its reference starts once the running one
    /// ends.
    wanted: Option<ViewState>,
    /// The progress last sent, so that only changes are.
    progress_sent: (u64, u64),
}

impl Session {
    pub(crate) fn new(scene: Arc<ViewedScene>) -> Session {
        Session {
            scene,
            shader: None,
            drawn: None,
            last: None,
            placed: None,
            reference: None,
            job: None,
            wanted: None,
            progress_sent: (0, 0),
        }
    }

    /// Serves the page on `ws` until it closes: the scene first, then a frame for every
    /// latest state.
    pub(crate) fn run(mut self, mut ws: WebSocket<TcpStream>, max_sessions: usize) {
        let opening = self
            .scene
            .scene_packet(max_sessions)
            .and_then(|scene| Ok([scene, self.scene.environment_packet()?]));
        let Ok(packets) = opening else {
            return;
        };
        for packet in packets {
            if ws.send(Message::binary(packet)).is_err() {
                return;
            }
        }
        let mut latest: Option<ViewState> = None;
        loop {
            let wait = if latest.is_some() {
                DRAIN_WAIT
            } else {
                IDLE_WAIT
            };
            if ws.get_ref().set_read_timeout(Some(wait)).is_err() {
                return;
            }
            let outgoing = match ws.read() {
                Ok(Message::Text(text)) => match self.request(&text) {
                    Ok(Request::State(state)) => {
                        latest = Some(*state);
                        continue;
                    }
                    Ok(Request::Picture(picture)) => vec![self.picture(&picture)],
                    Ok(Request::Glb(glb)) => vec![self.glb(&glb)],
                    Err(e) => vec![notice(&Notice::Error {
                        message: e.to_string(),
                    })],
                },
                Ok(Message::Binary(_)) => vec![notice(&Notice::Error {
                    message: "binary requests are not understood: send JSON text".into(),
                })],
                Ok(_) => continue,
                Err(tungstenite::Error::Io(e))
                    if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) =>
                {
                    // Nothing more queued: draw the latest state, report the reference.
                    let mut out = Vec::new();
                    if let Some(state) = latest.take() {
                        out.extend(self.answer(&state));
                    }
                    out.extend(self.poll_reference());
                    out
                }
                Err(_) => return,
            };
            for message in outgoing {
                if ws.send(message).is_err() {
                    return;
                }
            }
        }
    }

    /// A request, checked.
    fn request(&self, text: &str) -> Result<Request> {
        let request =
            serde_json::from_str(text).map_err(|e| Error::parameter("request", format!("{e}")))?;
        match &request {
            Request::State(state) => state.check()?,
            Request::Picture(picture) => picture.check()?,
            Request::Glb(glb) => glb.check()?,
        }
        Ok(request)
    }

    /// The last frame as an OpenEXR picture (linear f32, the environment behind), or the
    /// reason there is none.
    fn picture(&self, request: &PictureRequest) -> Message {
        let picture = || -> Result<Vec<u8>> {
            let (radiance, rotation, eye) = self
                .last
                .as_ref()
                .ok_or_else(|| Error::parameter("picture", "no frame has been drawn yet"))?;
            let view = ViewSpec {
                camera: Some((*eye, request.look_at)),
                fov: Some(request.fov),
                width: request.width,
                height: request.height,
                backdrop: Backdrop::Environment,
            };
            let mesh = match &self.placed {
                Some(placed) => std::borrow::Cow::Owned(placed.scene.mesh()),
                None => self.scene.mesh(),
            };
            let camera = view.camera(None, &mesh)?;
            let image = view.draw(
                &camera,
                &mesh,
                radiance.view(),
                &self.scene.environment,
                rotation,
            )?;
            let dir =
                tempfile::tempdir().map_err(|e| Error::parameter("picture", e.to_string()))?;
            let path = dir.path().join("view.exr");
            write_render(&image, &path, 0.0, false)?;
            let bytes = std::fs::read(&path).map_err(|source| {
                haarshift_relight::Error::from(haarshift::Error::Io { path, source })
            })?;
            let header =
                json!({ "width": request.width, "height": request.height, "format": "exr" });
            packet(PacketKind::Picture, &header, &bytes)
        };
        match picture() {
            Ok(packet) => Message::binary(packet),
            Err(e) => notice(&Notice::Error {
                message: e.to_string(),
            }),
        }
    }

    /// The last frame baked into binary glTF by the library's writer (`relight bake`'s), the
    /// mesh as that frame placed it, or the reason there is none.
    fn glb(&self, request: &GlbRequest) -> Message {
        let glb = || -> Result<Vec<u8>> {
            let ((radiance, _, _), state) = self
                .last
                .as_ref()
                .zip(self.drawn.as_ref())
                .ok_or_else(|| Error::parameter("glb", "no frame has been drawn yet"))?;
            let mesh = match &self.placed {
                Some(placed) => std::borrow::Cow::Owned(placed.scene.mesh()),
                None => self.scene.mesh(),
            };
            let path_yaw = self.placed.as_ref().map_or(0.0, |p| p.path_yaw);
            let info = BakeInfo {
                exposure: request.exposure,
                environment: self
                    .scene
                    .env_path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned()),
                rotation_degrees: [state.yaw + path_yaw, state.pitch, state.roll],
                shading: format!("relight view: {} {}", state.basis, state.brdf),
                cache: self
                    .scene
                    .path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned()),
            };
            let bytes = baked_gltf(&mesh, radiance.view(), &info, GltfContainer::Glb)?;
            let header = json!({ "bytes": bytes.len(), "format": "glb" });
            packet(PacketKind::Glb, &header, &bytes)
        };
        match glb() {
            Ok(packet) => Message::binary(packet),
            Err(e) => notice(&Notice::Error {
                message: e.to_string(),
            }),
        }
    }

    /// The messages answering `state`: its frame, or that the last frame answers it, and the
    /// start of its reference when the error view is on. A state that cannot be served is an error
    /// message; the session goes on.
    fn answer(&mut self, state: &ViewState) -> Vec<Message> {
        let mut out = Vec::new();
        let scene = Arc::clone(&self.scene);
        let frame = match &scene.source {
            Source::Cache(_) => self.frame(state).map(|f| f.map(|f| vec![f])),
            Source::Dynamic(base) => self.dynamic_frame(base, state),
        };
        match frame {
            Ok(Some(packets)) => out.extend(packets.into_iter().map(Message::binary)),
            Ok(None) => out.push(notice(&Notice::Unchanged { seq: state.seq })),
            Err(e) => {
                out.push(notice(&Notice::Error {
                    message: e.to_string(),
                }));
                return out;
            }
        }
        self.wanted = state.error.then(|| state.clone());
        out
    }

    /// The frame of `state`, or `None` when it is the one drawn last.
    fn frame(&mut self, state: &ViewState) -> Result<Option<Vec<u8>>> {
        let spec = self.spec(state)?;
        let mut key = ViewState {
            seq: 0,
            error: false,
            ..state.clone()
        };
        if !view_dependent(&spec) {
            key.eye = None;
        }
        if self.drawn.as_ref() == Some(&key) {
            return Ok(None);
        }
        let mut prepare_ms = 0.0;
        if self.shader.as_ref().map(|(s, _)| s) != Some(&spec) {
            let start = Instant::now();
            self.shader = None; // the old shader's memory goes before the new one's comes
            let cache = self.scene.cache("a shader")?;
            let input = ShadingInput::cache(cache).from_file(&self.scene.path);
            self.shader = Some((spec.clone(), spec.build(&input)?));
            prepare_ms = start.elapsed().as_secs_f64() * 1e3;
        }
        let (_, shader) = self.shader.as_mut().expect("built above");
        let rotation = SphereRotation::from_degrees(state.yaw, state.pitch, state.roll)?;
        let eye = state.eye.unwrap_or(self.scene.camera.position());
        let shading = shader.shade(&FrameSpec {
            environment: &self.scene.environment,
            rotation,
            eye: Some(eye),
        })?;
        self.drawn = Some(key);
        self.frame_packet(
            state,
            (rotation, eye),
            &shading,
            json!({ "prepare_ms": prepare_ms }),
        )
        .map(Some)
    }

    /// The frame packet of `state`, shaded by `shading` under `rotation` seen from `eye`, with
    /// `more` in its header; kept as the last frame.
    fn frame_packet(
        &mut self,
        state: &ViewState,
        (rotation, eye): (SphereRotation, [f64; 3]),
        shading: &Shading,
        more: serde_json::Value,
    ) -> Result<Vec<u8>> {
        let radiance = shading.radiance.to_f32();
        let mut header = json!({
            "seq": state.seq,
            "state": ViewState { eye: Some(eye), ..state.clone() },
            "rotation": rotation.matrix(),
            "format": state.format,
            "vertices": radiance.nrows(),
            "encode_ms": shading.timing.encode_seconds * 1e3,
            "rotate_ms": shading.timing.rotate_seconds * 1e3,
            "shade_ms": shading.timing.shade_seconds * 1e3,
            "prepare_ms": 0.0,
            "light_coefficients": shading.light_coefficients,
            "maps": shading.maps.as_ref().map(|m| json!({ "used": m.maps, "rotated": m.rotated, "cached": m.cached })),
            "description": shading.description,
        });
        if let (Some(header), serde_json::Value::Object(more)) = (header.as_object_mut(), more) {
            header.extend(more);
        }
        let payload = {
            let values = radiance.as_standard_layout();
            sample_bytes(values.as_slice().expect("standard layout"), state.format)
        };
        self.last = Some((radiance, rotation, eye));
        packet(PacketKind::Frame, &header, &payload)
    }

    /// The packets answering `state` in a dynamic scene built as `base`: the mesh's positions
    /// when an object moved since they were last sent, then the frame; `None` when the last
    /// frame answers it. Frames are `relight scene`'s: occlusion fields and Haar product
    /// integrals through [`DynamicShader`].
    fn dynamic_frame(
        &mut self,
        base: &DynamicScene,
        state: &ViewState,
    ) -> Result<Option<Vec<Vec<u8>>>> {
        check_dynamic(state)?;
        self.check_budgets(state)?;
        let glossy = !glossy_material(base)?.is_lambert();
        let mut key = ViewState {
            seq: 0,
            error: false,
            ..state.clone()
        };
        if !glossy {
            key.eye = None;
        }
        if self.drawn.as_ref() == Some(&key) {
            return Ok(None);
        }
        let (placements, path_yaw) = placements(base, self.scene.motion.as_deref(), state)?;
        let start = Instant::now();
        let placed = match self.placed.take() {
            Some(placed) if placed.keep_visibility == state.keep_visibility => placed,
            _ => Placed {
                scene: match state.keep_visibility {
                    Some(k) => base.truncated(Selection::Largest(k), Selection::All)?,
                    None => base.clone(),
                },
                keep_visibility: state.keep_visibility,
                sent: placements_now(base),
                path_yaw: 0.0,
            },
        };
        let placed = self.placed.insert(placed);
        placed.path_yaw = path_yaw;
        for (k, &p) in placements.iter().enumerate() {
            if placed.scene.placement(k) != p {
                placed.scene.place(k, p)?;
            }
        }
        let eye = state.eye.unwrap_or(self.scene.camera.position());
        if glossy {
            placed.scene.set_eye(eye)?;
        }
        let prepare_ms = start.elapsed().as_secs_f64() * 1e3;
        let rotation = SphereRotation::from_degrees(state.yaw + path_yaw, state.pitch, state.roll)?;
        let keep_light = state.keep_light.map_or(Selection::All, Selection::Largest);
        let shading = DynamicShader::new(&placed.scene, DynamicMethod::Haar, keep_light)
            .with_light_rotation(state.light_rotation.parse()?)
            .shade(&FrameSpec {
                environment: &self.scene.environment,
                rotation,
                eye: Some(eye),
            })?;
        let mut packets = Vec::new();
        if placed.sent != placements {
            let mesh = placed.scene.mesh();
            let header = json!({ "vertices": mesh.vertex_count() });
            packets.push(packet(
                PacketKind::Positions,
                &header,
                &positions_bytes(&mesh),
            )?);
            placed.sent.clone_from(&placements);
        }
        let translations: Vec<[f64; 3]> = placements.iter().map(|p| p.translate).collect();
        let more =
            json!({ "prepare_ms": prepare_ms, "translations": translations, "path_yaw": path_yaw });
        packets.push(self.frame_packet(state, (rotation, eye), &shading, more)?);
        self.drawn = Some(key);
        Ok(Some(packets))
    }

    /// Refuses budgets the scene's maps cannot meet: none kept, more than its texels, a depth
    /// past its levels.
    fn check_budgets(&self, state: &ViewState) -> Result<()> {
        let param = self.scene.param();
        let texels = param.texels();
        let levels = param.face_size().trailing_zeros() as usize;
        for (name, budget) in [
            ("keep_light", state.keep_light),
            ("keep_visibility", state.keep_visibility),
            ("keep_brdf", state.keep_brdf),
        ] {
            if let Some(k) = budget.filter(|&k| k == 0 || k > texels) {
                return Err(Error::parameter(
                    name,
                    format!("{k}: expected 1 to the {texels} coefficients of the scene's maps"),
                ));
            }
        }
        if let Some(d) = state.depth.filter(|&d| d > levels) {
            return Err(Error::parameter(
                "depth",
                format!("{d}: the scene's maps have {levels} detail levels"),
            ));
        }
        Ok(())
    }

    /// The shader `state` asks for, its budgets checked against the scene's.
    fn spec(&self, state: &ViewState) -> Result<ShaderSpec> {
        let method: Method = state.basis.parse()?;
        if method == Method::Reference {
            return Err(Error::parameter(
                "basis",
                "the reference is computed in the background: turn on the error view",
            ));
        }
        let brdf = self.scene.brdf(&state.brdf)?;
        // A cache's bounced light was gathered with its albedo and a Lambertian BRDF: its
        // material menu offers nothing else.
        if let Ok(cache) = self.scene.cache("a shader")
            && let Some(b) = &cache.bounced
            && !brdf.is_lambert()
        {
            return Err(Error::parameter(
                "brdf",
                format!(
                    "{}: this cache holds {} bounces of light gathered with its albedo and a \
                     Lambertian BRDF, so its material is fixed",
                    state.brdf,
                    b.bounces()
                ),
            ));
        }
        self.check_budgets(state)?;
        let material = GlossyOptions {
            brdf: brdf.clone(),
            rotation: state.brdf_rotation.parse::<BrdfRotation>()?,
            keep_brdf: state.keep_brdf,
            cache_bins: state.rotation_cache,
            ..GlossyOptions::default()
        }
        .for_brdf(&brdf);
        Ok(ShaderSpec {
            method,
            material,
            shade: ShadeOptions {
                keep_visibility: state.keep_visibility.map(Selection::Largest),
                depth: state.depth,
            },
            keep_light: state.keep_light.map_or(Selection::All, Selection::Largest),
            // Ambient occlusion ignores the lighting: its rotation is not asked for.
            light_rotation: match method {
                Method::Ambient => LightRotation::Source,
                _ => state.light_rotation.parse()?,
            },
            ..ShaderSpec::default()
        })
    }

    /// Starts the reference of `state`'s lighting and material unless it is the one sent or
    /// being computed; one at a time (a newer one starts when the running one ends).
    fn start_reference(&mut self, state: &ViewState) {
        let Ok(brdf) = self.scene.brdf(&state.brdf) else {
            return;
        };
        // The state's frame was drawn: a dynamic scene's copy is placed as it says.
        let path_yaw = self.placed.as_ref().map_or(0.0, |p| p.path_yaw);
        let placed = self.placed.as_ref().map(|p| p.scene.clone());
        let glossy = match &placed {
            Some(scene) => glossy_material(scene).is_ok_and(|b| !b.is_lambert()),
            None => !brdf.is_lambert(),
        };
        let key = ReferenceKey {
            angles: [state.yaw + path_yaw, state.pitch, state.roll],
            brdf: state.brdf.clone(),
            eye: glossy.then(|| state.eye.unwrap_or(self.scene.camera.position())),
            placements: placed.as_ref().map_or_else(Vec::new, placements_now),
        };
        if self.reference.as_ref() == Some(&key) || self.job.is_some() {
            return;
        }
        let Ok(rotation) =
            SphereRotation::from_degrees(key.angles[0], key.angles[1], key.angles[2])
        else {
            return;
        };
        let spec = ShaderSpec {
            method: Method::Reference,
            material: GlossyOptions {
                brdf,
                ..GlossyOptions::default()
            },
            progress: true,
            ..ShaderSpec::default()
        };
        let counter = Arc::new(Counter::default());
        let (send, result) = channel();
        let scene = Arc::clone(&self.scene);
        let watched = Arc::clone(&counter);
        let eye = key.eye.unwrap_or(self.scene.camera.position());
        std::thread::spawn(move || {
            watch(watched);
            let frame = FrameSpec {
                environment: &scene.environment,
                rotation,
                eye: Some(eye),
            };
            let shading = match &placed {
                Some(placed) => {
                    DynamicShader::new(placed, DynamicMethod::Reference, Selection::All)
                        .shade(&frame)
                }
                None => scene.cache("the reference").and_then(|cache| {
                    let input = ShadingInput::cache(cache).from_file(&scene.path);
                    spec.build(&input)?.shade(&frame)
                }),
            };
            // The page may have gone: nobody to tell.
            let _ = send.send(shading);
        });
        self.reference = Some(key.clone());
        self.progress_sent = (0, 0);
        self.job = Some(ReferenceJob {
            key,
            counter,
            result,
            start: Instant::now(),
        });
    }

    /// The reference's news: its progress when it changed, the reference when it is ready.
    fn poll_reference(&mut self) -> Vec<Message> {
        if let Some(state) = self.wanted.clone() {
            self.start_reference(&state);
        }
        let Some(job) = &self.job else {
            return Vec::new();
        };
        match job.result.try_recv() {
            Err(TryRecvError::Empty) => {
                let (done, total) = job.counter.get();
                if (done, total) == self.progress_sent {
                    return Vec::new();
                }
                self.progress_sent = (done, total);
                vec![notice(&Notice::Progress { done, total })]
            }
            Err(TryRecvError::Disconnected) => {
                self.job = None;
                self.reference = None;
                vec![notice(&Notice::Error {
                    message: "the reference's thread ended without a result".into(),
                })]
            }
            Ok(result) => {
                let job = self.job.take().expect("matched above");
                let message = result.and_then(|shading| {
                    let radiance = shading.radiance.to_f32();
                    let values = radiance.as_standard_layout();
                    let header = json!({
                        "yaw": job.key.angles[0],
                        "pitch": job.key.angles[1],
                        "roll": job.key.angles[2],
                        "brdf": job.key.brdf,
                        "eye": job.key.eye,
                        "translations": job.key.placements.iter().map(|p| p.translate).collect::<Vec<_>>(),
                        "seconds": job.start.elapsed().as_secs_f64(),
                        "description": shading.description,
                    });
                    let payload = sample_bytes(
                        values.as_slice().expect("standard layout"),
                        SampleFormat::F32,
                    );
                    packet(PacketKind::Reference, &header, &payload)
                });
                match message {
                    Ok(packet) => vec![Message::binary(packet)],
                    Err(e) => {
                        self.reference = None;
                        vec![notice(&Notice::Error {
                            message: format!("reference: {e}"),
                        })]
                    }
                }
            }
        }
    }
}

/// A dynamic scene's copy in one session.
struct Placed {
    /// The scene, its own transport truncated to `keep_visibility`, placed as the last frame
    /// asked.
    scene: DynamicScene,
    keep_visibility: Option<usize>,
    /// The placements whose positions the page has.
    sent: Vec<Placement>,
    /// The lighting's yaw the motion path adds at the frame drawn last.
    path_yaw: f64,
}

/// Every object's placement in `scene` now.
fn placements_now(scene: &DynamicScene) -> Vec<Placement> {
    (0..scene.object_count())
        .map(|k| scene.placement(k))
        .collect()
}

/// Refuses what a dynamic scene does not offer: it is shaded by Haar product integrals with
/// its file's materials.
fn check_dynamic(state: &ViewState) -> Result<()> {
    let refuse = |name: &'static str, what: &str| {
        Err(Error::parameter(
            name,
            format!(
                "{what}: a dynamic scene is shaded by Haar product integrals with its scene file's materials"
            ),
        ))
    };
    if state.basis != "haar" {
        return refuse("basis", &state.basis);
    }
    if state.brdf != "lambert" {
        return refuse("brdf", &state.brdf);
    }
    if let Some(d) = state.depth {
        return refuse("depth", &d.to_string());
    }
    if let Some(k) = state.keep_brdf {
        return refuse("keep_brdf", &k.to_string());
    }
    Ok(())
}

/// Every object's placement in `state` and the lighting's yaw that its motion path frame
/// adds: the scene's placements, then the path's moves up to its frame, then the page's
/// translations.
fn placements(
    scene: &DynamicScene,
    motion: Option<&[haarshift_relight::dynamic::motion::FrameState]>,
    state: &ViewState,
) -> Result<(Vec<Placement>, f64)> {
    let n = scene.object_count();
    let mut placements = placements_now(scene);
    let mut yaw = 0.0;
    if let Some(f) = state.path_frame {
        let frames = motion.ok_or_else(|| {
            Error::parameter(
                "path_frame",
                "the viewer has no motion path: start it with --animate PATH.json",
            )
        })?;
        let Some(last) = frames.get(f) else {
            return Err(Error::parameter(
                "path_frame",
                format!("{f}: the motion path has {} frames", frames.len()),
            ));
        };
        for frame in &frames[..=f] {
            if let (Change::Object(k), Some(p)) = (frame.change, frame.placement) {
                placements[k] = p;
            }
        }
        yaw = last.light_yaw;
    }
    if let Some(translations) = &state.objects {
        if translations.len() != n {
            return Err(Error::parameter(
                "objects",
                format!(
                    "{} translations: the scene has {n} objects",
                    translations.len()
                ),
            ));
        }
        for (p, &t) in placements.iter_mut().zip(translations) {
            p.translate = t;
        }
    }
    Ok((placements, yaw))
}

/// Whether frames of `spec` change with the eye.
fn view_dependent(spec: &ShaderSpec) -> bool {
    !spec.material.brdf.is_lambert()
}

/// A notice as a text message.
fn notice(n: &Notice) -> Message {
    Message::text(serde_json::to_string(n).expect("a notice serialises"))
}
