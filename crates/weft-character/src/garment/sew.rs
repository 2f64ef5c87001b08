//! Building a garment: validate the file, sample outlines seam-aware, triangulate each panel,
//! place it around the body, merge the panels into one mesh and list the seam pairs.

use glam::{DQuat, DVec2, DVec3};
use weft_solver::{ClothMesh, Mass};

use super::outline::{distribute, edge_lengths, run, run_vertices, samples};
use super::spec::GarmentSpec;
use super::triangulate::{TriangulateError, triangulate};
use super::{Garment, GarmentError, PanelMesh};

/// Most vertices a garment may have (guards against a tiny `edge_length`).
pub const MAX_GARMENT_VERTICES: usize = 2_000_000;

/// Shortest `edge_length` (m): a tenth of a millimetre, finer than a yarn.
pub const MIN_EDGE_LENGTH: f64 = 1e-4;

/// Largest outline coordinate (m): no sewing pattern spans more than a few metres.
pub const MAX_COORDINATE: f64 = 100.0;

/// Most corners a panel's outline may have (its self-crossing test is quadratic in them;
/// real pattern pieces have tens).
pub const MAX_CORNERS: usize = 10_000;

/// Triangulates, places and merges the panels of `spec`, and pairs its seams' vertices.
pub fn build_garment(spec: &GarmentSpec) -> Result<Garment, GarmentError> {
    let top = |key: &'static str, message: String| GarmentError::Key {
        line: spec.top_line(key),
        place: "the garment".into(),
        key,
        message,
    };
    let h = spec.edge_length;
    if !(h.is_finite() && h > 0.0) {
        return Err(top(
            "edge_length",
            format!("must be a positive length in metres, got {h}"),
        ));
    }
    if h < MIN_EDGE_LENGTH {
        return Err(top(
            "edge_length",
            format!("{h} m is below the shortest edge a garment may have, {MIN_EDGE_LENGTH} m"),
        ));
    }
    let density = spec.area_density;
    if !(density.is_finite() && density > 0.0) {
        return Err(top(
            "area_density",
            format!("must be positive (kg/m²), got {density}"),
        ));
    }
    if spec.panels.is_empty() {
        return Err(top(
            "panel",
            "a garment needs at least one [[panel]]".into(),
        ));
    }
    let outlines = check_panels(spec)?;
    // Counted before anything the count would size is allocated.
    let vertices = estimated_vertices(&outlines, h);
    if vertices > MAX_GARMENT_VERTICES as f64 {
        let area: f64 = outlines.iter().map(|o| polygon_area(o)).sum();
        return Err(top(
            "edge_length",
            format!(
                "{h} m over the panels' {area:.3} m² gives about {vertices:.2e} vertices, more \
                 than the {MAX_GARMENT_VERTICES} a garment may have; use at least {:.2e} m",
                h * (vertices / MAX_GARMENT_VERTICES as f64).sqrt()
            ),
        ));
    }
    let pieces = seam_aware_pieces(spec, &outlines, h)?;

    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut panels = Vec::with_capacity(spec.panels.len());
    let mut starts_of = Vec::with_capacity(spec.panels.len());
    for (i, (panel, outline)) in spec.panels.iter().zip(&outlines).enumerate() {
        let (boundary, starts) = samples(outline, &pieces[i]);
        let estimate = interior_vertices(outline, h);
        let budget = (4.0 * estimate) as usize + 4 * boundary.len() + 64;
        if positions.len() + budget > MAX_GARMENT_VERTICES {
            return Err(panel_error(
                spec,
                i,
                "outline",
                format!("edge_length {h} m would give more than {MAX_GARMENT_VERTICES} vertices"),
            ));
        }
        let tri = triangulate(&boundary, h, budget).map_err(|e| {
            let message = match e {
                TriangulateError::SelfIntersecting => "the outline crosses itself",
                TriangulateError::Duplicate => "the outline passes twice through one point",
                TriangulateError::Coordinate => "a corner is too large or too small",
                TriangulateError::TooManyVertices => "refinement did not converge",
            };
            panel_error(spec, i, "outline", message.into())
        })?;
        let offset = positions.len() as u32;
        let rotation = euler_xyz(panel.rotation);
        let position = DVec3::from_array(panel.position);
        positions.extend(
            tri.points
                .iter()
                .map(|p| position + rotation * DVec3::new(p.x, p.y, 0.0)),
        );
        let first_triangle = triangles.len();
        triangles.extend(tri.triangles.iter().map(|t| t.map(|v| v + offset)));
        panels.push(PanelMesh {
            name: panel.name.clone(),
            vertices: offset..positions.len() as u32,
            boundary: boundary.len(),
            triangles: first_triangle..triangles.len(),
            flat: tri.points,
            edge_starts: starts.clone(),
        });
        starts_of.push((starts, boundary.len()));
    }

    let mut seam_pairs = Vec::new();
    let mut seams = Vec::with_capacity(spec.seams.len());
    for seam in &spec.seams {
        let side = |s: &super::SeamSide| -> Vec<u32> {
            let p = panel_index(spec, &s.panel).unwrap_or(0);
            let m = outlines[p].len();
            let (starts, total) = &starts_of[p];
            let edges = run(s.edges[0], s.edges[1], m);
            run_vertices(&edges, &pieces[p], starts, *total)
                .into_iter()
                .map(|v| v as u32 + panels[p].vertices.start)
                .collect()
        };
        let a = side(&seam.a);
        let mut b = side(&seam.b);
        if seam.flip {
            b.reverse();
        }
        let first = seam_pairs.len();
        seam_pairs.extend(a.into_iter().zip(b).map(|(x, y)| [x, y]));
        seams.push(first..seam_pairs.len());
    }
    let mesh = ClothMesh::from_triangles(positions, triangles, Mass::Density(density), vec![])?;
    Ok(Garment {
        mesh,
        panels,
        seam_pairs,
        seams,
    })
}

