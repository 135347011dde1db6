//! `haarshift experiment rotation-cycle`: Alnasser 2008's Table 2.2 protocol.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use haarshift_experiments::kernel_cycle::{
    KernelCycle, NamedPlane, default_images, run_rotation_cycle,
};
use haarshift_experiments::plot::{LabeledPoint, labelled_tiles};
use haarshift_experiments::rotation_cycle::{CycleRecord, CycleRun, PROTOCOL};
use haarshift_experiments::table::significant;
use haarshift_relight::Result;
use ndarray::{Array2, ArrayView2, s};

use super::{MethodFlags, OutputFlags, PeakMeter, Reports, cycle_table, wrote};
use crate::commands::print;
use crate::progress::progress_bar;

const ABOUT: &str = "\
Protocol (fixed, printed with the results): luma 0.2125R+0.7154G+0.0721B on the stored values;
centred square crop of side m = min(width, height); zero-pad by floor(m/2) on every side;
rotate STEPS times by 360/STEPS degrees about the canvas centre (canvas same, fill 0); RMS,
PSNR (peak 255) and max error over the pixel centres within m/2 - 2 of the centre. Wall time
and peak heap are measured per run, one run at a time.

Default images (no IMAGES given): the six photographs embedded in haarshift (astronaut, brick,
camera, chelsea, coins, text: testdata/*.png) at their full size, plus a 300x200 zone plate
and a 256x256 Siemens star (32 spokes) generated in code.
Default methods (no --methods): every kernel (nearest, linear, keys, bspline3, bspline5,
lanczos3, lanczos4, fft) and haar in both modes: compact at --precision (default 3) and
retained at --retained-precision (default 1: h = 3 on the 512x512 photographs takes minutes).

Reports: DIR/rotation-cycle.csv, .json and .md (the table), DIR/rotation-cycle-rms-time.png and,
with --crops, DIR/rotation-cycle-crops-IMAGE.png.

Examples:
  haarshift experiment rotation-cycle
  haarshift experiment rotation-cycle testdata/camera.png --methods fft,haar --precision 2 --crops
  haarshift experiment rotation-cycle --methods fft --supersample 1 --json fft.json
  haarshift experiment rotation-cycle --out-dir results/rotation-cycle --force";

/// Rotate images STEPS times by 360/STEPS degrees and measure what the round trip lost.
#[derive(clap::Args, Debug)]
#[command(after_help = ABOUT)]
pub struct Args {
    /// Images to use [default: the embedded photographs and two synthetic patterns]
    pub images: Vec<PathBuf>,
    /// Also write, per image, the centred crop before and after the cycle with every method
    /// side by side (enlarged 2x by pixel replication)
    #[arg(long)]
    pub crops: bool,
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
    let reports = args.output.claim("rotation-cycle", &args.images)?;
    let methods = args.methods.methods(args.supersample)?;
    let images = load_images(&args.images)?;
    let mut crops = CropSheets::new(args.crops);
    let records = run_methods(&images, &methods, args.steps as usize, |run| crops.add(run))?;
    let mut text = format!(
        "rotation cycle: {} rotations of {} degrees\nprotocol: {PROTOCOL}\nparameters: {}, supersample S = {}\n\n",
        args.steps,
        360.0 / f64::from(args.steps),
        args.methods.describe(),
        args.supersample,
    );
    write!(text, "{}", cycle_table(&records)).ok();
    let mut written = cycle_reports(&reports, &text, &records)?;
    written.push_str(&crops.write(&reports)?);
    print(&format!("{text}\n{written}"))
}

/// The named images, or the default set.
pub fn load_images(paths: &[PathBuf]) -> Result<Vec<NamedPlane>> {
    if paths.is_empty() {
        return Ok(default_images()?);
    }
    Ok(paths
        .iter()
        .map(|p| NamedPlane::read(p))
        .collect::<haarshift::Result<_>>()?)
}

/// Runs every method on every image with a progress bar; `each` sees every run.
pub fn run_methods(
    images: &[NamedPlane],
    methods: &[KernelCycle],
    steps: usize,
    mut each: impl FnMut(&CycleRun),
) -> Result<Vec<CycleRecord>> {
    let bar = progress_bar(images.len() * methods.len());
    let records = run_rotation_cycle(images, methods, steps, &PeakMeter::default(), |run| {
        bar.set_message(format!(
            "{} {}",
            run.record.image,
            run.record.method.label()
        ));
        bar.inc(1);
        each(run);
    })?;
    bar.finish_and_clear();
    Ok(records)
}

/// Side of the crop shown in the figures: Alnasser 2008's Figs. 2.4-2.5 show a detail, not the
/// whole image.
const CROP_SIDE: usize = 128;

/// Tiles of a figure, each with its label.
type LabelledTiles = Vec<(String, Array2<f64>)>;

/// The `--crops` figures: per image, the centred crop before the cycle and after it with
/// every method.
struct CropSheets {
    enabled: bool,
    /// Per image: its name and the labelled tiles, the original first.
    sheets: Vec<(String, LabelledTiles)>,
}

impl CropSheets {
    fn new(enabled: bool) -> Self {
        CropSheets {
            enabled,
            sheets: Vec::new(),
        }
    }

    fn add(&mut self, run: &CycleRun) {
        if !self.enabled {
            return;
        }
        let crop = |plane: &Array2<f64>| {
            let side = CROP_SIDE.min(run.record.crop);
            let top = (plane.nrows() - side) / 2;
            let left = (plane.ncols() - side) / 2;
            plane
                .slice(s![top..top + side, left..left + side])
                .to_owned()
        };
        let image = &run.record.image;
        if self.sheets.last().is_none_or(|(name, _)| name != image) {
            self.sheets
                .push((image.clone(), vec![("original".into(), crop(&run.canvas))]));
        }
        if let Some((_, tiles)) = self.sheets.last_mut() {
            let label = format!(
                "{} (rms {})",
                run.record.method.label(),
                significant(run.record.rms, 3)
            );
            tiles.push((label, crop(&run.result)));
        }
    }

    /// Writes one PNG per image; returns the lines naming them.
    fn write(&self, reports: &Reports) -> Result<String> {
        let writer = reports.writer();
        let mut written = Vec::new();
        for (image, tiles) in &self.sheets {
            let views: Vec<(String, ArrayView2<'_, f64>)> =
                tiles.iter().map(|(l, t)| (l.clone(), t.view())).collect();
            let sheet = labelled_tiles(&views, 4, 2)?;
            let name = Path::new(image)
                .file_stem()
                .map_or_else(|| image.clone(), |s| s.to_string_lossy().into_owned());
            written.push(writer.png(&format!("crops-{name}"), &sheet)?);
        }
        Ok(if written.is_empty() {
            String::new()
        } else {
            wrote(&written)
        })
    }
}

/// Writes the reports of a rotation-cycle run (`report`: the printed header and table);
/// returns the lines naming the files.
pub fn cycle_reports(reports: &Reports, report: &str, records: &[CycleRecord]) -> Result<String> {
    let points: Vec<LabeledPoint> = records
        .iter()
        .filter(|r| r.rms > 0.0 && r.seconds > 0.0)
        .map(|r| LabeledPoint {
            label: r.method.label(),
            x: r.seconds,
            y: r.rms,
        })
        .collect();
    reports.write(report, records, &points)
}
