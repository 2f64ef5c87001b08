//! The command line.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use weft_record::{Channels, Compression, Precision, RecordOptions};
use weft_scene::Override;
use weft_solver::Method;

use crate::limits::LimitArgs;

/// Real-time cloth simulation with XPBD, PBD, mass-spring and implicit mass-spring.
///
/// With no command, opens the interactive viewer on the built-in default scene
/// (assets/scenes/hanging.toml); `weft run` runs scenes headless.
#[derive(Debug, Parser)]
#[command(version, about, args_conflicts_with_subcommands = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Options of the viewer (the default command).
    #[command(flatten)]
    pub view: ViewArgs,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene headless, optionally logging every frame to MCAP.
    Run(RunArgs),
    /// Validate a scene file (and overrides) without running it.
    Check(CheckArgs),
    /// Re-run a logged run from its MCAP alone (scene, overrides and meshes are in the log).
    Replay(ReplayArgs),
    /// Run an experiments file: a queue of runs, a summary table and plots.
    Experiments(ExperimentArgs),
    /// Open a scene in the interactive viewer (the default command).
    View(ViewArgs),
    /// Render a scene offscreen: PNG frames, an animated GIF and (with ffmpeg) an MP4.
    Render(RenderArgs),
    /// Rebuild a valid log from one cut short (killed, power cut): every complete chunk's
    /// messages, the scene attachments and metadata, and status `recovered`.
    Recover(RecoverArgs),
    /// Export a log's cloth and colliders for other tools: an OBJ sequence or an animated
    /// glTF binary (GLB) that Blender imports.
    Export(ExportArgs),
    /// Turn a textile lab's measurements into a material table for a scene, and check it on
    /// the virtual cantilever (ASTM D1388).
    Fabric(FabricArgs),
}

/// `weft fabric`.
#[derive(Debug, Args)]
pub struct FabricArgs {
    /// Areal weight (g/m²).
    #[arg(long, allow_negative_numbers = true)]
    pub weight: f64,
    /// Cantilever bending length c along the warp (cm): half the overhang at which the strip
    /// reaches ASTM D1388's 41.5° plane.
    #[arg(long, allow_negative_numbers = true)]
    pub bending_length_warp: f64,
    /// Cantilever bending length along the weft (cm; default: the warp's).
    #[arg(long, allow_negative_numbers = true)]
    pub bending_length_weft: Option<f64>,
    /// Extension along the warp at `--load` (%).
    #[arg(long, allow_negative_numbers = true)]
    pub extension_warp: f64,
    /// Extension along the weft at `--load` (%; default: the warp's).
    #[arg(long, allow_negative_numbers = true)]
    pub extension_weft: Option<f64>,
    /// The tensile load of the extensions per unit width (N/m; default KES-F's 500 gf/cm).
    #[arg(long, allow_negative_numbers = true, default_value_t = weft_solver::KES_LOAD)]
    pub load: f64,
    /// In-plane shear stiffness (N/m; default 56, a shirting's KES-F G of 1 gf/(cm·deg)).
    #[arg(long, allow_negative_numbers = true, default_value_t = 56.0)]
    pub shear: f64,
    /// The method the virtual cantilever runs, at its defaults.
    #[arg(long, default_value = "xpbd")]
    pub method: Method,
    /// Cells along the virtual strip's overhang.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub segments: u32,
    /// Print the material without running the virtual cantilever.
    #[arg(long)]
    pub no_check: bool,
}

/// What `weft export` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// One Wavefront OBJ per frame: `frame_00000.obj`, …
    Obj,
    /// One animated glTF binary, `<log stem>.glb`: the cloth animated by morph targets, the
    /// colliders by their node transforms.
    Glb,
}

/// How a GLB's animation goes from one exported frame to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Interpolation {
    /// Blend linearly (positions and translations; rotations by slerp).
    Linear,
    /// Hold each frame until the next.
    Step,
}

impl Interpolation {
    /// The name glTF gives it.
    pub fn gltf(self) -> &'static str {
        match self {
            Interpolation::Linear => "LINEAR",
            Interpolation::Step => "STEP",
        }
    }
}

