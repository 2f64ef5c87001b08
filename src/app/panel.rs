//! The egui side panel: scene and method, live parameters, statistics.
//!
//! Every widget edits a copy read from the solver this frame; a change goes through the
//! solver's validating setter, and a refused value is shown as an error (the solver keeps its
//! old value).

use std::path::{Path, PathBuf};

use egui::{ComboBox, DragValue, RichText, Ui};
use weft_solver::Method;
use weft_solver::glam::DVec3;

mod character;
mod families;
mod view;

pub use view::ViewControls;

use crate::app::command::Command;
use crate::app::session::{SceneSource, Session};

/// The panel's own state.
#[derive(Debug, Default)]
pub struct PanelState {
    /// The cloth whose parameters are shown.
    pub cloth: usize,
    /// The last refused value or failed action.
    pub error: Option<String>,
    /// The scenes offered.
    pub scenes: Vec<SceneSource>,
    /// Those of them with a character (the garments offered) and their labels, found when
    /// first shown.
    pub garments: Option<Vec<(SceneSource, String)>>,
}

/// What the window must do after the panel ran.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Outcome {
    /// The scene (and its meshes) changed: rebuild the renderer and re-frame the camera.
    pub scene_changed: bool,
    /// The pause, step or reset button that was pressed (one per frame).
    pub command: Option<Command>,
    /// The "frame scene" button was pressed.
    pub frame: bool,
    /// How much wider than the panel its contents are (points; 0 or less when they fit).
    pub overflow: f32,
}

/// The built-in scene, then every `*.toml` in `dir` (sorted) but the file the built-in scene
/// was compiled from (the same scene under the same name).
pub fn list_scenes(dir: &Path) -> Vec<SceneSource> {
    let builtin = |p: &Path| {
        p.file_name() == Path::new(crate::default_scene::NAME).file_name()
            && std::fs::read_to_string(p).is_ok_and(|t| t == crate::default_scene::HANGING)
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "toml") && !builtin(p))
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    std::iter::once(SceneSource::Default)
        .chain(files.into_iter().map(SceneSource::File))
        .collect()
}

fn note(state: &mut PanelState, r: Result<(), impl std::fmt::Display>) {
    if let Err(e) = r {
        state.error = Some(e.to_string());
    }
}

/// Draws the panel's contents, scrolling when they are taller or wider than the panel.
pub fn show(
    ui: &mut Ui,
    session: &mut Session,
    state: &mut PanelState,
    controls: &mut ViewControls<'_>,
) -> Outcome {
    let mut out = Outcome::default();
    // Solid scroll bars take their own room: egui's default floating ones are drawn over the
    // contents, a thin line through the text whenever the pointer is on the panel.
    ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
    let scrolled = egui::ScrollArea::both().show(ui, |ui| {
        ui.heading("Weft");
        scene_section(ui, session, state, &mut out);
        ui.separator();
        if session.sim.scene.character.is_some() {
            character::section(ui, session, state, &mut out);
            ui.separator();
        }
        stats_section(ui, session);
        ui.separator();
        solver_section(ui, session, state);
        ui.separator();
        cloth_section(ui, session, state);
        ui.separator();
        view::section(ui, session, controls, &mut out);
        if let Some(e) = &state.error {
            ui.separator();
            ui.colored_label(egui::Color32::from_rgb(255, 110, 110), e);
            if ui.small_button("dismiss").clicked() {
                state.error = None;
            }
        }
    });
    out.overflow = scrolled.content_size.x - scrolled.inner_rect.width();
    out
}

