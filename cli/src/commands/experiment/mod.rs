//! `haarshift experiment ...`: the error-accumulation experiments, one module per experiment.
//! Each prints its table to stdout and writes CSV, JSON and PNG files into `--out-dir`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use clap::Subcommand;
use haarshift::kernels::{KernelOptions, ShiftMethod};
use haarshift_experiments::journal::Journal;
use haarshift_experiments::kernel_cycle::KernelCycle;
use haarshift_experiments::output::{ReportDir, ReportWriter, write_json};
use haarshift_experiments::plot::{LabeledPoint, log_log_scatter};
use haarshift_experiments::rotation_cycle::{CycleRecord, MemoryMeter};
use haarshift_experiments::table::{Table, significant};
use haarshift_relight::Result;
use serde::Serialize;

use crate::commands::refuse_outputs;

pub mod dynamic;
pub mod relight;
pub mod rotation_cycle;
pub mod shift_chain;
pub mod sphere;
pub mod stability;
pub mod tradeoff;

/// The experiments.
#[derive(Subcommand)]
pub enum ExperimentCommand {
    Dynamic(dynamic::Args),
    Relight(relight::Args),
    RotationCycle(rotation_cycle::Args),
    ShiftChain(shift_chain::Args),
    Sphere(sphere::Args),
    Stability(stability::Args),
    Tradeoff(tradeoff::Args),
}

/// Runs one experiment.
pub fn run(command: ExperimentCommand) -> Result<()> {
    match command {
        ExperimentCommand::Dynamic(args) => dynamic::run_command(args),
        ExperimentCommand::Relight(args) => relight::run_command(args),
        ExperimentCommand::RotationCycle(args) => rotation_cycle::run(args),
        ExperimentCommand::ShiftChain(args) => shift_chain::run(args),
        ExperimentCommand::Sphere(args) => sphere::run(args),
        ExperimentCommand::Stability(args) => stability::run(args),
        ExperimentCommand::Tradeoff(args) => tradeoff::run(args),
    }
}

/// Heap use as the CLI's counting global allocator sees it: the peak since the reset, less
/// what was already allocated at the reset.
#[derive(Default)]
pub struct PeakMeter {
    base: AtomicUsize,
}

impl MemoryMeter for PeakMeter {
    fn reset_peak(&self) {
        crate::PEAK.reset_peak_usage();
        self.base
            .store(crate::PEAK.current_usage(), Ordering::SeqCst);
    }

    fn peak_bytes(&self) -> Option<u64> {
        let base = self.base.load(Ordering::SeqCst);
        Some(crate::PEAK.peak_usage().saturating_sub(base) as u64)
    }
}

/// Flags every experiment has: where the reports go.
#[derive(clap::Args, Debug)]
pub struct OutputFlags {
    /// Also write the records (a JSON list) to this file
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Directory for the reports: CSV, JSON, a Markdown table and PNG plots [default: the
    /// scratch directory `<temp>/haarshift/<experiment>`, which every run overwrites]. In a
    /// directory given here, reports of an earlier run stop the command before it computes
    /// anything, unless --force
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Replace existing report files in --out-dir, and the --json file
    #[arg(long)]
    pub force: bool,
}

impl OutputFlags {
    /// Claims the report directory of `experiment` (the stem of its files) before the work:
    /// refuses existing reports and an existing `--json` file unless `--force`, and any of
    /// them that is one of `inputs`.
    pub fn claim(&self, experiment: &'static str, inputs: &[PathBuf]) -> Result<Reports> {
        let dir = match &self.out_dir {
            Some(dir) => ReportDir::new(dir, self.force),
            None => ReportDir::scratch(experiment),
        };
        let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        dir.claim(experiment, &inputs)?;
        if let Some(json) = &self.json {
            refuse_outputs(&inputs, &[json], self.force)?;
        }
        Ok(Reports {
            dir,
            stem: experiment,
            json: self.json.clone(),
            force: self.force,
        })
    }
}

/// Ends a run whose reports are written: removes its journal, saying how much of the run it
/// gave back.
pub fn finish_journal(journal: Journal) -> Result<()> {
    let resumed = journal.resumed();
    journal.finish()?;
    if resumed > 0 {
        eprintln!("resumed: {resumed} units of work taken from the journal");
    }
    Ok(())
}

/// Where a claimed experiment writes: its directory, the stem of its files, `--json`.
pub struct Reports {
    /// The claimed directory.
    pub dir: ReportDir,
    /// The experiment's file stem.
    pub stem: &'static str,
    json: Option<PathBuf>,
    force: bool,
}

impl Reports {
    /// `DIR/<stem>.journal`.
    pub fn journal_path(&self) -> PathBuf {
        self.dir.path().join(format!("{}.journal", self.stem))
    }

    /// The run's journal, `DIR/<stem>.journal`: the stopped run's with `resume`; else a new
    /// one, replacing a stopped run's only under `--force`.
    pub fn journal(&self, options: &str, resume: bool) -> Result<Journal> {
        let path = self.journal_path();
        if resume {
            return Journal::resume(&path, options);
        }
        Journal::create(&path, options, self.dir.force()).map_err(|e| match e {
            haarshift_relight::Error::Core(haarshift::Error::OutputExists { path }) => {
                haarshift_relight::Error::from(haarshift::Error::Format {
                    path,
                    reason: "holds the measurements of a stopped run: --resume goes on with it, \
                         --force starts again"
                        .into(),
                })
            }
            e => e,
        })
    }

    /// The writer of the experiment's main files (`<stem>.*`).
    pub fn writer(&self) -> ReportWriter {
        self.dir.writer(self.stem)
    }

