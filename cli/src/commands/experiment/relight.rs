//! `haarshift experiment relight`: every relighting method against the ray-cast ground truth,
//! over the sources' axes, with picture grids.

use std::path::{Path, PathBuf};

use haarshift_experiments::journal::Journal;
use haarshift_experiments::relight::report::{coefficient_plot, report, time_plot};
use haarshift_experiments::relight::{Light, RelightProtocol, Subject, run};
use haarshift_relight::Result;

use super::{OutputFlags, finish_journal, wrote};
use crate::commands::print;
use crate::commands::relight::flags::ShardFlags;
use crate::progress::progress_bar;

const EXAMPLES: &str = "\
Examples:
  haarshift experiment relight                          (the bunny under rooitou_park, --quick)
  haarshift experiment relight --full --out-dir results/relight/experiments --force
  haarshift experiment relight --full --out-dir results/relight/experiments --resume
                                                        (goes on with a run that was stopped)
  haarshift experiment relight --scene testdata/scenes/cylinder_and_bump.json --env park.hdr

Defaults, relative to the repository's root: --scene testdata/scenes/bunny.json and
testdata/scenes/cylinder_and_bump.json (Vollick and Lessig's procedural scene), --env the four maps
testdata/envmaps/*_1k.hdr (512 x 1024). --quick runs the first scene under the first map;
--full the first scene under every map (each material; Phong 50 also under the lighting
rotated by yaw 90, pitch 30 and from the second camera, orbited 120 degrees), the second
under the first map.

The ground truth is `relight reference`: one ray per texel of the lighting at 256 x 512
(--quick) or 512 x 1024 (--full, the maps' native size), cast once per scene, the BRDF
evaluated exactly in each vertex's frame. Axes, each its own table:
  rotation      the BRDF brought into each vertex frame: haar from the sphere module's levels
                3, 4, 5 (thesis levels 4, 5, 6) and the finest, haar-cubic, spatial
                (bilinear), reference (solid-angle integration: --full, first setting only,
                minutes per render), direct (no rotation),
                128 x 256 maps, every coefficient kept; `vs spatial` is the thesis's metric
                (the Haar render against the spatially rotated one)
  coefficients  each rotated BRDF map cut to 4, 16, 64, 256 coefficients per face, coarse to
                fine (cutoff: the thesis's Fig. 4.7) or the largest, and all of them
  resolution    lat-long 32 x 64 to 128 x 256 (--full: 256 x 512) and cube 6 x 16^2 to
                6 x 32^2 (--full: 6 x 128^2) times kept ratio 1, 0.1, 0.05, 0.01 of the
                lighting's and each transport's (and BRDF map's) details (Vollick and Lessig's tables)
  depth         traversal depth 1 to 7 at 128 x 256 (Sun 2006's Fig. 3.5)
  harmonics     spherical harmonics of 2 to 8 bands against Haar at the same number of
                lighting and transport coefficients, and Haar at 128 to 1024 of them
Materials: Phong 50 (--full also Phong 10, Phong 200 and Blinn-Phong 50). The thesis's
measured materials are not redistributable; analytic stand-ins, chosen by the width of the
highlight and not fitted: steel = Phong 200, aluminium bronze = Phong 50, blue metallic paint
= Blinn-Phong 50. Lambert for the resolution and depth axes (--full also Phong 50), Lambert
and Phong 10 for harmonics.
Errors: RMS and maximum over every vertex and channel, relative to the truth's RMS radiance
(`rms rel`, `max rel`) and in radiance units (`rms`); `image rel` is the RMS over the pixels
of the two renders. Times: precompute (ray casting, encoding, preparing the shader), relight
(encoding the lighting, rotating the BRDFs, shading every vertex).

Writes DIR/relight.csv, .json and .md (every table), DIR/relight-rms-time.png (error against
relighting time, Pareto frontier joined), DIR/relight-rms-coefficients.png (error against kept
coefficients per method) and, per scene, DIR/relight-grid-SCENE-ENV-MATERIAL.png (the
rotation axis's renders over their false-colour error images). Each unit of work (a scene's
truth, a condition, an axis under one material) is appended to DIR/relight.journal as it is
measured, so that a run killed midway goes on with --resume; the journal is removed once the
reports are written.

Across machines: --shard I/N (or auto, from a Slurm array or Kubernetes Indexed Job, as for
relight precompute) measures every N-th unit of work from the I-th into
DIR/relight.journal.shard-I-of-N (DIR shared by the shards) and writes no report; a rerun
of a preempted shard goes on with its journal. Once every shard is done, --resume in DIR takes
in every shard's units and writes the reports, the same tables as one run's:
  haarshift experiment relight --full --out-dir shared/relight --shard auto
  haarshift experiment relight --full --out-dir shared/relight --resume";

/// Relighting methods against the ray-cast truth: tables, CSV, JSON, plots, picture grids.
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// A scene file (JSON) or a mesh put on its ground plane (repeatable) [default: the
    /// bunny and Vollick and Lessig's cylinder and bump]
    #[arg(long, value_name = "FILE")]
    pub scene: Vec<PathBuf>,

    /// An environment map (repeatable) [default: testdata/envmaps/*_1k.hdr]
    #[arg(long, value_name = "ENV")]
    pub env: Vec<PathBuf>,

    /// The full protocol (every scene and map, rotated lighting, two cameras, four glossy
    /// materials, larger maps, the truth at 512 x 1024): about an hour on two cores
    #[arg(long)]
    pub full: bool,

    /// The quick protocol (the default, stated)
    #[arg(long, conflicts_with = "full")]
    pub quick: bool,

    /// Go on with a run that was stopped: the measurements in DIR/relight.journal (written
    /// as they are made) are kept and the rest measured; refused if the protocol or the
    /// inputs differ
    #[arg(long, conflicts_with = "shard")]
    pub resume: bool,

    #[command(flatten)]
    pub shard: ShardFlags,

    #[command(flatten)]
    pub output: OutputFlags,
}

const DEFAULT_SCENES: [&str; 2] = [
    "testdata/scenes/bunny.json",
    "testdata/scenes/cylinder_and_bump.json",
];

const DEFAULT_ENVS: [&str; 4] = [
    "testdata/envmaps/rooitou_park_1k.hdr",
    "testdata/envmaps/st_fagans_interior_1k.hdr",
    "testdata/envmaps/studio_small_03_1k.hdr",
    "testdata/envmaps/venice_sunset_1k.hdr",
];

fn or_defaults(given: &[PathBuf], defaults: &[&str]) -> Vec<PathBuf> {
    if given.is_empty() {
        defaults.iter().map(PathBuf::from).collect()
    } else {
        given.to_vec()
    }
}

pub fn run_command(args: Args) -> Result<()> {
    let scenes = or_defaults(&args.scene, &DEFAULT_SCENES);
    let envs = or_defaults(&args.env, &DEFAULT_ENVS);
    let protocol = if args.full {
        RelightProtocol::full()
    } else {
        RelightProtocol::quick()
    };
    let scenes = &scenes[..protocol.scenes.min(scenes.len())];
    let envs = &envs[..protocol.lights.min(envs.len())];
    let inputs: Vec<PathBuf> = scenes.iter().chain(envs).cloned().collect();
    let shard = args.shard.resolve()?;
    let reports = args.output.claim("relight", &inputs)?;
    let options = format!("{protocol:?}; {}", Journal::fingerprint(&inputs)?);
    let mut journal = match shard {
        Some(shard) => Journal::create_shard(&reports.journal_path(), shard, &options)?,
        None => reports.journal(&options, args.resume)?,
    };
    let subjects = scenes
        .iter()
        .map(|p| Subject::load(p))
        .collect::<Result<Vec<_>>>()?;
    let lights = envs
        .iter()
        .map(|p| Light::load(p))
        .collect::<Result<Vec<_>>>()?;
    let bar = progress_bar(0);
    let results = run(&subjects, &lights, &protocol, &mut journal, |r| {
        bar.inc(1);
        bar.set_message(format!(
            "{} {}: {} {}",
            r.scene, r.axis, r.method, r.parameters
        ));
    })?;
    bar.finish_and_clear();
    if let Some(shard) = shard {
        return print(&format!(
            "shard {shard}: {} records ({} units taken from its journal) in {}; \
             once every shard is done, --resume in the same directory writes the reports\n",
            results.records.len(),
            journal.resumed(),
            journal.path().unwrap_or(Path::new("")).display(),
        ));
    }
    let text = report(&protocol, &results);
    let writer = reports.writer();
    let mut written = vec![
        writer.csv(&results.records)?,
        writer.json(&results.records)?,
        writer.markdown(&format!(
            "# Relighting experiment\n\nWritten by `haarshift {}`.\n\n{text}",
            std::env::args().skip(1).collect::<Vec<_>>().join(" ")
        ))?,
    ];
    written.extend(reports.write_json_flag(&results.records)?);
    written.push(writer.png("rms-time", &time_plot(&results.records)?)?);
    written.push(writer.png("rms-coefficients", &coefficient_plot(&results.records)?)?);
    for grid in &results.grids {
        written.push(writer.png(&format!("grid-{}", grid.name), &grid.image)?);
    }
    finish_journal(journal)?;
    print(&format!("{text}\n{}", wrote(&written)))
}
