//! Times rotating and encoding the lighting at random rotations, the way an interactive viewer
//! asks for it, and measures how far each fast method lands from the source-resolution path.
//!
//! ```text
//! cargo run --release -p haarshift-measure --bin lighting_rotation -- [ROTATIONS] [KEEP] [OUTPUT.md]
//!   ROTATIONS  random rotations per map and parameterisation (default 20)
//!   KEEP       lighting detail coefficients kept, or all (default 200)
//!   OUTPUT.md  where the table goes (default results/viewer/lighting_rotation.md)
//! ```
//!
//! For every environment map in `testdata/envmaps/` at least 128 texels high, and for the
//! working parameterisations lat-long 64 (64 x 128), lat-long 128 (128 x 256) and cube
//! 6 x 64^2, it times `Lighting::encode` end to end (rotation, resampling, the Haar transform
//! and the selection of the `KEEP` largest) for three ways of applying a rotation that is not
//! a whole-column yaw:
//!
//! - `source`: [`LightRotation::Source`], the map rotated at its own resolution (the baseline);
//! - `prefiltered`: [`LightRotation::Prefiltered`], a copy brought down once to twice the
//!   working lat-long height rotated instead (the copy's preparation is timed apart);
//! - `chain rule`: the working-resolution lat-long map rotated in the Haar domain
//!   ([`rotate_map`] with [`Method::Haar`], Alnasser 2008's chapter 4), converted to the cube
//!   where the working map is one, then transformed and selected like the others.
//!
//! Each fast method's error is against `source` at the same rotation: the relative RMS of the
//! rotated working map over the sphere, solid-angle weighted
//! ([`SphereMap::relative_rms_error`]), and the relative L2 error of the encoded (selected)
//! coefficients. Times and errors are medians over the rotations.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
use haarshift::product::Selection;
use haarshift::sphere::{LatLongMap, Method, SphereOptions, SphereRotation, rotate_map};
use haarshift_relight::Lighting;
use haarshift_relight::light::environment::{Environment, LightRotation, SphereMapping};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// The working parameterisations and their names in the table.
const PARAMS: [(ParamKind, usize, &str); 3] = [
    (ParamKind::LatLong, 64, "lat-long 64 x 128"),
    (ParamKind::LatLong, 128, "lat-long 128 x 256"),
    (ParamKind::Cube, 64, "cube 6 x 64^2"),
];

/// The chain-rule path: the working lat-long map (made once) rotated in the Haar domain, then
/// taken into the parameterisation (converted, for a cube) as the mapping does.
struct ChainRule<'a> {
    working: LatLongMap<f64>,
    mapping: &'a SphereMapping,
}

impl ChainRule<'_> {
    fn apply(&self, rotation: &SphereRotation) -> Fallible<SphereMap<f64>> {
        let options = SphereOptions {
            method: Method::Haar,
            ..SphereOptions::default()
        };
        let rotated = rotate_map(&self.working, rotation, &options)?.map;
        Ok(self.mapping.to_param(&rotated)?)
    }
}

/// A working map and its lighting, and the milliseconds the two took together.
struct Encoded {
    map: SphereMap<f64>,
    lighting: Lighting,
    ms: f64,
}

/// `map()` then [`Lighting::from_map`] (what [`Lighting::encode`] does), timed together.
fn encode(keep: Selection, map: impl FnOnce() -> Fallible<SphereMap<f64>>) -> Fallible<Encoded> {
    let start = Instant::now();
    let map = map()?;
    let lighting = Lighting::from_map(&map, keep)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(Encoded { map, lighting, ms })
}

/// Errors of `fast` against `truth`: the working map's (solid-angle-weighted relative RMS)
/// and the coefficients' (relative L2).
fn errors(fast: &Encoded, truth: &Encoded) -> Fallible<(f64, f64)> {
    let map = fast.map.relative_rms_error(&truth.map)?;
    let (a, b) = (
        fast.lighting.coefficients_f64(),
        truth.lighting.coefficients_f64(),
    );
    let difference: f64 = a.iter().zip(b.iter()).map(|(x, y)| (x - y).powi(2)).sum();
    let scale: f64 = b.iter().map(|y| y * y).sum();
    Ok((map, (difference / scale).sqrt()))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The medians of one map and parameterisation: times (source, prefiltered, chain rule),
/// errors (prefiltered map and coefficients, chain rule map and coefficients), and the
/// prefiltered copy's preparation.
struct Row {
    ms: [f64; 3],
    errors: [f64; 4],
    prepare_ms: f64,
}

fn measure(
    env: &Environment,
    kind: ParamKind,
    size: usize,
    rotations: &[SphereRotation],
    keep: Selection,
) -> Fallible<Row> {
    let param = Parameterization::new(kind, size)?;
    let source = SphereMapping::new(env.map().height(), param)?;
    let prefiltered = source.clone().with_rotation(LightRotation::Prefiltered);
    // The preparation: the prefiltered copy made (by the first frame) and kept.
    let start = Instant::now();
    prefiltered.apply(env, &rotations[0])?;
    let prepare_ms = start.elapsed().as_secs_f64() * 1e3;
    let chain = ChainRule {
        working: (*env.downsampled(source.lat_long_height())?).clone(),
        mapping: &source,
    };
    let (mut ms, mut errs) = ([vec![], vec![], vec![]], [vec![], vec![], vec![], vec![]]);
    for rotation in rotations {
        let truth = encode(keep, || Ok(source.apply(env, rotation)?))?;
        let fast = encode(keep, || Ok(prefiltered.apply(env, rotation)?))?;
        let haar = encode(keep, || chain.apply(rotation))?;
        let (fast_map, fast_coefficients) = errors(&fast, &truth)?;
        let (haar_map, haar_coefficients) = errors(&haar, &truth)?;
        for (list, value) in ms.iter_mut().zip([truth.ms, fast.ms, haar.ms]) {
            list.push(value);
        }
        let values = [fast_map, fast_coefficients, haar_map, haar_coefficients];
        for (list, value) in errs.iter_mut().zip(values) {
            list.push(value);
        }
    }
    Ok(Row {
        ms: ms.map(median),
        errors: errs.map(median),
        prepare_ms,
    })
}

/// The environment maps of `dir` at least `min_height` high, by name.
fn environments(dir: &Path, min_height: usize) -> Fallible<Vec<(String, Environment)>> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()?;
    paths.sort();
    let mut found = vec![];
    for path in paths {
        let image = matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("hdr" | "npy")
        );
        if !image {
            continue;
        }
        let name = path
            .file_name()
            .expect("a file")
            .to_string_lossy()
            .into_owned();
        match Environment::load(&path) {
            Ok(env) if env.map().height() >= min_height => found.push((name, env)),
            Ok(env) => eprintln!("skipped {name}: {} high", env.map().height()),
            Err(e) => eprintln!("skipped {name}: {e}"),
        }
    }
    Ok(found)
}

