//! A rectangle of a larger image, drawn on its own: big renders are drawn a tile at a time so
//! that a stop between tiles is honoured at once and the GPU holds one tile, not the image.

use glam::{Mat4, UVec2};

/// The pixels `origin .. origin + size` (origin top-left) of an image of `full` pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    /// The whole image's size (px): the camera's aspect comes from it.
    pub full: UVec2,
    /// The tile's top-left pixel in the image.
    pub origin: UVec2,
    /// The tile's size (px).
    pub size: UVec2,
}

impl Tile {
    /// The whole of an image of `size` pixels as one tile.
    pub fn whole(size: UVec2) -> Self {
        let size = size.max(UVec2::ONE);
        Self {
            full: size,
            origin: UVec2::ZERO,
            size,
        }
    }

    /// Tiles of `max` pixels a side (or the image's side where it is smaller) covering an
    /// image of `full` pixels, row by row from the top left. All have one size, so one target
    /// serves them all: the last tile of a row or column is moved back to end at the image's
    /// edge, overlapping its neighbour, rather than cut short.
    pub fn cover(full: UVec2, max: u32) -> Vec<Tile> {
        let full = full.max(UVec2::ONE);
        let size = full.min(UVec2::splat(max.max(1)));
        let starts = |full: u32, size: u32| {
            let mut s: Vec<u32> = (0..full - size).step_by(size as usize).collect();
            s.push(full - size);
            s
        };
        let mut tiles = Vec::new();
        for &y in &starts(full.y, size.y) {
            for &x in &starts(full.x, size.x) {
                tiles.push(Tile {
                    full,
                    origin: UVec2::new(x, y),
                    size,
                });
            }
        }
        tiles
    }

    /// Maps the whole image's clip space onto the tile's: normalised device coordinates of
    /// the tile's centre go to 0 and its edges to ±1 (x' = s (x − c w), w unchanged).
    pub fn clip_from_full(&self) -> Mat4 {
        let full = self.full.max(UVec2::ONE).as_vec2();
        let size = self.size.max(UVec2::ONE).as_vec2();
        let centre = self.origin.as_vec2() + 0.5 * size;
        // Pixel rows grow downwards, device y upwards.
        let c = glam::Vec2::new(2.0 * centre.x / full.x - 1.0, 1.0 - 2.0 * centre.y / full.y);
        let s = full / size;
        Mat4::from_cols(
            glam::Vec4::new(s.x, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, s.y, 0.0, 0.0),
            glam::Vec4::Z,
            glam::Vec4::new(-c.x * s.x, -c.y * s.y, 0.0, 1.0),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec4};

    #[test]
    fn tiles_of_one_size_cover_every_pixel() {
        let full = UVec2::new(1000, 700);
        let tiles = Tile::cover(full, 256);
        assert_eq!(tiles.len(), 4 * 3);
        let mut hits = vec![0u8; (full.x * full.y) as usize];
        for t in &tiles {
            assert_eq!(t.size, UVec2::splat(256));
            assert!((t.origin + t.size).cmple(full).all(), "{t:?}");
            for y in t.origin.y..t.origin.y + t.size.y {
                for x in t.origin.x..t.origin.x + t.size.x {
                    hits[(y * full.x + x) as usize] += 1;
                }
            }
        }
        assert!(hits.iter().all(|&h| h >= 1));
        // Only the moved-back last column and row overlap their neighbours.
        assert_eq!(
            hits.iter().filter(|&&h| h > 1).count(),
            1000 * 68 + 700 * 24 - 68 * 24
        );
        assert_eq!(Tile::cover(full, 4096), vec![Tile::whole(full)]);
        assert_eq!(Tile::cover(UVec2::new(512, 256), 256).len(), 2);
    }

    #[test]
    fn a_tile_sees_its_part_of_the_image() {
        let full = UVec2::new(800, 600);
        let tile = Tile {
            full,
            origin: UVec2::new(200, 300),
            size: UVec2::new(400, 150),
        };
        let m = tile.clip_from_full();
        // A pixel centre of the image, in the whole image's device coordinates, lands on the
        // same pixel of the tile; w stays as it was.
        for (px, w) in [
            (Vec2::new(200.5, 300.5), 1.0),
            (Vec2::new(599.5, 449.5), 3.0),
        ] {
            let ndc = Vec2::new(2.0 * px.x / 800.0 - 1.0, 1.0 - 2.0 * px.y / 600.0);
            let clip = m * Vec4::new(ndc.x * w, ndc.y * w, 0.25 * w, w);
            assert_eq!(clip.w, w);
            let t = Vec2::new(clip.x, clip.y) / clip.w;
            let in_tile = Vec2::new((t.x + 1.0) * 200.0, (1.0 - t.y) * 75.0);
            assert!(
                (in_tile - (px - Vec2::new(200.0, 300.0))).length() < 1e-3,
                "{in_tile}"
            );
        }
        assert_eq!(Tile::whole(full).clip_from_full(), Mat4::IDENTITY);
    }
}
