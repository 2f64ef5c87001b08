//! One frame as Wavefront OBJ text: each cloth and each collider an object (`o` and `g`
//! `cloth/<name>`, `collider/<name>`) with its vertices in world coordinates (the logged
//! float32 values, written so that they read back exactly), area-weighted vertex normals and
//! triangles `f a//a b//b c//c`.

use std::fmt::Write;

use glam::Vec3;

use crate::export::log::Tracks;

/// The file name of frame `frame`.
pub fn file_name(frame: u64) -> String {
    format!("frame_{frame:05}.obj")
}

/// Area-weighted vertex normals (the sum of the adjacent triangles' cross products,
/// normalised; +y where a vertex has no triangle of non-zero area).
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let face = (b - a).cross(c - a);
        for &i in t {
            n[i as usize] += face;
        }
    }
    n.into_iter()
        .map(|v| v.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}

/// Appends one object to `out`; `base` is the number of vertices written before it.
fn object(out: &mut String, name: &str, positions: &[Vec3], triangles: &[[u32; 3]], base: usize) {
    // Writing to a String cannot fail.
    let _ = writeln!(out, "o {name}\ng {name}");
    for p in positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    for n in vertex_normals(positions, triangles) {
        let _ = writeln!(out, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in triangles {
        let [a, b, c] = t.map(|i| base + i as usize + 1);
        let _ = writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}");
    }
}

/// The OBJ text of exported frame `k` of `tracks`.
pub fn frame_text(tracks: &Tracks, k: usize, log_name: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# weft export of {log_name}: frame {}, t = {} s",
        tracks.frames[k], tracks.times[k]
    );
    let mut base = 0;
    for c in &tracks.cloths {
        let p: Vec<Vec3> = c.positions[k].iter().map(|&v| Vec3::from(v)).collect();
        object(
            &mut out,
            &format!("cloth/{}", c.name),
            &p,
            &c.triangles,
            base,
        );
        base += p.len();
    }
    for c in &tracks.colliders {
        let (position, rotation) = c.poses[k];
        let p: Vec<Vec3> = c
            .vertices
            .iter()
            .map(|v| (position + rotation * v.as_dvec3()).as_vec3())
            .collect();
        object(
            &mut out,
            &format!("collider/{}", c.name),
            &p,
            &c.triangles,
            base,
        );
        base += p.len();
    }
    out
}

/// The text's size for `vertices` and `triangles` (bytes), estimated with 12-character numbers
/// and 7-digit indices (the output's disk-space check).
pub fn size_estimate(vertices: u64, triangles: u64) -> u64 {
    vertices * 2 * 42 + triangles * 56 + 256
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_of_a_flat_square_point_along_its_face() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, -1.0), Vec3::NEG_Z];
        let n = vertex_normals(&p, &[[0, 1, 2], [0, 2, 3]]);
        for v in n {
            assert!((v - Vec3::Y).length() < 1e-6, "{v}");
        }
    }
}
