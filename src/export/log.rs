//! What an export reads from a log: the logged frames (from `/stats`), each cloth's triangles
//! (the first `/cloth/<name>/mesh` message, or the logged scene's when the log has no surface),
//! its positions at the chosen frames (`/cloth/<name>/particles`, or the surface's points in a
//! log without particles), and each collider's mesh in
//! its own frame (the logged scene's shape, tessellated) with its pose at those frames
//! (`/colliders/state`, or the scene's prescribed motion for logs written before that channel).

use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, bail};
use foxglove::Decode;
use foxglove::messages::{PointCloud, SceneUpdate};
use weft_scene::Scene;

use super::collider_track::{ColliderTrack, logged_pose};
use crate::stop::Stopped;
use weft_record::collider_state::{self, ColliderState};

/// One cloth over the exported frames.
pub struct ClothTrack {
    /// The cloth's name.
    pub name: String,
    /// Its colour (the method's, as the log draws it), RGBA.
    pub color: [f32; 4],
    /// Its triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Positions per exported frame, as logged (float32).
    pub positions: Vec<Vec<[f32; 3]>>,
}

/// Everything an export writes.
pub struct Tracks {
    /// The exported frames' numbers.
    pub frames: Vec<u64>,
    /// Their simulated times (s).
    pub times: Vec<f64>,
    /// Cloths, in the scene's order.
    pub cloths: Vec<ClothTrack>,
    /// Colliders, in the scene's order, then the character's body parts.
    pub colliders: Vec<ColliderTrack>,
}

/// The frames a log holds: frame number by log time, from `/stats`.
pub fn logged_frames(bytes: &[u8], stop: &AtomicBool) -> anyhow::Result<BTreeMap<u64, u64>> {
    let mut frames = BTreeMap::new();
    for m in mcap::MessageStream::new(bytes)? {
        if stop.load(Ordering::Relaxed) {
            return Err(Stopped.into());
        }
        let m = m?;
        if m.channel.topic != "/stats" {
            continue;
        }
        let v: serde_json::Value =
            serde_json::from_slice(&m.data).context("a /stats message is not JSON")?;
        let frame = v["frame"]
            .as_u64()
            .context("a /stats message has no frame number")?;
        frames.insert(m.log_time, frame);
    }
    if frames.is_empty() {
        bail!("the log has no /stats messages: no frame to export");
    }
    Ok(frames)
}

fn rgba(c: foxglove::messages::Color) -> [f32; 4] {
    [c.r as f32, c.g as f32, c.b as f32, c.a as f32]
}

