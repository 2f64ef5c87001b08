//! A series side by side: every rendered run of a sweep tiled into one labelled video
//! (`series/<series>/frame_%05d.png`, a GIF and, with ffmpeg, an MP4).

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use anyhow::Context;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbImage, RgbaImage};
use plotters::prelude::*;

use crate::experiments::plot::{FAMILY, register_font};

/// One run of the series: its label, its rendered frames' folder, and whether it diverged.
pub struct Tile {
    /// What the run varied (`sim.substeps=10`).
    pub label: String,
    /// `runs/<run>/`, holding `frame_%05d.png`.
    pub dir: PathBuf,
    /// Whether it diverged (its last frames are marked in red).
    pub diverged: bool,
}

/// Frames images are shown at (the runs are rendered at about 30 images per simulated second).
const FPS: f64 = 30.0;

fn frames_in(dir: &Path) -> Vec<PathBuf> {
    (0..)
        .map(|i| dir.join(format!("frame_{i:05}.png")))
        .take_while(|p| p.exists())
        .collect()
}

/// Tiles `tiles` side by side into `dir` (created), one image per frame of the longest run,
/// a shorter run holding its last frame; returns the files written.
pub fn write(title: &str, tiles: &[Tile], dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    register_font();
    let frames: Vec<Vec<PathBuf>> = tiles.iter().map(|t| frames_in(&t.dir)).collect();
    let longest = frames.iter().map(Vec::len).max().unwrap_or(0);
    let Some(first) = frames.iter().find_map(|f| f.first()) else {
        return Ok(Vec::new());
    };
    let (tw, th) = image::image_dimensions(first)
        .with_context(|| format!("cannot read {}", first.display()))?;
    let cols = (tiles.len() as f64).sqrt().ceil().max(1.0) as u32;
    let rows = (tiles.len() as u32).div_ceil(cols);
    let (w, h) = (tw * cols, th * rows);
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let name = dir
        .file_name()
        .map_or_else(|| "series".into(), |n| n.to_string_lossy().into_owned());
    let gif_path = dir.join(format!("{name}.gif"));
    let mut gif = GifEncoder::new_with_speed(
        BufWriter::new(
            File::create(&gif_path)
                .with_context(|| format!("cannot write {}", gif_path.display()))?,
        ),
        10,
    );
    gif.set_repeat(Repeat::Infinite)?;
    let mut written = Vec::new();
    for t in 0..longest {
        let mut canvas = RgbImage::new(w, h);
        for (k, files) in frames.iter().enumerate() {
            let Some(file) = files.get(t.min(files.len().saturating_sub(1))) else {
                continue;
            };
            let img = image::open(file)
                .with_context(|| format!("cannot read {}", file.display()))?
                .to_rgb8();
            let (x0, y0) = ((k as u32 % cols) * tw, (k as u32 / cols) * th);
            image::imageops::replace(&mut canvas, &img, i64::from(x0), i64::from(y0));
        }
        label(
            &mut canvas,
            (w, h),
            (tw, th),
            cols,
            title,
            tiles,
            &frames,
            t,
        )?;
        let png = dir.join(format!("frame_{t:05}.png"));
        canvas
            .save(&png)
            .with_context(|| format!("cannot write {}", png.display()))?;
        if t % 2 == 0 {
            let rgba: RgbaImage = image::DynamicImage::ImageRgb8(canvas).to_rgba8();
            let delay = Delay::from_numer_denom_ms((2e3 / FPS).round() as u32, 1);
            gif.encode_frame(Frame::from_parts(rgba, 0, 0, delay))?;
        }
    }
    drop(gif);
    written.push(gif_path);
    if let Some(mp4) = crate::video::encode_mp4(dir, &name, FPS)? {
        written.push(mp4);
    }
    Ok(written)
}

/// Writes each tile's label (and `diverged` once its frames have run out) and the title.
#[allow(clippy::too_many_arguments)]
fn label(
    canvas: &mut RgbImage,
    (w, h): (u32, u32),
    (tw, th): (u32, u32),
    cols: u32,
    title: &str,
    tiles: &[Tile],
    frames: &[Vec<PathBuf>],
    t: usize,
) -> anyhow::Result<()> {
    let root = BitMapBackend::with_buffer(canvas.as_mut(), (w, h)).into_drawing_area();
    let font = (FAMILY, 18).into_font();
    for (k, (tile, files)) in tiles.iter().zip(frames).enumerate() {
        let (x0, y0) = ((k as u32 % cols) * tw, (k as u32 / cols) * th);
        let over = tile.diverged && t + 1 >= files.len();
        let text = if over {
            format!("{}: diverged", tile.label)
        } else {
            tile.label.clone()
        };
        let color = if over { RGBColor(255, 80, 80) } else { WHITE };
        let pos = (x0 as i32 + 14, y0 as i32 + th as i32 - 32);
        root.draw(&Rectangle::new(
            [
                (pos.0 - 6, pos.1 - 4),
                (x0 as i32 + tw as i32 - 8, pos.1 + 24),
            ],
            BLACK.mix(0.55).filled(),
        ))
        .map_err(|e| anyhow::anyhow!("drawing a label: {e}"))?;
        root.draw_text(&text, &font.color(&color), pos)
            .map_err(|e| anyhow::anyhow!("drawing a label: {e}"))?;
    }
    root.draw_text(title, &(FAMILY, 20).into_font().color(&WHITE), (14, 10))
        .map_err(|e| anyhow::anyhow!("drawing the title: {e}"))?;
    root.present()
        .map_err(|e| anyhow::anyhow!("drawing labels: {e}"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_dir(root: &Path, name: &str, frames: usize, shade: u8) -> PathBuf {
        let dir = root.join(name);
        std::fs::create_dir_all(&dir).expect("dir");
        for i in 0..frames {
            let img = RgbaImage::from_pixel(200, 160, image::Rgba([shade, i as u8 * 40, 0, 255]));
            img.save(dir.join(format!("frame_{i:05}.png")))
                .expect("png");
        }
        dir
    }

    #[test]
    fn runs_are_tiled_side_by_side_and_a_short_run_holds_its_last_frame() {
        let root = std::env::temp_dir().join(format!("weft-montage-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let tiles = vec![
            Tile {
                label: "n=3".into(),
                dir: run_dir(&root, "a", 3, 200),
                diverged: false,
            },
            Tile {
                label: "n=1".into(),
                dir: run_dir(&root, "b", 2, 90),
                diverged: true,
            },
        ];
        let out = root.join("series").join("s");
        let files = write("title", &tiles, &out).expect("montage");
        assert!(
            files
                .iter()
                .any(|f| f.extension().is_some_and(|e| e == "gif"))
        );
        let frames = frames_in(&out);
        assert_eq!(frames.len(), 3, "one image per frame of the longest run");
        let last = image::open(&frames[2]).expect("png").to_rgb8();
        assert_eq!(last.dimensions(), (400, 160), "two tiles side by side");
        // Away from the labels (top band, bottom band): the first run's third frame on the
        // left, the second run's last (second) frame held on the right.
        assert_eq!(last.get_pixel(100, 80).0, [200, 80, 0]);
        assert_eq!(last.get_pixel(300, 80).0, [90, 40, 0]);
        let _ = std::fs::remove_dir_all(&root);
    }
}
