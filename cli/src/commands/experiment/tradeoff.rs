//! `haarshift experiment tradeoff`: error against time and memory for every method and
//! parameter on the rotation cycle, with the Pareto frontiers.

use std::fmt::Write;
use std::path::PathBuf;

use haarshift_experiments::plot::{LabeledPoint, log_log_scatter};
use haarshift_experiments::rotation_cycle::{CycleRecord, PROTOCOL};
use haarshift_experiments::table::{Table, significant};
use haarshift_experiments::tradeoff::{TradeoffGrid, TradeoffPoint, summarize};
use haarshift_relight::Result;
use serde::Serialize;

use super::rotation_cycle::{load_images, run_methods};
use super::{OutputFlags, Reports, markdown_report, parse_methods, peak_megabytes, wrote};
use crate::commands::print;

const ABOUT: &str = "\
Runs the rotation-cycle protocol (see `haarshift experiment rotation-cycle --help`) for every
configuration of every method: compact Haar at h = 0..=MAX_PRECISION, retained Haar at
h = 1..=MAX_RETAINED_PRECISION (at s = 0: it already works on a 2^h-finer grid), and every
configuration but retained Haar on a 2^s-finer grid for s = 0..=MAX_SUPERSAMPLE. Kernel sizes
are kernels of their own (keys, bspline3/bspline5, lanczos3/lanczos4).

Default images: those of rotation-cycle (the embedded photographs and two synthetic patterns),
each cut to its centred 128x128 crop (--size), so that the default run takes a few minutes
rather than the hours retained Haar at h = 2 and supersampling need on the full crops.

Per configuration: mean RMS over the images, largest max error, total and median seconds, and
the largest peak heap of a single run (the runs are made one at a time). A configuration is on
the time frontier (T) when no other has both a lower or equal total time and a lower or equal
mean RMS (one of them strictly), and on the memory frontier (M) likewise with peak heap.

Writes DIR/tradeoff.csv, .json and .md (one record per configuration, with the frontier
flags), DIR/tradeoff-rms-time.png and DIR/tradeoff-rms-memory.png (log-log, frontier in red),
and DIR/tradeoff-runs.csv and .json (one record per image and configuration, with its
configuration's frontier flags; --json FILE writes these too).

Examples:
  haarshift experiment tradeoff
  haarshift experiment tradeoff testdata/camera.png --size 256 --methods fft,keys,haar
  haarshift experiment tradeoff --max-supersample 2 --max-retained-precision 3 --size 64";

/// Error against time and memory for every method and parameter, with the Pareto frontiers.
#[derive(clap::Args, Debug)]
#[command(after_help = ABOUT)]
pub struct Args {
    /// Images to use [default: the embedded photographs and two synthetic patterns]
    pub images: Vec<PathBuf>,
    /// Side of the centred crop each image is cut to first, or `full` for the protocol's own
    /// crop (the whole shorter side)
    #[arg(long, value_name = "N|full", default_value = "128", value_parser = parse_size)]
    pub size: CropSize,
    /// Rotations in the cycle
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=3600))]
    pub steps: u32,
    /// Comma-separated kernels: nearest, linear, keys, bspline3, bspline5, lanczos3, lanczos4,
    /// fft, haar (both modes), haar-compact, haar-retained [default: all, haar in both modes]
    #[arg(long, value_name = "LIST")]
    pub methods: Option<String>,
    /// Compact Haar runs at h = 0..=H
    #[arg(long, value_name = "H", default_value_t = TradeoffGrid::default().max_precision)]
    pub max_precision: u32,
    /// Retained Haar runs at h = 1..=H (0: not at all)
    #[arg(long, value_name = "H", default_value_t = TradeoffGrid::default().max_retained_precision)]
    pub max_retained_precision: u32,
    /// Every configuration but retained Haar runs at s = 0..=S
    #[arg(long, value_name = "S", default_value_t = TradeoffGrid::default().max_supersample)]
    pub max_supersample: u32,
    #[command(flatten)]
    pub output: OutputFlags,
}

/// `--size`: a crop side, or the protocol's own crop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CropSize {
    /// The centred `N x N` crop first.
    Side(usize),
    /// No crop before the protocol's.
    Full,
}

fn parse_size(text: &str) -> std::result::Result<CropSize, String> {
    if text == "full" {
        return Ok(CropSize::Full);
    }
    match text.parse::<usize>() {
        Ok(n) if n >= 4 => Ok(CropSize::Side(n)),
        _ => Err(format!(
            "`{text}` is neither `full` nor a side of at least 4 pixels"
        )),
    }
}

/// A per-image run with its configuration's frontier flags.
#[derive(Serialize)]
struct Run<'a> {
    #[serde(flatten)]
    record: &'a CycleRecord,
    time_frontier: bool,
    memory_frontier: bool,
}