/// Reads the tracks of the frames `wanted` (log time → frame number, in order) for `scene`.
pub fn read_tracks(
    bytes: &[u8],
    scene: &Scene,
    wanted: &BTreeMap<u64, u64>,
    stop: &AtomicBool,
) -> anyhow::Result<Tracks> {
    let slot: HashMap<u64, usize> = wanted.keys().enumerate().map(|(i, t)| (*t, i)).collect();
    let n = wanted.len();
    let cloth_index: HashMap<String, usize> = scene
        .cloths
        .iter()
        .enumerate()
        .map(|(i, c)| (c.name.clone(), i))
        .collect();
    let mut positions: Vec<Vec<Option<Vec<[f32; 3]>>>> = vec![vec![None; n]; scene.cloths.len()];
    let mut logged_triangles: Vec<Option<Vec<[u32; 3]>>> = vec![None; scene.cloths.len()];
    let mut states: Vec<Option<serde_json::Value>> = vec![None; n];
    let mut has_states = false;
    for m in mcap::MessageStream::new(bytes)? {
        if stop.load(Ordering::Relaxed) {
            return Err(Stopped.into());
        }
        let m = m?;
        let topic = m.channel.topic.as_str();
        if topic == collider_state::TOPIC {
            has_states = true;
        }
        let cloth = topic
            .strip_prefix("/cloth/")
            .and_then(|t| t.rsplit_once('/'))
            .and_then(|(name, what)| Some((*cloth_index.get(name)?, what)));
        match cloth {
            Some((i, "mesh")) => {
                // A surface-only log (`--log surface`) gives the positions too; the particles,
                // written before the surface within a frame, are preferred.
                let at = slot
                    .get(&m.log_time)
                    .copied()
                    .filter(|&k| positions[i][k].is_none());
                if logged_triangles[i].is_some() && at.is_none() {
                    continue;
                }
                let update = SceneUpdate::decode(&m.data[..])
                    .with_context(|| format!("{topic}: not a foxglove.SceneUpdate"))?;
                let list = update
                    .entities
                    .first()
                    .and_then(|e| e.triangles.first())
                    .with_context(|| format!("{topic}: a message without triangles"))?;
                if logged_triangles[i].is_none() {
                    if list.indices.len() % 3 != 0 {
                        bail!(
                            "{topic}: {} indices, not whole triangles",
                            list.indices.len()
                        );
                    }
                    logged_triangles[i] = Some(
                        list.indices
                            .chunks_exact(3)
                            .map(|t| [t[0], t[1], t[2]])
                            .collect(),
                    );
                }
                if let Some(k) = at {
                    positions[i][k] = Some(
                        list.points
                            .iter()
                            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
                            .collect(),
                    );
                }
            }
            Some((i, "particles")) => {
                let Some(&k) = slot.get(&m.log_time) else {
                    continue;
                };
                let cloud = PointCloud::decode(&m.data[..])
                    .with_context(|| format!("{topic}: not a foxglove.PointCloud"))?;
                let points = weft_record::messages::positions_of(&cloud).with_context(|| {
                    format!(
                        "{topic}: points are neither float32 x, y, z nor binary16 x_f16, y_f16, \
                         z_f16 (stride {})",
                        cloud.point_stride
                    )
                })?;
                positions[i][k] = Some(points);
            }
            _ => {
                if topic == collider_state::TOPIC
                    && let Some(&k) = slot.get(&m.log_time)
                {
                    states[k] = Some(
                        serde_json::from_slice(&m.data)
                            .with_context(|| format!("{topic}: a message is not JSON"))?,
                    );
                }
            }
        }
    }
    let frames: Vec<u64> = wanted.values().copied().collect();
    let times: Vec<f64> = wanted.keys().map(|t| *t as f64 * 1e-9).collect();
    let mut cloths = Vec::with_capacity(scene.cloths.len());
    for ((spec, logged), per_frame) in scene.cloths.iter().zip(logged_triangles).zip(positions) {
        let count = spec.mesh.positions.len();
        let mut track = Vec::with_capacity(n);
        for (k, p) in per_frame.into_iter().enumerate() {
            let p = p.with_context(|| {
                format!(
                    "neither /cloth/{0}/particles nor /cloth/{0}/mesh has a message at frame {1}",
                    spec.name, frames[k]
                )
            })?;
            if p.len() != count {
                bail!(
                    "/cloth/{} holds {} points at frame {}; the logged scene's cloth has {count}",
                    spec.name,
                    p.len(),
                    frames[k]
                );
            }
            track.push(p);
        }
        let triangles = logged.unwrap_or_else(|| spec.mesh.triangles.clone());
        if let Some(bad) = triangles.iter().flatten().find(|&&i| i as usize >= count) {
            bail!(
                "/cloth/{}/mesh: index {bad} beyond its {count} points",
                spec.name
            );
        }
        cloths.push(ClothTrack {
            name: spec.name.clone(),
            color: rgba(weft_record::messages::method_color(spec.method)),
            triangles,
            positions: track,
        });
    }
    let mut colliders = Vec::with_capacity(scene.colliders.len());
    for spec in &scene.colliders {
        let desc = weft_scene::collider_desc(spec);
        let collider = weft_collide::Collider::new(&desc)
            .map_err(|e| anyhow::anyhow!("collider {}: {e}", spec.name))?;
        let (vertices, triangles) = collider.tessellate();
        let mut poses = Vec::with_capacity(n);
        for (k, &time) in times.iter().enumerate() {
            let pose = if has_states {
                logged_pose(&states, k, &frames, &spec.name)?
            } else {
                let s = ColliderState::at(spec, time);
                (s.position, s.rotation)
            };
            poses.push(pose);
        }
        colliders.push(ColliderTrack {
            name: spec.name.clone(),
            vertices,
            triangles,
            poses,
        });
    }
    colliders.extend(super::body::tracks(
        scene, has_states, &states, &frames, &times,
    )?);
    Ok(Tracks {
        frames,
        times,
        cloths,
        colliders,
    })
}