fn panel_error(spec: &GarmentSpec, i: usize, key: &'static str, message: String) -> GarmentError {
    GarmentError::Key {
        line: spec.panel_line(i, key),
        place: format!("panel {} (`{}`)", i + 1, spec.panels[i].name),
        key,
        message,
    }
}

fn seam_error(spec: &GarmentSpec, i: usize, key: &'static str, message: String) -> GarmentError {
    GarmentError::Key {
        line: spec.seam_line(i, key),
        place: format!("seam {}", i + 1),
        key,
        message,
    }
}

fn panel_index(spec: &GarmentSpec, name: &str) -> Option<usize> {
    spec.panels.iter().position(|p| p.name == name)
}

/// Checks names, corners, edges, placement; returns the outlines as points.
fn check_panels(spec: &GarmentSpec) -> Result<Vec<Vec<DVec2>>, GarmentError> {
    let mut outlines = Vec::with_capacity(spec.panels.len());
    for (i, panel) in spec.panels.iter().enumerate() {
        if spec.panels[..i].iter().any(|p| p.name == panel.name) {
            return Err(panel_error(
                spec,
                i,
                "name",
                "two panels have this name".into(),
            ));
        }
        let outline: Vec<DVec2> = panel
            .outline
            .iter()
            .map(|&c| DVec2::from_array(c))
            .collect();
        if outline.len() < 3 {
            return Err(panel_error(
                spec,
                i,
                "outline",
                "needs at least 3 corners".into(),
            ));
        }
        if outline.len() > MAX_CORNERS {
            return Err(panel_error(
                spec,
                i,
                "outline",
                format!(
                    "has {} corners, more than the {MAX_CORNERS} a panel may have",
                    outline.len()
                ),
            ));
        }
        if let Some(k) = outline.iter().position(|p| !p.is_finite()) {
            return Err(panel_error(
                spec,
                i,
                "outline",
                format!("corner {k} is not finite"),
            ));
        }
        if let Some(k) = outline
            .iter()
            .position(|p| p.abs().max_element() > MAX_COORDINATE)
        {
            return Err(panel_error(
                spec,
                i,
                "outline",
                format!(
                    "corner {k} lies {:.3e} m out, beyond the {MAX_COORDINATE} m a panel may span",
                    outline[k].abs().max_element()
                ),
            ));
        }
        if let Some(k) = edge_lengths(&outline).iter().position(|&l| l <= 0.0) {
            return Err(panel_error(
                spec,
                i,
                "outline",
                format!("corners {k} and {} coincide", (k + 1) % outline.len()),
            ));
        }
        if let Some((i1, i2)) = crossing_edges(&outline) {
            return Err(panel_error(
                spec,
                i,
                "outline",
                format!("the outline crosses itself (edges {i1} and {i2})"),
            ));
        }
        if !panel.position.iter().all(|v| v.abs() <= MAX_COORDINATE) {
            return Err(panel_error(
                spec,
                i,
                "position",
                format!("must be finite and within {MAX_COORDINATE} m of the origin"),
            ));
        }
        if !panel.rotation.iter().all(|v| v.is_finite()) {
            return Err(panel_error(spec, i, "rotation", "must be finite".into()));
        }
        outlines.push(outline);
    }
    Ok(outlines)
}