/// `weft export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// A log written by `weft run --out` (or `weft view --record`).
    pub log: PathBuf,
    /// What to write.
    #[arg(long, value_enum)]
    pub format: ExportFormat,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Logged frames to export: `A..B` (B excluded), `A..=B`, `A..` or `..B` (default: all).
    #[arg(long, value_name = "RANGE", value_parser = FrameRange::parse)]
    pub frames: Option<FrameRange>,
    /// Export every N-th of those frames, starting with the first.
    #[arg(long, default_value_t = 1, value_name = "N",
          value_parser = clap::value_parser!(u64).range(1..))]
    pub every: u64,
    /// GLB: how the animation goes between exported frames.
    #[arg(long, value_enum, default_value_t = Interpolation::Linear)]
    pub interpolation: Interpolation,
    /// No summary line.
    #[arg(long, short)]
    pub quiet: bool,
    /// Memory and file-size limits (the memory the export needs is estimated first).
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `weft recover`.
#[derive(Debug, Args)]
pub struct RecoverArgs {
    /// The damaged log (e.g. `run.partial-4242-0.mcap`, left by a killed run).
    pub log: PathBuf,
    /// Where to write the recovered log.
    #[arg(long)]
    pub out: PathBuf,
}

/// `weft run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scene file (default: the built-in hanging cloth).
    pub scene: Option<PathBuf>,
    /// Frames to simulate.
    #[arg(long, default_value_t = 300)]
    pub frames: u64,
    /// MCAP file to write.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override a scene key: `--set sim.substeps=20` (repeatable; values are TOML, else strings).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<Override>,
    /// Shorthand for `--set sim.method=…` (xpbd, pbd, mass-spring or implicit-mass-spring).
    #[arg(long)]
    pub method: Option<Method>,
    /// Write every cloth's final positions (as float32) to this JSON file.
    #[arg(long, value_name = "FILE.json")]
    pub dump_final: Option<PathBuf>,
    /// What the log carries.
    #[command(flatten)]
    pub log: LogArgs,
    /// Add wall-clock step time and the wait for the log to /stats (the file is then no
    /// longer reproducible byte for byte).
    #[arg(long)]
    pub timing: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Exit with an error, running nothing, when a cloth's explicit springs are past their
    /// stability limit (the warning `weft check` prints).
    #[arg(long)]
    pub strict: bool,
    /// Memory and file-size limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

impl RunArgs {
    /// The overrides, `--method` first.
    pub fn overrides(&self) -> Vec<Override> {
        overrides(self.method, &self.set)
    }
}

/// `--method` as an override, followed by the `--set` ones.
fn overrides(method: Option<Method>, set: &[Override]) -> Vec<Override> {
    let mut v: Vec<Override> = method
        .map(|m| Override {
            key: "sim.method".into(),
            value: format!("\"{}\"", m.name()),
        })
        .into_iter()
        .collect();
    v.extend(set.iter().cloned());
    v
}

/// Where the camera stands and looks (`weft view`, `weft render`): both or neither.
#[derive(Debug, Args)]
pub struct CameraArgs {
    /// Camera position `X,Y,Z` (m) instead of the automatic framing (with --target).
    #[arg(
        long,
        value_name = "X,Y,Z",
        requires = "target",
        allow_hyphen_values = true
    )]
    pub eye: Option<Point>,
    /// Point the camera looks at, `X,Y,Z` (m) (with --eye).
    #[arg(
        long,
        value_name = "X,Y,Z",
        requires = "eye",
        allow_hyphen_values = true
    )]
    pub target: Option<Point>,
}

impl CameraArgs {
    /// `(eye, target)` when both were given.
    pub fn pair(&self) -> Option<(glam::Vec3, glam::Vec3)> {
        self.eye
            .zip(self.target)
            .map(|(e, t)| (glam::Vec3::from(e.0), glam::Vec3::from(t.0)))
    }
}

