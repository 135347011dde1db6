//! `haarshift relight animate`: the lighting turning about the vertical axis, frame by frame.

use std::path::PathBuf;
use std::time::Instant;

use haarshift_relight::Result;
use haarshift_relight::SceneCache;
use haarshift_relight::render::animation::{numbered_path, write_gif};
use haarshift_relight::render::view::Frames;
use haarshift_relight::render::{to_srgb8, write_render};
use haarshift_relight::shade::{FrameSpec, Method, ShadingInput};

use super::flags::{
    CameraFlags, GlossyFlags, LightFlags, MaterialFlags, ShadingFlags, ms, rotation,
};
use crate::commands::{print, refuse_outputs};

const HELP: &str = "\
Frame k (0 to F - 1) is `relight render` with the lighting's yaw increased by k x 360 / F
degrees (pitch and roll as given): the environment turns about +Y while the scene and the
camera stay. With --orbit the lighting stays and the camera circles the point it looks at
instead, k x 360 / F degrees about the vertical: every frame is a new view, so a glossy
material's highlights move (with a rotation cache, a frame rotates only the BRDF maps no
earlier frame needed; each frame prints how many). The transport is prepared once; each
frame encodes the lighting, shades and rasterises, and its time is printed. The output is
one looping GIF (per-frame palette), or numbered PNG files when -o holds %d or %0Nd
(frame_%03d.png: frame_000.png, frame_001.png ...).

Examples:
  haarshift relight animate bunny.hsr --env testdata/envmaps/rooitou_park_256x128.npy --frames 24 -o turn.gif
  haarshift relight animate bunny.hsr --env park.hdr --frames 36 --keep-light 300 --delay 80 -o turn.gif
  haarshift relight animate bunny.hsr --env park.hdr --frames 12 -o frames/frame_%03d.png
  haarshift relight animate bunny.hsr --env park.hdr --brdf phong:50 --rotation-cache 64 --orbit -o orbit.gif";

/// Animate a precomputed scene under a turning environment.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    /// The scene cache (`relight precompute ... -o SCENE.hsr`)
    #[arg(value_name = "SCENE.hsr")]
    pub cache: PathBuf,

    /// Frames in one turn (360 / F degrees a frame)
    #[arg(long, value_name = "F", default_value_t = 24)]
    pub frames: usize,

    /// A looping .gif, or numbered .png frames (a pattern with %d or %0Nd)
    #[arg(short, long, value_name = "turn.gif|frame_%03d.png")]
    pub output: PathBuf,

    /// Time each GIF frame is shown, milliseconds (stored in hundredths of a second)
    #[arg(long, value_name = "MS", default_value_t = 100)]
    pub delay: u32,

    /// Circle the camera about the point it looks at instead of turning the lighting
    #[arg(long)]
    pub orbit: bool,

    #[command(flatten)]
    pub light: LightFlags,

    #[command(flatten)]
    pub material: MaterialFlags,

    #[command(flatten)]
    pub shading: ShadingFlags,

    #[command(flatten)]
    pub glossy: GlossyFlags,

    #[command(flatten)]
    pub camera: CameraFlags,

    /// Replace the outputs if they exist
    #[arg(long)]
    pub force: bool,
}

/// The most frames in one animation.
const MAX_FRAMES: usize = 3600;

pub fn run(args: Args) -> Result<()> {
    if !(1..=MAX_FRAMES).contains(&args.frames) {
        return Err(haarshift_relight::Error::from(
            haarshift::Error::InvalidParameter {
                name: "frames",
                reason: format!("{}: must be 1 to {MAX_FRAMES}", args.frames),
            },
        ));
    }
    let gif = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gif"));
    // Numbered frames' files (none for a GIF).
    let frame_paths: Vec<PathBuf> = if gif {
        Vec::new()
    } else {
        (0..args.frames)
            .map(|k| numbered_path(&args.output, k))
            .collect::<Result<_>>()?
    };
    if let Some(first) = frame_paths.first() {
        haarshift_relight::render::render_format(first)?;
    }
    let outputs = if gif {
        vec![args.output.clone()]
    } else {
        frame_paths.clone()
    };
    let output_refs: Vec<&std::path::Path> = outputs.iter().map(|p| p.as_path()).collect();
    let mut inputs = vec![args.cache.as_path()];
    inputs.extend(args.light.env.as_deref());
    inputs.extend(args.material.brdf_file());
    refuse_outputs(&inputs, &output_refs, args.force)?;
    let view = args.camera.view()?;
    let mut cache = SceneCache::read(&args.cache)?;
    args.material.apply_to_cache(&mut cache, &args.cache)?;
    let (env, [yaw, pitch, roll]) = args.light.load(cache.environment.as_ref())?;
    let camera = view.camera(cache.camera.as_ref(), &cache.mesh)?;
    let brdf = args.material.brdf()?;
    // Lambertian: one sparse dot per vertex and frame. Glossy: with a rotation cache, a frame
    // rotates only the maps no earlier frame (or --fill-cache) rotated: with a fixed view,
    // the first frame's.
    let spec = args
        .shading
        .spec(Method::Haar, &brdf, &args.glossy, &args.light);
    spec.check()?;
    let mut shader = spec.build(&ShadingInput::cache(&cache).from_file(&args.cache))?;
    let prepared = shader.preparation();
    let mut text = format!(
        "{}transport prepared once in {:.1} ms\n",
        prepared.filled.map_or(String::new(), |f| format!(
            "cache filled ahead: {} maps rotated in {:.1} ms; ",
            f.maps,
            f.seconds * 1e3
        )),
        prepared.seconds * 1e3
    );
    let mut frames = Vec::with_capacity(if gif { args.frames } else { 0 });
    // Each pixel's place in the environment is prepared with the first frame and kept while
    // the camera stays.
    let mut drawing = Frames::new(view);
    for k in 0..args.frames {
        let step = 360.0 * k as f64 / args.frames as f64;
        let (frame_yaw, orbit) = if args.orbit {
            (yaw, step)
        } else {
            (yaw + step, 0.0)
        };
        let view_camera = camera.orbited(orbit)?;
        let turn = rotation([frame_yaw, pitch, roll])?;
        let shading = shader.shade(&FrameSpec {
            environment: &env,
            rotation: turn,
            eye: Some(view_camera.position()),
        })?;
        let maps = shading.maps.map_or(String::new(), |report| {
            format!(
                ", BRDF maps {} ({} rotated in {:.1} ms)",
                report.maps,
                report.rotated,
                1e3 * report.rotate_seconds
            )
        });
        let shade_ms = shading.timing.total_seconds() * 1e3;
        let radiance = shading.radiance.to_f32();
        let start = Instant::now();
        let image = drawing.draw(&view_camera, &cache.mesh, radiance.view(), &env, &turn)?;
        let raster_ms = ms(start);
        match frame_paths.get(k) {
            Some(path) => write_render(&image, path, args.camera.exposure, args.force)?,
            None => frames.push(to_srgb8(&image, args.camera.exposure)?),
        }
        let placement = if args.orbit {
            format!("camera orbit {orbit:.2}")
        } else {
            format!("yaw {frame_yaw:.2}")
        };
        text += &format!(
            "frame {k}: {placement}, lighting and shading {shade_ms:.1} ms{maps}, \
             rasterisation {raster_ms:.1} ms\n"
        );
    }
    if gif {
        write_gif(&frames, &args.output, args.delay, args.force)?;
    }
    text += &format!(
        "{}: {} frames of {} x {}\n",
        args.output.display(),
        args.frames,
        args.camera.width,
        args.camera.height
    );
    print(&text)
}
