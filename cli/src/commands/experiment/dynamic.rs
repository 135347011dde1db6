//! `haarshift experiment dynamic`: occlusion fields and just-in-time radiance transfer against
//! the ray-cast ground truth.

use std::path::PathBuf;

use haarshift_experiments::journal::Journal;
use haarshift_experiments::moving_objects::{DynamicProtocol, DynamicRecord, Scenario, run};
use haarshift_experiments::pareto::frontier;
use haarshift_experiments::plot::{LabeledPoint, log_log_scatter};
use haarshift_experiments::table::{Table, significant};
use haarshift_relight::Result;
use haarshift_relight::Transform;
use haarshift_relight::light::environment::Environment;

use super::{OutputFlags, finish_journal, wrote};
use crate::commands::print;
use crate::progress::progress_bar;

const EXAMPLES: &str = "\
Examples:
  haarshift experiment dynamic                         (the two scenarios below, --quick)
  haarshift experiment dynamic --full --out-dir results/dynamic --force
  haarshift experiment dynamic --scenario scene.json:ball:1.5,0.3,0 --env park.hdr

A scenario FILE:NAME:X,Y,Z is a scene file, the object that moves and the point it moves to
(translation only). The default scenarios, relative to the repository's root, are
testdata/scenes/bunny_and_ball.json:ball:1.5,1.2,4.5 (a ball passing by the bunny) and
testdata/scenes/table_and_chair.json:chair:0.9,0,1.3 (Sun 2006's table with a chair beside
it). For each setting the scene is built, just-in-time transfer is formed for the moving
object where the file places it, the object moves to its target and the frame is shaded;
the ground truth ray-casts the moved scene against every object (`relight scene --method
reference`), over the lighting at the protocol's reference resolution. Axes, each its own
rows: resolution (lat-long N x 2N maps, Sun 2006's field density), density (the base
resolution, the circles, points and shells scaled), budget (lighting / own transport /
occlusion-map details kept, occlusion maps truncated before or after the blend), depth
(traversal depth at the base budget), change (the transfer formed for a change of lighting
instead), static (the moved scene precomputed as a static scene, no field: the floor that the
resolution alone sets). --quick: resolutions 16 and 32, densities 0.25 to 1, reference 64; --full adds 64
and density 2, reference 128. Errors are relative to the ground truth's RMS radiance.

Writes DIR/dynamic.csv, .json and .md and, per scene, DIR/dynamic-SCENE-rms-time.png (error
against frame time, Pareto frontier joined). Each setting's measurements (a resolution or a
density, with the rows measured on its build) and each scenario's ground truth are appended
to DIR/dynamic.journal as they are made, so that a run killed midway goes on with --resume;
the journal is removed once the reports are written.";

/// Occlusion fields and just-in-time transfer against ray casting: table, CSV, JSON, plot.
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// A scenario FILE:NAME:X,Y,Z (repeatable) [default: the two of the examples]
    #[arg(long, value_name = "FILE:NAME:X,Y,Z")]
    pub scenario: Vec<String>,

    /// Environment map [default: each scene file's]
    #[arg(long, value_name = "ENV")]
    pub env: Option<PathBuf>,

    /// The full protocol (64 x 128 maps, twice Sun 2006's density, reference 128)
    #[arg(long)]
    pub full: bool,

    /// The quick protocol (the default, stated)
    #[arg(long, conflicts_with = "full")]
    pub quick: bool,

    /// Go on with a run that was stopped: the measurements in DIR/dynamic.journal (written
    /// as they are made, a setting's build at a time) are kept and the rest measured; refused
    /// if the protocol, the scenarios or the inputs differ
    #[arg(long)]
    pub resume: bool,

    #[command(flatten)]
    pub output: OutputFlags,
}

const DEFAULT_SCENARIOS: [&str; 2] = [
    "testdata/scenes/bunny_and_ball.json:ball:1.5,1.2,4.5",
    "testdata/scenes/table_and_chair.json:chair:0.9,0,1.3",
];

/// `FILE:NAME:X,Y,Z`, parsed.
fn parse_scenario(s: &str) -> Result<(PathBuf, String, [f64; 3])> {
    let bad = || {
        haarshift_relight::Error::from(haarshift::Error::InvalidParameter {
            name: "scenario",
            reason: format!("{s:?}: expected FILE:NAME:X,Y,Z"),
        })
    };
    let mut parts = s.rsplitn(3, ':');
    let (Some(to), Some(name), Some(file)) = (parts.next(), parts.next(), parts.next()) else {
        return Err(bad());
    };
    let xyz = crate::commands::relight::flags::triple(to).map_err(|_| bad())?;
    if name.is_empty() {
        return Err(bad());
    }
    Ok((PathBuf::from(file), name.to_owned(), xyz))
}

