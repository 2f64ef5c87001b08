//! A cloth's surface message (`/cloth/<name>/mesh`) encoded with what every frame repeats —
//! the pose, the colour and the triangle list (four bytes an index) — encoded once: a frame
//! writes its timestamp and points around those bytes. The result is the protobuf encoding of
//! [`messages::cloth_mesh`](crate::messages::cloth_mesh), byte for byte.

use foxglove::Encode;
use foxglove::messages::{Color, SceneEntity, TriangleListPrimitive};
use weft_solver::glam::{DQuat, DVec3};

use crate::messages::{FRAME_ID, pose, timestamp};

/// Protobuf key of a length-delimited field.
const fn key(field: u8) -> u8 {
    (field << 3) | 2
}

/// Appends `v` as a protobuf varint.
fn varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Bytes of `v` as a varint.
fn varint_len(v: u64) -> usize {
    1 + (63 - v.max(1).leading_zeros() as usize) / 7
}

/// Bytes of a `Point3` message: a key and 8 bytes for each coordinate that is not zero
/// (proto3 leaves zero out, −0.0 too, as prost compares with `!= 0.0`).
fn point_len(p: &DVec3) -> usize {
    [p.x, p.y, p.z].iter().filter(|&&c| c != 0.0).count() * 9
}

/// One cloth's surface messages.
pub(crate) struct SurfaceEncoder {
    /// The entity's id, `cloth/<name>`.
    id: String,
    /// The triangle list's pose field, whole.
    pose: Vec<u8>,
    /// The triangle list's colour and index fields, whole.
    tail: Vec<u8>,
}

impl SurfaceEncoder {
    /// The encoder of cloth `name` with `triangles` drawn in `color`.
    pub fn new(name: &str, triangles: &[[u32; 3]], color: Color) -> Self {
        let constant = TriangleListPrimitive {
            pose: Some(pose(DVec3::ZERO, DQuat::IDENTITY)),
            points: vec![],
            color: Some(color),
            colors: vec![],
            indices: triangles.iter().flatten().copied().collect(),
        };
        let mut pose_only = constant.clone();
        pose_only.color = None;
        pose_only.indices.clear();
        let mut pose_bytes = Vec::new();
        let mut tail = Vec::new();
        // Encoding into a Vec cannot run out of room.
        let _ = pose_only.encode(&mut pose_bytes);
        let mut all = Vec::new();
        let _ = constant.encode(&mut all);
        tail.extend_from_slice(&all[pose_bytes.len()..]);
        Self {
            id: format!("cloth/{name}"),
            pose: pose_bytes,
            tail,
        }
    }

    /// The surface at `positions` at time `time` (s), in `out` (cleared first).
    pub fn encode(&self, time: f64, positions: &[DVec3], out: &mut Vec<u8>) {
        let head = SceneEntity {
            timestamp: Some(timestamp(time)),
            frame_id: FRAME_ID.into(),
            id: self.id.clone(),
            ..SceneEntity::default()
        };
        let mut head_bytes = Vec::new();
        let _ = head.encode(&mut head_bytes);
        let points: usize = positions
            .iter()
            .map(|p| {
                let n = point_len(p);
                1 + varint_len(n as u64) + n
            })
            .sum();
        let list = self.pose.len() + points + self.tail.len();
        let entity = head_bytes.len() + 1 + varint_len(list as u64) + list;
        out.clear();
        out.reserve(1 + varint_len(entity as u64) + entity);
        out.push(key(2));
        varint(out, entity as u64);
        out.extend_from_slice(&head_bytes);
        out.push(key(12));
        varint(out, list as u64);
        out.extend_from_slice(&self.pose);
        for p in positions {
            out.push(key(2));
            varint(out, point_len(p) as u64);
            for (field, c) in [(1u8, p.x), (2, p.y), (3, p.z)] {
                if c != 0.0 {
                    // A double field: wire type 1 (64-bit), little-endian.
                    out.push((field << 3) | 1);
                    out.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
        out.extend_from_slice(&self.tail);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{cloth_mesh, method_color};

    /// The same bytes as the foxglove encoding of the whole message, zeros and negative zeros
    /// among the coordinates, for several sizes (varint lengths of 1 to 3 bytes).
    #[test]
    fn the_bytes_are_the_foxglove_encoding_of_the_whole_message() {
        for n in [0_usize, 1, 7, 300, 5000] {
            let positions: Vec<DVec3> = (0..n)
                .map(|i| {
                    let t = i as f64;
                    let pick = |k: usize, v: f64| match (i + k) % 5 {
                        0 => 0.0,
                        1 => -0.0,
                        _ => v,
                    };
                    DVec3::new(
                        pick(0, t.sin()),
                        pick(1, -t * 1e-3),
                        pick(2, 1e9 / (t + 1.0)),
                    )
                })
                .collect();
            let triangles: Vec<[u32; 3]> = (0..n.saturating_sub(2) as u32)
                .map(|i| [i, i + 1, i + 2])
                .collect();
            let color = method_color(weft_solver::Method::Pbd);
            let encoder = SurfaceEncoder::new("sheet", &triangles, color);
            let mut ours = Vec::new();
            encoder.encode(2.25, &positions, &mut ours);
            let mut theirs = Vec::new();
            cloth_mesh(2.25, "sheet", &positions, &triangles, color)
                .encode(&mut theirs)
                .expect("encodes");
            assert_eq!(ours, theirs, "{n} points");
        }
    }
}
