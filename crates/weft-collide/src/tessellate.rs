//! Colliders as triangle meshes for drawing: each parry shape tessellated in its local frame
//! (parry's own `to_trimesh` where it has one).

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::Shape;

use crate::collider::Collider;

/// Longitude subdivisions of balls and capsules.
const ROUND_THETA: u32 = 48;
/// Latitude subdivisions of balls and capsules.
const ROUND_PHI: u32 = 24;
/// Half the side of the square drawn for a half-space (m): large, but finite.
pub const HALF_SPACE_EXTENT: f32 = 50.0;

/// A tessellated shape: vertex positions and triangles, in the shape's local frame.
pub type Tessellation = (Vec<Vec3>, Vec<[u32; 3]>);

/// Tessellates a parry shape in its local frame: ball, cuboid, capsule, half-space (a
/// square of side 2 × [`HALF_SPACE_EXTENT`] on its boundary plane), convex polyhedron,
/// triangle mesh and compound (every part at its pose). Other shapes give an empty mesh.
pub fn tessellate_shape(shape: &dyn Shape) -> Tessellation {
    if let Some(b) = shape.as_ball() {
        b.to_trimesh(ROUND_THETA, ROUND_PHI)
    } else if let Some(c) = shape.as_cuboid() {
        c.to_trimesh()
    } else if let Some(c) = shape.as_capsule() {
        c.to_trimesh(ROUND_THETA, ROUND_PHI / 2)
    } else if let Some(h) = shape.as_halfspace() {
        half_space_quad(h.normal)
    } else if let Some(c) = shape.as_convex_polyhedron() {
        c.to_trimesh()
    } else if let Some(m) = shape.as_trimesh() {
        (m.vertices().to_vec(), m.indices().to_vec())
    } else if let Some(c) = shape.as_compound() {
        let mut out: Tessellation = (Vec::new(), Vec::new());
        for (pose, part) in c.shapes() {
            let (vertices, triangles) = tessellate_shape(part.as_ref());
            append(&mut out, pose, vertices, triangles);
        }
        out
    } else {
        (Vec::new(), Vec::new())
    }
}

/// Appends a part's mesh, placed at `pose`, to `out`.
fn append(out: &mut Tessellation, pose: &Pose, vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) {
    let base = u32::try_from(out.0.len()).unwrap_or(u32::MAX);
    out.0
        .extend(vertices.into_iter().map(|v| pose.transform_point(v)));
    out.1.extend(
        triangles
            .into_iter()
            .map(|t| t.map(|i| base.saturating_add(i))),
    );
}

