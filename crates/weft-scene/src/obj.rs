//! A small Wavefront OBJ reader for cloth meshes: `v` and `f` lines (polygons become fans).

use weft_solver::glam::DVec3;

/// Vertices and triangles read from OBJ text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles (0-based indices).
    pub triangles: Vec<[u32; 3]>,
}

/// Parses OBJ text; an error names the 1-based line.
pub fn parse_obj(text: &str) -> Result<ObjMesh, String> {
    let mut mesh = ObjMesh::default();
    for (n, line) in text.lines().enumerate() {
        let at = |msg: String| format!("line {}: {msg}", n + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words
                    .take(3)
                    .map(|w| {
                        w.parse::<f64>()
                            .map_err(|_| at(format!("bad number `{w}`")))
                    })
                    .collect::<Result<_, _>>()?;
                if c.len() != 3 || c.iter().any(|x| !x.is_finite()) {
                    return Err(at("a vertex needs three finite coordinates".into()));
                }
                mesh.positions.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let n_vertices = mesh.positions.len() as i64;
                let idx: Vec<u32> = words
                    .map(|w| {
                        let first = w.split('/').next().unwrap_or("");
                        let i: i64 = first
                            .parse()
                            .map_err(|_| at(format!("bad face index `{w}`")))?;
                        let i = if i < 0 { n_vertices + i } else { i - 1 };
                        if i < 0 || i >= n_vertices {
                            return Err(at(format!("face index `{w}` out of range")));
                        }
                        Ok(i as u32)
                    })
                    .collect::<Result<_, _>>()?;
                if idx.len() < 3 {
                    return Err(at("a face needs at least three vertices".into()));
                }
                for k in 1..idx.len() - 1 {
                    mesh.triangles.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    if mesh.triangles.is_empty() {
        return Err("no faces".into());
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_become_two_triangles_and_bad_lines_are_named() {
        let m = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\n")
            .expect("valid obj");
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let e = parse_obj("v 0 0 0\nf 1 2 3\n").expect_err("out of range");
        assert!(e.starts_with("line 2:"), "{e}");
    }
}
