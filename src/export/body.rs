//! The character's body in an export: each body part a collider track, its mesh made once in
//! its own frame (as the viewer draws it) and its pose at each exported frame from
//! `/colliders/state` (or, in a log without that channel, the character's own pose then).

use weft_collide::KinematicBody;
use weft_scene::Scene;

use crate::export::collider_track::{ColliderTrack, logged_pose};
use weft_sim::body::{PartPose, mesh, part_name};

/// One track per body part of `scene`'s character (none without one).
pub fn tracks(
    scene: &Scene,
    has_states: bool,
    states: &[Option<serde_json::Value>],
    frames: &[u64],
    times: &[f64],
) -> anyhow::Result<Vec<ColliderTrack>> {
    let Some(spec) = &scene.character else {
        return Ok(Vec::new());
    };
    let mut parts = Vec::new();
    spec.character.parts_at(0.0, &mut parts);
    let mut per_frame: Vec<Vec<weft_collide::BodyPart>> = Vec::new();
    if !has_states {
        for &t in times {
            let mut p = Vec::new();
            spec.character.parts_at(t, &mut p);
            per_frame.push(p);
        }
    }
    let mut out = Vec::with_capacity(parts.len());
    for (i, part) in parts.iter().enumerate() {
        let name = part_name(i);
        let p = PartPose::of(part);
        let (vertices, triangles) = mesh::round_cone(p.r0, p.r1, p.half_height());
        let poses = (0..times.len())
            .map(|k| {
                if has_states {
                    logged_pose(states, k, frames, &name)
                } else {
                    let p = PartPose::of(&per_frame[k][i]);
                    Ok((p.position, p.rotation))
                }
            })
            .collect::<anyhow::Result<_>>()?;
        out.push(ColliderTrack {
            name,
            vertices,
            triangles,
            poses,
        });
    }
    Ok(out)
}

/// Number of body parts `scene`'s character has (0 without one).
pub fn part_count(scene: &Scene) -> usize {
    scene
        .character
        .as_ref()
        .map_or(0, |c| c.character.part_count())
}
