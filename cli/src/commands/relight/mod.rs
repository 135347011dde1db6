//! `haarshift relight ...`: all-frequency relighting of meshes under environment maps.
//!
//! One file per subcommand; the flags they share (scene, lighting, material, camera, image)
//! are in [`flags`].

use clap::Subcommand;
use haarshift::Result;

mod flags;
pub mod precompute;

/// Relight meshes under environment maps: precompute, render, reference, animate.
#[derive(Subcommand, Debug)]
pub enum RelightCommand {
    Precompute(precompute::Args),
}

pub fn run(command: RelightCommand) -> Result<()> {
    match command {
        RelightCommand::Precompute(args) => precompute::run(args),
    }
}
