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
                    *slot = word
                        .parse()
                        .map_err(|_| malformed(line, format!("`{word}` is not a number")))?;
                }
                vertices.push(Vec3::from(xyz));
                vertex_lines.push(line);
            }
            Some("f") => {
                let mut corners = Vec::new();
                for word in words {
                    let first = word.split('/').next().unwrap_or("");
                    let index: i64 = first.parse().map_err(|_| {
                        malformed(line, format!("`{word}` is not a vertex reference"))
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
        vertices,
        triangles,
    })
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
}
