//! The panel's view section: what is drawn (wireframe, particles, grid, shadows, labels),
//! the camera (frame the scene, follow the character), and the legend naming each cloth's
//! method beside its colour.

use egui::{RichText, Ui, Vec2};
use weft_render::RenderOptions;

use crate::app::camera::ViewCamera;
use crate::app::labels;
use crate::app::panel::Outcome;
use crate::app::session::Session;

/// What the view section changes: the renderer's layers, the camera and the labels.
pub struct ViewControls<'a> {
    /// Layers the renderer draws.
    pub options: &'a mut RenderOptions,
    /// The camera (its "follow" switch; the frame button asks through [`Outcome`]).
    pub camera: &'a mut ViewCamera,
    /// Whether the cloths are labelled in the 3-D view.
    pub labels: &'a mut bool,
}

/// Draws the section.
pub fn section(ui: &mut Ui, session: &Session, view: &mut ViewControls<'_>, out: &mut Outcome) {
    ui.label(RichText::new("View").strong());
    let o = &mut *view.options;
    ui.horizontal_wrapped(|ui| {
        ui.checkbox(&mut o.wireframe, "wireframe (W)");
        ui.checkbox(&mut o.particles, "particles (P)");
        ui.checkbox(&mut o.grid, "grid");
        ui.checkbox(&mut o.shadows, "shadows");
        ui.checkbox(view.labels, "labels (L)")
            .on_hover_text("each cloth's name and method over it in the 3-D view");
    });
    ui.horizontal_wrapped(|ui| {
        if ui
            .button("frame scene (F)")
            .on_hover_text("look at everything the scene holds from the default angle")
            .clicked()
        {
            out.frame = true;
        }
        let can = view.camera.can_follow();
        ui.add_enabled(
            can,
            egui::Checkbox::new(&mut view.camera.follow, "follow (C)"),
        )
        .on_hover_text("the camera moves with the character's hips")
        .on_disabled_hover_text("no character in this scene to follow");
    });
    legend(ui, session);
}

/// One row per cloth: its colour, its name and the method that simulates it.
fn legend(ui: &mut Ui, session: &Session) {
    let sim = &session.sim;
    if sim.scene.cloths.is_empty() {
        return;
    }
    ui.label(RichText::new("Cloths").strong());
    for (i, c) in sim.scene.cloths.iter().enumerate() {
        let method = labels::method(sim, i).name();
        ui.horizontal(|ui| {
            let (rect, _) = ui.allocate_exact_size(Vec2::splat(12.0), egui::Sense::hover());
            ui.painter().rect_filled(rect, 2.0, labels::colour(i));
            ui.label(format!("{} · {method}", c.name))
                .on_hover_text(format!("cloth {:?}, simulated by {method}", c.name));
        });
    }
}
