//! Fixtures shared by the character tests, and (`watch`) weft-collide's test hook that checks
//! every substep.
//!
//! - `triangle`: weft-collide's reference closest point on a triangle, included by path.
//! - `watch`: weft-collide's hook that checks the particles after every substep, included by path.
#![allow(dead_code)]

#[path = "../../../../weft-collide/tests/integration/common/triangle.rs"]
pub mod triangle;
#[path = "../../../../weft-collide/tests/integration/common/watch.rs"]
pub mod watch;

/// Root (6 channels, Z X Y rotation order), Mid (Y X Z), Tip (2 channels: X Z), End Site.
/// Centimetres; frame 0 is the rest pose, frame 1 turns Mid 90° about y (and more, worked out
/// by hand in the BVH tests).
pub const TINY_BVH: &str = "HIERARCHY
ROOT Root
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Mid
  {
    OFFSET 0 10 0
    CHANNELS 3 Yrotation Xrotation Zrotation
    JOINT Tip
    {
      OFFSET 5 0 0
      CHANNELS 2 Xrotation Zrotation
      End Site
      {
        OFFSET 0 0 3
      }
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.5
0 0 0 0 0 0 0 0 0 0 0
100 200 300 90 90 0 90 0 0 90 0
";

/// Garment TOML for a tube: front and back rectangles `2·half_width` wide and `height` tall,
/// bottoms at `y`, facing each other at z = ±`z`, sewn at both sides; edge length 0.03 m.
pub fn tube_garment(half_width: f64, height: f64, y: f64, z: f64, area_density: f64) -> String {
    let (w, h) = (half_width, height);
    let outline = format!(
        "[[{:?}, 0.0], [{w:?}, 0.0], [{w:?}, {h:?}], [{:?}, {h:?}]]",
        -w, -w
    );
    format!(
        r#"edge_length = 0.03
area_density = {area_density:?}

[[panel]]
name = "front"
outline = {outline}
position = [0.0, {y:?}, {z:?}]

[[panel]]
name = "back"
outline = {outline}
position = [0.0, {y:?}, {:?}]
rotation = [0.0, 180.0, 0.0]

# Front's right side (going up) to the back's edge 3, which runs down on the same side.
[[seam]]
a = {{ panel = "front", edges = [1, 1] }}
b = {{ panel = "back", edges = [3, 3] }}
flip = true

[[seam]]
a = {{ panel = "front", edges = [3, 3] }}
b = {{ panel = "back", edges = [1, 1] }}
flip = true
"#,
        -z
    )
}

/// The vertices of `garment` (global indices) that lie at height `y` (m) in their flat panel:
/// a panel edge such as a skirt's waistband.
pub fn flat_row(garment: &weft_character::garment::Garment, y: f64) -> Vec<u32> {
    garment
        .panels
        .iter()
        .flat_map(|panel| {
            panel
                .flat
                .iter()
                .enumerate()
                .filter(move |(_, q)| (q.y - y).abs() < 1e-12)
                .map(move |(k, _)| panel.vertices.start + k as u32)
        })
        .collect()
}
