//! `haarshift experiment ...`: measurements of error and cost, written as a table, CSV, JSON
//! and plots.

use clap::Subcommand;
use haarshift::Result;

pub mod sphere;

/// Experiments that compare methods against ground truth.
#[derive(Subcommand, Debug)]
pub enum ExperimentCommand {
    Sphere(sphere::Args),
}

pub fn run(command: ExperimentCommand) -> Result<()> {
    match command {
        ExperimentCommand::Sphere(args) => sphere::run(args),
    }
}