    /// Writes `records` as CSV and JSON, `report` (the printed header and table) as Markdown,
    /// `points` as the RMS-against-time plot, and `--json`; returns the lines naming the
    /// files.
    pub fn write<R: Serialize>(
        &self,
        report: &str,
        records: &[R],
        points: &[LabeledPoint],
    ) -> Result<String> {
        let writer = self.writer();
        let mut written = vec![
            writer.csv(records)?,
            writer.json(records)?,
            writer.markdown(&markdown_report(self.stem, report))?,
        ];
        if !points.is_empty() {
            let plot = log_log_scatter(
                &format!("{}: RMS against time", self.stem),
                "seconds",
                "RMS",
                points,
                &[],
            )?;
            written.push(writer.png("rms-time", &plot)?);
        }
        written.extend(self.write_json_flag(records)?);
        Ok(wrote(&written))
    }

    /// Writes `records` to the `--json` file, if one was given, and returns its path.
    pub fn write_json_flag<R: Serialize>(&self, records: &[R]) -> Result<Option<PathBuf>> {
        let Some(path) = &self.json else {
            return Ok(None);
        };
        write_json(path, records, self.force)?;
        Ok(Some(path.clone()))
    }
}

/// The Markdown file of a report: the command that made it, the printed header as a text
/// block, then the table (every line starting with `|`).
pub fn markdown_report(stem: &str, report: &str) -> String {
    let command: Vec<String> = std::env::args().skip(1).collect();
    let (table, header): (Vec<&str>, Vec<&str>) = report.lines().partition(|l| l.starts_with('|'));
    let header = header.join("\n");
    format!(
        "# {stem}\n\nWritten by `haarshift {}`.\n\n```text\n{}\n```\n\n{}\n",
        command.join(" "),
        header.trim(),
        table.join("\n")
    )
}

/// `wrote PATH` lines for the files written.
pub fn wrote(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| format!("wrote {}\n", p.display()))
        .collect()
}

/// The methods to compare and their parameters.
#[derive(clap::Args, Debug)]
pub struct MethodFlags {
    /// Comma-separated kernels: nearest, linear, keys, bspline3, bspline5, lanczos3, lanczos4,
    /// fft, haar (both modes), haar-compact, haar-retained [default: all, haar in both modes]
    #[arg(long, value_name = "LIST")]
    pub methods: Option<String>,
    /// Compact Haar precision h: shifts rounded to the 1/2^h grid
    #[arg(long, value_name = "H", default_value_t = 3)]
    pub precision: u32,
    /// Retained Haar precision h: a 2^h-finer grid kept across the whole experiment. The
    /// default is 1 to keep the default run within two minutes: at h = 3 a 512x512 image
    /// rotates on an 8192x8192 grid (minutes and gigabytes); ask for it explicitly
    #[arg(long, value_name = "H", default_value_t = 1)]
    pub retained_precision: u32,
}

impl MethodFlags {
    /// The methods, each rotating on a `2^supersample`-finer grid.
    pub fn methods(&self, supersample: u32) -> Result<Vec<KernelCycle>> {
        parse_methods(
            self.methods.as_deref(),
            self.precision,
            self.retained_precision,
            supersample,
        )
    }

    /// The parameter line printed with the results.
    pub fn describe(&self) -> String {
        format!(
            "compact haar precision h = {}, retained haar precision h = {}",
            self.precision, self.retained_precision
        )
    }
}

/// Parses `--methods`: kernel names separated by commas; `haar` means both Haar modes,
/// `haar-compact` and `haar-retained` one of them. Empty: every kernel, Haar in both modes.
/// Compact Haar runs at `precision`, retained Haar at `retained_precision`.
pub fn parse_methods(
    list: Option<&str>,
    precision: u32,
    retained_precision: u32,
    supersample: u32,
) -> Result<Vec<KernelCycle>> {
    let options = KernelOptions {
        precision,
        ..Default::default()
    };
    let haar = |retain| {
        let precision = if retain {
            retained_precision
        } else {
            precision
        };
        let options = KernelOptions {
            precision,
            retain,
            ..options
        };
        KernelCycle::new(ShiftMethod::Haar, options, supersample)
    };
    let Some(list) = list else {
        let mut all = KernelCycle::every_kernel(options, supersample);
        all.retain(|m| m.method != ShiftMethod::Haar);
        all.extend([haar(false), haar(true)]);
        return Ok(all);
    };
    let mut methods = Vec::new();
    for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        match name {
            "haar" => methods.extend([haar(false), haar(true)]),
            "haar-compact" => methods.push(haar(false)),
            "haar-retained" => methods.push(haar(true)),
            other => methods.push(KernelCycle::new(other.parse()?, options, supersample)),
        }
    }
    if methods.is_empty() {
        return Err(haarshift_relight::Error::from(
            haarshift::Error::InvalidParameter {
                name: "methods",
                reason: "the list is empty".into(),
            },
        ));
    }
    Ok(methods)
}

/// The rotation-cycle records as a table: one row per image and method.
pub fn cycle_table(records: &[CycleRecord]) -> Table {
    let mut table = Table::new([
        "image",
        "method",
        "rms",
        "psnr",
        "max_error",
        "seconds",
        "peak_MB",
    ]);
    for r in records {
        table.push([
            r.image.clone(),
            r.method.label(),
            significant(r.rms, 3),
            significant(r.psnr, 4),
            significant(r.max_error, 3),
            significant(r.seconds, 2),
            peak_megabytes(r.peak_bytes),
        ]);
    }
    table
}

/// A peak heap figure for a table: megabytes to 3 digits, blank when not measured.
pub fn peak_megabytes(bytes: Option<u64>) -> String {
    bytes.map_or_else(String::new, |b| significant(b as f64 / 1e6, 3))
}