/// What a log carries (`weft run --out`, `weft view --record`).
#[derive(Debug, Args)]
pub struct LogArgs {
    /// What the log carries of each cloth: `particles` (positions), `surface` (the triangle
    /// list Foxglove draws) or `all` (both; the surface every --mesh-every frames).
    #[arg(long = "log", default_value = "particles", value_name = "CHANNELS")]
    pub channels: Channels,
    /// Log every N-th frame (and the last one).
    #[arg(long, default_value_t = 1, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub every: u64,
    /// Log the cloth surface every N frames with `--log all` (0: never).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub mesh_every: u64,
    /// Particle positions as `f32` (within 2^-24 of each coordinate) or `f16` (half the
    /// bytes, within 2^-11: 0.49 mm at 1 m from the origin; Foxglove cannot draw them).
    #[arg(long, default_value = "f32", value_name = "PRECISION")]
    pub precision: Precision,
    /// Chunk compression: `none` (keeps pace with the solver) or `zstd` (about half the
    /// bytes, on one worker per core).
    #[arg(long, default_value = "none", value_name = "KIND")]
    pub compression: Compression,
}

impl LogArgs {
    /// The recorder's options, `timing` as asked.
    pub fn options(&self, timing: bool) -> RecordOptions {
        RecordOptions {
            channels: self.channels,
            every: self.every,
            mesh_every: self.mesh_every,
            precision: self.precision,
            compression: self.compression,
            timing,
        }
    }
}

/// `weft view` (and `weft` with no command).
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Scene file (default: the built-in hanging cloth).
    pub scene: Option<PathBuf>,
    /// Override a scene key: `--set sim.substeps=20` (repeatable; values are TOML, else strings).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<Override>,
    /// Shorthand for `--set sim.method=…` (xpbd, pbd, mass-spring or implicit-mass-spring).
    #[arg(long)]
    pub method: Option<Method>,
    /// Log the session to this MCAP file (as `weft run --out`, plus an `/interaction` channel).
    #[arg(long, value_name = "FILE.mcap")]
    pub record: Option<PathBuf>,
    /// What the log of --record carries.
    #[command(flatten)]
    pub log: LogArgs,
    /// Window size in pixels.
    #[arg(long, default_value = "1280x800", value_name = "WxH")]
    pub size: WindowSize,
    /// Quit cleanly after this many simulated frames (for tests and scripts).
    #[arg(long, value_name = "N")]
    pub exit_after_frames: Option<u64>,
    /// Start paused (Space resumes).
    #[arg(long)]
    pub paused: bool,
    /// The camera, instead of the automatic framing.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// At most this many simulation frames per displayed frame; real time beyond is dropped.
    #[arg(long, default_value_t = 4, value_name = "K")]
    pub max_steps_per_frame: u32,
}

impl ViewArgs {
    /// The overrides, `--method` first.
    pub fn overrides(&self) -> Vec<Override> {
        overrides(self.method, &self.set)
    }
}

/// A point `X,Y,Z` in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point(pub [f32; 3]);

impl std::str::FromStr for Point {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let v: Vec<f32> = s
            .split(',')
            .map(|c| c.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("expected X,Y,Z in metres, got {s:?}: {e}"))?;
        match v[..] {
            [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Self([x, y, z])),
            _ => Err(format!("expected three finite numbers X,Y,Z, got {s:?}")),
        }
    }
}

/// A window size `WxH` in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WindowSize {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

impl std::str::FromStr for WindowSize {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("expected WIDTHxHEIGHT in pixels (e.g. 1280x800), got {s:?}");
        let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
        let parse = |v: &str| {
            v.trim()
                .parse::<u32>()
                .ok()
                .filter(|&n| (64..=16384).contains(&n))
        };
        match (parse(w), parse(h)) {
            (Some(width), Some(height)) => Ok(Self { width, height }),
            _ => Err(format!("{}; each side in 64..=16384", bad())),
        }
    }
}

/// `weft check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Scene file.
    pub scene: PathBuf,
    /// Overrides to validate with the file.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<Override>,
    /// Shorthand for `--set sim.method=…` (xpbd, pbd, mass-spring or implicit-mass-spring).
    #[arg(long)]
    pub method: Option<Method>,
    /// Print the scene as it will run, as TOML with every default filled in (each cloth's
    /// method, grid, mass, thickness and 36 constraint-family keys), instead of the summary.
    #[arg(long)]
    pub explain: bool,
    /// Memory and file-size limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

impl CheckArgs {
    /// The overrides, `--method` first.
    pub fn overrides(&self) -> Vec<Override> {
        overrides(self.method, &self.set)
    }
}

