//! What the page and the server say to each other over the WebSocket.
//!
//! **Page to server**: JSON text messages, one [`Request`] each, with unknown fields refused
//! (a misspelt option is an error on the page, not a silent default). The page sends the whole
//! view state on every change ([`ViewState`]); the server keeps only the latest state it has
//! read when it starts a frame, so a fast drag costs no queue.
//!
//! **Server to page**: JSON text messages ([`Notice`]: the scene's description, errors, the
//! reference's progress) and binary messages, each one [`packet`]: a kind, a JSON header and a
//! little-endian payload starting at a multiple of 4 bytes, so the page reads it as a
//! `Float32Array`, `Uint16Array` (f16) or `Uint32Array` view without a copy:
//!
//! | bytes | content |
//! |---|---|
//! | 0..4 | kind, u32 ([`PacketKind`]) |
//! | 4..8 | header length `J`, u32 |
//! | 8..8+J | header, UTF-8 JSON |
//! | then | zeros to a multiple of 4 |
//! | then | payload |

use serde::{Deserialize, Serialize};

use haarshift_relight::{Error, Result};

/// The largest angle, in degrees, a state may carry: a hundred turns either way. Beyond it a
/// request is refused rather than reduced, since no drag produces it.
pub const MAX_DEGREES: f64 = 36_000.0;

/// The most object translations a state may carry (the scene's own count is checked by the
/// session).
pub const MAX_OBJECTS: usize = 4096;

/// One message from the page.
///
/// ```
/// use haarshift_viewer::protocol::Request;
/// let r: Request = serde_json::from_str(r#"{"type": "state", "seq": 3, "yaw": 10}"#).unwrap();
/// let Request::State(state) = r else { unreachable!() };
/// assert_eq!((state.seq, state.yaw, state.pitch), (3, 10.0, 0.0));
/// assert!(serde_json::from_str::<Request>(r#"{"type": "state", "seq": 1, "yawn": 1}"#).is_err());
/// ```
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Request {
    /// The view as the page now shows it: compute its frame.
    State(Box<ViewState>),
    /// The last frame drawn as a linear OpenEXR picture, by `relight render`'s rasteriser.
    Picture(PictureRequest),
    /// The last frame's radiance baked into binary glTF, as `relight bake` writes it.
    Glb(GlbRequest),
}

/// The baked glTF of the last frame: its colours `clamp(2^exposure x radiance, 0, 1)`, as
/// `relight bake --exposure` makes them (the page's exposure slider).
///
/// ```
/// use haarshift_viewer::protocol::{GlbRequest, Request};
/// let r: Request = serde_json::from_str(r#"{"type": "glb", "exposure": 1.5}"#).unwrap();
/// assert_eq!(r, Request::Glb(GlbRequest { exposure: 1.5 }));
/// assert!(GlbRequest { exposure: 1e9 }.check().is_err());
/// ```
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GlbRequest {
    /// Stops.
    pub exposure: f64,
}

impl GlbRequest {
    /// Refuses an exposure `relight bake` would refuse.
    pub fn check(&self) -> Result<()> {
        haarshift_relight::render::baked::BakeInfo {
            exposure: self.exposure,
            ..Default::default()
        }
        .check()
    }
}

/// The largest picture side, in pixels.
pub const MAX_PICTURE_SIDE: usize = 8192;

/// The camera of a picture: the eye is the last frame's.
///
/// ```
/// use haarshift_viewer::protocol::PictureRequest;
/// let p = PictureRequest { look_at: [0.0; 3], fov: 40.0, width: 640, height: 480 };
/// assert!(p.check().is_ok());
/// assert!(PictureRequest { width: 100_000, ..p }.check().is_err());
/// ```
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PictureRequest {
    /// The point looked at.
    pub look_at: [f64; 3],
    /// Vertical field of view, degrees.
    pub fov: f64,
    /// Pixels.
    pub width: usize,
    /// Pixels.
    pub height: usize,
}

impl PictureRequest {
    /// Refuses a picture of no pixels or more than [`MAX_PICTURE_SIDE`] a side (the camera is
    /// checked when it is made).
    pub fn check(&self) -> Result<()> {
        for (name, side) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_PICTURE_SIDE).contains(&side) {
                return Err(Error::parameter(
                    name,
                    format!("{side} pixels: expected 1 to {MAX_PICTURE_SIDE}"),
                ));
            }
        }
        Ok(())
    }
}

