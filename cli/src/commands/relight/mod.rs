//! `haarshift relight ...`: all-frequency relighting of meshes under environment maps.
//!
//! One file per subcommand; the flags they share (scene, lighting, material, camera, image)
//! are in [`flags`].

use clap::Subcommand;
use haarshift_relight::Result;

pub mod animate;
pub mod bake;
pub mod error;
pub(crate) mod flags;
pub mod gallery;
pub mod merge;
pub mod precompute;
pub mod reference;
pub mod render;
pub mod scene;
pub mod view;

/// Relight meshes under environment maps: precompute (whole or in shards, merged by merge), render, bake (glTF out), reference, animate, gallery,
/// dynamic scenes of moving objects (scene), the error of renders against a reference, and the
/// interactive viewer in the browser (view).
#[derive(Subcommand, Debug)]
pub enum RelightCommand {
    Precompute(Box<precompute::Args>),
    Merge(Box<merge::Args>),
    Render(Box<render::Args>),
    Bake(Box<bake::Args>),
    Reference(Box<reference::Args>),
    Animate(Box<animate::Args>),
    Gallery(Box<gallery::Args>),
    Scene(Box<scene::Args>),
    Error(Box<error::Args>),
    View(Box<view::Args>),
}

pub fn run(command: RelightCommand) -> Result<()> {
    match command {
        RelightCommand::Precompute(args) => precompute::run(*args),
        RelightCommand::Merge(args) => merge::run(*args),
        RelightCommand::Render(args) => render::run(*args),
        RelightCommand::Bake(args) => bake::run(*args),
        RelightCommand::Reference(args) => reference::run(*args),
        RelightCommand::Animate(args) => animate::run(*args),
        RelightCommand::Gallery(args) => gallery::run(*args),
        RelightCommand::Scene(args) => scene::run(*args),
        RelightCommand::Error(args) => error::run(*args),
        RelightCommand::View(args) => view::run(*args),
    }
}
