//! `haarshift experiment sphere`: each rotation method against the ground truth on real maps.

use std::path::{Path, PathBuf};

use haarshift::io::read_image;
use haarshift::sphere::map_error::{self, Record, STANDARD_ROTATIONS, default_maps};
use haarshift::sphere::{LatLongMap, Method};
use haarshift_experiments::plot::{Series, category_points};
use haarshift_experiments::table::{Table, significant};
use haarshift_relight::Result;

use super::{OutputFlags, wrote};
use crate::commands::{choice, names, print};
use crate::progress::progress_bar;

const EXAMPLES: &str = "\
Examples:
  haarshift experiment sphere                       (the embedded rooitou_park_256x128 map)
  haarshift experiment sphere park.hdr studio.exr --out-dir results/envmaps --force
  haarshift experiment sphere --methods bilinear,haar --levels full,full-2,4 --samples 4
  haarshift experiment sphere --json sphere-records.json

Each map is rotated by pitch 5, 30, 60 and 90 degrees, yaw 10 degrees and the compound
yaw 40, pitch -25, roll 60 (conventions: `haarshift sphere rotate --help`), first by the
reference (SAMPLES x SAMPLES solid-angle samples per pixel, the ground truth), then by every
method at every level. Reported per row: rms, the solid-angle weighted RMS pixel difference
from the reference; rms@level, the same with both sides reduced to the computed level (the
method's own error without the detail it skipped); coef rms, the RMS difference of the Haar
coefficients (average normalisation); energy err, the relative change of the solid-angle
integral against the input map (a rotation preserves it); ms, the wall-clock time of the
rotation. Maps are computed in single precision.

Writes DIR/sphere.csv, DIR/sphere.json (the same records), DIR/sphere.md (the table) and
DIR/sphere-rms.png (rms per rotation, one marker colour per method and level).";

/// Compare sphere rotation methods with the ground truth: table, CSV, JSON, plot.
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Lat-long maps (.hdr, .exr or .npy; 2:1, the height a power of two) [default: the
    /// embedded 256x128 copy of rooitou_park (testdata/envmaps)]
    pub maps: Vec<PathBuf>,

    #[command(flatten)]
    pub output: OutputFlags,

    /// Methods to compare with the reference, comma-separated
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        default_value = "bilinear,bicubic,haar",
        value_parser = choice::<Method>(names!(Method))
    )]
    pub methods: Vec<Method>,

    /// Finest detail levels to compute each method at, comma-separated: `full` (the map's
    /// finest), `full-K` (K levels coarser, 4^K times less work) or a level number L
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        default_value = "full,full-1,full-2",
        value_parser = parse_level
    )]
    pub levels: Vec<LevelChoice>,

    /// Samples per axis and pixel of the reference (1 to 64)
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub samples: usize,
}

/// A level as given on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LevelChoice {
    /// This many levels coarser than the map's finest (0: the finest).
    BelowFinest(usize),
    /// This level.
    Level(usize),
}

fn parse_level(s: &str) -> std::result::Result<LevelChoice, String> {
    let bad = || format!("{s:?} is not `full`, `full-K` or a level number");
    let number = |t: &str| t.parse::<usize>().map_err(|_| bad());
    match s.strip_prefix("full") {
        Some("") => Ok(LevelChoice::BelowFinest(0)),
        Some(rest) => match rest.strip_prefix('-') {
            Some(k) => number(k).map(LevelChoice::BelowFinest),
            None => Err(bad()),
        },
        None => number(s).map(LevelChoice::Level),
    }
}

impl LevelChoice {
    /// The level option for a map whose finest level is `finest`.
    fn resolve(self, finest: usize, map: &str) -> Result<Option<usize>> {
        match self {
            LevelChoice::BelowFinest(0) => Ok(None),
            LevelChoice::BelowFinest(k) => finest.checked_sub(k).map(Some).ok_or_else(|| {
                haarshift_relight::Error::from(haarshift::Error::InvalidParameter {
                    name: "levels",
                    reason: format!("full-{k}: {map} has detail levels 0..={finest} only"),
                })
            }),
            LevelChoice::Level(l) => Ok(Some(l)),
        }
    }

