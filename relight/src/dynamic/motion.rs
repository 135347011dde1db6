//! Animations of dynamic scenes: a path file of segments, each varying one thing (one object
//! moving, the lighting turning, or the eye orbiting), played with just-in-time radiance transfer re-formed
//! whenever the kind of change switches (Sun 2006 section 3.5.3).
//!
//! **Path file** (JSON, unknown keys refused):
//!
//! ```json
//! { "segments": [
//!     { "frames": 24, "object": "ball", "to": { "translate": [1.5, 0, 0.5] } },
//!     { "frames": 24, "light_yaw": 90 },
//!     { "frames": 12, "object": "chair", "to": { "translate": [0, 0, 1], "yaw": 45 } },
//!     { "frames": 12, "eye_yaw": 30 }
//! ] }
//! ```
//!
//! Frame 0 is the scene as its file places it. A segment of `F` frames adds frames
//! `1..=F`: an object segment moves the named object linearly (translation, scale and yaw)
//! from where it is to `to`; a lighting segment turns the lighting about +Y by `light_yaw`
//! degrees in all, in equal steps; an eye segment turns the eye by `eye_yaw` degrees about the
//! vertical through the point the scene's camera looks at (right-handed about +Y: +Z toward
//! +X), so that glossy vertices are seen from elsewhere ([`Change::View`]). Each segment re-forms the transfer for its change; a
//! segment that turns an object re-forms at every frame whose turn (in whole columns)
//! differs from the last (the object's own transport turns with it).

use std::path::Path;
use std::time::Instant;

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use crate::SceneError;
use crate::dynamic::{Change, DynamicScene, JustInTimeTransfer, Placement, TransferReport};
use crate::light::environment::{Environment, SphereMapping};
use crate::light::lighting::Lighting;
use crate::scene::Transform;
use crate::{Error, Result};
use haarshift::product::Selection;
use haarshift::sphere::SphereRotation;

/// The most frames a path may have.
pub const MAX_FRAMES: usize = 3600;

/// One segment of a path; see the [module docs](self).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    /// Frames the segment adds.
    pub frames: usize,
    /// The object that moves (its `name` in the scene file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<String>,
    /// Where it goes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to: Option<Transform>,
    /// Degrees the lighting turns about +Y over the segment.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light_yaw: Option<f64>,
    /// Degrees the eye turns about the vertical through the camera's point of interest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eye_yaw: Option<f64>,
}

/// A path file's content; see the [module docs](self).
///
/// ```
/// use haarshift_relight::dynamic::motion::MotionPath;
/// let p: MotionPath = serde_json::from_str(r#"{"segments": [
///     {"frames": 3, "object": "ball", "to": {"translate": [1, 0, 0]}},
///     {"frames": 2, "light_yaw": 90}]}"#).unwrap();
/// assert_eq!(p.frame_count(), 1 + 3 + 2);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionPath {
    /// The segments, played in order.
    pub segments: Vec<Segment>,
}

/// What one frame of a path is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameState {
    /// The segment it belongs to (frame 0: the first).
    pub segment: usize,
    /// What varies in its segment.
    pub change: Change,
    /// The moving object's placement (object segments).
    pub placement: Option<Placement>,
    /// The lighting's yaw added to the scene's, degrees.
    pub light_yaw: f64,
    /// Where the eye is (`None`: the scene has none).
    pub eye: Option<[f64; 3]>,
}

/// What playing one frame did.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameReport {
    /// Frame number.
    pub index: usize,
    /// The frame's state.
    pub state: FrameState,
    /// What re-forming the transfer before this frame cost, when it was re-formed.
    pub reformed: Option<TransferReport>,
    /// Seconds encoding the varying factor and shading (the per-frame cost).
    pub shade_seconds: f64,
}

impl MotionPath {
    /// Reads a path file.
    pub fn load(path: &Path) -> Result<Self> {
        let motion: Self = crate::scene::read_json(path)?;
        motion.check_counts().map_err(|e| e.in_file(path))?;
        Ok(motion)
    }

    /// The checks that need no scene: at least one segment, at most [`MAX_FRAMES`] frames.
    fn check_counts(&self) -> Result<()> {
        if self.segments.is_empty() {
            return Err(SceneError::SceneFile("a path needs at least one segment".into()).into());
        }
        if self.frame_count() > MAX_FRAMES + 1 {
            return Err(SceneError::SceneFile(format!(
                "path segment 0: more than {MAX_FRAMES} frames in all"
            ))
            .into());
        }
        Ok(())
    }

    /// Frames in all, frame 0 included (`usize::MAX` when the sum does not fit: checked, so
    /// that no count wraps around [`MAX_FRAMES`]).
    pub fn frame_count(&self) -> usize {
        self.segments
            .iter()
            .try_fold(1usize, |n, s| n.checked_add(s.frames))
            .unwrap_or(usize::MAX)
    }