/// Pieces per edge: ⌈length / h⌉ for free edges; for a seam, the same total on both sides
/// (enough for the longer side), spread over each side's edges by length.
fn seam_aware_pieces(
    spec: &GarmentSpec,
    outlines: &[Vec<DVec2>],
    h: f64,
) -> Result<Vec<Vec<usize>>, GarmentError> {
    let lengths: Vec<Vec<f64>> = outlines.iter().map(|o| edge_lengths(o)).collect();
    let mut pieces: Vec<Vec<usize>> = lengths
        .iter()
        .map(|ls| {
            ls.iter()
                .map(|l| ((l / h).ceil() as usize).max(1))
                .collect()
        })
        .collect();
    let mut owner: Vec<Vec<Option<usize>>> = outlines.iter().map(|o| vec![None; o.len()]).collect();
    for (s, seam) in spec.seams.iter().enumerate() {
        let mut runs = Vec::with_capacity(2);
        for (key, side) in [("a", &seam.a), ("b", &seam.b)] {
            let Some(p) = panel_index(spec, &side.panel) else {
                return Err(seam_error(
                    spec,
                    s,
                    key,
                    format!("no panel `{}`", side.panel),
                ));
            };
            let m = outlines[p].len();
            if let Some(&e) = side.edges.iter().find(|&&e| e >= m) {
                return Err(seam_error(
                    spec,
                    s,
                    key,
                    format!("panel `{}` has edges 0 to {}, not {e}", side.panel, m - 1),
                ));
            }
            let edges = run(side.edges[0], side.edges[1], m);
            for &e in &edges {
                if let Some(other) = owner[p][e] {
                    let message = if other == s {
                        format!("edge {e} of `{}` is on both sides of the seam", side.panel)
                    } else {
                        format!(
                            "edge {e} of `{}` is already in seam {}",
                            side.panel,
                            other + 1
                        )
                    };
                    return Err(seam_error(spec, s, key, message));
                }
                owner[p][e] = Some(s);
            }
            runs.push((p, edges));
        }
        let total = runs
            .iter()
            .map(|(p, edges)| {
                let len: f64 = edges.iter().map(|&e| lengths[*p][e]).sum();
                ((len / h).ceil() as usize).max(edges.len())
            })
            .max()
            .unwrap_or(1);
        for (p, edges) in runs {
            let ls: Vec<f64> = edges.iter().map(|&e| lengths[p][e]).collect();
            for (e, n) in edges.iter().zip(distribute(total, &ls)) {
                pieces[p][*e] = n;
            }
        }
    }
    Ok(pieces)
}

/// Vertices that triangulating `outlines` to edge length `h` makes, about: each panel's
/// interior and its boundary samples (in floating point, so no count can overflow).
fn estimated_vertices(outlines: &[Vec<DVec2>], h: f64) -> f64 {
    outlines
        .iter()
        .map(|o| {
            let boundary: f64 = edge_lengths(o).iter().map(|l| (l / h).ceil()).sum();
            interior_vertices(o, h) + boundary
        })
        .sum()
}

/// Vertices inside `outline` at edge length `h`, about: its area over an equilateral
/// triangle's.
fn interior_vertices(outline: &[DVec2], h: f64) -> f64 {
    polygon_area(outline) / (3f64.sqrt() / 4.0 * h * h)
}

/// R = R_z R_y R_x from degrees about x, y, z.
fn euler_xyz(deg: [f64; 3]) -> DQuat {
    let [x, y, z] = deg.map(f64::to_radians);
    DQuat::from_rotation_z(z) * DQuat::from_rotation_y(y) * DQuat::from_rotation_x(x)
}

/// Area of a simple polygon (shoelace), either winding (m²).
pub(crate) fn polygon_area(outline: &[DVec2]) -> f64 {
    let m = outline.len();
    0.5 * (0..m)
        .map(|k| outline[k].perp_dot(outline[(k + 1) % m]))
        .sum::<f64>()
        .abs()
}

/// The first pair of non-adjacent outline edges that touch or cross, if any.
fn crossing_edges(outline: &[DVec2]) -> Option<(usize, usize)> {
    let m = outline.len();
    let edge = |k: usize| (outline[k], outline[(k + 1) % m]);
    for i in 0..m {
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue;
            }
            let (a, b) = edge(i);
            let (c, d) = edge(j);
            if segments_touch(a, b, c, d) {
                return Some((i, j));
            }
        }
    }
    None
}

/// Whether segments ab and cd share a point (orientation tests).
fn segments_touch(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let orient = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}
