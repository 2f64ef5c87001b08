//! A `[[collider]]` table: its shape (one of the primitives, a hull, an OBJ mesh or a compound
//! of convex parts), pose, motion and friction, checked into a [`ColliderSpec`] whose shape
//! is the collision crate's [`ShapeDesc`].

use weft_collide::{CompoundPart, ShapeDesc, TriangleMesh};
use weft_solver::glam::DVec3;

use super::{Checker, valid_name};
use crate::ranges;
use crate::scene::ColliderSpec;
use crate::schema::{ColliderSection, PartSection, ShapeKind};

struct Geometry<'s> {
    shape: ShapeKind,
    radius: Option<f64>,
    half_extents: Option<[f64; 3]>,
    half_height: Option<f64>,
    normal: Option<[f64; 3]>,
    points: &'s Option<Vec<[f64; 3]>>,
}

fn shape(c: &mut Checker<'_>, key: &str, g: &Geometry<'_>) -> Option<ShapeDesc> {
    let k = |f: &str| format!("{key}.{f}");
    let what = format!("by a {:?} shape", g.shape).to_lowercase();
    let need = |c: &mut Checker<'_>, f: &str, v: Option<f64>| -> f64 {
        match v {
            Some(v) => {
                c.positive(&k(f), v);
                v
            }
            None => {
                c.bad(&k(f), "missing");
                0.0
            }
        }
    };
    use ShapeKind as S;
    if !matches!(g.shape, S::Sphere | S::Capsule) {
        c.unused(&k("radius"), &g.radius, &what);
    }
    if g.shape != S::Cuboid {
        c.unused(&k("half_extents"), &g.half_extents, &what);
    }
    if g.shape != S::Capsule {
        c.unused(&k("half_height"), &g.half_height, &what);
    }
    if g.shape != S::Plane {
        c.unused(&k("normal"), &g.normal, &what);
    }
    if g.shape != S::ConvexHull {
        c.unused(&k("points"), g.points, &what);
    }
    Some(match g.shape {
        S::Sphere => ShapeDesc::Sphere {
            radius: need(c, "radius", g.radius),
        },
        S::Cuboid => {
            let Some(h) = g.half_extents else {
                c.bad(&k("half_extents"), "missing");
                return None;
            };
            let v = c.vector(&k("half_extents"), h);
            if v.min_element() <= 0.0 {
                c.bad(&k("half_extents"), "every component must be > 0");
            }
            ShapeDesc::Cuboid { half_extents: v }
        }
        S::Capsule => {
            let half_height = g.half_height.unwrap_or(0.0);
            c.non_negative(&k("half_height"), half_height);
            ShapeDesc::Capsule {
                half_height,
                radius: need(c, "radius", g.radius),
            }
        }
        S::Plane => {
            let n = c.vector(&k("normal"), g.normal.unwrap_or([0.0, 1.0, 0.0]));
            if n.length_squared() == 0.0 {
                c.bad(&k("normal"), "must not be zero");
            }
            ShapeDesc::HalfSpace { normal: n }
        }
        S::ConvexHull => {
            let points: Vec<DVec3> = g
                .points
                .as_deref()
                .unwrap_or_default()
                .iter()
                .enumerate()
                .map(|(i, p)| c.vector(&format!("{}[{i}]", k("points")), *p))
                .collect();
            if points.len() < 4 {
                c.bad(
                    &k("points"),
                    format!("a hull needs at least 4 points, got {}", points.len()),
                );
            }
            ShapeDesc::ConvexHull { points }
        }
        S::Mesh | S::Compound => return None,
    })
}

pub(super) fn collider(c: &mut Checker<'_>, i: usize, s: &ColliderSection) -> Option<ColliderSpec> {
    let key = format!("collider[{i}]");
    let k = |f: &str| format!("{key}.{f}");
    let before = c.errors.len();
    let name = s.name.clone().unwrap_or_else(|| format!("collider{i}"));
    if !valid_name(&name) {
        c.bad(&k("name"), "may hold only letters, digits, `_` and `-`");
    }
    let geometry = Geometry {
        shape: s.shape,
        radius: s.radius,
        half_extents: s.half_extents,
        half_height: s.half_height,
        normal: s.normal,
        points: &s.points,
    };
    if s.shape != ShapeKind::Mesh {
        c.unused(&k("mesh"), &s.mesh, "by this shape");
        c.unused(&k("scale"), &s.scale, "by this shape");
    }
    if s.shape != ShapeKind::Compound {
        c.unused(&k("parts"), &s.parts, "by this shape");
    }
    let spec = match s.shape {
        ShapeKind::Mesh => {
            let scale = s.scale.unwrap_or(1.0);
            c.within(&k("scale"), scale, &ranges::SCALE);
            match &s.mesh {
                Some(path) => {
                    c.read_mesh(&k("mesh"), path, scale)
                        .and_then(|(positions, triangles)| {
                            match TriangleMesh::new(positions, triangles) {
                                Ok(mesh) => Some(ShapeDesc::TriMesh(mesh)),
                                Err(e) => {
                                    c.bad(
                                        &k("mesh"),
                                        format!("bad mesh once scaled by {scale}: {e}"),
                                    );
                                    None
                                }
                            }
                        })
                }
                None => {
                    c.bad(&k("mesh"), "missing: an OBJ file");
                    None
                }
            }
        }
        ShapeKind::Compound => {
            let parts = s.parts.as_deref().unwrap_or_default();
            if parts.is_empty() {
                c.bad(&k("parts"), "a compound needs at least one part");
            }
            let mut out = Vec::new();
            for (j, p) in parts.iter().enumerate() {
                let pk = format!("{}[{j}]", k("parts"));
                if matches!(
                    p.shape,
                    ShapeKind::Mesh | ShapeKind::Compound | ShapeKind::Plane
                ) {
                    c.bad(
                        &format!("{pk}.shape"),
                        "a compound part must be convex: sphere, cuboid, capsule or convex-hull",
                    );
                    continue;
                }
                if let Some(sh) = part(c, &pk, p) {
                    out.push(sh);
                }
            }
            Some(ShapeDesc::Compound(out))
        }
        _ => shape(c, &key, &geometry),
    };
    let position = c.vector(&k("position"), s.position);
    let rotation = c.rotation(&k("rotation_deg"), s.rotation_deg);
    c.friction(&key, s.static_friction, s.dynamic_friction);
    let motion = c.motion(&k("motion"), &s.motion);
    let shape = spec?;
    (c.errors.len() == before).then_some(ColliderSpec {
        name,
        shape,
        position,
        rotation,
        motion,
        static_friction: s.static_friction,
        dynamic_friction: s.dynamic_friction,
    })
}

fn part(c: &mut Checker<'_>, key: &str, p: &PartSection) -> Option<CompoundPart> {
    let g = Geometry {
        shape: p.shape,
        radius: p.radius,
        half_extents: p.half_extents,
        half_height: p.half_height,
        normal: p.normal,
        points: &p.points,
    };
    let shape = shape(c, key, &g)?;
    let position = c.vector(&format!("{key}.position"), p.position);
    let rotation = c.rotation(&format!("{key}.rotation_deg"), p.rotation_deg);
    Some(CompoundPart {
        position,
        rotation,
        shape,
    })
}
