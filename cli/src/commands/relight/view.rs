//! `haarshift relight view`: the scene in the browser, relit as the lighting is dragged.

use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;

use haarshift_relight::Result;
use haarshift_relight::dynamic::DynamicScene;
use haarshift_viewer::{ViewedScene, Viewer, ViewerOptions};

use super::flags::{DynamicFlags, LightFlags};
use crate::commands::print;

const HELP: &str = "\
Starts a local server and prints the page's address: the page draws the scene (WebGL2) with
the radiance computed by the same shaders as relight render, frame after frame, as the
lighting is dragged (any angle), the camera orbited and zoomed, and the basis, material and
budgets changed. The error view computes the reference (ray cast) in the background and
shows each vertex's error in false colour. The page copies the relight render command of its
view, saves it as PNG, and keeps its view in the URL. Nothing is fetched from the network;
the server listens on 127.0.0.1 unless --host says otherwise, and serves each page (up to
--max-sessions) a session of its own.

Against DNS rebinding (another site's page pointing its own name at this address), the
server answers a request only when its Host is a name of the address listened on, at its
port (on 127.0.0.1: 127.0.0.1:PORT, localhost:PORT or [::1]:PORT), or one given with
--allow-host; anything else gets 403. With --host 0.0.0.0, name the machine's names and
addresses the pages use with --allow-host.

A scene file (SCENE.json, as relight scene takes it) is built into occlusion fields first
(or its fields loaded from --fields-dir): the page then moves its objects (drag with the
object chosen) and plays --animate's motion path, each frame occlusion fields and Haar
product integrals as relight scene computes them; the error view ray-casts the placed scene.

Examples:
  haarshift relight view bunny.hsr --env testdata/envmaps/rooitou_park_1k.hdr
  haarshift relight view cubes.hsr --env park.hdr --port 9000 --open
  haarshift relight view bunny.hsr --env park.hdr --yaw 120 --port 0   (any free port)
  haarshift relight view bunny.hsr --env park.hdr --results results/relight/experiments
  haarshift relight view bunny.hsr --env park.hdr --host 0.0.0.0 --allow-host viewer.lan --allow-host 192.168.1.5
  haarshift relight view bunny.hsr --env park.hdr --merl gold-metallic-paint.binary   (merl:gold-metallic-paint on the page)
  haarshift relight view testdata/scenes/bunny_and_ball.json --animate testdata/scenes/ball_path.json";

/// Serve a precomputed or dynamic scene to the browser and relight it interactively.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    /// The scene cache (`relight precompute ... -o SCENE.hsr`), or a scene file whose objects
    /// the page moves (SCENE.json, built as `relight scene` builds it)
    #[arg(value_name = "SCENE.hsr|SCENE.json")]
    pub scene: PathBuf,

    /// A scene file's motion path (`relight scene --animate`'s), played by the page
    #[arg(long, value_name = "PATH.json")]
    pub animate: Option<PathBuf>,

    #[command(flatten)]
    pub dynamic: DynamicFlags,

    #[command(flatten)]
    pub light: LightFlags,

    /// A measured BRDF (MERL table) the page offers as a material, named by its file stem;
    /// repeat for more (a scene cache only)
    #[arg(long, value_name = "FILE")]
    pub merl: Vec<PathBuf>,

    /// The port to listen on; 0 takes a free one
    #[arg(long, value_name = "P", default_value_t = 8765)]
    pub port: u16,

    /// The address to listen on (another than 127.0.0.1 serves the network: the viewer has
    /// no authentication)
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1")]
    pub host: IpAddr,

    /// Another name the page is reached by (Host), answered besides the address's own: NAME at
    /// --port, or NAME:PORT as given (a proxy's port); repeat for more. Needed with --host
    /// 0.0.0.0
    #[arg(long = "allow-host", value_name = "NAME")]
    pub allow_host: Vec<String>,

    /// Pages served at once, each a session of its own; one more is refused in one line
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub max_sessions: usize,

    /// An `experiment relight` output directory to serve at /results: its records, picture grids
    /// and plots side by side, with an error/time plot marking the method clicked
    #[arg(long, value_name = "DIR")]
    pub results: Option<PathBuf>,

    /// Open the page in the desktop's browser (xdg-open, open)
    #[arg(long)]
    pub open: bool,
}

pub fn run(args: Args) -> Result<()> {
    let is_json = args
        .scene
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let scene = if is_json {
        let options = args.dynamic.options()?;
        let mut store = args.dynamic.field_store(false)?;
        let built = DynamicScene::load_with(&args.scene, &options, store.as_mut())?;
        ViewedScene::dynamic(
            built,
            &args.scene,
            args.animate.as_deref(),
            &args.light.spec(),
        )?
    } else {
        for (flag, given) in [
            ("animate", args.animate.is_some()),
            ("fields-dir", args.dynamic.fields_dir.is_some()),
        ] {
            if given {
                return Err(haarshift_relight::Error::from(
                    haarshift::Error::InvalidParameter {
                        name: flag,
                        reason: format!(
                            "--{flag} applies to a scene file (SCENE.json); {} is a scene cache",
                            args.scene.display()
                        ),
                    },
                ));
            }
        }
        ViewedScene::load(&args.scene, &args.light.spec())?
    }
    .with_measured(&args.merl)?;
    let viewer = Viewer::bind(
        scene,
        ViewerOptions {
            address: SocketAddr::new(args.host, args.port),
            max_sessions: args.max_sessions,
            results: args.results.clone(),
            allowed_hosts: args.allow_host.clone(),
        },
    )?;
    let url = viewer.url();
    print(&format!("haarshift viewer: {url} (Ctrl-C stops it)\n"))?;
    if args.results.is_some() {
        print(&format!("the experiment's results: {url}results\n"))?;
    }
    if args.open {
        open_in_browser(&url);
    }
    viewer.serve();
    Ok(())
}

/// Asks the desktop to open `url`; a failure is said, not fatal (the address is printed).
fn open_in_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else {
        "xdg-open"
    };
    if std::process::Command::new(opener).arg(url).spawn().is_err() {
        eprintln!("haarshift: could not run {opener}: open {url} by hand");
    }
}
