//! `weft view` (and `weft` with no command): the interactive viewer.
//!
//! | file | holds |
//! |---|---|
//! | `window.rs` | winit event loop, renderer + egui drawing, input wiring |
//! | `surface.rs` | the window's wgpu surface: format, size, reconfiguration |
//! | `session.rs` | the simulation side: solvers, clock, grab, live changes, log |
//! | `clock.rs` | fixed simulation step decoupled from the display rate |
//! | `picking.rs`, `grab.rs` | ray–cloth picking; grabbing and dragging through the solver |
//! | `command.rs` | pause, step and reset, as the keys and the panel both ask for them |
//! | `camera.rs` | the camera's framing (F, Home) and following a character |
//! | `character.rs` | the character choices (clip, garment scene, fabrics), applied by reloading |
//! | `labels.rs` | the cloths' labels in the 3-D view and their legend colours |
//! | `input.rs` | key and mouse-button bindings |
//! | `panel.rs` | the egui side panel |
//! | `recording.rs` | `--record`: the MCAP log and its `/interaction` channel |

pub mod camera;
pub mod character;
pub mod clock;
pub mod command;
pub mod grab;
pub mod input;
pub mod labels;
pub mod panel;
pub mod picking;
pub mod recording;
pub mod session;
pub mod surface;
pub mod window;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use anyhow::Context;
use winit::event_loop::EventLoop;

use crate::cli::ViewArgs;
use crate::output::{Named, Output, refuse_clashes};
use crate::run::{EXIT_INTERRUPTED, scene_inputs};
use recording::SessionLog;
use session::{SceneSource, Session};
use weft_sim::Simulation;
use window::{App, WindowConfig};

/// Opens the viewer as `args` say; returns when the window closes.
pub fn view(args: &ViewArgs, stop: Arc<AtomicBool>) -> anyhow::Result<ExitCode> {
    let source = args
        .scene
        .clone()
        .map_or(SceneSource::Default, SceneSource::File);
    let overrides = args.overrides();
    let scene = match source.load(&overrides) {
        Ok(s) => s,
        Err(errors) => {
            for e in &errors.0 {
                eprintln!("error: {e}");
            }
            return Ok(ExitCode::FAILURE);
        }
    };
    // The log may not be an input (the scene, its meshes); an unwritable log, or one another
    // weft is writing, fails before any window opens. It stays a partial file until finished.
    if let Some(record) = &args.record {
        let inputs = match &args.scene {
            Some(file) => scene_inputs(file, &scene),
            None => Vec::new(),
        };
        refuse_clashes(
            &inputs
                .iter()
                .map(|(role, path)| Named { role, path })
                .collect::<Vec<_>>(),
            &[Named {
                role: "--record",
                path: record,
            }],
        )?;
    }
    let file = args.record.as_deref().map(Output::create_log).transpose()?;
    let sim = Simulation::new(scene)?;
    crate::stability::warn(&sim.groups);
    crate::crossing_report::warn_start(&sim);
    let log = file
        .map(|f| {
            SessionLog::new(
                f,
                &sim,
                args.log.options(false),
                args.exit_after_frames.unwrap_or(0),
            )
        })
        .transpose()?;
    let event_loop = match EventLoop::new() {
        Ok(l) => l,
        Err(e) => {
            // Unfinished: its partial file goes, and whatever was at the target stays.
            drop(log);
            anyhow::bail!(
                "cannot open a window: {}\n  \
                 The viewer needs a display (DISPLAY or WAYLAND_DISPLAY); none is usable here.\n  \
                 Use `weft run [SCENE]` to simulate headless (with --out FILE.mcap to log it), \
                 or `weft render` to draw a scene to image files.",
                without_source_location(&e.to_string())
            );
        }
    };
    let mut panel = panel::PanelState {
        scenes: panel::list_scenes(&scenes_dir(args.scene.as_deref())),
        ..Default::default()
    };
    if !panel.scenes.contains(&source) {
        panel.scenes.push(source.clone());
    }
    let mut session = Session::new(sim, source, args.max_steps_per_frame);
    session.log = log;
    let config = WindowConfig {
        size: (args.size.width, args.size.height),
        exit_after_frames: args.exit_after_frames,
        paused: args.paused,
        camera: args.camera.pair(),
    };
    let mut app = App::new(session, config, stop, panel);
    let ran = event_loop.run_app(&mut app);
    // Finish the log on every way out (window closed, q, Ctrl-C, an error).
    let interrupted = app.interrupted;
    let error = app.error.take();
    let rate = app.frame_rate();
    let session = app.session_mut();
    let frames = session.frames;
    let finished = session.finish(interrupted);
    ran.context("the window's event loop failed")?;
    if let Some(e) = error {
        return Err(e);
    }
    finished.context("finishing the MCAP file")?;
    println!("{frames} frames simulated");
    if let Some((drawn, per_second)) = rate {
        println!("{drawn} frames drawn, {per_second:.1} a second");
    }
    if let Some(p) = &args.record {
        let size = std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
        println!("wrote {} ({size} bytes)", p.display());
    }
    Ok(if interrupted {
        ExitCode::from(EXIT_INTERRUPTED)
    } else {
        ExitCode::SUCCESS
    })
}

/// `message` without the "os error at <source file>:<line>: " prefix winit puts on its OS
/// errors: a user has no use for the library's internal source path.
fn without_source_location(message: &str) -> &str {
    message
        .strip_prefix("os error at ")
        .and_then(|rest| {
            // "<file>:<line>: <error>": skip to the text after the line number.
            let (_, after) = rest.split_once(": ")?;
            Some(after)
        })
        .unwrap_or(message)
}

/// Where the panel looks for scenes: beside the opened scene file, else `assets/scenes`.
fn scenes_dir(scene: Option<&Path>) -> PathBuf {
    scene
        .and_then(Path::parent)
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("assets/scenes"), Path::to_path_buf)
}