/// Everything a frame depends on, as the page's controls set it.
///
/// ```
/// use haarshift_viewer::protocol::ViewState;
/// let s = ViewState::default();
/// assert_eq!((s.basis.as_str(), s.brdf.as_str(), s.format), ("haar", "lambert", haarshift_viewer::protocol::SampleFormat::F32));
/// ```
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct ViewState {
    /// The page's number for this state, echoed in the frame computed for it.
    pub seq: u64,
    /// Rotation of the lighting about +Y, degrees (`relight render --yaw`).
    pub yaw: f64,
    /// About +X, degrees.
    pub pitch: f64,
    /// About +Z, degrees.
    pub roll: f64,
    /// `haar`, `sh`, `ambient` (`relight render --basis`; the reference is the error view's).
    pub basis: String,
    /// `lambert`, `phong:EXP`, `blinn:EXP` (`relight render --brdf`).
    pub brdf: String,
    /// How a glossy BRDF is rotated into each vertex's frame (`--brdf-rotation`).
    pub brdf_rotation: String,
    /// Detail coefficients of the lighting kept (`--keep-light`); all when absent.
    pub keep_light: Option<usize>,
    /// Detail coefficients of each vertex's transport kept (`--keep-visibility`).
    pub keep_visibility: Option<usize>,
    /// Traversal depth (`--depth`).
    pub depth: Option<usize>,
    /// Detail coefficients of each rotated BRDF map kept, the largest (`--keep-brdf`); all
    /// when absent.
    pub keep_brdf: Option<usize>,
    /// A glossy BRDF's rotation cache, `N x 2N` bins (`--rotation-cache`); one rotation per
    /// vertex when absent.
    pub rotation_cache: Option<usize>,
    /// How a general rotation of the lighting is applied (`--light-rotation`): `prefiltered`
    /// (a few milliseconds, the viewer's default) or `source`.
    pub light_rotation: String,
    /// The camera's position: the eye of view-dependent BRDFs.
    pub eye: Option<[f64; 3]>,
    /// The radiance's sample format in frames.
    pub format: SampleFormat,
    /// Compute the reference for this lighting and material in the background, and send it
    /// when ready, so the page can show the frame's error.
    pub error: bool,
    /// A dynamic scene's motion path frame (`relight view --animate`): every object where
    /// the path has put it by then, and the lighting turned by the path's yaw on top of `yaw`.
    pub path_frame: Option<usize>,
    /// A dynamic scene's objects' translations, one per object in the scene's order (their
    /// scale and turn stay): where the page has dragged them. Absent: the scene file's (or
    /// the path frame's) placements.
    pub objects: Option<Vec<[f64; 3]>>,
}

impl Default for ViewState {
    fn default() -> Self {
        ViewState {
            seq: 0,
            yaw: 0.0,
            pitch: 0.0,
            roll: 0.0,
            basis: "haar".into(),
            brdf: "lambert".into(),
            brdf_rotation: "haar".into(),
            keep_light: None,
            keep_visibility: None,
            depth: None,
            keep_brdf: None,
            rotation_cache: None,
            light_rotation: "prefiltered".into(),
            eye: None,
            format: SampleFormat::F32,
            error: false,
            path_frame: None,
            objects: None,
        }
    }
}

impl ViewState {
    /// Refuses angles and an eye no drag produces: not finite, or beyond [`MAX_DEGREES`].
    ///
    /// ```
    /// use haarshift_viewer::protocol::ViewState;
    /// assert!(ViewState { yaw: 1e9, ..ViewState::default() }.check().is_err());
    /// assert!(ViewState { eye: Some([0.0, f64::INFINITY, 0.0]), ..ViewState::default() }.check().is_err());
    /// assert!(ViewState { objects: Some(vec![[0.0, f64::NAN, 1.0]]), ..ViewState::default() }.check().is_err());
    /// assert!(ViewState { objects: Some(vec![[1.0; 3]; 5000]), ..ViewState::default() }.check().is_err());
    /// assert!(ViewState::default().check().is_ok());
    /// ```
    pub fn check(&self) -> Result<()> {
        for (name, angle) in [
            ("yaw", self.yaw),
            ("pitch", self.pitch),
            ("roll", self.roll),
        ] {
            if !angle.is_finite() || angle.abs() > MAX_DEGREES {
                return Err(Error::parameter(
                    name,
                    format!("{angle} degrees: expected a finite angle within {MAX_DEGREES}"),
                ));
            }
        }
        if let Some(eye) = self.eye.filter(|e| e.iter().any(|v| !v.is_finite())) {
            return Err(Error::parameter(
                "eye",
                format!("{eye:?}: expected three finite numbers"),
            ));
        }
        let objects = self.objects.as_deref().unwrap_or_default();
        if objects.len() > MAX_OBJECTS {
            return Err(Error::parameter(
                "objects",
                format!("{} translations: at most {MAX_OBJECTS}", objects.len()),
            ));
        }
        if let Some(t) = objects.iter().find(|t| t.iter().any(|v| !v.is_finite())) {
            return Err(Error::parameter(
                "objects",
                format!("{t:?}: expected three finite numbers"),
            ));
        }
        Ok(())
    }
}

