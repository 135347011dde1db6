//! `haarshift experiment shift-chain`: Alnasser 2008's Table 3.1 protocol.

use std::fmt::Write;
use std::path::PathBuf;

use haarshift_experiments::plot::LabeledPoint;
use haarshift_experiments::shift_chain::{ChainRecord, run_chain};
use haarshift_experiments::table::{Table, significant};
use haarshift_relight::Result;

use super::rotation_cycle::load_images;
use super::{MethodFlags, OutputFlags, Reports};
use crate::commands::print;
use crate::progress::progress_bar;

const ABOUT: &str = "\
Protocol (fixed, printed with the results): luma of each image; its centred square crop whose
side is the largest power of two that fits (so every method is periodic with one period);
shift it once by (DX, DY) and, separately, in STEPS equal steps, periodic boundary; RMS, PSNR
(peak 255) and max error of the difference over the whole frame. Pixel kernels shift with
wrapped rows; compact Haar shifts the coefficients once per step, each step rounded to 1/2^h;
retained Haar keeps its 2^h-finer grid across the steps.

Default images and methods as for rotation-cycle.

Examples:
  haarshift experiment shift-chain
  haarshift experiment shift-chain testdata/camera.png --dx 7.3 --dy -4.7 --steps 16";

/// One shift by (DX, DY) against the same shift made as STEPS equal steps.
#[derive(clap::Args, Debug)]
#[command(after_help = ABOUT)]
pub struct Args {
    /// Images to use [default: the embedded photographs and two synthetic patterns]
    pub images: Vec<PathBuf>,
    /// Total shift in columns (right for positive)
    #[arg(long, default_value_t = 7.3, allow_negative_numbers = true)]
    pub dx: f64,
    /// Total shift in rows (down for positive)
    #[arg(long, default_value_t = -4.7, allow_negative_numbers = true)]
    pub dy: f64,
    /// Steps of the chain
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=100000))]
    pub steps: u32,
    #[command(flatten)]
    pub methods: MethodFlags,
    #[command(flatten)]
    pub output: OutputFlags,
}

pub fn run(args: Args) -> Result<()> {
    let reports = args.output.claim("shift-chain", &args.images)?;
    let methods = args.methods.methods(0)?;
    let images = load_images(&args.images)?;
    let bar = progress_bar(images.len() * methods.len());
    let mut records = Vec::new();
    for image in &images {
        for m in &methods {
            let shift = (args.dx, args.dy);
            let steps = args.steps as usize;
            records.push(run_chain(
                &image.name,
                image.plane.view(),
                m.method,
                &m.options,
                shift,
                steps,
            )?);
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let mut text = format!(
        "shift chain: one shift by ({}, {}) against {} steps of ({}, {})\nparameters: {}\n\n",
        args.dx,
        args.dy,
        args.steps,
        args.dx / f64::from(args.steps),
        args.dy / f64::from(args.steps),
        args.methods.describe(),
    );
    write!(text, "{}", chain_table(&records)).ok();
    let written = write_chain_reports(&reports, &text, &records)?;
    print(&format!("{text}\n{written}"))
}

fn label(r: &ChainRecord) -> String {
    let mut l = r.method.clone();
    if let (Some(h), Some(retain)) = (r.precision, r.retain) {
        write!(l, " h={h} {}", if retain { "retained" } else { "compact" }).ok();
    }
    l
}

fn chain_table(records: &[ChainRecord]) -> Table {
    let mut table = Table::new([
        "image",
        "size",
        "method",
        "rms",
        "psnr",
        "max_error",
        "seconds",
    ]);
    for r in records {
        table.push([
            r.image.clone(),
            r.size.to_string(),
            label(r),
            significant(r.rms, 3),
            significant(r.psnr, 4),
            significant(r.max_error, 3),
            significant(r.seconds, 2),
        ]);
    }
    table
}

fn write_chain_reports(reports: &Reports, report: &str, records: &[ChainRecord]) -> Result<String> {
    let points: Vec<LabeledPoint> = records
        .iter()
        .filter(|r| r.rms > 0.0 && r.seconds > 0.0)
        .map(|r| LabeledPoint {
            label: label(r),
            x: r.seconds,
            y: r.rms,
        })
        .collect();
    reports.write(report, records, &points)
}
