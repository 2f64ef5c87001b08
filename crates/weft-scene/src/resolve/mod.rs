//! Validation: turns a deserialised [`SceneFile`] into a checked [`Scene`](crate::Scene) with
//! solver types, reporting every bad value with its key and line. The [`Checker`] holds the
//! shared checks; a cloth, a collider each have their own file.
//!
//! Its modules:
//!
//! - `character`: the `[character]` table, checked and built into a `CharacterSpec`.
//! - `checker`: the `Checker`, which collects every error, and the shared checks.
//! - `cloth`: a `[cloth.<name>]` table, checked and built into a `ClothSpec`.
//! - `collider`: a `[[collider]]` table, checked into a `ColliderSpec`.
//! - `garment`: a garment cloth: its panels built into a mesh, its seams and its attachments.
//! - `model`: a skinned glTF character (`[character] model`): read, animated and placed.
//! - `pins`: a cloth's `pins` and `held` lists, checked into solver pins or vertex indices.

mod character;
mod checker;
mod cloth;
mod collider;
mod garment;
mod model;
mod pins;

use weft_collide::SelfCollisionParams;
use weft_solver::{Aero, Forces, Settings, Wind};

use crate::ranges;
use crate::scene::{CharacterSpec, ClothSpec, ColliderSpec, ModelSpec, SelfCollisionSpec};
use crate::schema::SceneFile;

use character::character;
pub(crate) use checker::Checker;
use cloth::cloth;
use collider::collider;
use garment::Rig;
use model::model;

/// Checks every value of `file` and resolves it into solver types.
pub(crate) fn resolve(file: &SceneFile, c: &mut Checker<'_>) -> Option<ResolvedParts> {
    let sim = &file.sim;
    let dt = sim.dt.0;
    c.within("sim.dt", dt, &ranges::DT);
    let count = |c: &mut Checker<'_>, key: &str, v: i64| -> u32 {
        if !(1..=100_000).contains(&v) {
            c.bad(key, format!("must be an integer in 1..=100000, got {v}"));
            1
        } else {
            v as u32
        }
    };
    let substeps = count(c, "sim.substeps", sim.substeps);
    let iterations = count(c, "sim.iterations", sim.iterations);
    let sweeps = u64::from(substeps) * u64::from(iterations);
    if sweeps > ranges::SWEEPS_PER_FRAME {
        c.bad(
            "sim.iterations",
            format!(
                "substeps x iterations = {sweeps} constraint sweeps per frame, more than {}: \
                 one frame would take minutes (no scene needs that many)",
                ranges::SWEEPS_PER_FRAME
            ),
        );
    }
    let gravity = c.vector("sim.gravity", sim.gravity);
    c.within("sim.damping", sim.damping, &ranges::RATE);
    c.within(
        "sim.divergence_bound",
        sim.divergence_bound,
        &ranges::DIVERGENCE_BOUND,
    );
    let cg_max_iterations = count(c, "sim.cg_max_iterations", sim.cg_max_iterations);
    c.within("sim.cg_tolerance", sim.cg_tolerance, &ranges::CG_TOLERANCE);
    let settings = Settings {
        method: sim.method.into(),
        dt,
        substeps,
        iterations,
        divergence_bound: sim.divergence_bound,
        cg_max_iterations,
        cg_tolerance: sim.cg_tolerance,
        ..Settings::default()
    };
    let mut wind = Wind::default();
    if let Some(w) = &file.wind {
        wind.velocity = c.vector("wind.velocity", w.velocity);
        c.within("wind.drag", w.drag, &ranges::RATE);
        wind.drag = w.drag;
        if let Some(a) = &w.aero {
            c.non_negative("wind.aero.air_density", a.air_density);
            c.non_negative("wind.aero.drag_coefficient", a.drag_coefficient);
            c.non_negative("wind.aero.lift_coefficient", a.lift_coefficient);
            wind.aero = Some(Aero {
                air_density: a.air_density,
                drag_coefficient: a.drag_coefficient,
                lift_coefficient: a.lift_coefficient,
            });
        }
    }
    let forces = Forces {
        gravity,
        wind,
        damping: sim.damping,
    };
    if file.cloth.is_empty() {
        c.bad("cloth", "a scene needs at least one [cloth.<name>] table");
    }
    let (character, model) = match &file.character {
        Some(s) if s.model.is_some() => (None, model(c, s)),
        Some(s) => (character(c, s), None),
        None => (None, None),
    };
    let rig = Rig {
        character: character.as_ref(),
        model: model.as_ref(),
        present: file.character.is_some(),
    };
    let cloths: Vec<ClothSpec> = file
        .cloth
        .iter()
        .filter_map(|(name, section)| cloth(c, name, section, &settings, rig))
        .collect();
    let colliders: Vec<ColliderSpec> = file
        .collider
        .iter()
        .enumerate()
        .filter_map(|(i, s)| collider(c, i, s))
        .collect();
    let self_collision = file.self_collision.as_ref().and_then(|s| {
        let names: Vec<String> = s
            .cloths
            .clone()
            .unwrap_or_else(|| file.cloth.keys().cloned().collect());
        for (i, n) in names.iter().enumerate() {
            if !file.cloth.contains_key(n) {
                c.bad(
                    &format!("self_collision.cloths[{i}]"),
                    format!("no cloth named `{n}`"),
                );
            }
        }
        c.friction("self_collision", s.static_friction, s.dynamic_friction);
        // The ranges are weft-collide's, the one authority on them.
        c.rule(
            "self_collision.max_displacement",
            s.max_displacement,
            SelfCollisionParams::check_max_displacement,
        );
        c.rule(
            "self_collision.search_margin",
            s.search_margin,
            SelfCollisionParams::check_search_margin,
        );
        s.enabled.then_some(SelfCollisionSpec {
            cloths: names,
            static_friction: s.static_friction,
            dynamic_friction: s.dynamic_friction,
            max_displacement: s.max_displacement,
            search_margin: s.search_margin,
            adaptive_search_margin: s.adaptive_search_margin,
            contact: s.contact,
        })
    });
    c.errors.is_empty().then_some(ResolvedParts {
        settings,
        forces,
        cloths,
        colliders,
        self_collision,
        character,
        model,
    })
}

/// What [`resolve`] yields.
pub(crate) struct ResolvedParts {
    pub settings: Settings,
    pub forces: Forces,
    pub cloths: Vec<ClothSpec>,
    pub colliders: Vec<ColliderSpec>,
    pub self_collision: Option<SelfCollisionSpec>,
    pub character: Option<CharacterSpec>,
    pub model: Option<ModelSpec>,
}

pub(super) fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '-')
}