fn main() -> Fallible<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() > 3 {
        eprintln!("usage: lighting_rotation [ROTATIONS] [KEEP|all] [OUTPUT.md]");
        std::process::exit(2);
    }
    let count: usize = args.first().map_or(Ok(20), |a| a.parse())?;
    let keep = match args.get(1).map(String::as_str) {
        None => Selection::Largest(200),
        Some("all") => Selection::All,
        Some(k) => Selection::Largest(k.parse()?),
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let output = args.get(2).map_or_else(
        || root.join("results/viewer/lighting_rotation.md"),
        PathBuf::from,
    );
    // Random rotations, none a whole-column yaw (every rotation with a pitch or roll is not).
    let mut rng = StdRng::seed_from_u64(2024);
    let rotations: Vec<SphereRotation> = (0..count)
        .map(|_| {
            SphereRotation::from_degrees(
                rng.random_range(0.0..360.0),
                rng.random_range(-90.0..90.0),
                rng.random_range(-180.0..180.0),
            )
        })
        .collect::<Result<_, _>>()?;
    let keep_text = match keep {
        Selection::Largest(k) => format!("the {k} largest detail coefficients"),
        _ => "every coefficient".into(),
    };
    let mut text = format!(
        "# Rotating and encoding the lighting at any angle\n\n\
         Reproduce: `cargo run --release -p haarshift-measure --bin lighting_rotation -- {count} {} {}`\n\n\
         Per frame: `Lighting::encode` end to end (rotation, resampling to the working \
         parameterisation, Haar transform, selection of {keep_text}), median of {count} \
         random rotations (yaw, pitch, roll uniform in degrees; none a whole-column yaw), \
         {} threads{}. `source` rotates the map at its own resolution (the default); \
         `prefiltered` rotates a copy brought down once to twice the working lat-long height \
         (its preparation, once per environment and parameterisation, in the last column); \
         `chain rule` rotates the working lat-long map in the Haar domain (`rotate_map`, \
         `Method::Haar`). Errors are against `source` at the same rotation, medians: the \
         rotated working map's relative RMS over the sphere (solid-angle weighted) and the \
         encoded coefficients' relative L2.\n",
        args.get(1).map_or("200", String::as_str),
        args.get(2)
            .map_or("results/viewer/lighting_rotation.md", String::as_str),
        rayon::current_num_threads(),
        // Other work on the machine moves the times: say how busy it was.
        std::fs::read_to_string("/proc/loadavg").map_or(String::new(), |l| {
            let one_minute = l.split_whitespace().next().unwrap_or("?").to_owned();
            format!(" (load average {one_minute} as the run began)")
        }),
    );
    for (name, env) in environments(&root.join("../../testdata/envmaps"), 128)? {
        let (h, w) = (env.map().height(), env.map().width());
        eprintln!("{name} ({w} x {h})");
        let _ = write!(
            text,
            "\n## {name} ({w} x {h})\n\n\
             | working map | source ms | prefiltered ms | chain rule ms | prefiltered map error | \
             prefiltered coefficient error | chain rule map error | chain rule coefficient error | \
             prefilter once ms |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n"
        );
        for (kind, size, label) in PARAMS {
            let row = measure(&env, kind, size, &rotations, keep)?;
            let [source, fast, haar] = row.ms;
            let [fm, fc, hm, hc] = row.errors;
            let line = format!(
                "| {label} | {source:.1} | {fast:.2} | {haar:.2} | {fm:.2e} | {fc:.2e} | \
                 {hm:.2e} | {hc:.2e} | {:.1} |\n",
                row.prepare_ms
            );
            eprint!("{line}");
            text += &line;
        }
    }
    if let Some(dir) = output.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let temporary = output.with_extension("md.part");
    std::fs::write(&temporary, &text)?;
    std::fs::rename(&temporary, &output)?;
    print!("{text}");
    Ok(())
}