    /// Every frame's state in `scene` (checked: names, placements, counts).
    pub fn states(&self, scene: &DynamicScene) -> Result<Vec<FrameState>> {
        let bad = |k: usize, why: String| -> Error {
            SceneError::SceneFile(format!("path segment {k}: {why}")).into()
        };
        self.check_counts()?;
        let param = scene.param();
        let mut placements: Vec<Placement> = (0..scene.object_count())
            .map(|k| scene.placement(k))
            .collect();
        let mut light = 0.0;
        let mut eye = scene.eye();
        let mut out = Vec::with_capacity(self.frame_count());
        for (k, seg) in self.segments.iter().enumerate() {
            if seg.frames == 0 {
                return Err(bad(k, "frames must be at least 1".into()));
            }
            let finite = |yaw: f64| yaw.is_finite() && yaw.abs() <= 1e6;
            let change = match (&seg.object, &seg.to, seg.light_yaw, seg.eye_yaw) {
                (Some(name), Some(to), None, None) => {
                    let object = scene
                        .object_index(name)
                        .ok_or_else(|| bad(k, format!("no object is named {name:?}")))?;
                    let target =
                        Placement::from_transform(to, param).map_err(|e| bad(k, e.to_string()))?;
                    Move::Object {
                        object,
                        from: placements[object],
                        target,
                    }
                }
                (None, None, Some(yaw), None) if finite(yaw) => Move::Lighting { yaw },
                (None, None, None, Some(yaw)) if finite(yaw) => {
                    let (Some(from), Some(camera)) = (eye, &scene.camera) else {
                        return Err(bad(
                            k,
                            "an eye segment turns the camera about the point it looks at: the \
                             scene needs a camera"
                                .into(),
                        ));
                    };
                    Move::View {
                        from,
                        pivot: camera.look_at,
                        yaw,
                    }
                }
                _ => {
                    return Err(bad(
                        k,
                        "give either \"object\" and \"to\", a finite \"light_yaw\" or a \
                         finite \"eye_yaw\""
                            .into(),
                    ));
                }
            };
            if out.is_empty() {
                // Frame 0: the scene as given, the first segment's kind of change.
                out.push(FrameState {
                    segment: 0,
                    change: change.kind(),
                    placement: change.start(),
                    light_yaw: 0.0,
                    eye,
                });
            }
            let start_light = light;
            for f in 1..=seg.frames {
                let t = f as f64 / seg.frames as f64;
                let placement = match change {
                    Move::Object {
                        object,
                        from,
                        target,
                    } => {
                        placements[object] = interpolate(&from, &target, t, 2 * param.face_size());
                        Some(placements[object])
                    }
                    Move::Lighting { yaw } => {
                        light = start_light + t * yaw;
                        None
                    }
                    Move::View { from, pivot, yaw } => {
                        eye = Some(orbit(from, pivot, t * yaw));
                        None
                    }
                };
                out.push(FrameState {
                    segment: k,
                    change: change.kind(),
                    placement,
                    light_yaw: light,
                    eye,
                });
            }
        }
        Ok(out)
    }
}

/// What one path segment changes: an object's placement (from where the segment finds it to
/// `target`), the lighting's yaw (by `yaw` degrees), or the eye (from `from`, by `yaw` degrees
/// about the vertical through `pivot`).
#[derive(Clone, Copy)]
enum Move {
    Object {
        object: usize,
        from: Placement,
        target: Placement,
    },
    Lighting {
        yaw: f64,
    },
    View {
        from: [f64; 3],
        pivot: [f64; 3],
        yaw: f64,
    },
}

impl Move {
    /// The kind of change a frame of this segment records.
    fn kind(&self) -> Change {
        match *self {
            Move::Object { object, .. } => Change::Object(object),
            Move::Lighting { .. } => Change::Lighting,
            Move::View { .. } => Change::View,
        }
    }

    /// The moving object's placement when the segment starts.
    fn start(&self) -> Option<Placement> {
        match *self {
            Move::Object { from, .. } => Some(from),
            Move::Lighting { .. } | Move::View { .. } => None,
        }
    }
}

/// `p` turned by `degrees` about the vertical through `pivot` (+Z toward +X).
fn orbit(p: [f64; 3], pivot: [f64; 3], degrees: f64) -> [f64; 3] {
    let (sin, cos) = degrees.to_radians().sin_cos();
    let (x, z) = (p[0] - pivot[0], p[2] - pivot[2]);
    [
        pivot[0] + x * cos + z * sin,
        p[1],
        pivot[2] - x * sin + z * cos,
    ]
}

/// The placement a fraction `t` of the way from `a` to `b`; the turn takes the shorter way
/// round (`w` columns in a turn) and is rounded to whole columns.
fn interpolate(a: &Placement, b: &Placement, t: f64, w: usize) -> Placement {
    let mut delta = b.turn as f64 - a.turn as f64;
    if delta > w as f64 / 2.0 {
        delta -= w as f64;
    } else if delta < -(w as f64) / 2.0 {
        delta += w as f64;
    }
    Placement {
        translate: std::array::from_fn(|k| a.translate[k] + t * (b.translate[k] - a.translate[k])),
        scale: a.scale + t * (b.scale - a.scale),
        turn: (a.turn as f64 + t * delta).round().rem_euclid(w as f64) as usize % w,
    }
}

