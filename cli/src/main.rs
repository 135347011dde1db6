//! `haarshift`: Haar-domain signal processing on image files.
//!
//! This file parses the command line and reports errors; each command lives in
//! [`commands`] and does its work through the `haarshift` library.

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

mod commands;
mod peak;
mod progress;

/// Counts heap use, so that the experiments can report peak memory per run.
#[global_allocator]
static PEAK: peak::PeakAlloc = peak::PeakAlloc;

/// Haar wavelet transforms of images, shifts and rotations computed directly on the
/// coefficients.
#[derive(Parser)]
#[command(name = "haarshift", version, propagate_version = true)]
#[command(after_help = "Run `haarshift <COMMAND> --help` for each command's flags and examples.")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    Transform(commands::transform::Args),
    Inverse(commands::inverse::Args),
    Info(commands::info::Args),
    Rotate(commands::rotate::Args),
    Shift(commands::shift::Args),
    /// Spherical environment maps: rotate a lat-long map
    Sphere {
        #[command(subcommand)]
        command: commands::sphere::SphereCommand,
    },
    /// Relight meshes under environment maps: precompute, render, reference, animate
    Relight {
        #[command(subcommand)]
        command: commands::relight::RelightCommand,
    },
    /// Measure methods against ground truth: rotation cycle, shift chain, sphere, stability
    Experiment {
        #[command(subcommand)]
        command: commands::experiment::ExperimentCommand,
    },
}

/// The command line, parsed. When help may be shown, `relight precompute`'s help gains the
/// line on this machine's ray tracer, which loads Embree to find out; other runs skip that.
fn parse() -> Cli {
    let help = std::env::args_os().any(|a| a == "--help" || a == "-h" || a == "help");
    if !help {
        return Cli::parse();
    }
    let command = Cli::command().mut_subcommand("relight", |relight| {
        relight.mut_subcommand("precompute", |precompute| {
            let after = precompute
                .get_after_help()
                .map(|h| h.to_string())
                .unwrap_or_default();
            let line = commands::relight::precompute::tracer_help();
            precompute.after_help(format!("{line}\n\n{after}"))
        })
    });
    Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit())
}

fn main() -> ExitCode {
    // A bug must still end in one line, not a backtrace.
    std::panic::set_hook(Box::new(|info| {
        eprintln!("haarshift: internal error (please report it): {info}");
    }));
    let cli = parse();
    if matches!(
        &cli.command,
        Command::Relight {
            command: commands::relight::RelightCommand::View(_)
        }
    ) {
        // The viewer's reference reports to the page that asked, not to the terminal.
        haarshift_viewer::progress::PageProgress::install();
    }
    progress::TerminalProgress::install();
    let result = match cli.command {
        Command::Transform(args) => commands::transform::run(args),
        Command::Inverse(args) => commands::inverse::run(args),
        Command::Info(args) => commands::info::run(args),
        Command::Rotate(args) => commands::rotate::run(args),
        Command::Shift(args) => commands::shift::run(args),
        Command::Sphere { command } => commands::sphere::run(command),
        Command::Relight { command } => commands::relight::run(command),
        Command::Experiment { command } => commands::experiment::run(command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The library's message serves every caller; the flag that replaces a file is ours.
        Err(error @ haarshift_relight::Error::Core(haarshift::Error::OutputExists { .. })) => {
            eprintln!("haarshift: {error} (use --force to replace it)");
            ExitCode::FAILURE
        }
        Err(error) => {
            eprintln!("haarshift: {error}");
            ExitCode::FAILURE
        }
    }
}
