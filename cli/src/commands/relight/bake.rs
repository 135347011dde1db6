//! `haarshift relight bake`: a precomputed scene's per-vertex radiance under a lighting, baked
//! into glTF 2.0 files, one per yaw.

use std::path::{Path, PathBuf};

use haarshift_relight::Result;
use haarshift_relight::SceneCache;
use haarshift_relight::light::environment::LightRotation;
use haarshift_relight::render::baked::{BakeInfo, GltfContainer, write_baked_gltf};
use haarshift_relight::render::view::ViewSpec;
use haarshift_relight::shade::{FrameSpec, Method, ShadingInput};

use super::flags::{GlossyFlags, LightFlags, MaterialFlags, ShadingFlags, rotation, triple};
use crate::commands::{choice, names, print, refuse_outputs};

const HELP: &str = "\
Each vertex's radiance is computed as `relight render --vertices` computes it (the same
shader, lighting, material and truncation flags, bit for bit) and written with the mesh as
glTF 2.0: POSITION, NORMAL, COLOR_0 = clamp(2^E x radiance, 0, 1) (linear, E = --exposure,
the range glTF allows a float colour), _RADIANCE = the radiance itself (f32, unclamped) and
the triangles, under an unlit material (KHR_materials_unlit) so that a viewer shows the
colours as they are. The asset's extras state the exposure, the environment, its rotation
and the shading. .glb is binary glTF, .gltf the JSON with its buffer embedded (base64).