/// Plays `path` in `scene` under `env` (its rotation `[yaw, pitch, roll]` in degrees, the
/// lighting's yaw added per frame), the lighting truncated to `keep_light`; `frame` receives
/// each frame's scene, per-vertex radiance, lighting rotation and report.
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
/// use haarshift_relight::light::environment::Environment;
/// use haarshift_relight::dynamic::motion::{MotionPath, play};
/// use haarshift_relight::SceneFile;
/// use haarshift::sphere::LatLongMap;
/// use haarshift::faces::param::{ParamKind, Parameterization};
/// let file: SceneFile = serde_json::from_str(r#"{"objects": [
///     {"generator": {"sphere": {"cells": 2}}},
///     {"name": "ball", "generator": {"sphere": {"cells": 2}}, "transform": {"translate": [2.5, 0, 0]}}
///   ]}"#).unwrap();
/// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
/// (options.field.circles, options.field.circle_points) = (8, 16);
/// (options.field.shells, options.field.shell_grid) = (4, 3);
/// let mut scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
/// let env = Environment::new(LatLongMap::<f64>::from_fn(16, 3, |d, o| o.fill(1.0 + d[1])).unwrap());
/// let path: MotionPath = serde_json::from_str(r#"{"segments": [
///     {"frames": 2, "object": "ball", "to": {"translate": [1.5, 0, 1]}},
///     {"frames": 1, "light_yaw": 90}]}"#).unwrap();
/// let mut reformed = Vec::new();
/// play(&mut scene, &env, [0.0; 3], Selection::All, &path, |_, radiance, _, report| {
///     assert_eq!(radiance.dim(), (108, 3));
///     reformed.push(report.reformed.is_some());
///     Ok(())
/// }).unwrap();
/// // Formed at frame 0 for the moving ball, re-formed when the lighting starts to turn.
/// assert_eq!(reformed, [true, false, false, true]);
/// assert_eq!(scene.placement(1).translate, [1.5, 0.0, 1.0]);
/// ```
pub fn play(
    scene: &mut DynamicScene,
    env: &Environment,
    angles: [f64; 3],
    keep_light: Selection,
    path: &MotionPath,
    mut frame: impl FnMut(&DynamicScene, &Array2<f32>, &SphereRotation, &FrameReport) -> Result<()>,
) -> Result<()> {
    let states = path.states(scene)?;
    let mapping = SphereMapping::new(env.map().height(), scene.param())?;
    let rotation = |yaw: f64| SphereRotation::from_degrees(angles[0] + yaw, angles[1], angles[2]);
    let mut lighting = Lighting::encode(env, &mapping, &rotation(0.0)?, keep_light)?;
    let mut jrt: Option<(usize, JustInTimeTransfer<f32>, usize)> = None;
    for (index, state) in states.iter().enumerate() {
        let turn = |k: usize, scene: &DynamicScene| scene.placement(k).turn;
        let mut reformed = None;
        // The moving object where this frame has it, once: a re-formation needs its turn.
        if let (Change::Object(k), Some(p)) = (state.change, state.placement) {
            scene.place(k, p)?;
        }
        if let (Change::View, Some(eye)) = (state.change, state.eye) {
            scene.set_eye(eye)?;
        }
        // Re-form for a new segment, or when the moving object turns.
        let stale = match (&jrt, state.change) {
            (None, _) => true,
            (Some((segment, _, t)), Change::Object(_)) => {
                *segment != state.segment || state.placement.is_some_and(|p| p.turn != *t)
            }
            (Some((segment, ..)), Change::Lighting | Change::View) => *segment != state.segment,
        };
        if stale {
            let formed = JustInTimeTransfer::form(scene, &lighting, state.change)?;
            let t = match state.change {
                Change::Object(k) => turn(k, scene),
                Change::Lighting | Change::View => 0,
            };
            reformed = Some(*formed.report());
            jrt = Some((state.segment, formed, t));
        }
        let (_, transfer, _) = jrt.as_ref().expect("formed above");
        let start = Instant::now();
        let radiance = match state.change {
            Change::Object(_) => transfer.frame_moved(scene)?,
            Change::Lighting => {
                lighting =
                    Lighting::encode(env, &mapping, &rotation(state.light_yaw)?, keep_light)?;
                transfer.frame_lit(scene, &lighting)?
            }
            Change::View => transfer.frame_view(scene)?,
        };
        let report = FrameReport {
            index,
            state: *state,
            reformed,
            shade_seconds: start.elapsed().as_secs_f64(),
        };
        frame(scene, &radiance, &rotation(state.light_yaw)?, &report)?;
    }
    Ok(())
}

#[cfg(test)]
#[path = "motion_tests.rs"]
mod tests;