/// A square on the plane `normal · x = 0`, centred on the origin, counter-clockwise seen
/// from the side `normal` points to.
fn half_space_quad(normal: Vec3) -> Tessellation {
    let n = normal.normalize_or(Vec3::Y);
    let rotation = Quat::from_rotation_arc(Vec3::Y, n);
    let e = HALF_SPACE_EXTENT;
    let corners = [
        Vec3::new(-e, 0.0, -e),
        Vec3::new(-e, 0.0, e),
        Vec3::new(e, 0.0, e),
        Vec3::new(e, 0.0, -e),
    ];
    (
        corners.iter().map(|&c| rotation * c).collect(),
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

impl Collider {
    /// This collider's shape tessellated in its local frame (see [`tessellate_shape`]).
    pub fn tessellate(&self) -> Tessellation {
        tessellate_shape(self.shape().as_ref())
    }

    /// The outward world normal at the current pose if the collider is a half-space (an
    /// unbounded ground or wall, drawn as a finite square).
    pub fn half_space_normal(&self) -> Option<Vec3> {
        let h = self.shape().as_halfspace()?;
        Some((self.pose().rotation * h.normal).normalize_or_zero())
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Vec3};

    use super::*;
    use crate::collider::ColliderDesc;
    use crate::mesh::TriangleMesh;
    use crate::shape::{CompoundPart, ShapeDesc};

    fn build(shape: ShapeDesc) -> Collider {
        Collider::new(&ColliderDesc::new(shape)).expect("valid collider")
    }

    fn bounds(v: &[Vec3]) -> (Vec3, Vec3) {
        v.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }

    fn check_indices((v, t): &Tessellation) {
        assert!(!t.is_empty());
        assert!(t.iter().flatten().all(|&i| (i as usize) < v.len()));
    }

    #[test]
    fn sphere_vertices_lie_at_the_radius() {
        let m = build(ShapeDesc::Sphere { radius: 0.3 }).tessellate();
        check_indices(&m);
        for p in &m.0 {
            assert!((p.length() - 0.3).abs() < 1e-5, "{p:?}");
        }
        let (lo, hi) = bounds(&m.0);
        assert!((hi.y - 0.3).abs() < 1e-5 && (lo.y + 0.3).abs() < 1e-5);
    }

    #[test]
    fn cuboid_bounds_are_the_half_extents() {
        let h = Vec3::new(0.5, 0.2, 1.5);
        let m = build(ShapeDesc::Cuboid {
            half_extents: h.as_dvec3(),
        })
        .tessellate();
        check_indices(&m);
        let (lo, hi) = bounds(&m.0);
        assert!((hi - h).abs().max_element() < 1e-6, "{hi:?}");
        assert!((lo + h).abs().max_element() < 1e-6, "{lo:?}");
        assert_eq!(m.1.len(), 12);
    }

    #[test]
    fn capsule_points_are_at_radius_from_its_core_segment() {
        let (hh, r) = (0.4f32, 0.1f32);
        let m = build(ShapeDesc::Capsule {
            half_height: hh.into(),
            radius: r.into(),
        })
        .tessellate();
        check_indices(&m);
        for p in &m.0 {
            let core = Vec3::new(0.0, p.y.clamp(-hh, hh), 0.0);
            assert!(((*p - core).length() - r).abs() < 1e-5, "{p:?}");
        }
        let (lo, hi) = bounds(&m.0);
        assert!((hi.y - (hh + r)).abs() < 1e-5 && (lo.y + hh + r).abs() < 1e-5);
    }

    #[test]
    fn half_space_is_a_large_square_on_its_plane() {
        let n = Vec3::new(0.0, 1.0, 1.0).normalize();
        let c = build(ShapeDesc::HalfSpace {
            normal: n.as_dvec3(),
        });
        assert!((c.half_space_normal().expect("a half-space") - n).length() < 1e-6);
        assert!(
            build(ShapeDesc::Sphere { radius: 1.0 })
                .half_space_normal()
                .is_none()
        );
        let m = c.tessellate();
        check_indices(&m);
        for p in &m.0 {
            assert!(p.dot(n).abs() < 1e-4);
            assert!(p.length() > HALF_SPACE_EXTENT);
        }
        // Counter-clockwise seen from the outside: the face normal is the plane's normal.
        let [a, b, c] = m.1[0].map(|i| m.0[i as usize]);
        assert!((b - a).cross(c - a).normalize().dot(n) > 0.999);
    }

    #[test]
    fn convex_hull_keeps_its_extreme_points() {
        let points = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::splat(0.1), // interior: dropped by the hull
        ];
        let m = build(ShapeDesc::ConvexHull { points }).tessellate();
        check_indices(&m);
        let (lo, hi) = bounds(&m.0);
        assert_eq!((lo, hi), (Vec3::ZERO, Vec3::ONE));
        assert_eq!(m.1.len(), 4, "a tetrahedron");
    }

    #[test]
    fn triangle_mesh_is_passed_through() {
        let mesh = TriangleMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        };
        let m = build(ShapeDesc::TriMesh(mesh.clone())).tessellate();
        assert_eq!(m.0, mesh.vertices_f32());
        assert_eq!(m.1, mesh.triangles);
    }

    #[test]
    fn compound_parts_sit_at_their_poses() {
        let c = build(ShapeDesc::Compound(vec![
            CompoundPart::at(
                DVec3::new(1.0, 0.0, 0.0),
                ShapeDesc::Sphere { radius: 0.25 },
            ),
            CompoundPart::at(
                DVec3::new(-1.0, 0.0, 0.0),
                ShapeDesc::Cuboid {
                    half_extents: DVec3::splat(0.5),
                },
            ),
        ]));
        let m = c.tessellate();
        check_indices(&m);
        let (lo, hi) = bounds(&m.0);
        assert!((lo - Vec3::new(-1.5, -0.5, -0.5)).abs().max_element() < 1e-5);
        assert!((hi - Vec3::new(1.25, 0.5, 0.5)).abs().max_element() < 1e-5);
        let near_ball =
            m.0.iter()
                .filter(|p| (**p - Vec3::X).length() < 0.3)
                .count();
        assert!(near_ball > 100, "the ball's vertices are around x = 1");
    }
}