/// `weft replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// A log written by `weft run --out`.
    pub log: PathBuf,
    /// Where to write the re-run (default: `<log>.replay.mcap`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Memory and file-size limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `weft experiments`.
#[derive(Debug, Args)]
pub struct ExperimentArgs {
    /// Experiments file.
    pub file: PathBuf,
    /// Output directory (default: `experiments-out/<file stem>`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run only every N-th run starting at K (`K/N`, K in 0..N), for batch schedulers.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Parallel runs, at least 1 (default: the number of cores; more than four per core is
    /// cut to that, with a message).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub jobs: Option<u32>,
    /// Skip writing one MCAP per run.
    #[arg(long)]
    pub no_mcap: bool,
    /// Only rebuild the summary and plots from the results already in the output directory
    /// (e.g. after every shard of a batch job has finished).
    #[arg(long)]
    pub report_only: bool,
    /// Also render each run (PNG frames and a GIF, ~30 images/s) into `runs/<run>/`.
    #[arg(long)]
    pub render: bool,
    /// Skip runs that already have a result in the output directory (after an interrupted or
    /// killed queue).
    #[arg(long)]
    pub resume: bool,
    /// Run a queue longer than 1000 runs (without it such a queue is refused).
    #[arg(long)]
    pub yes: bool,
    /// Memory and file-size limits (the memory limit applies to each run's scene).
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `weft render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Scene file (default: the built-in hanging cloth).
    pub scene: Option<PathBuf>,
    /// Frames to simulate.
    #[arg(long, default_value_t = 180)]
    pub frames: u64,
    /// Output directory (created if missing): frame_00000.png…, <scene>.gif, <scene>.mp4.
    #[arg(long)]
    pub out: PathBuf,
    /// Image size in pixels.
    #[arg(long, default_value = "800x600", value_name = "WxH", value_parser = crate::video::parse_size)]
    pub size: glam::UVec2,
    /// Render every K-th frame.
    #[arg(long, default_value_t = 1, value_name = "K")]
    pub every: u64,
    /// Override a scene key: `--set sim.substeps=20` (repeatable; values are TOML, else strings).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<Override>,
    /// Shorthand for `--set sim.method=…` (xpbd, pbd, mass-spring or implicit-mass-spring).
    #[arg(long)]
    pub method: Option<Method>,
    /// Draw the cloth's edges.
    #[arg(long)]
    pub wireframe: bool,
    /// Draw the particles.
    #[arg(long)]
    pub particles: bool,
    /// The camera, instead of the automatic framing.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// No shadows.
    #[arg(long)]
    pub no_shadows: bool,
    /// No ground grid lines.
    #[arg(long)]
    pub no_grid: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Memory and file-size limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

impl RenderArgs {
    /// The overrides, `--method` first.
    pub fn overrides(&self) -> Vec<Override> {
        overrides(self.method, &self.set)
    }
}

/// A range of frame numbers: `A..B` (B excluded), `A..=B`, `A..`, `..B`, `..=B` or `..`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    /// First frame.
    pub start: u64,
    /// Frame after the last (`None`: to the end).
    pub end: Option<u64>,
}

impl FrameRange {
    /// Parses `A..B`, `A..=B`, `A..`, `..B`, `..=B` or `..`.
    pub fn parse(s: &str) -> Result<Self, String> {
        let bad = || format!("expected a frame range such as 0..100, 10..=20 or 50.., got {s:?}");
        let (a, b) = s.trim().split_once("..").ok_or_else(bad)?;
        let number = |t: &str| t.trim().parse::<u64>().map_err(|_| bad());
        let start = if a.trim().is_empty() { 0 } else { number(a)? };
        let end = match b.strip_prefix('=') {
            Some(last) => Some(number(last)?.checked_add(1).ok_or_else(bad)?),
            None if b.trim().is_empty() => None,
            None => Some(number(b)?),
        };
        if end.is_some_and(|e| e <= start) {
            return Err(format!("the frame range {s:?} is empty"));
        }
        Ok(Self { start, end })
    }

    /// Whether `frame` lies in the range.
    pub fn contains(&self, frame: u64) -> bool {
        frame >= self.start && self.end.is_none_or(|e| frame < e)
    }
}