pub fn run(args: Args) -> Result<()> {
    let reports = args.output.claim("tradeoff", &args.images)?;
    let grid = TradeoffGrid {
        max_precision: args.max_precision,
        max_retained_precision: args.max_retained_precision,
        max_supersample: args.max_supersample,
    };
    grid.validate()?;
    // The precisions and supersampling given here are replaced by the grid's sweep.
    let configs = grid.expand(&parse_methods(args.methods.as_deref(), 0, 1, 0)?);
    if configs.is_empty() {
        return Err(haarshift_relight::Error::from(
            haarshift::Error::InvalidParameter {
                name: "methods",
                reason: "no configuration to run (retained Haar with --max-retained-precision 0)"
                    .into(),
            },
        ));
    }
    let mut images = load_images(&args.images)?;
    if let CropSize::Side(side) = args.size {
        images = images
            .iter()
            .map(|image| image.centre_crop(side))
            .collect::<haarshift::Result<_>>()?;
    }
    let runs = run_methods(&images, &configs, args.steps as usize, |_| {})?;
    let points = summarize(&runs);

    let crops: Vec<String> = images
        .iter()
        .map(|image| {
            let (h, w) = image.plane.dim();
            format!("{} ({})", image.name, h.min(w))
        })
        .collect();
    let size = match args.size {
        CropSize::Side(side) => format!("each image cut to its centred {side}x{side} crop first"),
        CropSize::Full => "the protocol's crop of each whole image".into(),
    };
    let mut text = format!(
        "trade-off: rotation cycle of {} rotations of {} degrees, {} configurations, {} images\n\
         protocol: {PROTOCOL}\nimages ({size}; crop side m in brackets): {}\ngrid: {}\n\
         per configuration: mean RMS over the images, total and median seconds, largest peak \
         heap of one run; frontier T: (seconds, RMS), M: (peak heap, RMS)\n\n",
        args.steps,
        360.0 / f64::from(args.steps),
        configs.len(),
        images.len(),
        crops.join(", "),
        grid.describe(),
    );
    write!(text, "{}", tradeoff_table(&points)).ok();
    let written = write_tradeoff_reports(&reports, &text, &runs, &points)?;
    print(&format!("{text}\n{written}"))
}

/// The summary as a table, frontier members marked.
fn tradeoff_table(points: &[TradeoffPoint]) -> Table {
    let mut table = Table::new([
        "method",
        "mean_rms",
        "max_error",
        "total_s",
        "median_s",
        "peak_MB",
        "frontier",
    ]);
    for p in points {
        let marks = [(p.time_frontier, "T"), (p.memory_frontier, "M")]
            .iter()
            .filter(|(on, _)| *on)
            .map(|(_, mark)| *mark)
            .collect::<Vec<_>>()
            .join(" ");
        table.push([
            p.method.label(),
            significant(p.mean_rms, 3),
            significant(p.max_error, 3),
            significant(p.total_seconds, 2),
            significant(p.median_seconds, 2),
            peak_megabytes(p.peak_bytes),
            marks,
        ]);
    }
    table
}

/// Writes the summary, the per-run reports (and `--json`) and the two frontier plots;
/// returns the lines naming the files.
fn write_tradeoff_reports(
    reports: &Reports,
    report: &str,
    runs: &[CycleRecord],
    points: &[TradeoffPoint],
) -> Result<String> {
    let flagged: Vec<Run<'_>> = runs
        .iter()
        .map(|record| {
            let point = points
                .iter()
                .find(|p| p.method == record.method && p.steps == record.steps);
            Run {
                record,
                time_frontier: point.is_some_and(|p| p.time_frontier),
                memory_frontier: point.is_some_and(|p| p.memory_frontier),
            }
        })
        .collect();
    let writer = reports.writer();
    let runs_writer = reports.dir.writer("tradeoff-runs");
    let mut files = vec![
        writer.csv(points)?,
        writer.json(points)?,
        writer.markdown(&markdown_report(reports.stem, report))?,
        runs_writer.csv(&flagged)?,
        runs_writer.json(&flagged)?,
    ];
    files.extend(reports.write_json_flag(&flagged)?);
    for axis in &COST_AXES {
        let placed: Vec<(&TradeoffPoint, LabeledPoint)> = points
            .iter()
            .filter_map(|p| {
                let x = (axis.cost)(p).filter(|&x| x > 0.0 && p.mean_rms > 0.0)?;
                let label = p.method.label();
                Some((
                    p,
                    LabeledPoint {
                        label,
                        x,
                        y: p.mean_rms,
                    },
                ))
            })
            .collect();
        if placed.is_empty() {
            continue;
        }
        let frontier: Vec<LabeledPoint> = placed
            .iter()
            .filter(|(p, _)| (axis.on_frontier)(p))
            .map(|(_, l)| l.clone())
            .collect();
        let all: Vec<LabeledPoint> = placed.into_iter().map(|(_, l)| l).collect();
        let title = format!("Rotation cycle: mean RMS against {}", axis.cost_name);
        let plot = log_log_scatter(&title, axis.x_label, "mean RMS", &all, &frontier)?;
        files.push(writer.png(axis.file, &plot)?);
    }
    Ok(wrote(&files))
}

/// A cost the error is plotted against, with its frontier.
struct CostAxis {
    file: &'static str,
    cost_name: &'static str,
    x_label: &'static str,
    cost: fn(&TradeoffPoint) -> Option<f64>,
    on_frontier: fn(&TradeoffPoint) -> bool,
}

const COST_AXES: [CostAxis; 2] = [
    CostAxis {
        file: "rms-time",
        cost_name: "time",
        x_label: "total seconds over the images",
        cost: |p| Some(p.total_seconds),
        on_frontier: |p| p.time_frontier,
    },
    CostAxis {
        file: "rms-memory",
        cost_name: "memory",
        x_label: "peak heap of one run (MB)",
        cost: |p| p.peak_bytes.map(|b| b as f64 / 1e6),
        on_frontier: |p| p.memory_frontier,
    },
];
