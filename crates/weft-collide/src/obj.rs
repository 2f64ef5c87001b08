//! A tiny Wavefront OBJ reader: `v` and `f` lines only (polygons fan-triangulated; `v/vt/vn`,
//! `v//vn` and negative indices accepted); every other statement is ignored.

use std::path::Path;

use glam::Vec3;

use crate::error::MeshError;
use crate::mesh::{TriangleMesh, validate};

/// Reads and validates an OBJ file.
pub fn load_obj(path: impl AsRef<Path>) -> Result<TriangleMesh, MeshError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_obj(&text, path)
}

/// Parses and validates OBJ text; `path` only names the source in errors.
pub fn parse_obj(text: &str, path: impl AsRef<Path>) -> Result<TriangleMesh, MeshError> {
    let path = path.as_ref();
    let malformed = |line: usize, reason: String| MeshError::Malformed {
        path: path.to_path_buf(),
        line,
        reason,
    };
    let mut vertices = Vec::new();
    let mut vertex_lines = Vec::new();
    let mut triangles = Vec::new();
    let mut lines = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = n + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        let mut words = content.split_whitespace();
        match words.next() {
            Some("v") => {
                let coords: Vec<&str> = words.collect();
                if !(3..=4).contains(&coords.len()) {
                    return Err(malformed(
                        line,
                        format!("`v` needs 3 coordinates, got {}", coords.len()),
                    ));
                }
                let mut xyz = [0.0f32; 3];
                for (slot, word) in xyz.iter_mut().zip(&coords) {
                    let v: f64 = word.parse().map_err(|_| {
                        malformed(line, format!("`{}` is not a number", short(word)))
                    })?;
                    // Coordinates are stored as float32: a finite value beyond its range is
                    // out of range, not "non-finite" (NaN and infinities are reported as such
                    // by the mesh check).
                    if v.is_finite() && v.abs() > f64::from(f32::MAX) {
                        return Err(malformed(
                            line,
                            format!(
                                "coordinate `{}` is out of range (an OBJ vertex is read as \
                                 float32: |v| <= {:e})",
                                short(word),
                                f32::MAX
                            ),
                        ));
                    }
                    *slot = v as f32;
                }
                vertices.push(Vec3::from(xyz));
                vertex_lines.push(line);
            }
            Some("f") => {
                let mut corners = Vec::new();
                for word in words {
                    let first = word.split('/').next().unwrap_or("");
                    let index: i64 = first.parse().map_err(|_| {
                        malformed(line, format!("`{}` is not a vertex reference", short(word)))
                    })?;
                    // OBJ indices are 1-based; negative ones count back from the last vertex.
                    let resolved = match index {
                        0 => return Err(malformed(line, "vertex index 0 (OBJ is 1-based)".into())),
                        i if i > 0 => i - 1,
                        i => vertices.len() as i64 + i,
                    };
                    if resolved < 0 || resolved > i64::from(u32::MAX) {
                        return Err(MeshError::IndexOutOfRange {
                            path: path.to_path_buf(),
                            line,
                            index: resolved,
                            vertices: vertices.len(),
                        });
                    }
                    corners.push(resolved as u32);
                }
                if corners.len() < 3 {
                    return Err(malformed(
                        line,
                        format!("a face needs at least 3 vertices, got {}", corners.len()),
                    ));
                }
                for k in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[k], corners[k + 1]]);
                    lines.push(line);
                }
            }
            _ => {}
        }
    }
    validate(path, &vertices, &triangles, &lines, &vertex_lines)?;
    Ok(TriangleMesh {
        vertices: vertices.iter().map(|v| v.as_dvec3()).collect(),
        triangles,
    })
}

/// The longest word an error echoes whole.
const LONGEST_WORD: usize = 64;

/// `word`, cut to [`LONGEST_WORD`] characters and `…` when longer.
fn short(word: &str) -> String {
    match word.char_indices().nth(LONGEST_WORD) {
        Some((at, _)) => format!("{}…", &word[..at]),
        None => word.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_and_slash_forms_are_triangulated() {
        let text =
            "# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1 -1\n";
        let m = parse_obj(text, "quad.obj").expect("valid OBJ");
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.vertices.len(), 4);
    }

    #[test]
    fn messages_count_vertices_from_one_and_keep_values_short() {
        let missing = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "m.obj")
            .expect_err("vertex 9 does not exist")
            .to_string();
        assert!(missing.contains("m.obj:4: face uses vertex 9"), "{missing}");
        let far = parse_obj("v 0 0 0\nv 1e308 0 0\nv 0 1 0\nf 1 2 3\n", "m.obj")
            .expect_err("1e308 overflows float32")
            .to_string();
        assert!(
            far.contains("m.obj:2") && far.contains("out of range"),
            "{far}"
        );
        assert!(!far.contains("non-finite"), "{far}");
        let huge = format!("v {} 0 0\n", "9".repeat(100_000) + "x");
        let long = parse_obj(&huge, "m.obj")
            .expect_err("not a number")
            .to_string();
        assert!(
            long.len() < 300 && long.contains('…'),
            "{} chars",
            long.len()
        );
    }
}