pub fn run_command(args: Args) -> Result<()> {
    let specs: Vec<String> = if args.scenario.is_empty() {
        DEFAULT_SCENARIOS.iter().map(|s| s.to_string()).collect()
    } else {
        args.scenario.clone()
    };
    let parsed = specs
        .iter()
        .map(|s| parse_scenario(s))
        .collect::<Result<Vec<_>>>()?;
    let mut inputs: Vec<PathBuf> = parsed.iter().map(|p| p.0.clone()).collect();
    inputs.extend(args.env.clone());
    let reports = args.output.claim("dynamic", &inputs)?;
    let protocol = if args.full {
        DynamicProtocol::full()
    } else {
        DynamicProtocol::quick()
    };
    let options = format!(
        "{protocol:?}; {specs:?}; {}",
        Journal::fingerprint(&inputs)?
    );
    let mut journal = reports.journal(&options, args.resume)?;
    let mut records: Vec<DynamicRecord> = Vec::new();
    let bar = progress_bar(parsed.len());
    for (file, name, to) in &parsed {
        let scenario = Scenario::load(
            file,
            name,
            Transform {
                translate: *to,
                ..Transform::default()
            },
        )?;
        // The target is a translation: the moving object keeps its scale and its turn.
        let keep = scenario
            .file
            .objects
            .iter()
            .find(|o| o.name.as_deref() == Some(name))
            .map(|o| o.transform.clone())
            .unwrap_or_default();
        let scenario = Scenario {
            to: Transform {
                translate: *to,
                ..keep
            },
            ..scenario
        };
        let (env_path, angles) = match (&args.env, &scenario.file.environment) {
            (Some(p), _) => (p.clone(), [0.0; 3]),
            (None, Some(e)) => (scenario.dir.join(&e.path), [e.yaw, e.pitch, e.roll]),
            (None, None) => {
                return Err(haarshift_relight::Error::from(
                    haarshift::Error::InvalidParameter {
                        name: "env",
                        reason: format!(
                            "{}: the scene names no environment; give --env",
                            file.display()
                        ),
                    },
                ));
            }
        };
        let env = Environment::load(&env_path)?;
        bar.set_message(scenario.name.clone());
        let got = run(&scenario, &env, angles, &protocol, &mut journal, |r| {
            bar.set_message(format!("{}: {}", r.scene, label(r)));
        })?;
        records.extend(got);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let header = format!(
        "protocol: {}; resolutions {:?}, densities {:?} (x Sun 2006's 100 x 200 circle points \
         and 20 x 6 x 9 x 9 shell points), base resolution {}, budgets (light / visibility / \
         field) {}, depth and change at {}, reference lighting {} x {}\n",
        if args.full { "full" } else { "quick" },
        protocol.resolutions,
        protocol.densities,
        protocol.base_resolution,
        protocol
            .budgets
            .iter()
            .map(|b| budget_label(b.light, b.visibility, b.field))
            .collect::<Vec<_>>()
            .join(", "),
        budget_label(
            protocol.base_budget.light,
            protocol.base_budget.visibility,
            protocol.base_budget.field
        ),
        protocol.reference_resolution,
        2 * protocol.reference_resolution
    );
    let text = format!("{header}{}", table(&records));
    let mut written = reports.write(&text, &records, &[])?;
    // One plot per scene: error against frame time, the Pareto frontier joined (the static
    // precomputation left out: its cost is a new precomputation per move, not a frame).
    let mut scenes: Vec<&str> = records.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    for scene in scenes {
        let points: Vec<LabeledPoint> = records
            .iter()
            .filter(|r| r.scene == scene && r.axis != "static")
            .filter(|r| r.frame_seconds > 0.0 && r.rms_relative > 0.0)
            .map(|r| LabeledPoint {
                label: label(r),
                x: r.frame_seconds,
                y: r.rms_relative,
            })
            .collect();
        if points.is_empty() {
            continue;
        }
        let front: Vec<LabeledPoint> =
            frontier(&points.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>())
                .into_iter()
                .map(|i| points[i].clone())
                .collect();
        let plot = log_log_scatter(
            &format!("{scene}: error against the time of a frame"),
            "seconds per frame",
            "RMS error / RMS radiance",
            &points,
            &front,
        )?;
        written.push_str(&wrote(&[reports
            .writer()
            .png(&format!("{scene}-rms-time"), &plot)?]));
    }
    finish_journal(journal)?;
    print(&format!("{text}\n{written}"))
}

fn budget_label(l: Option<usize>, v: Option<usize>, f: Option<usize>) -> String {
    let k = |x: Option<usize>| x.map_or("all".to_string(), |k| k.to_string());
    format!("{}/{}/{}", k(l), k(v), k(f))
}

/// The setting a record varies.
fn label(r: &DynamicRecord) -> String {
    match r.axis.as_str() {
        "resolution" => format!("maps {} x {}", r.resolution, 2 * r.resolution),
        "density" => format!("{} field samples", r.field_samples),
        "budget" => format!(
            "kept {} {}",
            budget_label(r.keep_light, r.keep_visibility, r.keep_field),
            r.truncation
        ),
        "depth" => format!("depth {}", r.depth),
        "static" => "static precomputation".into(),
        _ => format!("{} changes", r.change),
    }
}

/// The records as a Markdown table.
fn table(records: &[DynamicRecord]) -> Table {
    let mut t = Table::new([
        "scene",
        "axis",
        "vertices",
        "maps",
        "field samples",
        "light/vis/field kept",
        "truncation",
        "depth",
        "change",
        "rms rel",
        "max rel",
        "fields s",
        "fields MiB",
        "re-form s",
        "frame ms",
        "T coef/vertex",
    ]);
    for r in records {
        t.push([
            r.scene.clone(),
            r.axis.clone(),
            r.vertices.to_string(),
            format!("{} x {}", r.resolution, 2 * r.resolution),
            r.field_samples.to_string(),
            budget_label(r.keep_light, r.keep_visibility, r.keep_field),
            r.truncation.clone(),
            r.depth.to_string(),
            r.change.clone(),
            significant(r.rms_relative, 3),
            significant(r.max_relative, 3),
            significant(r.field_seconds, 3),
            significant(r.field_bytes as f64 / (1 << 20) as f64, 3),
            significant(r.reform_seconds, 3),
            significant(r.frame_seconds * 1e3, 3),
            significant(r.product_coefficients, 3),
        ]);
    }
    t
}