One file per yaw: with one yaw (or none: the scene file's, else 0) the file is -o itself; with
a list of several, each is -o's name with `_yawA` before the extension (`-o out.glb --yaw
0,90` writes out_yaw0.glb and out_yaw90.glb). Every output is checked before any work.

Examples:
  haarshift relight bake bunny.hsr --env testdata/envmaps/rooitou_park_256x128.npy -o bunny.glb
  haarshift relight bake bunny.hsr --env park.hdr --yaw 0,90,180,270 --exposure 1 -o bunny.glb
  haarshift relight bake bunny.hsr --env park.hdr --keep-light 200 -o bunny.gltf --force
Validate a file: node tools/gltf-validate/validate.mjs bunny.glb (after npm ci there).";

/// Bake a precomputed scene's radiance under an environment map into glTF 2.0 files.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    /// The scene cache (`relight precompute ... -o SCENE.hsr`)
    #[arg(value_name = "SCENE.hsr")]
    pub cache: PathBuf,

    /// The glTF file to write: .glb (binary) or .gltf (JSON, buffer embedded); with several
    /// yaws, the name each file's `_yawA` is added to
    #[arg(short, long, value_name = "OUT.glb")]
    pub output: PathBuf,

    /// Environment map: lat-long (2:1) .hdr, .exr or .npy [default: the scene file's]
    #[arg(long, value_name = "ENV")]
    pub env: Option<PathBuf>,

    /// Rotations of the lighting about +Y, degrees, one file each: A or A,B,...
    /// [default: the scene file's]
    #[arg(long, value_name = "A,B,...", value_parser = yaws, allow_hyphen_values = true)]
    pub yaw: Option<Yaws>,

    /// Rotation of the lighting about +X, degrees [default: the scene file's]
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub pitch: Option<f64>,

    /// Rotation of the lighting about +Z, degrees [default: the scene file's]
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub roll: Option<f64>,

    /// How a rotation other than a yaw by whole columns of the working map is applied (as
    /// `relight render`'s)
    #[arg(long, value_name = "HOW", default_value = "source",
          value_parser = choice::<LightRotation>(names!(LightRotation)))]
    pub light_rotation: LightRotation,

    /// Exposure, stops: COLOR_0 is the radiance times 2^E, clamped to 0..1
    #[arg(
        long,
        value_name = "E",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub exposure: f64,

    #[command(flatten)]
    pub material: MaterialFlags,

    #[command(flatten)]
    pub shading: ShadingFlags,

    #[command(flatten)]
    pub glossy: GlossyFlags,

    /// The bases of `relight render --basis`
    #[arg(long, value_name = "BASIS", default_value = "haar",
          value_parser = choice::<Method>(names!(Method)))]
    pub basis: Method,

    /// The eye a view-dependent BRDF is shaded for, x,y,z [default: `relight render`'s
    /// camera: the scene file's, else one that frames the scene]
    #[arg(long, value_name = "X,Y,Z", value_parser = triple, allow_hyphen_values = true)]
    pub eye: Option<[f64; 3]>,

    /// Replace the outputs if they exist
    #[arg(long)]
    pub force: bool,
}

/// The angles of `--yaw`, degrees, none listed twice.
#[derive(Clone, Debug, PartialEq)]
pub struct Yaws(pub Vec<f64>);

/// `--yaw`: one or more finite angles, comma-separated.
fn yaws(s: &str) -> std::result::Result<Yaws, String> {
    let angles = s
        .split(',')
        .map(|part| match part.trim().parse::<f64>() {
            Ok(a) if a.is_finite() => Ok(a),
            _ => Err(format!(
                "{s:?}: expected one or more finite angles A,B,... (degrees)"
            )),
        })
        .collect::<std::result::Result<Vec<_>, _>>()?;
    for (k, a) in angles.iter().enumerate() {
        if angles[..k].contains(a) {
            return Err(format!("{s:?}: yaw {a} is listed twice (one file each)"));
        }
    }
    Ok(Yaws(angles))
}

/// The file of each yaw: `output` itself for one (or none), `STEM_yawA.EXT` for several.
fn output_paths(output: &Path, yaws: Option<&[f64]>) -> Vec<(Option<f64>, PathBuf)> {
    match yaws {
        None => vec![(None, output.to_path_buf())],
        Some([only]) => vec![(Some(*only), output.to_path_buf())],
        Some(list) => list
            .iter()
            .map(|&yaw| {
                let stem = output.file_stem().unwrap_or_default().to_string_lossy();
                let mut name = format!("{stem}_yaw{yaw}");
                if let Some(ext) = output.extension() {
                    name = format!("{name}.{}", ext.to_string_lossy());
                }
                (Some(yaw), output.with_file_name(name))
            })
            .collect(),
    }
}

/// An output's folder exists and is a folder (the write itself would fail only after the
/// shading).
fn refuse_missing_folder(path: &Path) -> Result<()> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => return Ok(()),
    };
    if folder.is_dir() {
        return Ok(());
    }
    Err(haarshift_relight::Error::from(haarshift::Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "the output directory does not exist or is not a directory",
        ),
    }))
}

/// The file name of `path`, as the asset's extras state it.
fn file_name(path: &Path) -> Option<String> {
    path.file_name().map(|n| n.to_string_lossy().into_owned())
}

pub fn run(args: Args) -> Result<()> {
    let files = output_paths(&args.output, args.yaw.as_ref().map(|y| y.0.as_slice()));
    let outputs: Vec<&Path> = files.iter().map(|(_, p)| p.as_path()).collect();
    let mut inputs = vec![args.cache.as_path()];
    inputs.extend(args.env.as_deref());
    inputs.extend(args.material.brdf_file());
    refuse_outputs(&inputs, &outputs, args.force)?;
    BakeInfo {
        exposure: args.exposure,
        ..BakeInfo::default()
    }
    .check()?;
    for path in &outputs {
        GltfContainer::from_path(path)?;
        refuse_missing_folder(path)?;
    }
    let mut cache = SceneCache::read(&args.cache)?;
    args.material.apply_to_cache(&mut cache, &args.cache)?;
    let light = LightFlags {
        env: args.env.clone(),
        yaw: None,
        pitch: args.pitch,
        roll: args.roll,
        light_rotation: args.light_rotation,
    };
    let (env_path, _) = light.spec().resolve(cache.environment.as_ref())?;
    let (env, angles) = light.load(cache.environment.as_ref())?;
    let eye = match args.eye {
        Some(eye) => eye,
        None => ViewSpec::default()
            .camera(cache.camera.as_ref(), &cache.mesh)?
            .position(),
    };
    let brdf = args.material.brdf()?;
    let spec = args.shading.spec(args.basis, &brdf, &args.glossy, &light);
    spec.check()?;
    let mut shader = spec.build(&ShadingInput::cache(&cache).from_file(&args.cache))?;
    for (yaw, path) in &files {
        let angles = [yaw.unwrap_or(angles[0]), angles[1], angles[2]];
        let shading = shader.shade(&FrameSpec {
            environment: &env,
            rotation: rotation(angles)?,
            eye: Some(eye),
        })?;
        let radiance = shading.radiance.to_f32();
        let info = BakeInfo {
            exposure: args.exposure,
            environment: file_name(&env_path),
            rotation_degrees: angles,
            shading: shading.description.clone(),
            cache: file_name(&args.cache),
        };
        write_baked_gltf(path, &cache.mesh, radiance.view(), &info, args.force)?;
        print(&format!(
            "{}: {} vertices, {} triangles, yaw {} degrees, exposure {} stops ({})\n",
            path.display(),
            cache.mesh.vertex_count(),
            cache.mesh.triangles().len(),
            angles[0],
            args.exposure,
            shading.description,
        ))?;
    }
    Ok(())
}
