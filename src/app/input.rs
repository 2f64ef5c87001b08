//! Keyboard shortcuts and mouse-button roles, as data the window loop and the help overlay share.

use winit::event::MouseButton;
use winit::keyboard::{Key, NamedKey};

use crate::app::command::Command;

/// Something a key press asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Pause, step or reset the simulation (as the panel's buttons do).
    Command(Command),
    /// Draw the cloth as a wireframe.
    ToggleWireframe,
    /// Draw the particles.
    ToggleParticles,
    /// Show or hide the help overlay.
    ToggleHelp,
    /// Show or hide the side panel.
    TogglePanel,
    /// Frame what the scene contains (cloths, colliders, character) from the default angle.
    FrameScene,
    /// Follow the character with the camera, or stop following it.
    ToggleFollow,
    /// Show or hide the cloths' labels in the 3-D view.
    ToggleLabels,
    /// Quit (the log, if any, is finished first).
    Quit,
}

/// Every shortcut as (keys, what it does), in the order the help overlay lists them.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("Space", "pause / resume"),
    ("S or Right", "single step (pauses)"),
    ("R", "reset the scene"),
    ("W", "wireframe on / off"),
    ("P", "particles on / off"),
    ("F or Home", "frame the scene (reset the camera)"),
    ("C", "follow the character on / off"),
    ("L", "cloth labels on / off"),
    ("Tab", "side panel on / off"),
    ("H or F1", "this help"),
    ("Esc or Q", "quit"),
];

/// What each mouse button does, for the help overlay.
pub const MOUSE: &[(&str, &str)] = &[
    ("left drag", "grab and drag the cloth"),
    ("right drag", "orbit the camera"),
    ("middle drag or Shift + right drag", "pan"),
    ("wheel", "zoom"),
];

/// The action bound to a key, if any (letters in either case).
pub fn action_for(key: &Key) -> Option<Action> {
    match key {
        Key::Named(NamedKey::Space) => Some(Action::Command(Command::TogglePause)),
        Key::Named(NamedKey::ArrowRight) => Some(Action::Command(Command::Step)),
        Key::Named(NamedKey::Escape) => Some(Action::Quit),
        Key::Named(NamedKey::Tab) => Some(Action::TogglePanel),
        Key::Named(NamedKey::F1) => Some(Action::ToggleHelp),
        Key::Named(NamedKey::Home) => Some(Action::FrameScene),
        Key::Character(c) => match c.to_lowercase().as_str() {
            "s" => Some(Action::Command(Command::Step)),
            "r" => Some(Action::Command(Command::Reset)),
            "w" => Some(Action::ToggleWireframe),
            "p" => Some(Action::ToggleParticles),
            "f" => Some(Action::FrameScene),
            "c" => Some(Action::ToggleFollow),
            "l" => Some(Action::ToggleLabels),
            "h" => Some(Action::ToggleHelp),
            "q" => Some(Action::Quit),
            _ => None,
        },
        _ => None,
    }
}

/// What a mouse drag does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DragMode {
    /// Grab the cloth under the cursor.
    Grab,
    /// Orbit the camera about its target.
    Orbit,
    /// Move the camera target in the view plane.
    Pan,
}

/// The role of a pressed button, given whether Shift is held.
pub fn drag_mode(button: MouseButton, shift: bool) -> Option<DragMode> {
    match button {
        MouseButton::Left => Some(DragMode::Grab),
        MouseButton::Right if shift => Some(DragMode::Pan),
        MouseButton::Right => Some(DragMode::Orbit),
        MouseButton::Middle => Some(DragMode::Pan),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_listed_shortcut_is_bound() {
        let key = |c: &str| Key::Character(c.into());
        assert_eq!(
            action_for(&Key::Named(NamedKey::Space)),
            Some(Action::Command(Command::TogglePause))
        );
        assert_eq!(
            action_for(&Key::Named(NamedKey::ArrowRight)),
            Some(Action::Command(Command::Step))
        );
        assert_eq!(action_for(&key("S")), Some(Action::Command(Command::Step)));
        assert_eq!(action_for(&key("r")), Some(Action::Command(Command::Reset)));
        assert_eq!(action_for(&key("w")), Some(Action::ToggleWireframe));
        assert_eq!(action_for(&key("p")), Some(Action::ToggleParticles));
        assert_eq!(action_for(&key("h")), Some(Action::ToggleHelp));
        assert_eq!(
            action_for(&Key::Named(NamedKey::F1)),
            Some(Action::ToggleHelp)
        );
        assert_eq!(
            action_for(&Key::Named(NamedKey::Tab)),
            Some(Action::TogglePanel)
        );
        assert_eq!(action_for(&key("q")), Some(Action::Quit));
        assert_eq!(action_for(&key("F")), Some(Action::FrameScene));
        assert_eq!(
            action_for(&Key::Named(NamedKey::Home)),
            Some(Action::FrameScene)
        );
        assert_eq!(action_for(&key("c")), Some(Action::ToggleFollow));
        assert_eq!(action_for(&key("L")), Some(Action::ToggleLabels));
        assert_eq!(
            action_for(&Key::Named(NamedKey::Escape)),
            Some(Action::Quit)
        );
        assert_eq!(action_for(&key("x")), None);
    }

    #[test]
    fn left_grabs_right_orbits_middle_and_shift_right_pan() {
        assert_eq!(drag_mode(MouseButton::Left, false), Some(DragMode::Grab));
        assert_eq!(drag_mode(MouseButton::Left, true), Some(DragMode::Grab));
        assert_eq!(drag_mode(MouseButton::Right, false), Some(DragMode::Orbit));
        assert_eq!(drag_mode(MouseButton::Right, true), Some(DragMode::Pan));
        assert_eq!(drag_mode(MouseButton::Middle, false), Some(DragMode::Pan));
        assert_eq!(drag_mode(MouseButton::Back, false), None);
    }
}
