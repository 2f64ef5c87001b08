//! Screenshots of the virtual X server: Xvfb started with `-fbdir` keeps its screen in a file
//! (an XWD image, 32 bits a pixel), read here into RGB pixels, compared region by region and
//! saved as PNG beside a failing test's files.

use std::path::{Path, PathBuf};

/// The directory Xvfb keeps the screen of `display` (":N") in.
pub fn fb_dir(display: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("xvfb-{}", display.trim_start_matches(':')))
}

/// An RGB image of the screen.
#[derive(Clone, Debug, PartialEq)]
pub struct Shot {
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// Pixels, row by row from the top left.
    pub rgb: Vec<[u8; 3]>,
}

/// A rectangle of pixels: `x0..x1` by `y0..y1`.
#[derive(Clone, Copy, Debug)]
pub struct Region {
    /// Left (included).
    pub x0: u32,
    /// Top (included).
    pub y0: u32,
    /// Right (excluded).
    pub x1: u32,
    /// Bottom (excluded).
    pub y1: u32,
}

impl Shot {
    /// The pixel at `(x, y)`.
    pub fn at(&self, x: u32, y: u32) -> [u8; 3] {
        self.rgb[(y * self.width + x) as usize]
    }

    /// The pixels of `r`, clipped to the image, with their coordinates.
    pub fn pixels(&self, r: Region) -> impl Iterator<Item = (u32, u32, [u8; 3])> + '_ {
        let (x1, y1) = (r.x1.min(self.width), r.y1.min(self.height));
        (r.y0..y1).flat_map(move |y| (r.x0..x1).map(move |x| (x, y, self.at(x, y))))
    }

    /// Pixels of `r` that differ between `self` and `other` by more than `tolerance` in a
    /// channel.
    pub fn differing(&self, other: &Shot, r: Region, tolerance: u8) -> Vec<(u32, u32)> {
        self.pixels(r)
            .filter(|&(x, y, p)| {
                let q = other.at(x, y);
                (0..3).any(|c| p[c].abs_diff(q[c]) > tolerance)
            })
            .map(|(x, y, _)| (x, y))
            .collect()
    }

    /// Writes the image as a PNG (for a failing test to show what it saw).
    pub fn save(&self, path: &Path) {
        let bytes: Vec<u8> = self.rgb.iter().flatten().copied().collect();
        if let Some(img) = image::RgbImage::from_raw(self.width, self.height, bytes) {
            let _ = img.save(path);
        }
    }
}

/// The screen of `display` now, cut to its top-left `width` × `height` pixels.
pub fn shot(display: &str, width: u32, height: u32) -> Shot {
    let path = fb_dir(display).join("Xvfb_screen0");
    let b = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let word = |i: usize| u32::from_be_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]]);
    let (header, w, h) = (word(0) as usize, word(4), word(5));
    let (byte_order, bits, stride, colours) = (word(7), word(11), word(12) as usize, word(19));
    assert_eq!(bits, 32, "{}: {bits} bits a pixel", path.display());
    let start = header + 12 * colours as usize;
    let (width, height) = (width.min(w), height.min(h));
    let mut rgb = Vec::with_capacity((width * height) as usize);
    for y in 0..height as usize {
        for x in 0..width as usize {
            let p = &b[start + y * stride + 4 * x..][..4];
            // 0x00RRGGBB, least significant byte first unless the byte order is 1 (MSB).
            rgb.push(if byte_order == 0 {
                [p[2], p[1], p[0]]
            } else {
                [p[1], p[2], p[3]]
            });
        }
    }
    Shot { width, height, rgb }
}
