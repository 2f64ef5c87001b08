//! A collider's track over the exported frames, and its pose as `/colliders/state` logged it.

use anyhow::Context;
use glam::Vec3;
use weft_solver::glam::{DQuat, DVec3};

use weft_record::collider_state;

/// One collider over the exported frames.
pub struct ColliderTrack {
    /// The collider's name.
    pub name: String,
    /// Its shape as triangles, in its own frame.
    pub vertices: Vec<Vec3>,
    /// Triangles of `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// World pose (position, rotation) per exported frame.
    pub poses: Vec<(DVec3, DQuat)>,
}

/// A collider's pose as `/colliders/state` writes it.
fn pose_of(v: &serde_json::Value) -> Option<(DVec3, DQuat)> {
    let n = |a: &serde_json::Value, i: usize| a.get(i)?.as_f64();
    let (p, r) = (&v["position"], &v["rotation"]);
    Some((
        DVec3::new(n(p, 0)?, n(p, 1)?, n(p, 2)?),
        DQuat::from_xyzw(n(r, 0)?, n(r, 1)?, n(r, 2)?, n(r, 3)?),
    ))
}

/// Collider `name`'s pose at exported frame `k` as `/colliders/state` logged it.
pub fn logged_pose(
    states: &[Option<serde_json::Value>],
    k: usize,
    frames: &[u64],
    name: &str,
) -> anyhow::Result<(DVec3, DQuat)> {
    let state = states[k].as_ref().with_context(|| {
        format!(
            "{} has no message at frame {}",
            collider_state::TOPIC,
            frames[k]
        )
    })?;
    let entry = state["colliders"]
        .as_array()
        .and_then(|cs| cs.iter().find(|c| c["name"] == name))
        .with_context(|| {
            format!(
                "{} at frame {} does not list collider {name}",
                collider_state::TOPIC,
                frames[k],
            )
        })?;
    pose_of(entry).with_context(|| {
        format!(
            "{} at frame {}: collider {name} has no position or rotation",
            collider_state::TOPIC,
            frames[k],
        )
    })
}
