//! The built-in default scene: `assets/scenes/hanging.toml`, compiled in so there is one source.

use weft_scene::{DirFiles, Override, Scene, SceneErrors};

/// The default scene's text.
pub const HANGING: &str = include_str!("../assets/scenes/hanging.toml");

/// The name the default scene goes by in messages and logs.
pub const NAME: &str = "assets/scenes/hanging.toml";

/// Loads the built-in default scene with `overrides`.
pub fn load(overrides: &[Override]) -> Result<Scene, SceneErrors> {
    weft_scene::from_text(NAME, HANGING, overrides, &DirFiles(".".into()))
}
