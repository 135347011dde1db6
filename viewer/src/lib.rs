//! The browser viewer of haarshift: drag the lighting, orbit the camera, and watch every
//! method's frame and error as it is computed.
//!
//! `haarshift relight view SCENE.hsr --env ENV` starts a [`Viewer`] on the loopback and prints
//! its address. The page it serves (one HTML file and one script, embedded in the binary: no
//! network at run time) draws the scene's mesh with WebGL2 and the per-vertex radiance the
//! server computes for every view through the library's
//! [`Shader`](haarshift_relight::shade::Shader): the same code, options and numbers as
//! `relight render`, whose command line for the current view the page copies.
//!
//! | module | what it holds |
//! |---|---|
//! | [`server`] | the HTTP and WebSocket server: one session per page |
//! | [`protocol`] | the messages: the page's [`ViewState`](protocol::ViewState), the server's packets |
//! | [`scene`] | the scene cache and environment, loaded once |
//! | [`progress`] | the reference's progress, counted for the page that asked |
//!
//! The viewer answers only its own names, against DNS rebinding (a page of another site
//! pointing its name at the loopback to read the viewer as its own): every request's `Host`
//! must be a name of the address listened on at its port (on the loopback `127.0.0.1:PORT`,
//! `localhost:PORT` or `[::1]:PORT`) or one of
//! [`ViewerOptions::allowed_hosts`](server::ViewerOptions::allowed_hosts)
//! (`relight view --allow-host NAME`, which allows `NAME:PORT`, or `NAME:OTHER` as given),
//! compared case-insensitively, or it is refused with 403 before anything else is looked at.
//! A WebSocket must also come from a page at one of those names (`Origin: http://NAME:PORT`);
//! one without `Origin` is refused.
//!
//! The page's sessions are in `session.rs`: each keeps its own shader (rebuilt when the
//! method, material or budgets change), answers only the newest state queued on its socket,
//! and computes the reference of the error view on a thread of its own.

mod host;
pub mod progress;
pub mod protocol;
pub mod scene;
pub mod server;
mod session;

pub use scene::ViewedScene;
pub use server::{Viewer, ViewerOptions};
