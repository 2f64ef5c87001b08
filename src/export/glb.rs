//! The exported frames as one animated glTF 2.0 binary (GLB), in the form Blender's glTF
//! importer turns into shape keys and object animation:
//!
//! * each cloth is a mesh whose base positions are the first exported frame and which has one
//!   morph target per later frame (its displacement from the first); an animation channel on the
//!   node's `weights` holds, at frame k's time, weight 1 on target k and 0 elsewhere, with
//!   LINEAR interpolation (positions blend linearly between consecutive frames) or STEP
//!   (each frame held until the next);
//! * each collider is a node holding its shape's mesh in its own frame, with `translation` and
//!   `rotation` channels (rotations kept on one hemisphere so slerp takes the short way) when it
//!   moves;
//! * times start at 0 s for the first exported frame; y is up and lengths are metres, as in Weft.
//!
//! The JSON is written here; the container is `gltf::binary::Glb`.

use glam::Vec3;
use serde_json::{Value, json};
use weft_solver::glam::DQuat;

use crate::export::log::Tracks;

/// The file name for a log named `stem`.
pub fn file_name(stem: &str) -> String {
    format!("{stem}.glb")
}

/// Accessors and buffer views over one binary buffer.
#[derive(Default)]
struct Buffers {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

/// glTF's component type codes.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
/// glTF's buffer view targets.
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

impl Buffers {
    /// A buffer view over `bytes`, 4-byte aligned.
    fn view(&mut self, bytes: impl Iterator<Item = [u8; 4]>, target: Option<u32>) -> usize {
        let start = self.bin.len();
        for b in bytes {
            self.bin.extend_from_slice(&b);
        }
        let mut view =
            json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.views.push(view);
        self.views.len() - 1
    }

    /// A float accessor of `width` components per element ("SCALAR", "VEC3", "VEC4"), with the
    /// per-component bounds glTF requires of positions and animation inputs.
    fn floats(&mut self, data: &[f32], kind: &str, width: usize, target: Option<u32>) -> usize {
        let mut lo = vec![f32::INFINITY; width];
        let mut hi = vec![f32::NEG_INFINITY; width];
        for e in data.chunks_exact(width) {
            for (c, v) in e.iter().enumerate() {
                lo[c] = lo[c].min(*v);
                hi[c] = hi[c].max(*v);
            }
        }
        let view = self.view(data.iter().map(|v| v.to_le_bytes()), target);
        self.accessors.push(json!({
            "bufferView": view, "componentType": FLOAT, "count": data.len() / width,
            "type": kind, "min": lo, "max": hi,
        }));
        self.accessors.len() - 1
    }

