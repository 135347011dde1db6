//! `haarshift experiment rotation-cycle`: the seed's Table 2.2 protocol.

use std::fmt::Write;
use std::path::PathBuf;

use haarshift::Result;
use haarshift::experiments::kernel_cycle::{
    KernelCycle, NamedPlane, default_images, run_rotation_cycle,
};
use haarshift::experiments::plot::LabeledPoint;
use haarshift::experiments::rotation_cycle::{CycleRecord, PROTOCOL};

use super::{MethodFlags, OutputFlags, PeakMeter, cycle_table, progress_bar, write_reports};
use crate::commands::print;

const ABOUT: &str = "\
Protocol (fixed, printed with the results): luma 0.2125R+0.7154G+0.0721B on the stored values;
centred square crop of side m = min(width, height); zero-pad by floor(m/2) on every side;
rotate STEPS times by 360/STEPS degrees about the canvas centre (canvas same, fill 0); RMS,
PSNR (peak 255) and max error over the pixel centres within m/2 - 2 of the centre. Wall time
and peak heap are measured per run, one run at a time.

Default images (no IMAGES given): every PNG in testdata/ at its full size, plus a 300x200 zone
plate and a 256x256 Siemens star (32 spokes) generated in code.
Default methods (no --methods): every kernel (nearest, linear, keys, bspline3, bspline5,
lanczos3, lanczos4, fft) and haar in both modes: compact at --precision (default 3) and
retained at --retained-precision (default 1: h = 3 on the 512x512 photographs takes minutes).

Examples:
  haarshift experiment rotation-cycle
  haarshift experiment rotation-cycle testdata/camera.png --methods fft,haar --precision 2
  haarshift experiment rotation-cycle --methods fft --supersample 1 --json fft.json";

/// Rotate images STEPS times by 360/STEPS degrees and measure what the round trip lost.
#[derive(clap::Args, Debug)]
#[command(after_help = ABOUT)]
pub struct Args {
    /// Images to use [default: testdata/*.png and two synthetic patterns]
    pub images: Vec<PathBuf>,
    /// Rotations in the cycle
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=3600))]
    pub steps: u32,
    #[command(flatten)]
    pub methods: MethodFlags,
    /// Rotate on a 2^S-finer grid (every method)
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub supersample: u32,
    #[command(flatten)]
    pub output: OutputFlags,
}

pub fn run(args: Args) -> Result<()> {
    let methods = args.methods.methods(args.supersample)?;
    let images = load_images(&args.images)?;
    let records = run_methods(&images, &methods, args.steps as usize)?;
    let mut text = format!(
        "rotation cycle: {} rotations of {} degrees\nprotocol: {PROTOCOL}\nparameters: {}, supersample S = {}\n\n",
        args.steps,
        360.0 / f64::from(args.steps),
        args.methods.describe(),
        args.supersample,
    );
    write!(text, "{}", cycle_table(&records)).ok();
    text.push_str(&write_cycle_reports(
        "rotation-cycle",
        &records,
        &args.output,
    )?);
    print(&text)
}

/// The named images, or the default set.
pub fn load_images(paths: &[PathBuf]) -> Result<Vec<NamedPlane>> {
    if paths.is_empty() {
        return default_images("testdata".as_ref());
    }
    paths.iter().map(|p| NamedPlane::read(p)).collect()
}

/// Runs every method on every image with a progress bar.
pub fn run_methods(
    images: &[NamedPlane],
    methods: &[KernelCycle],
    steps: usize,
) -> Result<Vec<CycleRecord>> {
    let bar = progress_bar(images.len() * methods.len());
    let records = run_rotation_cycle(images, methods, steps, &PeakMeter::default(), |r| {
        bar.set_message(format!("{} {}", r.image, r.method.label()));
        bar.inc(1);
    })?;
    bar.finish_and_clear();
    Ok(records)
}

/// Writes the reports of a rotation-cycle run; returns the lines naming the files.
pub fn write_cycle_reports(
    stem: &str,
    records: &[CycleRecord],
    output: &OutputFlags,
) -> Result<String> {
    let points: Vec<LabeledPoint> = records
        .iter()
        .filter(|r| r.rms > 0.0 && r.seconds > 0.0)
        .map(|r| LabeledPoint {
            label: r.method.label(),
            x: r.seconds,
            y: r.rms,
        })
        .collect();
    write_reports(stem, records, &points, output)
}
