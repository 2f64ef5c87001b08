//! Which cloth is which: a label over each cloth in the 3-D view (its name and method, on a
//! swatch of its colour; L or the panel's "labels" box turns them off), and the colours the
//! panel's legend shows.

use egui::{Color32, FontId, Painter, Pos2, Rect, Stroke, StrokeKind, Vec2};
use glam::{UVec2, Vec3};
use weft_render::Camera;
use weft_sim::Simulation;
use weft_solver::Method;

/// Height above a cloth's highest particle at which its label is anchored (m).
const LIFT: f32 = 0.05;

/// The sRGB colour the renderer gives the cloth at index `i` (the front of its material).
pub fn colour(i: usize) -> Color32 {
    let [r, g, b] = weft_render::cloth_colour(i);
    egui::Rgba::from_rgb(r, g, b).into()
}

/// The method simulating cloth `i` now (the panel may have changed the scene's).
pub fn method(sim: &Simulation, i: usize) -> Method {
    sim.groups
        .iter()
        .find(|g| g.cloths.contains(&i))
        .map_or(sim.scene.cloths[i].method, |g| g.method)
}

/// What a cloth's label says: its name and the method simulating it.
pub fn text(sim: &Simulation, i: usize) -> String {
    format!("{} · {}", sim.scene.cloths[i].name, method(sim, i).name())
}

/// Where the label of cloth `i` is anchored: a little above its highest particle, at the
/// middle of the particles there (so labels of cloths side by side stay apart).
fn anchor(sim: &Simulation, i: usize) -> Option<Vec3> {
    let ps = sim.cloth_positions(i);
    let top = ps
        .iter()
        .map(|p| p.y)
        .filter(|y| y.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return None;
    }
    let band = 0.02 * (top - ps.iter().map(|p| p.y).fold(top, f64::min)).max(0.01);
    let (mut sum, mut n) = (weft_solver::glam::DVec3::ZERO, 0.0);
    for p in ps.iter().filter(|p| p.y >= top - band) {
        sum += *p;
        n += 1.0;
    }
    Some((sum / n).as_vec3() + Vec3::Y * LIFT)
}

/// Paints every cloth's label as seen by `camera` in a view of `size` physical pixels, with
/// `pixels_per_point` of them to an egui point; a label whose anchor is outside the
/// painter's clip rectangle (the 3-D view's part of the window) is left out.
pub fn paint(
    painter: &Painter,
    sim: &Simulation,
    camera: &Camera,
    size: UVec2,
    pixels_per_point: f32,
) {
    let font = FontId::proportional(13.0);
    let clip = painter.clip_rect();
    for i in 0..sim.scene.cloths.len() {
        let Some(at) = anchor(sim, i).and_then(|p| camera.project(p, size)) else {
            continue;
        };
        let at = Pos2::new(at.x, at.y) / pixels_per_point;
        if !clip.contains(at) {
            continue;
        }
        let galley = painter.layout_no_wrap(text(sim, i), font.clone(), Color32::WHITE);
        let swatch = 10.0;
        let pad = Vec2::new(6.0, 3.0);
        let inner = Vec2::new(swatch + 5.0 + galley.size().x, galley.size().y.max(swatch));
        let rect = Rect::from_min_size(
            at - Vec2::new(0.5 * inner.x + pad.x, inner.y + 2.0 * pad.y),
            inner + 2.0 * pad,
        );
        painter.rect(
            rect,
            4.0,
            Color32::from_black_alpha(190),
            Stroke::new(1.0, colour(i)),
            StrokeKind::Inside,
        );
        let sw = Rect::from_min_size(
            rect.left_center() + Vec2::new(pad.x, -0.5 * swatch),
            Vec2::splat(swatch),
        );
        painter.rect_filled(sw, 2.0, colour(i));
        painter.galley(
            Pos2::new(sw.right() + 5.0, rect.center().y - 0.5 * galley.size().y),
            galley,
            Color32::WHITE,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The four cloths of compare.toml are labelled with their names and methods, in four
    /// colours, at four different places.
    #[test]
    fn compare_labels_name_each_cloths_method_in_its_own_colour() {
        let scene = weft_scene::load(std::path::Path::new("assets/scenes/compare.toml"), &[])
            .expect("the compare scene");
        let sim = Simulation::new(scene).expect("solvers");
        let n = sim.scene.cloths.len();
        assert_eq!(n, 4);
        let texts: Vec<String> = (0..n).map(|i| text(&sim, i)).collect();
        for m in ["xpbd", "pbd", "mass-spring", "implicit-mass-spring"] {
            assert!(
                texts.iter().any(|t| t.ends_with(&format!(" · {m}"))),
                "{m}: {texts:?}"
            );
        }
        let colours: std::collections::HashSet<Color32> = (0..n).map(colour).collect();
        assert_eq!(colours.len(), n);
        let anchors: Vec<Vec3> = (0..n)
            .map(|i| anchor(&sim, i).expect("an anchor"))
            .collect();
        for a in 0..n {
            for b in a + 1..n {
                assert!((anchors[a] - anchors[b]).length() > 0.3, "{anchors:?}");
            }
        }
    }
}
