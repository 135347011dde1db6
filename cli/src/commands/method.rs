//! The `--method` flags shared by `rotate` and `shift`: which 1D shift kernel, and its
//! parameters.

use haarshift::kernels::{KernelOptions, ShiftMethod};
use haarshift_relight::Result;

use super::{choice, names};

/// The kernel and its parameters; each command picks its own default method.
#[derive(clap::Args, Debug)]
pub struct MethodFlags {
    /// Shift kernel: `nearest`, `linear`, `keys` (cubic convolution), `bspline3`/`bspline5`
    /// (interpolating B-splines, exact prefilter), `lanczos3`/`lanczos4` (normalised windowed
    /// sinc), `fft` (band-limited phase shift), `haar` (shift in the Haar domain with
    /// precision 1/2^H) [default: bspline3 for rotate, haar for shift]
    #[arg(long, value_parser = choice::<ShiftMethod>(names!(ShiftMethod)))]
    pub method: Option<ShiftMethod>,

    /// Haar only: shifts are rounded to 1/2^H pixel (0 = whole pixels) [default: 3]
    #[arg(long, value_name = "H")]
    pub precision: Option<u32>,

    /// Haar only: keep the H extra levels (a 2^H-finer grid) instead of projecting back to
    /// the original levels after every shift
    #[arg(long)]
    pub retain: bool,

    /// Keys only: the cubic convolution parameter a [default: -0.5]
    #[arg(long, value_name = "A", allow_negative_numbers = true)]
    pub keys_a: Option<f64>,
}

impl MethodFlags {
    /// The method (`default` when none was given) and its options; refuses parameters that
    /// the method does not have, so that a flag is never silently ignored.
    pub fn resolve(&self, default: ShiftMethod) -> Result<(ShiftMethod, KernelOptions)> {
        let method = self.method.unwrap_or(default);
        let options = KernelOptions::for_method(method, self.precision, self.retain, self.keys_a)?;
        Ok((method, options))
    }
}
