//! The panel's character section (scenes with a `[character]`): the clip the body plays, the
//! garment scene and each cloth's fabric preset. Each choice reloads the scene with overrides
//! (see `app::character`), so the clip starts again from its beginning.

use egui::{ComboBox, RichText, Ui};

use crate::app::character::{CLIPS, current_clip, garment_label};
use crate::app::panel::{Outcome, PanelState, short};
use crate::app::session::Session;

/// Draws the section if the scene has a character.
pub fn section(ui: &mut Ui, session: &mut Session, state: &mut PanelState, out: &mut Outcome) {
    if session.sim.scene.character.is_none() {
        return;
    }
    ui.label(RichText::new("Character").strong());
    let overrides = &session.sim.scene.overrides;
    let clip = current_clip(overrides);
    let mut chosen_clip = None;
    ComboBox::from_label("clip")
        .selected_text(clip.map_or("as in the scene", |i| CLIPS[i].label))
        .width(190.0)
        .show_ui(ui, |ui| {
            for (i, c) in CLIPS.iter().enumerate() {
                if ui.selectable_label(clip == Some(i), c.label).clicked() {
                    chosen_clip = Some(i);
                }
            }
        });
    if state.garments.is_none() {
        state.garments = Some(
            state
                .scenes
                .iter()
                .filter_map(|s| Some((s.clone(), garment_label(s)?)))
                .collect(),
        );
    }
    let garments = state.garments.clone().unwrap_or_default();
    let current = garments
        .iter()
        .find(|(s, _)| *s == session.source)
        .map_or_else(|| short(&session.source.label()), |(_, l)| l.clone());
    let mut chosen_garment = None;
    ComboBox::from_label("garment")
        .selected_text(current)
        .width(190.0)
        .show_ui(ui, |ui| {
            for (g, label) in &garments {
                if ui.selectable_label(*g == session.source, label).clicked() {
                    chosen_garment = Some(g.clone());
                }
            }
        });
    let mut chosen_fabric = None;
    for c in &session.sim.scene.cloths {
        let key = format!("cloth.{}.material", c.name);
        let current = overrides
            .iter()
            .rev()
            .find(|o| o.key == key)
            .map(|o| o.value.trim_matches('"').to_owned());
        ComboBox::from_label(format!("fabric ({})", c.name))
            .selected_text(current.as_deref().unwrap_or("as in the scene"))
            .show_ui(ui, |ui| {
                for (name, _, _) in weft_solver::PRESETS {
                    if ui
                        .selectable_label(current.as_deref() == Some(name), name)
                        .clicked()
                    {
                        chosen_fabric = Some((c.name.clone(), name));
                    }
                }
            });
    }
    let result = if let Some(i) = chosen_clip {
        Some(session.set_clip(i))
    } else if let Some(g) = chosen_garment.filter(|g| *g != session.source) {
        Some(session.set_garment(g))
    } else {
        chosen_fabric.map(|(cloth, preset)| session.set_fabric(&cloth, preset))
    };
    match result {
        Some(Ok(())) => {
            out.scene_changed = true;
            state.cloth = state
                .cloth
                .min(session.sim.scene.cloths.len().saturating_sub(1));
            state.error = None;
        }
        Some(Err(e)) => state.error = Some(format!("{e:#}")),
        None => {}
    }
    ui.weak("a change reloads the scene: the clip starts again");
}
