//! `haarshift experiment stability`: the numerical extremes, each check with its figure, its
//! tolerance and a pass/fail.

use std::fmt::Write;
use std::path::PathBuf;

use haarshift_experiments::kernel_cycle::{NamedPlane, default_photograph};
use haarshift_experiments::plot::{LabeledPoint, log_log_scatter};
use haarshift_experiments::stability::{
    FAMILIES, StabilityConfig, StabilityRecord, StabilityReport, eight_bit, run_stability,
};
use haarshift_experiments::table::{Table, significant};
use haarshift_relight::Result;

use super::{OutputFlags, PeakMeter, Reports};
use crate::commands::print;
use crate::progress::progress_bar;

const ABOUT: &str = "\
Checks (each with its figure, tolerance and pass/fail; see the library's
experiments::stability docs for every oracle):
  angle      0, 90, 180, -180 deg bit-exact against quarter turns; 1e-9 and 90+-1e-9 deg
             within 4|delta| r G of them; 359.999 ~ -0.001; 1e6 = 280 bit for bit; the
             switch at 45+-1e-6 deg (linear, keys, bspline3, fft, compact haar)
  size       1x1, 1x17, 17x1, 2x2, 13x17, 127x131, 64x128: round trip, haar shifts,
             rotation; the largest square within the rotation's memory budget
  values     scales 1e-30..1e30 in f32 and f64, subnormals, constants, an impulse, a Nyquist
             checkerboard, NaN and infinity
  shift      10^4 whole haar shifts (bit-exact where the arithmetic is) and 10^3 fractional
             ones in f32 against f64 (drift plotted)
  precision  compact h = 0..20 against bilinear interpolation, h = 21 refused; retained h up
             to 7 against the compact shift, the first h beyond the 1 GiB budget refused

Exit status 1 when any check fails.

Examples:
  haarshift experiment stability
  haarshift experiment stability --quick --json stability.json";

/// The numerical extremes: angles, sizes, values, shift chains, precisions.
#[derive(clap::Args, Debug)]
#[command(after_help = ABOUT)]
pub struct Args {
    /// The photograph (rounded to 8-bit values, at least 128x128) [default: the embedded
    /// camera.png]
    #[arg(long, value_name = "FILE")]
    pub image: Option<PathBuf>,
    /// Shorter chains: 10^3 whole and 10^2 fractional shifts instead of 10^4 and 10^3
    #[arg(long)]
    pub quick: bool,
    #[command(flatten)]
    pub output: OutputFlags,
}

pub fn run(args: Args) -> Result<()> {
    let inputs: Vec<PathBuf> = args.image.iter().cloned().collect();
    let reports = args.output.claim("stability", &inputs)?;
    let photo = match &args.image {
        Some(path) => NamedPlane::read(path)?,
        None => default_photograph("camera.png")?,
    };
    let mut config = StabilityConfig::new(eight_bit(photo.plane.view()));
    if args.quick {
        config.integer_shifts = 1_000;
        config.fractional_shifts = 100;
    }
    let bar = progress_bar(FAMILIES);
    // Its errors are about the photograph (too small): they name the file.
    let report = run_stability(&config, &PeakMeter::default(), |family| {
        bar.set_message(family.to_owned());
        bar.inc(1);
    })
    .map_err(|e| e.in_file(args.image.as_deref().unwrap_or(photo.name.as_ref())))?;
    bar.finish_and_clear();
    let failures = report.failures();
    let mut text = format!(
        "stability: {} checks on {} ({} whole, {} fractional shifts)\n\n",
        report.records.len(),
        photo.name,
        config.integer_shifts,
        config.fractional_shifts
    );
    write!(text, "{}", stability_table(&report.records)).ok();
    writeln!(
        text,
        "\n{} of {} checks passed",
        report.records.len() - failures,
        report.records.len()
    )
    .ok();
    let written = write_stability_reports(&reports, &text, &report)?;
    print(&format!("{text}\n{written}"))?;
    if failures > 0 {
        eprintln!("haarshift: {failures} stability checks failed");
        std::process::exit(1);
    }
    Ok(())
}

/// One row per check: its parameters follow its name.
fn stability_table(records: &[StabilityRecord]) -> Table {
    let mut table = Table::new(["category", "check", "figure", "tolerance", "pass"]);
    let number = |v: Option<f64>| v.map_or_else(|| "error".to_owned(), |v| significant(v, 3));
    for r in records {
        let mut check = r.check.clone();
        if !r.parameters.is_empty() {
            let params: Vec<String> = r
                .parameters
                .iter()
                .map(|(k, v)| {
                    format!(
                        "{k}={}",
                        v.as_str().map_or_else(|| v.to_string(), str::to_owned)
                    )
                })
                .collect();
            write!(check, " ({})", params.join(", ")).ok();
        }
        table.push([
            r.category.to_string(),
            check,
            number(r.figure),
            number(r.tolerance),
            if r.pass { "yes" } else { "NO" }.to_owned(),
        ]);
    }
    table
}

/// CSV and JSON of the records (and `--json`), and the drift plot.
fn write_stability_reports(
    reports: &Reports,
    printed: &str,
    report: &StabilityReport,
) -> Result<String> {
    let mut text = reports.write(printed, &report.records, &[])?;
    let points: Vec<LabeledPoint> = report
        .drift
        .iter()
        .filter(|(_, d)| *d > 0.0)
        .map(|&(k, d)| LabeledPoint {
            label: String::new(),
            x: k as f64,
            y: d,
        })
        .collect();
    if !points.is_empty() {
        let plot = log_log_scatter(
            "f32 against f64: drift of a chain of compact Haar shifts",
            "shifts",
            "max |f32 - f64| / peak",
            &points,
            &points,
        )?;
        writeln!(
            text,
            "wrote {}",
            reports.writer().png("drift", &plot)?.display()
        )
        .ok();
    }
    Ok(text)
}
