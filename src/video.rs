//! `weft render`: a scene stepped headless and drawn offscreen every K frames, written as
//! numbered PNGs, an animated GIF and (when `ffmpeg` is on PATH) an MP4, through the same
//! meshes, floor and framing as the window (`view.rs`).

use std::fs::File;
use std::io::{BufWriter, IsTerminal};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, bail};
use glam::UVec2;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use weft_render::{Camera, FrameData, Gpu, OFFSCREEN_FORMAT, Offscreen, RenderOptions, Renderer};
use weft_scene::Scene;

use crate::output::Output;
use crate::run::{EXIT_DIVERGED, EXIT_INTERRUPTED};
use crate::stop::Stopped;
use crate::view;
use weft_sim::Simulation;

/// Shortest GIF frame delay players honour (ms); faster frames are dropped to keep real time.
const GIF_MIN_DELAY_MS: f64 = 20.0;
/// GIF colour quantisation speed (1 best … 30 fastest).
const GIF_SPEED: i32 = 10;
/// The GIF's longest side at most (px): a preview, shrunk from larger images (quantising an
/// 8192² frame takes seconds); the PNGs keep the full size.
const GIF_MAX_SIDE: u32 = 1920;

/// Parses `WxH` (e.g. `800x600`) into a size in pixels.
pub fn parse_size(s: &str) -> Result<UVec2, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size `{s}` is not WIDTHxHEIGHT (e.g. 800x600)"))?;
    let dim = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=8192).contains(&n))
            .ok_or_else(|| format!("size `{s}`: `{v}` is not a whole number of pixels in 1..=8192"))
    };
    Ok(UVec2::new(dim(w)?, dim(h)?))
}

/// Width over height of an image of `size` pixels.
fn aspect(size: UVec2) -> f32 {
    size.x.max(1) as f32 / size.y.max(1) as f32
}

/// Options of `weft render`.
pub struct VideoPlan<'a> {
    /// Frames to simulate.
    pub frames: u64,
    /// Render every K-th frame.
    pub every: u64,
    /// Output directory.
    pub out: &'a Path,
    /// Image size (px).
    pub size: UVec2,
    /// Layers to draw.
    pub options: RenderOptions,
    /// A fixed camera `(eye, target)` instead of the automatic framing.
    pub camera: Option<(glam::Vec3, glam::Vec3)>,
    /// Show a progress bar (on a terminal only).
    pub progress: bool,
}

/// Writes frames of one simulation: PNGs as they come, the GIF streamed to a temporary
/// name and renamed when [`finish`](Self::finish)ed, then the MP4.
pub struct VideoRecorder<'g> {
    gpu: &'g Gpu,
    renderer: Renderer,
    target: Offscreen,
    /// The image's size (px); the target holds one tile of it.
    size: UVec2,
    camera: Camera,
    options: RenderOptions,
    dir: PathBuf,
    name: String,
    every: u64,
    images: u64,
    gif: Option<GifEncoder<BufWriter<File>>>,
    /// The GIF's output (its partial file, locked, renamed when finished): it also keeps a
    /// second weft from rendering the same scene into the same directory.
    gif_out: Option<Output>,
    gif_stride: u64,
    gif_delay_ms: u32,
    fps: f64,
    /// Raised by a signal: the image being written is abandoned (see [`Self::set_stop`]).
    stop: Option<Arc<AtomicBool>>,
    /// The last image written (kept to mark a divergence).
    last: Option<image::RgbaImage>,
}