fn scene_section(ui: &mut Ui, session: &mut Session, state: &mut PanelState, out: &mut Outcome) {
    let current = session.source.label();
    let mut chosen = None;
    ComboBox::from_label("scene")
        .selected_text(short(&current))
        .width(190.0)
        .show_ui(ui, |ui| {
            for s in &state.scenes {
                if ui
                    .selectable_label(*s == session.source, short(&s.label()))
                    .clicked()
                {
                    chosen = Some(s.clone());
                }
            }
        });
    if let Some(s) = chosen
        && s != session.source
    {
        match session.switch_scene(s) {
            Ok(()) => {
                out.scene_changed = true;
                state.cloth = 0;
                state.error = None;
            }
            Err(e) => state.error = Some(format!("{e:#}")),
        }
    }
    let method = session
        .sim
        .groups
        .first()
        .map_or(Method::Xpbd, |g| g.solver.settings().method);
    let mixed = session
        .sim
        .groups
        .iter()
        .any(|g| g.solver.settings().method != method);
    let mut chosen_method = None;
    ComboBox::from_label("method")
        .selected_text(if mixed { "mixed" } else { method.name() })
        .show_ui(ui, |ui| {
            for candidate in Method::ALL {
                let on = !mixed && candidate == method;
                if ui.selectable_label(on, candidate.name()).clicked() {
                    chosen_method = Some(candidate);
                }
            }
        });
    if let Some(m) = chosen_method {
        let r = session.set_method(m);
        note(state, r);
    }
    for g in &session.sim.groups {
        for i in 0..g.solver.cloths().len() {
            if let Some(v) = crate::stability::verdict(&g.solver, i) {
                let color = if v.ok {
                    ui.visuals().weak_text_color()
                } else {
                    egui::Color32::from_rgb(255, 110, 110)
                };
                ui.colored_label(color, v.text);
            }
        }
    }
    ui.horizontal(|ui| {
        let paused = session.clock.paused();
        let buttons = [
            (if paused { "run" } else { "pause" }, Command::TogglePause),
            ("step", Command::Step),
            ("reset", Command::Reset),
        ];
        for (label, command) in buttons {
            if ui.button(label).clicked() {
                out.command = Some(command);
            }
        }
    });
    if let Some(m) = &session.diverged {
        ui.colored_label(
            egui::Color32::from_rgb(255, 110, 110),
            format!("diverged: {m} (R resets)"),
        );
    }
    if session.log.is_some() {
        ui.label("recording to MCAP");
    }
}

pub(crate) fn short(label: &str) -> String {
    Path::new(label)
        .file_name()
        .map_or_else(|| label.to_owned(), |f| f.to_string_lossy().into_owned())
        .trim_end_matches(')')
        .to_owned()
}

fn stats_section(ui: &mut Ui, session: &Session) {
    let s = &session.stats;
    let particles: usize = session
        .sim
        .groups
        .iter()
        .map(|g| g.solver.particles().len())
        .sum();
    let constraints: usize = session
        .sim
        .groups
        .iter()
        .map(|g| g.solver.constraints().len())
        .sum();
    let time: f64 = session.sim.groups.first().map_or(0.0, |g| g.solver.time());
    egui::Grid::new("stats").num_columns(2).show(ui, |ui| {
        let mut row = |k: &str, v: String, tip: &str| {
            ui.label(k).on_hover_text(tip);
            ui.label(v).on_hover_text(tip);
            ui.end_row();
        };
        row(
            "step",
            format!("{:.2} ms", s.step_ms),
            "wall-clock time of the last simulation frame",
        );
        row(
            "frame",
            format!("{:.1} ms", s.frame_ms),
            "wall-clock time between drawn frames",
        );
        row(
            "particles",
            particles.to_string(),
            "particles of every cloth",
        );
        row(
            "constraints",
            constraints.to_string(),
            "constraints of every family and cloth",
        );
        row(
            "contacts",
            s.contacts.to_string(),
            "cloth–collider contacts in the last frame",
        );
        row(
            "stretch error",
            format!("{:.2} mm", s.stretch_error * 1e3),
            "the largest |C| over the stretch and shear constraints after the last frame: how far \
             the stiffest edge stands from its rest length",
        );
        if s.cg_iterations > 0 {
            row(
                "CG iterations",
                s.cg_iterations.to_string(),
                "conjugate-gradient iterations of the last frame, every substep together: \
                 implicit mass-spring's solve, XPBD's solve of stiff bending (with the stretch \
                 on small cloths)",
            );
        }
        if let Some(b) = s.bending_residual {
            row(
                "bending residual",
                format!("{b:.1e}"),
                "how far XPBD's last substep left the bending hinges from their equation: 0 \
                 converged, 1 a hinge about twice as soft as its compliance",
            );
        }
        if let Some(c) = &s.crossings {
            row(
                "crossings",
                crate::crossing_report::frame_text(c),
                "edge–triangle crossings between cloth elements in the last frame (0 while \
                 contact holds), and how close non-adjacent elements came, by a count \
                 independent of contact",
            );
        }
        let open: Vec<String> = (0..session.sim.scene.cloths.len())
            .filter_map(|i| session.sim.open_seams(i))
            .map(|s| format!("{}: {} of {}", s.cloth, s.open, s.pairs))
            .collect();
        if !open.is_empty() {
            let tip = format!(
                "seam pairs still over {} mm apart {} s after the cloth's seam_time: something \
                 holds them (a fold caught in the seam, the body's friction, soft springs); a \
                 longer seam_time gives the panels time to settle as they close",
                weft_sim::seams::OPEN_GAP * 1e3,
                weft_sim::seams::SETTLE
            );
            row("open seams", open.join(", "), &tip);
        }
        row(
            "sim time",
            format!("{time:.3} s"),
            "simulated time since the start or the last reset",
        );
        row(
            "frames",
            session.sim.frame().to_string(),
            "simulated frames since the start or the last reset",
        );
        let grabbed = session.grab.map_or_else(
            || "nothing (left-drag the cloth)".to_owned(),
            |g| {
                let name = session
                    .sim
                    .scene
                    .cloths
                    .get(g.cloth)
                    .map_or("?", |c| c.name.as_str());
                format!("{name} particle {}", g.particle)
            },
        );
        row("grabbed", grabbed, "the particle the mouse holds");
        let dropped = session.clock.dropped_total();
        row(
            "dropped",
            if dropped > 0 {
                format!("{dropped} frames (slower than real time)")
            } else {
                "0".into()
            },
            "frames of real time the simulation skipped to keep up (--max-steps-per-frame)",
        );
    });
}