    /// How the plot's legend names a method at this level.
    fn label(self, method: Method) -> String {
        match self {
            LevelChoice::BelowFinest(0) => method.to_string(),
            LevelChoice::BelowFinest(k) => format!("{method} full-{k}"),
            LevelChoice::Level(l) => format!("{method} level {l}"),
        }
    }
}

pub fn run(args: Args) -> Result<()> {
    let reports = args.output.claim("sphere", &args.maps)?;
    let maps = if args.maps.is_empty() {
        default_maps::<f32>()?
    } else {
        args.maps
            .iter()
            .map(|p| load_map(p))
            .collect::<Result<Vec<_>>>()?
    };

    let combos: Vec<(Method, LevelChoice)> = args
        .methods
        .iter()
        .flat_map(|&m| args.levels.iter().map(move |&l| (m, l)))
        .collect();
    let mut series: Vec<Series> = combos
        .iter()
        .map(|&(m, l)| Series {
            name: l.label(m),
            values: Vec::new(),
        })
        .collect();
    let mut categories = Vec::new();
    let mut records: Vec<Record> = Vec::new();
    let bar = progress_bar(maps.len() * STANDARD_ROTATIONS.len());
    for (name, map) in &maps {
        let finest = map.height().trailing_zeros().saturating_sub(1) as usize;
        let methods = combos
            .iter()
            .map(|&(m, l)| Ok((m, l.resolve(finest, name)?)))
            .collect::<Result<Vec<_>>>()?;
        for rotation in STANDARD_ROTATIONS {
            let label = rotation_label(rotation);
            bar.set_message(format!("{name}: {label}"));
            let rows = map_error::run(name, map, &[rotation], &methods, args.samples)?;
            categories.push(if maps.len() > 1 {
                format!("{name}: {label}")
            } else {
                label
            });
            // rows[0] is the reference itself; the others follow `combos`.
            for (s, row) in series.iter_mut().zip(&rows[1..]) {
                s.values.push(Some(row.comparison.rms).filter(|&v| v > 0.0));
            }
            records.extend(rows);
            bar.inc(1);
        }
    }
    bar.finish_and_clear();

    let text = table(&records).to_string();
    let mut written = reports.write(&text, &records, &[])?;
    if series.iter().flat_map(|s| &s.values).any(Option::is_some) {
        let title = format!(
            "Solid-angle weighted RMS against the reference ({0}x{0} samples per pixel)",
            args.samples
        );
        let plot = category_points(&title, "weighted RMS", &categories, &series)?;
        written.push_str(&wrote(&[reports.writer().png("rms", &plot)?]));
    } else {
        eprintln!("haarshift: note: every method matched the reference exactly; no plot");
    }
    print(&format!("{text}\n{written}"))
}

/// A map file as `(name, map)`, the name being the file's stem.
fn load_map(path: &Path) -> Result<(String, LatLongMap<f32>)> {
    let image = read_image::<f32>(path)?;
    let map = LatLongMap::from_image(&image).map_err(|e| e.in_file(path))?;
    let name = path.file_stem().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into(),
    );
    Ok((name, map))
}

/// `pitch 30`, `yaw 40 pitch -25 roll 60`: the non-zero angles.
fn rotation_label((yaw, pitch, roll): (f64, f64, f64)) -> String {
    let parts: Vec<String> = [("yaw", yaw), ("pitch", pitch), ("roll", roll)]
        .iter()
        .filter(|(_, v)| *v != 0.0)
        .map(|(n, v)| format!("{n} {v}"))
        .collect();
    if parts.is_empty() {
        "identity".into()
    } else {
        parts.join(" ")
    }
}

/// The records as a Markdown table.
fn table(records: &[Record]) -> Table {
    let mut t = Table::new([
        "map",
        "yaw",
        "pitch",
        "roll",
        "method",
        "level",
        "thesis level",
        "rms",
        "rms@level",
        "coef rms",
        "energy err",
        "ms",
    ]);
    for r in records {
        let c = &r.comparison;
        t.push([
            r.map.clone(),
            r.yaw.to_string(),
            r.pitch.to_string(),
            r.roll.to_string(),
            r.method.to_string(),
            r.level.to_string(),
            r.thesis_level.to_string(),
            significant(c.rms, 3),
            significant(c.rms_at_level, 3),
            significant(c.coefficient_rms, 3),
            significant(c.energy_error, 2),
            significant(r.seconds * 1e3, 3),
        ]);
    }
    t
}