impl<'g> VideoRecorder<'g> {
    /// Opens `dir` (created if missing) and the GIF, and sets the camera from `sim` now.
    pub fn new(
        gpu: &'g Gpu,
        sim: &Simulation,
        dir: &Path,
        size: UVec2,
        every: u64,
        options: RenderOptions,
    ) -> anyhow::Result<Self> {
        if every == 0 {
            bail!("--every must be at least 1");
        }
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output directory {}", dir.display()))?;
        let name = file_stem(&sim.scene.name);
        let gif_out = Output::create(&dir.join(format!("{name}.gif")))?;
        let mut gif = GifEncoder::new_with_speed(BufWriter::new(gif_out.handle()?), GIF_SPEED);
        gif.set_repeat(Repeat::Infinite)
            .with_context(|| format!("cannot write {}", gif_out.target().display()))?;
        // Frame period of the images, and the GIF's: at least 20 ms, whole images apart.
        let period_ms = 1e3 * sim.scene.settings.dt * every as f64;
        let gif_stride = (GIF_MIN_DELAY_MS / period_ms).ceil().max(1.0) as u64;
        let gif_delay_ms = (period_ms * gif_stride as f64).round().max(1.0) as u32;

        let (renderer, scene_view) = view::renderer_for(&gpu.device, OFFSCREEN_FORMAT, sim);
        let camera = crate::framing::framing_camera(sim, &scene_view, aspect(size), 0.0);
        Ok(Self {
            gpu,
            renderer,
            target: Offscreen::for_image(&gpu.device, size),
            size,
            camera,
            options,
            dir: dir.to_owned(),
            name,
            every,
            images: 0,
            gif: Some(gif),
            gif_out: Some(gif_out),
            gif_stride,
            gif_delay_ms,
            fps: 1.0 / (sim.scene.settings.dt * every as f64),
            stop: None,
            last: None,
        })
    }

    /// Frames what `sim` contains now and, for its character, over the next `span` seconds
    /// (a character that jumps or walks stays in the picture).
    pub fn frame_span(&mut self, sim: &Simulation, span: f64) {
        let view = view::scene_meshes(sim);
        self.camera = crate::framing::framing_camera(sim, &view, aspect(self.target.size()), span);
    }

    /// Looks from `eye` at `target` instead of the automatic framing.
    pub fn set_camera(&mut self, eye: glam::Vec3, target: glam::Vec3) {
        self.camera = Camera::looking_at(eye, target);
    }

    /// A flag polled while an image is written: once raised, the PNG being compressed is
    /// abandoned (its partial file removed) and no GIF frame is added, so a stop is honoured
    /// within a second even at 8192².
    pub fn set_stop(&mut self, flag: Arc<AtomicBool>) {
        self.stop = Some(flag);
    }