fn drag_f64(ui: &mut Ui, label: &str, v: &mut f64, speed: f64, tip: &str) -> bool {
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(tip);
        ui.add(DragValue::new(v).speed(speed).max_decimals(9))
            .on_hover_text(tip)
            .changed()
    })
    .inner
}

fn drag_vec(ui: &mut Ui, label: &str, v: &mut DVec3, speed: f64, tip: &str) -> bool {
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(tip);
        let mut changed = false;
        for (c, axis) in [(&mut v.x, "x"), (&mut v.y, "y"), (&mut v.z, "z")] {
            changed |= ui
                .add(DragValue::new(c).speed(speed))
                .on_hover_text(format!("{tip}: its {axis} component"))
                .changed();
        }
        changed
    })
    .inner
}

fn solver_section(ui: &mut Ui, session: &mut Session, state: &mut PanelState) {
    let Some(first) = session.sim.groups.first() else {
        return;
    };
    ui.label(RichText::new("Solver (every method)").strong());
    let mut settings = *first.solver.settings();
    let mut forces = *first.solver.forces();
    let mut changed = false;
    let mut dt_ms = settings.dt * 1e3;
    if drag_f64(
        ui,
        "time step (ms)",
        &mut dt_ms,
        0.1,
        "the simulated time of one frame, ms (sim.dt)",
    ) {
        settings.dt = dt_ms * 1e-3;
        changed = true;
    }
    ui.horizontal(|ui| {
        ui.label("substeps");
        changed |= ui
            .add(DragValue::new(&mut settings.substeps).speed(0.2))
            .on_hover_text("solver substeps per frame (sim.substeps)")
            .changed();
        ui.label("iterations");
        changed |= ui
            .add(DragValue::new(&mut settings.iterations).speed(0.2))
            .on_hover_text("constraint sweeps per substep (sim.iterations)")
            .changed();
    });
    if changed {
        let r = session.sim.set_settings(settings);
        note(state, r);
    }
    let mut fchanged = drag_vec(
        ui,
        "gravity",
        &mut forces.gravity,
        0.05,
        "gravity, m/s² (sim.gravity)",
    );
    fchanged |= drag_vec(
        ui,
        "wind",
        &mut forces.wind.velocity,
        0.05,
        "wind velocity, m/s (wind.velocity)",
    );
    fchanged |= drag_f64(
        ui,
        "wind drag (1/s)",
        &mut forces.wind.drag,
        0.01,
        "how fast each particle is pulled towards the wind's velocity, 1/s (wind.drag)",
    );
    fchanged |= drag_f64(
        ui,
        "damping (1/s)",
        &mut forces.damping,
        0.01,
        "global velocity damping, 1/s (sim.damping)",
    );
    if fchanged {
        let r = session.sim.set_forces(forces);
        note(state, r);
    }
}

