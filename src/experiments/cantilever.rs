//! The cantilever bending test (ASTM D1388) in an experiments file: a `[cantilever]` table
//! names the scene's strip cloth and its overhang in bending lengths; each run's strip is then
//! shaped from its own material (overhang, square cells, two clamped columns), with
//! `cantilever.segments` swept like a scene key (and `cantilever.direction`, the strip cut
//! along the `"warp"` or the `"weft"`), and the run measures the chord angle against the heavy
//! elastica's.

use std::path::Path;

use anyhow::{Context, bail};
use serde::Deserialize;
use weft_scene::Override;
use weft_solver::{Cantilever, Direction, Material};

/// The key that sets the segments along the overhang (swept, or in `set`).
pub const SEGMENTS_KEY: &str = "cantilever.segments";

/// The key that cuts the strip along the warp or the weft (swept, or in `set`).
pub const DIRECTION_KEY: &str = "cantilever.direction";

/// `[cantilever]` of an experiments file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverSpec {
    /// The scene's cloth that is the strip.
    pub cloth: String,
    /// The overhang in bending lengths c = (B/w)^(1/3) (ASTM D1388's 41.5° plane: 2).
    #[serde(default = "two")]
    pub lengths: f64,
}

fn two() -> f64 {
    2.0
}

/// One run's strip: its shape, the cloth's material and the gravity it bends under.
#[derive(Clone, Copy, Debug)]
pub struct Strip {
    /// The strip's geometry.
    pub shape: Cantilever,
    /// Its material.
    pub material: Material,
    /// |gravity| (m/s²).
    pub g: f64,
    /// The strip's index among the scene's cloths.
    pub cloth: usize,
}

impl Strip {
    /// Chord angle of the strip at `positions` (degrees below the horizontal).
    pub fn chord_angle(&self, positions: &[weft_solver::glam::DVec3]) -> f64 {
        self.shape.chord_angle(positions).to_degrees()
    }

    /// The heavy elastica's chord angle for the strip (degrees), NaN out of its range.
    pub fn elastica_angle(&self) -> f64 {
        self.shape
            .elastica(&self.material, self.g)
            .map_or(f64::NAN, |e| e.chord_angle().to_degrees())
    }
}

/// A run's `overrides` with the strip shaped from its material: `cantilever.segments` taken
/// out, the strip's resolution, size, centre, orientation and clamp put in; and the strip.
/// Without a `[cantilever]` table, the overrides as they are.
pub fn prepare(
    spec: Option<&CantileverSpec>,
    scene_path: &Path,
    run_overrides: &[Override],
    limits: &weft_scene::Limits,
) -> anyhow::Result<(Vec<Override>, Option<Strip>)> {
    let Some(spec) = spec else {
        return Ok((run_overrides.to_vec(), None));
    };
    if !(spec.lengths.is_finite() && spec.lengths > 0.0) {
        bail!(
            "cantilever.lengths must be finite and > 0, got {}",
            spec.lengths
        );
    }
    let mut segments = None;
    let mut direction = Direction::Warp;
    let mut overrides = Vec::new();
    for o in run_overrides {
        if o.key == DIRECTION_KEY {
            direction = match o.value.trim().trim_matches('"') {
                "warp" => Direction::Warp,
                "weft" => Direction::Weft,
                other => bail!("{DIRECTION_KEY} must be \"warp\" or \"weft\", got {other}"),
            };
        } else if o.key == SEGMENTS_KEY {
            let n = o
                .value
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|n| n.fract() == 0.0 && (1.0..=4096.0).contains(n))
                .with_context(|| {
                    format!(
                        "{SEGMENTS_KEY} must be a whole number in 1..=4096, got {}",
                        o.value
                    )
                })?;
            segments = Some(n as usize);
        } else {
            overrides.push(o.clone());
        }
    }
    let segments = segments.with_context(|| format!("[cantilever] needs `{SEGMENTS_KEY}`"))?;
    let scene = weft_scene::load_with(scene_path, &overrides, limits)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let name = &spec.cloth;
    let cloth = scene
        .cloths
        .iter()
        .position(|c| &c.name == name)
        .with_context(|| format!("cantilever.cloth: the scene has no cloth `{name}`"))?;
    let material = scene
        .file
        .cloth
        .get(name)
        .and_then(|c| c.material.as_ref())
        .with_context(|| format!("cantilever: cloth `{name}` needs a `material`"))?;
    let material = weft_scene::material::resolve(material)
        .map_err(|(field, message)| anyhow::anyhow!("cloth.{name}.{field}: {message}"))?;
    let g = scene.forces.gravity.length();
    if g.is_nan() || g <= 0.0 {
        bail!("cantilever: the scene needs gravity");
    }
    let shape = Cantilever::of_material_along(&material, direction, g, spec.lengths, segments);
    let grid = shape.grid(material.density);
    let list = |v: &[f64]| {
        format!(
            "[{}]",
            v.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let key = |k: &str| format!("cloth.{name}.{k}");
    let (cols, rows) = grid.resolution;
    let pins: Vec<String> = shape.clamp().iter().map(u32::to_string).collect();
    for (k, v) in [
        (key("resolution"), format!("[{cols}, {rows}]")),
        (key("size"), list(&[grid.size.0, grid.size.1])),
        (key("center"), list(&grid.center.to_array())),
        (key("orientation"), "\"horizontal\"".to_owned()),
        (key("pins"), format!("[{}]", pins.join(", "))),
    ] {
        overrides.push(format!("{k}={v}").parse::<Override>()?);
    }
    let strip = Strip {
        shape,
        material,
        g,
        cloth,
    };
    Ok((overrides, Some(strip)))
}