    fn stopping(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// Images written so far.
    pub fn images(&self) -> u64 {
        self.images
    }

    /// Renders the simulation's current state if its frame is a multiple of `every`.
    pub fn frame(&mut self, sim: &Simulation) -> anyhow::Result<()> {
        if sim.frame() % self.every != 0 {
            return Ok(());
        }
        let image = self.draw(sim)?;
        self.write(image)
    }

    /// Writes one image as the next PNG (and GIF frame, every `gif_stride`).
    fn write(&mut self, image: image::RgbaImage) -> anyhow::Result<()> {
        if self.stopping() {
            return Err(Stopped.into());
        }
        let png = self.dir.join(format!("frame_{:05}.png", self.images));
        save_png(&image, &png, self.stop.as_deref())
            .with_context(|| format!("cannot write {}", png.display()))?;
        if self.stopping() {
            return Err(Stopped.into());
        }
        if self.images % self.gif_stride == 0
            && let Some(gif) = self.gif.as_mut()
        {
            let delay = Delay::from_numer_denom_ms(self.gif_delay_ms, 1);
            let (w, h) = image.dimensions();
            let frame = if w.max(h) > GIF_MAX_SIDE {
                let scale = f64::from(GIF_MAX_SIDE) / f64::from(w.max(h));
                let size = |v: u32| ((f64::from(v) * scale).round() as u32).max(1);
                image::imageops::thumbnail(&image, size(w), size(h))
            } else {
                image.clone()
            };
            gif.encode_frame(Frame::from_parts(frame, 0, 0, delay))
                .with_context(|| format!("cannot write {}", self.gif_path().display()))?;
        }
        self.images += 1;
        self.last = Some(image);
        Ok(())
    }

    /// Completes a run that diverged: the frames up to the divergence, then one second of the
    /// last of them framed in red, and `diverged.txt` holding `message`, next to the video.
    pub fn finish_diverged(mut self, message: &str) -> anyhow::Result<Vec<PathBuf>> {
        if let Some(last) = self.last.take() {
            let marked = mark_diverged(last);
            let hold = self.fps.round().max(1.0) as u64;
            for _ in 0..hold {
                self.write(marked.clone())?;
            }
        }
        let note = self.dir.join("diverged.txt");
        crate::output::write_file(&note, format!("{message}\n").as_bytes())?;
        let mut files = self.finish()?;
        files.push(note);
        Ok(files)
    }

    /// Draws the current state offscreen and reads it back.
    pub fn draw(&mut self, sim: &Simulation) -> anyhow::Result<image::RgbaImage> {
        let cloths: Vec<&[weft_solver::glam::DVec3]> = (0..sim.scene.cloths.len())
            .map(|i| sim.cloth_positions(i))
            .collect();
        let poses = view::frame_poses(sim);
        view::refresh_deformed(&mut self.renderer, sim);
        self.renderer.update(
            &self.gpu.queue,
            &FrameData {
                cloths: &cloths,
                collider_poses: &poses,
                highlight: None,
                drag_target: None,
            },
        );
        // Drawn a tile at a time: an 8192² image is seconds of software rasterising, and a
        // stop between its tiles is honoured within a tile's time.
        let stop = self.stop.clone();
        let stopped = move || stop.as_ref().is_some_and(|f| f.load(Ordering::Relaxed));
        self.target
            .capture(
                self.gpu,
                &mut self.renderer,
                &self.camera,
                &self.options,
                self.size,
                &stopped,
            )?
            .ok_or_else(|| Stopped.into())
    }

    /// Completes the GIF (renamed from its temporary name) and the MP4; returns the files.
    pub fn finish(mut self) -> anyhow::Result<Vec<PathBuf>> {
        let mut written = Vec::new();
        let gif_path = self.gif_path();
        if let (Some(gif), Some(out)) = (self.gif.take(), self.gif_out.take()) {
            // Dropping the encoder writes the trailer and flushes, but cannot report a failed
            // write: check the file ends with the GIF trailer byte (0x3B) instead. An
            // unfinished output removes its partial file when dropped.
            drop(gif);
            if self.images == 0 && self.stopping() {
                // Stopped before the first image: nothing to keep, nothing wrong.
                return Ok(written);
            }
            if !ends_with_trailer(out.partial()) {
                bail!("cannot write {} (incomplete)", gif_path.display());
            }
            if self.images == 0 {
                bail!("no frames were rendered");
            }
            out.commit()?;
            written.push(gif_path);
        }
        if let Some(mp4) = self.mp4()? {
            written.push(mp4);
        }
        Ok(written)
    }

    /// Where the GIF goes.
    fn gif_path(&self) -> PathBuf {
        self.dir.join(format!("{}.gif", self.name))
    }

    /// Encodes the PNGs as H.264 with ffmpeg when it is on PATH; logs and skips otherwise.
    fn mp4(&self) -> anyhow::Result<Option<PathBuf>> {
        encode_mp4(&self.dir, &self.name, self.fps)
    }
}

/// `dir/frame_%05d.png` encoded as `dir/<name>.mp4` (H.264) at `fps` when ffmpeg is on PATH;
/// logs and returns `None` otherwise.
pub fn encode_mp4(dir: &Path, name: &str, fps: f64) -> anyhow::Result<Option<PathBuf>> {
    let path = dir.join(format!("{name}.mp4"));
    // Claimed (partial file, locked) first; ffmpeg writes the partial, renamed when finished.
    let out = Output::create(&path)?;
    let partial = out.partial().to_path_buf();
    let status = Command::new("ffmpeg")
        .args(["-y", "-loglevel", "error", "-framerate"])
        .arg(format!("{fps:.6}"))
        .arg("-i")
        .arg(dir.join("frame_%05d.png"))
        .args([
            "-c:v",
            "libx264",
            "-pix_fmt",
            "yuv420p",
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
        ])
        .arg(&partial)
        .status();
    match status {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            eprintln!("weft: ffmpeg is not on PATH: skipping {}", path.display());
            Ok(None)
        }
        Err(e) => Err(e).context("cannot run ffmpeg"),
        Ok(s) if !s.success() => bail!("ffmpeg failed ({s}) encoding {}", path.display()),
        Ok(_) => {
            out.commit()?;
            Ok(Some(path))
        }
    }
}