    /// A triangle index accessor.
    fn indices(&mut self, triangles: &[[u32; 3]]) -> usize {
        let view = self.view(
            triangles.iter().flatten().map(|i| i.to_le_bytes()),
            Some(ELEMENT_ARRAY_BUFFER),
        );
        self.accessors.push(json!({
            "bufferView": view, "componentType": UNSIGNED_INT,
            "count": triangles.len() * 3, "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}

fn flat(points: impl Iterator<Item = [f32; 3]>) -> Vec<f32> {
    points.flatten().collect()
}

fn material(name: String, color: [f32; 4]) -> Value {
    json!({
        "name": name,
        "pbrMetallicRoughness": {"baseColorFactor": color, "metallicFactor": 0.0,
                                 "roughnessFactor": 0.8},
        "doubleSided": true,
    })
}

const COLLIDER_GREY: [f32; 4] = [0.6, 0.6, 0.62, 1.0];

/// The glTF JSON and binary buffer of `tracks`, every channel interpolated as
/// `interpolation` ("LINEAR" or "STEP"); `poll` is called once per frame written and stops the
/// build when it returns an error.
pub fn build(
    tracks: &Tracks,
    interpolation: &str,
    mut poll: impl FnMut() -> anyhow::Result<()>,
) -> anyhow::Result<(Vec<u8>, Vec<u8>)> {
    let mut b = Buffers::default();
    let (mut meshes, mut nodes, mut materials) = (Vec::new(), Vec::new(), Vec::new());
    let (mut samplers, mut channels) = (Vec::new(), Vec::new());
    let t0 = tracks.times.first().copied().unwrap_or(0.0);
    let times: Vec<f32> = tracks.times.iter().map(|t| (t - t0) as f32).collect();
    let input = b.floats(&times, "SCALAR", 1, None);
    let frames = times.len();
    let mut animate = |path: &str, node: usize, output: usize| {
        samplers.push(json!({"input": input, "output": output, "interpolation": interpolation}));
        channels.push(json!({"sampler": samplers.len() - 1,
                             "target": {"node": node, "path": path}}));
    };
    for c in &tracks.cloths {
        let base = &c.positions[0];
        let position = b.floats(&flat(base.iter().copied()), "VEC3", 3, Some(ARRAY_BUFFER));
        let indices = b.indices(&c.triangles);
        let mut targets = Vec::with_capacity(frames.saturating_sub(1));
        let mut names = Vec::with_capacity(frames.saturating_sub(1));
        for (k, p) in c.positions.iter().enumerate().skip(1) {
            poll()?;
            let delta = p
                .iter()
                .zip(base)
                .map(|(a, o)| (Vec3::from(*a) - Vec3::from(*o)).to_array());
            let t = b.floats(&flat(delta), "VEC3", 3, Some(ARRAY_BUFFER));
            targets.push(json!({"POSITION": t}));
            names.push(format!("frame_{:05}", tracks.frames[k]));
        }
        materials.push(material(format!("cloth/{}", c.name), c.color));
        let mut primitive = json!({
            "attributes": {"POSITION": position}, "indices": indices,
            "material": materials.len() - 1, "mode": 4,
        });
        let mut mesh = json!({"name": format!("cloth/{}", c.name)});
        if !targets.is_empty() {
            primitive["targets"] = json!(targets);
            mesh["weights"] = json!(vec![0.0f32; targets.len()]);
            // Blender names its shape keys from these.
            mesh["extras"] = json!({"targetNames": names});
        }
        mesh["primitives"] = json!([primitive]);
        meshes.push(mesh);
        nodes.push(json!({"name": format!("cloth/{}", c.name), "mesh": meshes.len() - 1}));
        if !targets.is_empty() {
            // At frame k: weight 1 on target k − 1 (frame 0 is the base, all weights 0).
            let n = targets.len();
            let mut weights = vec![0.0f32; frames * n];
            for k in 1..frames {
                weights[k * n + k - 1] = 1.0;
            }
            let output = b.floats(&weights, "SCALAR", 1, None);
            animate("weights", nodes.len() - 1, output);
        }
    }
    for c in &tracks.colliders {
        poll()?;
        let position = b.floats(
            &flat(c.vertices.iter().map(|v| v.to_array())),
            "VEC3",
            3,
            Some(ARRAY_BUFFER),
        );
        let indices = b.indices(&c.triangles);
        materials.push(material(format!("collider/{}", c.name), COLLIDER_GREY));
        meshes.push(json!({
            "name": format!("collider/{}", c.name),
            "primitives": [{"attributes": {"POSITION": position}, "indices": indices,
                            "material": materials.len() - 1, "mode": 4}],
        }));
        // Each rotation on the hemisphere of the one before it: slerp then takes the short way.
        let mut rotations: Vec<DQuat> = Vec::with_capacity(c.poses.len());
        for (_, r) in &c.poses {
            let r = r.normalize();
            let r = match rotations.last() {
                Some(prev) if prev.dot(r) < 0.0 => -r,
                _ => r,
            };
            rotations.push(r);
        }
        let (p0, r0) = (c.poses[0].0.as_vec3(), rotations[0].as_quat());
        nodes.push(json!({
            "name": format!("collider/{}", c.name), "mesh": meshes.len() - 1,
            "translation": p0.to_array(), "rotation": r0.to_array(),
        }));
        let node = nodes.len() - 1;
        if c.poses.iter().any(|p| p.0 != c.poses[0].0) {
            let t: Vec<f32> = flat(c.poses.iter().map(|p| p.0.as_vec3().to_array()));
            let output = b.floats(&t, "VEC3", 3, None);
            animate("translation", node, output);
        }
        if rotations.iter().any(|r| *r != rotations[0]) {
            let r: Vec<f32> = rotations
                .iter()
                .flat_map(|r| r.as_quat().to_array())
                .collect();
            let output = b.floats(&r, "VEC4", 4, None);
            animate("rotation", node, output);
        }
    }
    let mut root = json!({
        "asset": {"version": "2.0", "generator": concat!("weft ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"name": "weft", "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "buffers": [{"byteLength": b.bin.len()}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    if !channels.is_empty() {
        root["animations"] = json!([{"name": "weft", "samplers": samplers, "channels": channels}]);
    }
    Ok((serde_json::to_vec(&root)?, b.bin))
}

/// The GLB's size for `frames` frames of cloths of `particles` (each) and `triangles`, and
/// colliders of `collider_vertices` and `collider_triangles` in all (bytes).
pub fn size_estimate(
    frames: u64,
    particles: &[u64],
    triangles: u64,
    collider_vertices: u64,
    collider_triangles: u64,
    colliders: u64,
) -> u64 {
    let f = frames;
    let cloth: u64 = particles
        .iter()
        .map(|&n| f * n * 12 + f.saturating_sub(1) * f * 4 + f * 200)
        .sum();
    cloth
        + triangles * 12
        + collider_vertices * 12
        + collider_triangles * 12
        + colliders * (f * 28 + 600)
        + f * 4
        + 4096
}