/// How radiance travels in a frame.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SampleFormat {
    /// 4 bytes a value: the shader's f32 radiance bit for bit.
    #[default]
    F32,
    /// 2 bytes a value (IEEE half, rounded to nearest): half the bytes.
    F16,
}

/// A text message from the server.
///
/// ```
/// use haarshift_viewer::protocol::Notice;
/// let n = Notice::Error { message: "bad".into() };
/// assert_eq!(serde_json::to_string(&n).unwrap(), r#"{"type":"error","message":"bad"}"#);
/// ```
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Notice {
    /// A request could not be served; the session goes on.
    Error {
        /// One line.
        message: String,
    },
    /// State `seq` changes nothing the last frame depends on (only the eye, say, under a
    /// Lambertian material): that frame answers it.
    Unchanged {
        /// The state's number.
        seq: u64,
    },
    /// The reference in the background: `done` of `total` units.
    Progress {
        /// Units done.
        done: u64,
        /// Units in all.
        total: u64,
    },
}

/// The kinds of binary [`packet`]s.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum PacketKind {
    /// The scene: header the description, payload positions `(V, 3)` f32 then triangles
    /// `(T, 3)` u32.
    Scene = 1,
    /// The environment for the background: header its size, payload `(H, 2H, 3)` f32.
    Environment = 2,
    /// A frame: header the state it answers and its timing, payload radiance `(V, 3)`.
    Frame = 3,
    /// The reference of a lighting and material: header the state, payload radiance
    /// `(V, 3)` f32.
    Reference = 4,
    /// A picture: header its size, payload an OpenEXR file.
    Picture = 5,
    /// A dynamic scene's mesh as the next frame places its objects: header the vertex count,
    /// payload positions `(V, 3)` f32 (the triangles stay the scene packet's).
    Positions = 6,
    /// A baked glTF of the last frame: header its size, payload a `.glb` file.
    Glb = 7,
}

/// The bytes of one binary message of `kind`: its JSON `header`, then `payload` aligned to 4
/// bytes.
///
/// ```
/// use haarshift_viewer::protocol::{PacketKind, packet};
/// let bytes = packet(PacketKind::Frame, &serde_json::json!({"seq": 1}), &[1.5f32.to_le_bytes()].concat()).unwrap();
/// assert_eq!(&bytes[0..4], &3u32.to_le_bytes());
/// let header_len = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
/// assert_eq!(&bytes[8..8 + header_len], br#"{"seq":1}"#);
/// let payload = (8 + header_len).next_multiple_of(4);
/// assert_eq!(&bytes[payload..], &1.5f32.to_le_bytes());
/// ```
pub fn packet(kind: PacketKind, header: &impl Serialize, payload: &[u8]) -> Result<Vec<u8>> {
    let header = serde_json::to_vec(header)
        .map_err(|e| Error::parameter("packet", format!("header: {e}")))?;
    let start = (8 + header.len()).next_multiple_of(4);
    let mut bytes = Vec::with_capacity(start + payload.len());
    bytes.extend_from_slice(&(kind as u32).to_le_bytes());
    let len = u32::try_from(header.len())
        .map_err(|_| Error::parameter("packet", "a header of more than 4 GiB"))?;
    bytes.extend_from_slice(&len.to_le_bytes());
    bytes.extend_from_slice(&header);
    bytes.resize(start, 0);
    bytes.extend_from_slice(payload);
    Ok(bytes)
}

/// `values` as little-endian bytes in `format`.
///
/// ```
/// use haarshift_viewer::protocol::{SampleFormat, sample_bytes};
/// assert_eq!(sample_bytes(&[1.0, -2.0], SampleFormat::F32), [1f32.to_le_bytes(), (-2f32).to_le_bytes()].concat());
/// // f16: 1.0 is 0x3C00, -2.0 is 0xC000
/// assert_eq!(sample_bytes(&[1.0, -2.0], SampleFormat::F16), vec![0x00, 0x3C, 0x00, 0xC0]);
/// ```
pub fn sample_bytes(values: &[f32], format: SampleFormat) -> Vec<u8> {
    match format {
        SampleFormat::F32 => values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        SampleFormat::F16 => values
            .iter()
            .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
            .collect(),
    }
}