/// Refuses an `--out` directory where the render would write over one of `inputs` (role,
/// path): a frame `frame_NNNNN.png`, the GIF or MP4 named after `scene_name`, `diverged.txt`,
/// or the partial file of any of them.
pub fn refuse_overwriting_inputs(
    inputs: &[(&str, PathBuf)],
    out: &Path,
    scene_name: &str,
) -> anyhow::Result<()> {
    let Ok(dir) = std::fs::canonicalize(out) else {
        // No directory yet: no input is in it.
        return Ok(());
    };
    let name = file_stem(scene_name);
    for (role, input) in inputs {
        let Ok(input) = std::fs::canonicalize(input) else {
            continue;
        };
        let Some(file) = input.file_name().map(|f| f.to_string_lossy()) else {
            continue;
        };
        if input.parent() == Some(dir.as_path()) && written_by_render(&file, &name) {
            bail!(
                "--out {} would write {}, which is {role}: refusing to overwrite an input; \
                 choose another --out",
                out.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// Whether `render` writes a file called `file` (or its partial) into its directory.
fn written_by_render(file: &str, name: &str) -> bool {
    let whole = crate::output::target_of_partial(file).unwrap_or_else(|| file.to_owned());
    let frame = whole
        .strip_prefix("frame_")
        .and_then(|f| f.strip_suffix(".png"))
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
    frame
        || whole == format!("{name}.gif")
        || whole == format!("{name}.mp4")
        || whole == "diverged.txt"
}

/// Width of the red frame that marks a diverged run's last image (px).
pub const DIVERGED_BORDER: u32 = 12;

/// `image` framed in red and dimmed inside: the mark of a run that diverged after it.
pub fn mark_diverged(mut image: image::RgbaImage) -> image::RgbaImage {
    let (w, h) = image.dimensions();
    for (x, y, p) in image.enumerate_pixels_mut() {
        let edge = x < DIVERGED_BORDER
            || y < DIVERGED_BORDER
            || x + DIVERGED_BORDER >= w
            || y + DIVERGED_BORDER >= h;
        if edge {
            *p = image::Rgba([220, 30, 30, 255]);
        } else {
            p.0[0] = p.0[0] / 2 + 100;
            p.0[1] /= 2;
            p.0[2] /= 2;
        }
    }
    image
}

/// A writer that fails once `stop` is raised, so an encoder writing through it gives up
/// between two of its writes.
struct StopWriter<'a, W> {
    inner: W,
    stop: Option<&'a AtomicBool>,
}

impl<W: std::io::Write> std::io::Write for StopWriter<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.stop.is_some_and(|f| f.load(Ordering::Relaxed)) {
            return Err(std::io::Error::other(Stopped));
        }
        self.inner.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// Rows of an image compressed between two looks at the stop flag: 64 rows of an 8192-pixel
/// image are 2 MiB, tens of milliseconds of the strongest compression.
const PNG_ROWS_PER_CHECK: usize = 64;

/// Writes `image` as a PNG with the strongest compression (about half the default's size),
/// to its partial file, renamed into place when whole; a raised `stop` abandons it (the
/// partial file is removed) with [`Stopped`]. The rows are streamed through the compressor
/// a few at a time: compressing a whole 8192² image before writing takes seconds no stop
/// could cut short.
fn save_png(
    image: &image::RgbaImage,
    path: &Path,
    stop: Option<&AtomicBool>,
) -> anyhow::Result<()> {
    use std::io::Write;
    let stopped = || stop.is_some_and(|f| f.load(Ordering::Relaxed));
    let out = Output::create(path)?;
    let mut file = StopWriter {
        inner: BufWriter::new(out.handle()?),
        stop,
    };
    let encoded: anyhow::Result<()> = (|| {
        let mut encoder = png::Encoder::new(&mut file, image.width(), image.height());
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        encoder.set_filter(png::Filter::Adaptive);
        let mut writer = encoder.write_header()?;
        let mut stream = writer.stream_writer()?;
        let row = 4 * image.width() as usize;
        for rows in image.as_raw().chunks(row * PNG_ROWS_PER_CHECK) {
            if stopped() {
                return Err(Stopped.into());
            }
            stream.write_all(rows)?;
        }
        stream.finish()?;
        writer.finish()?;
        Ok(())
    })();
    if stopped() {
        return Err(Stopped.into());
    }
    encoded?;
    file.flush()?;
    drop(file);
    out.commit()
}

/// Whether the file at `path` ends with the GIF trailer byte.
fn ends_with_trailer(path: &Path) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    let mut last = [0u8; 1];
    File::open(path)
        .and_then(|mut f| {
            f.seek(SeekFrom::End(-1))?;
            f.read_exact(&mut last)
        })
        .is_ok()
        && last[0] == 0x3B
}

/// A file name from the scene's name (a path: its stem), of letters, digits, `-` and `_`.
fn file_stem(name: &str) -> String {
    let stem = Path::new(name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let s: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() { "scene".into() } else { s }
}

/// Progress where standard error is not a terminal (a log file, CI): a line whenever a
/// tenth more of the frames is done or a second has passed since the last line.
struct ProgressLines {
    total: u64,
    start: std::time::Instant,
    last: std::time::Instant,
    tenths: u64,
}

impl ProgressLines {
    fn new(total: u64) -> Self {
        let now = std::time::Instant::now();
        Self {
            total: total.max(1),
            start: now,
            last: now,
            tenths: 0,
        }
    }

    /// The line to print after frame `done` at `now`, if one is due.
    fn frame(&mut self, done: u64, now: std::time::Instant) -> Option<String> {
        let tenths = done.min(self.total) * 10 / self.total;
        if tenths <= self.tenths && now - self.last < std::time::Duration::from_secs(1) {
            return None;
        }
        self.tenths = tenths;
        self.last = now;
        Some(format!(
            "frame {done}/{} ({} %), {:.0} s",
            self.total,
            done.min(self.total) * 100 / self.total,
            (now - self.start).as_secs_f64()
        ))
    }
}

/// Runs `weft render`.
pub fn render(
    scene: Scene,
    plan: &VideoPlan<'_>,
    stop: &Arc<AtomicBool>,
) -> anyhow::Result<ExitCode> {
    if plan.every == 0 || plan.frames / plan.every == 0 {
        bail!(
            "nothing to render: --frames {} with --every {} gives no image",
            plan.frames,
            plan.every
        );
    }
    // The output directory first, so an unwritable one fails before any GPU work.
    std::fs::create_dir_all(plan.out)
        .with_context(|| format!("cannot create output directory {}", plan.out.display()))?;
    let gpu = Gpu::headless().context("cannot render")?;
    let mut sim = Simulation::new(scene)?;
    crate::stability::warn(&sim.groups);
    crate::crossing_report::warn_start(&sim);
    // From here a signal raises the flag (the solver sees it within a substep) and the images
    // rendered so far are kept.
    sim.set_stop(Arc::clone(stop));
    let _polling = crate::stop::Polling::start();
    let mut rec = VideoRecorder::new(&gpu, &sim, plan.out, plan.size, plan.every, plan.options)?;
    match plan.camera {
        Some((eye, target)) => rec.set_camera(eye, target),
        None => rec.frame_span(&sim, plan.frames as f64 * sim.scene.settings.dt),
    }
    rec.set_stop(Arc::clone(stop));
    eprintln!(
        "weft: rendering {} on {} at {}x{}, every {} frame(s) of {}",
        sim.scene.name,
        gpu.describe(),
        plan.size.x,
        plan.size.y,
        plan.every,
        plan.frames
    );
    let terminal = std::io::stderr().is_terminal();
    let mut lines = (plan.progress && !terminal).then(|| ProgressLines::new(plan.frames));
    let bar = if plan.progress && terminal {
        let bar = ProgressBar::with_draw_target(Some(plan.frames), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} frames  eta {eta}") {
            bar.set_style(style);
        }
        bar
    } else {
        ProgressBar::hidden()
    };
    let mut code = ExitCode::SUCCESS;
    let mut seams = weft_sim::SeamWatch::default();
    for _ in 0..plan.frames {
        if stop.load(Ordering::SeqCst) {
            eprintln!("weft: interrupted after {} frames", sim.frame());
            code = ExitCode::from(EXIT_INTERRUPTED);
            break;
        }
        if let Err(e) = sim.step() {
            if sim.interrupted(&e) {
                eprintln!("weft: interrupted after {} frames", sim.frame());
                code = ExitCode::from(EXIT_INTERRUPTED);
                break;
            }
            bar.finish_and_clear();
            eprintln!("weft: error: {e}");
            eprintln!(
                "weft: {} image(s) of the frames before it are in {}; no GIF written",
                rec.images(),
                plan.out.display()
            );
            return Ok(ExitCode::from(EXIT_DIVERGED));
        }
        bar.suspend(|| crate::seam_report::warn_open(&mut seams, &sim));
        match rec.frame(&sim) {
            Err(e) if e.is::<Stopped>() => {
                eprintln!("weft: interrupted after {} frames", sim.frame());
                code = ExitCode::from(EXIT_INTERRUPTED);
                break;
            }
            r => r?,
        }
        bar.inc(1);
        if let Some(l) = lines.as_mut()
            && let Some(line) = l.frame(sim.frame(), std::time::Instant::now())
        {
            eprintln!("weft: {line}");
        }
    }
    bar.finish_and_clear();
    let images = rec.images();
    let written = rec.finish()?;
    say!(
        "wrote {images} PNG frame(s) to {}/frame_*.png",
        plan.out.display()
    )?;
    for w in written {
        let size = std::fs::metadata(&w).map(|m| m.len()).unwrap_or(0);
        say!("wrote {} ({size} bytes)", w.display())?;
    }
    Ok(code)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_bad_ones_are_named() {
        assert_eq!(parse_size("800x600"), Ok(UVec2::new(800, 600)));
        assert_eq!(parse_size("16X9"), Ok(UVec2::new(16, 9)));
        for bad in ["800", "0x10", "axb", "10x99999", "-1x5"] {
            let e = parse_size(bad).expect_err(bad);
            assert!(e.contains(bad), "{e}");
        }
    }

    #[test]
    fn a_raised_stop_abandons_a_png_and_leaves_no_file() {
        let dir = std::env::temp_dir().join(format!("weft-png-stop-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let img =
            image::RgbaImage::from_fn(512, 512, |x, y| image::Rgba([x as u8, y as u8, 7, 255]));
        let path = dir.join("frame.png");
        let raised = AtomicBool::new(true);
        let e = save_png(&img, &path, Some(&raised)).expect_err("stopped");
        assert!(e.is::<Stopped>(), "{e}");
        let left: Vec<_> = std::fs::read_dir(&dir).expect("dir").collect();
        assert!(left.is_empty(), "{left:?}");
        save_png(&img, &path, Some(&AtomicBool::new(false))).expect("written");
        assert_eq!(image::open(&path).expect("a PNG").to_rgba8(), img);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_diverged_frame_is_framed_in_red_and_dimmed() {
        let img = image::RgbaImage::from_pixel(100, 80, image::Rgba([200, 200, 200, 255]));
        let m = mark_diverged(img);
        assert_eq!(m.get_pixel(0, 0).0, [220, 30, 30, 255]);
        assert_eq!(m.get_pixel(99, 40).0, [220, 30, 30, 255]);
        assert_eq!(m.get_pixel(50, 40).0, [200, 100, 100, 255]);
    }

    #[test]
    fn file_stems_are_safe() {
        assert_eq!(file_stem("assets/scenes/sphere_drop.toml"), "sphere_drop");
        assert_eq!(file_stem("my scene (2).toml"), "my_scene__2_");
        assert_eq!(file_stem(""), "scene");
    }

    #[test]
    fn off_a_terminal_a_line_comes_each_tenth_or_second() {
        let mut p = ProgressLines::new(100);
        let t0 = p.start;
        let ms = |n: u64| t0 + std::time::Duration::from_millis(n);
        assert_eq!(p.frame(5, ms(100)), None);
        let line = p.frame(10, ms(200)).expect("a tenth done");
        assert!(line.starts_with("frame 10/100 (10 %)"), "{line}");
        assert_eq!(p.frame(12, ms(300)), None);
        let line = p.frame(13, ms(1300)).expect("a second passed");
        assert!(line.starts_with("frame 13/100 (13 %), 1 s"), "{line}");
        assert_eq!(p.frame(19, ms(1400)), None);
        assert!(
            p.frame(100, ms(1500))
                .is_some_and(|l| l.contains("(100 %)"))
        );
    }
}