fn cloth_section(ui: &mut Ui, session: &mut Session, state: &mut PanelState) {
    let cloths = &session.sim.scene.cloths;
    if cloths.is_empty() {
        return;
    }
    state.cloth = state.cloth.min(cloths.len() - 1);
    let names: Vec<String> = cloths.iter().map(|c| c.name.clone()).collect();
    ComboBox::from_label("cloth")
        .selected_text(names[state.cloth].clone())
        .show_ui(ui, |ui| {
            for (i, n) in names.iter().enumerate() {
                ui.selectable_value(&mut state.cloth, i, n);
            }
        });
    let cloth = state.cloth;
    let (Some(mut params), Some(mut thickness)) = (
        session.sim.cloth_params(cloth),
        session.sim.thickness(cloth),
    ) else {
        return;
    };
    if drag_f64(
        ui,
        "thickness (m)",
        &mut thickness,
        0.0005,
        "collision thickness: how far the cloth keeps from colliders and itself, m",
    ) {
        let r = session.sim.set_thickness(cloth, thickness);
        note(state, r);
    }
    let method = crate::app::labels::method(&session.sim, cloth);
    let changed = families::grid(ui, method, &mut params);
    if changed {
        let r = session.sim.set_cloth_params(cloth, params);
        note(state, r);
    }
    ui.label(
        RichText::new(format!(
            "{} values; families off in the scene are not listed",
            method.name()
        ))
        .small()
        .weak(),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::camera::ViewCamera;
    use crate::app::window::panel_width;

    /// Lays the panel out for `scene` in a window of `w`×`h` points, as the window does;
    /// returns what the panel reported and the panel's rectangle.
    fn lay_out(scene: &str, w: f32, h: f32) -> (Outcome, egui::Rect) {
        let source = SceneSource::File(PathBuf::from(scene));
        let sim =
            weft_sim::Simulation::new(source.load(&[]).expect("the scene loads")).expect("solvers");
        let mut session = Session::new(sim, source, 4);
        let mut state = PanelState {
            scenes: list_scenes(Path::new("assets/scenes")),
            ..Default::default()
        };
        let mut options = weft_render::RenderOptions::default();
        let mut camera = ViewCamera::new(weft_render::Camera::default(), &session.sim);
        let mut labels = true;
        let ctx = egui::Context::default();
        let mut result = (Outcome::default(), egui::Rect::NOTHING);
        // Twice: egui settles some sizes on its first pass.
        for _ in 0..2 {
            let input = egui::RawInput {
                screen_rect: Some(egui::Rect::from_min_size(
                    egui::Pos2::ZERO,
                    egui::vec2(w, h),
                )),
                ..Default::default()
            };
            let output = ctx.run_ui(input, |ui| {
                let mut controls = ViewControls {
                    options: &mut options,
                    camera: &mut camera,
                    labels: &mut labels,
                };
                let r = egui::Panel::right("weft-panel")
                    .exact_size(panel_width(w))
                    .resizable(false)
                    .show(ui, |ui| show(ui, &mut session, &mut state, &mut controls));
                result = (r.inner, r.response.rect);
            });
            output.drop_without_applying_deltas();
        }
        result
    }

    /// At 1280×800 the panel's contents fit its width on every shipped scene (the character,
    /// glTF and flag scenes once had their "spring k" column cut off), and the panel lies
    /// inside its window.
    #[test]
    fn the_panel_fits_its_window_on_every_shipped_scene() {
        for source in list_scenes(Path::new("assets/scenes")) {
            let SceneSource::File(path) = source else {
                continue;
            };
            let scene = path.to_string_lossy();
            let (out, rect) = lay_out(&scene, 1280.0, 800.0);
            assert!(
                out.overflow <= 0.0,
                "{scene}: {} points too wide",
                out.overflow
            );
            assert!(
                rect.min.x >= 0.0 && rect.max.x <= 1280.0,
                "{scene}: {rect:?}"
            );
            assert!(rect.width() <= 300.5, "{scene}: {rect:?}");
        }
        // A narrow window keeps most of its width for the 3-D view.
        let (_, rect) = lay_out("assets/scenes/character.toml", 400.0, 600.0);
        assert!(rect.width() <= 240.5 && rect.max.x <= 400.0, "{rect:?}");
    }

    #[test]
    fn the_shipped_scenes_list_the_hanging_cloth_once() {
        let scenes = list_scenes(Path::new("assets/scenes"));
        let labels: Vec<String> = scenes.iter().map(|s| short(&s.label())).collect();
        let hanging = labels.iter().filter(|l| *l == "hanging.toml").count();
        assert_eq!(hanging, 1, "{labels:?}");
        assert_eq!(scenes[0], SceneSource::Default);
        assert!(labels.iter().any(|l| l == "compare.toml"), "{labels:?}");
    }
}
