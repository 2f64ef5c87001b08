//! Colliders: a parry shape with a pose that follows a prescribed motion, and friction.

use std::sync::Arc;

use glam::{DQuat, DVec3, Mat4, Vec3};
use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose;
use parry3d::query::{PointProjection, PointQuery, PointQueryWithLocation, Ray};
use parry3d::shape::{Shape, SharedShape};
use weft_solver::Motion;

use crate::analytic::{Analytic, WorldPose};
use crate::convert::{compose, pose};
use crate::error::ShapeError;
use crate::friction::Friction;
use crate::shape::ShapeDesc;
use crate::surface::SurfacePoint;
use crate::trimesh::MeshGeometry;
use crate::trimesh::deforming::MeshAnimation;

/// How to build a collider: shape, placement at t = 0, motion and friction, in f64 (the
/// collider rounds shape and placement to the f32 parry holds, see [`ShapeDesc`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ColliderDesc {
    /// The geometry, in the collider's frame.
    pub shape: ShapeDesc,
    /// Position of the collider's frame at rest (m).
    pub position: DVec3,
    /// Orientation of the collider's frame at rest.
    pub rotation: DQuat,
    /// Prescribed motion applied to the rest placement ([`Motion::Static`] for a fixed collider).
    pub motion: Motion,
    /// Coulomb friction against cloth particles.
    pub friction: Friction,
}

impl ColliderDesc {
    /// A static collider at the origin with default friction.
    pub fn new(shape: ShapeDesc) -> Self {
        Self {
            shape,
            position: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            motion: Motion::Static,
            friction: Friction::default(),
        }
    }

    /// Builder-style: sets the rest position.
    pub fn at(mut self, position: DVec3) -> Self {
        self.position = position;
        self
    }

    /// Builder-style: sets the rest orientation.
    pub fn rotated(mut self, rotation: DQuat) -> Self {
        self.rotation = rotation;
        self
    }

    /// Builder-style: makes the collider kinematic with `motion`.
    pub fn moving(mut self, motion: Motion) -> Self {
        self.motion = motion;
        self
    }

    /// Builder-style: sets the friction.
    pub fn with_friction(mut self, friction: Friction) -> Self {
        self.friction = friction;
        self
    }
}

/// A built collider: parry shape, rest pose, motion, friction and the current pose.
///
/// Spheres, half-spaces, cuboids and capsules are queried in closed form in f64
/// (`analytic.rs`) with the pose held in f64, triangle meshes in f64 through their own BVH
/// (`trimesh/`); convex hulls and compounds go through parry in f32.
#[derive(Clone)]
pub struct Collider {
    shape: SharedShape,
    kind: &'static str,
    rest: Pose,
    motion: Motion,
    friction: Friction,
    pose: Pose,
    prev_pose: Pose,
    /// Local AABB; `None` for unbounded shapes (half-spaces).
    local_aabb: Option<Aabb>,
    /// The closed form of the shape, where it has one.
    analytic: Option<Analytic>,
    /// Rest pose in f64.
    rest64: WorldPose,
    /// Current pose in f64.
    pose64: WorldPose,
    /// Pose at the start of the substep in f64.
    prev_pose64: WorldPose,
    /// Whether the f64 pose did not change over the substep.
    still: bool,
    /// A triangle mesh's own geometry, in f64 (the collider's frame).
    mesh: Option<Box<MeshGeometry>>,
    /// What moves a deforming mesh's vertices.
    animation: Option<Arc<dyn MeshAnimation>>,
    /// The animation's output for the frame's end.
    next_vertices: Vec<DVec3>,
    /// The frame a deforming mesh moves across: its start and end times (s).
    frame: (f64, f64),
}

impl std::fmt::Debug for Collider {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Collider")
            .field("kind", &self.kind)
            .field("pose", &self.pose)
            .field("motion", &self.motion)
            .field("friction", &self.friction)
            .field("deforming", &self.animation.is_some())
            .finish()
    }
}

impl Collider {
    /// Validates and builds a collider.
    pub fn new(desc: &ColliderDesc) -> Result<Self, ShapeError> {
        desc.friction.validate()?;
        // The rest placement as parry holds it (f32); the f64 pose starts from the same values.
        let (position, rotation) = (desc.position.as_vec3(), desc.rotation.as_quat());
        if !(position.is_finite() && rotation.is_finite()) {
            return Err(ShapeError::InvalidParameter {
                name: "collider.position",
                value: f64::NAN,
                expected: "finite position and rotation",
            });
        }
        let shape = desc.shape.build()?;
        let local_aabb = match desc.shape {
            ShapeDesc::HalfSpace { .. } => None,
            _ => Some(shape.compute_local_aabb()),
        };
        let rest = pose(position, rotation.normalize());
        let start = compose(desc.motion.transform(0.0), &rest);
        let rest64 = WorldPose::new(position.as_dvec3(), rotation.as_dquat());
        let start64 = carry(desc.motion, 0.0, &rest64);
        let mesh = match &desc.shape {
            ShapeDesc::TriMesh(m) => {
                // The mesh parry holds, widened: its contacts and its drawing are one surface.
                let vertices: Vec<DVec3> =
                    m.vertices.iter().map(|v| v.as_vec3().as_dvec3()).collect();
                Some(Box::new(MeshGeometry::new(&vertices, &m.triangles)))
            }
            _ => None,
        };
        Ok(Self {
            shape,
            kind: desc.shape.kind(),
            rest,
            motion: desc.motion,
            friction: desc.friction,
            pose: start,
            prev_pose: start,
            local_aabb,
            analytic: Analytic::of(&desc.shape),
            rest64,
            pose64: start64,
            prev_pose64: start64,
            still: true,
            mesh,
            animation: None,
            next_vertices: Vec::new(),
            frame: (0.0, 0.0),
        })
    }

    /// A deforming triangle-mesh collider: `desc`'s mesh, whose vertices (in the collider's
    /// frame, which still follows `desc`'s placement and motion) `animation` gives at every
    /// frame's end; they move linearly across the frame's substeps. Its acceleration
    /// structure is refitted once a frame to the boxes the triangles sweep, not rebuilt, and
    /// contacts are swept against the moving triangles.
    pub fn deforming(
        desc: &ColliderDesc,
        animation: Arc<dyn MeshAnimation>,
    ) -> Result<Self, ShapeError> {
        let mut c = Self::new(desc)?;
        let Some(mesh) = c.mesh.as_mut() else {
            return Err(ShapeError::InvalidParameter {
                name: "deforming collider shape",
                value: f64::NAN,
                expected: "a triangle mesh",
            });
        };
        let mut now = mesh.rest().to_vec();
        animation.vertices_at(0.0, mesh.rest(), &mut now);
        if !now.iter().all(|v| v.is_finite()) {
            return Err(ShapeError::InvalidParameter {
                name: "deforming mesh vertices at t = 0",
                value: f64::NAN,
                expected: "finite positions",
            });
        }
        mesh.advance(&now);
        mesh.advance(&now);
        c.next_vertices = now;
        c.animation = Some(animation);
        c.local_aabb = c.mesh_aabb();
        Ok(c)
    }

    /// Whether the collider is a deforming mesh.
    pub fn is_deforming(&self) -> bool {
        self.animation.is_some()
    }

    /// A triangle mesh's vertices at the end of the current substep, in the collider's frame,
    /// in the order of its `TriangleMesh` (for drawing a deforming mesh); `None` for others.
    pub fn mesh_vertices(&self) -> Option<&[DVec3]> {
        self.mesh.as_ref().map(|m| m.vertices())
    }

    /// The triangle-mesh geometry, for the world's contacts.
    pub(crate) fn mesh(&self) -> Option<&MeshGeometry> {
        self.mesh.as_deref()
    }

    /// The closed form of the shape, if it has one.
    pub(crate) fn analytic(&self) -> Option<Analytic> {
        self.analytic
    }

    /// The f64 poses at the end and start of the substep, and whether they are equal.
    pub(crate) fn poses64(&self) -> (&WorldPose, &WorldPose, bool) {
        (&self.pose64, &self.prev_pose64, self.still)
    }

    /// The mesh's local box (swept over the substep while it deforms).
    fn mesh_aabb(&self) -> Option<Aabb> {
        self.mesh.as_ref().map(|m| {
            let (lo, hi) = m.bounds();
            Aabb::new(lo.as_vec3(), hi.as_vec3())
        })
    }

    /// The parry shape.
    pub fn shape(&self) -> &SharedShape {
        &self.shape
    }

    /// The kind of shape (`"sphere"`, `"triangle mesh"`, …).
    pub fn kind(&self) -> &'static str {
        self.kind
    }

    /// The current pose (at the end of the current substep) as parry holds it (f32).
    pub fn pose(&self) -> &Pose {
        &self.pose
    }

    /// The current world pose `(position, rotation)` in f64: the rest placement carried by
    /// the motion with [`weft_solver::RigidTransform::carry`], the one pose function the
    /// log uses too.
    pub fn world_pose(&self) -> (DVec3, DQuat) {
        (self.pose64.translation, self.pose64.rotation)
    }

    /// [`Self::world_pose`] as an f32 matrix, for drawing.
    pub fn world_matrix(&self) -> Mat4 {
        let (position, rotation) = self.world_pose();
        Mat4::from_rotation_translation(rotation.as_quat(), position.as_vec3())
    }

    /// The prescribed motion.
    pub fn motion(&self) -> Motion {
        self.motion
    }

    /// The friction coefficients.
    pub fn friction(&self) -> Friction {
        self.friction
    }

    /// Moves the collider to its poses at the start (`t0`) and end (`t1`) of a substep (s),
    /// a frame of its own.
    pub fn set_time(&mut self, t0: f64, t1: f64) {
        self.set_time_in_frame(t0, t1, t1);
    }

    /// [`Self::set_time`] for a substep of the frame that ends at `frame_end` (s): a
    /// deforming mesh's animation is evaluated at the frame's end when a frame starts, and
    /// its vertices move there linearly over the frame's substeps (as its rigid pose moves
    /// along its motion at every substep).
    pub fn set_time_in_frame(&mut self, t0: f64, t1: f64, frame_end: f64) {
        self.prev_pose = compose(self.motion.transform(t0), &self.rest);
        self.pose = compose(self.motion.transform(t1), &self.rest);
        self.prev_pose64 = carry(self.motion, t0, &self.rest64);
        self.pose64 = carry(self.motion, t1, &self.rest64);
        self.still = self.pose64 == self.prev_pose64;
        if let (Some(animation), Some(mesh)) = (&self.animation, self.mesh.as_mut()) {
            let (start, end) = self.frame;
            if frame_end != end || !(start..end).contains(&t0) {
                self.frame = (t0, frame_end);
                let next = &mut self.next_vertices;
                animation.vertices_at(frame_end, mesh.rest(), next);
                if !next.iter().all(|v| v.is_finite()) {
                    next.copy_from_slice(mesh.vertices()); // a bad frame: hold the last good one
                }
                mesh.begin_frame(next);
            }
            let (start, end) = self.frame;
            let w = if t1 >= end {
                1.0
            } else {
                ((t1 - start) / (end - start)).clamp(0.0, 1.0)
            };
            mesh.advance_to(w);
            self.local_aabb = self.mesh_aabb();
        }
    }

    /// Whether one push along [`Self::closest`]'s normal to a distance r always clears a
    /// contact, so that no re-query is needed: true for the closed-form shapes. They are
    /// convex, so the points within r of one form a convex set; the push lands on its
    /// boundary where the normal is the boundary's, and a move in that tangent plane
    /// (friction's) stays outside.
    pub(crate) fn one_push_clears(&self) -> bool {
        self.analytic.is_some()
    }

    /// World AABB at the current pose grown by `margin`, or `None` if unbounded.
    pub fn world_aabb(&self, margin: f32) -> Option<Aabb> {
        self.local_aabb.map(|a| {
            let w = a.transform_by(&self.pose);
            Aabb::new(w.mins - Vec3::splat(margin), w.maxs + Vec3::splat(margin))
        })
    }

    /// The closest surface point to `x` if it lies within `max_dist` of the surface or `x` is
    /// inside (for meshes: within `max_dist` on either side).
    ///
    /// Spheres, half-spaces, cuboids and capsules are answered in closed form in f64, triangle
    /// meshes in f64 through their BVH, signed by pseudo-normals (negative inside a closed
    /// mesh). For hulls and compounds parry works in f32, so the query point is rounded to f32 here and the
    /// answer widened back (a ~1e-7 m error on the surface point, none on the state).
    pub fn closest(&self, x: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        if let Some(mesh) = &self.mesh {
            let p = mesh.nearest(self.pose64.inverse_transform_point(x), max_dist)?;
            return Some(SurfacePoint {
                point: self.pose64.transform_point(p.closest.point),
                normal: self.pose64.rotation * p.normal,
                distance: p.distance,
            });
        }
        match &self.analytic {
            Some(a) => a.closest(&self.pose64, x, max_dist),
            None => self.parry_closest(x, max_dist),
        }
    }

    /// [`Self::closest`] through parry's f32 queries, for any shape.
    pub(crate) fn parry_closest(&self, x: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        let local = self.pose.inverse_transform_point(x.as_vec3());
        let (q, n, d) = local_closest(self.shape.as_ref(), local, max_dist as f32)?;
        Some(SurfacePoint {
            point: self.pose.transform_point(q).as_dvec3(),
            normal: (self.pose.rotation * n).as_dvec3().normalize_or_zero(),
            distance: f64::from(d),
        })
    }

    /// How far the material point of the collider now at `point` moved during this substep
    /// (for a deforming mesh, by the collider's rigid motion only; its contacts follow the
    /// triangles themselves).
    pub fn displacement_at(&self, point: DVec3) -> DVec3 {
        if self.analytic.is_some() || self.mesh.is_some() {
            if self.still {
                return DVec3::ZERO; // exactly, as below
            }
            let local = self.pose64.inverse_transform_point(point);
            return self.pose64.transform_point(local) - self.prev_pose64.transform_point(local);
        }
        if self.pose == self.prev_pose {
            // Exactly zero: a round trip through the inverse pose would leave a rounding error
            // that is the same every substep, which friction would read as a slowly moving
            // surface and follow.
            return DVec3::ZERO;
        }
        let local = self.pose.inverse_transform_point(point.as_vec3());
        (self.pose.transform_point(local) - self.prev_pose.transform_point(local)).as_dvec3()
    }

    /// First hit of the segment `from → to` with the surface: `(fraction, normal facing from)`.
    pub fn sweep(&self, from: DVec3, to: DVec3) -> Option<(f64, DVec3)> {
        if let Some(mesh) = &self.mesh {
            let (a, b) = (
                self.pose64.inverse_transform_point(from),
                self.pose64.inverse_transform_point(to),
            );
            let (t, n) = mesh.sweep(a, b)?;
            return Some((t, self.pose64.rotation * n));
        }
        let Some(shape) = &self.analytic else {
            return self.parry_sweep(from, to);
        };
        let (toi, n) = shape.sweep(&self.pose64, from, to)?;
        Some((toi, if n.dot(to - from) > 0.0 { -n } else { n }))
    }

    /// [`Self::sweep`] through parry's f32 ray cast, for any shape.
    pub(crate) fn parry_sweep(&self, from: DVec3, to: DVec3) -> Option<(f64, DVec3)> {
        let a = self.pose.inverse_transform_point(from.as_vec3());
        let b = self.pose.inverse_transform_point(to.as_vec3());
        let ray = Ray::new(a, b - a);
        let hit = self.shape.cast_local_ray_and_get_normal(&ray, 1.0, false)?;
        let mut n = hit.normal;
        if n.dot(b - a) > 0.0 {
            n = -n;
        }
        Some((
            f64::from(hit.time_of_impact),
            (self.pose.rotation * n).as_dvec3().normalize_or_zero(),
        ))
    }
}

/// The f64 pose of a body at `rest` carried by `motion` at time `t` (s).
fn carry(motion: Motion, t: f64, rest: &WorldPose) -> WorldPose {
    let (translation, rotation) = motion.transform(t).carry(rest.translation, rest.rotation);
    WorldPose::new(translation, rotation)
}

/// Signed closest-point query in the shape's frame: `(point, outward normal, signed distance)`.
fn local_closest(shape: &dyn Shape, p: Vec3, max_dist: f32) -> Option<(Vec3, Vec3, f32)> {
    if let Some(mesh) = shape.as_trimesh() {
        // BVH-pruned: only triangles within max_dist are visited. With pseudo-normals
        // (TriMeshFlags::ORIENTED) `is_inside` says which side of the surface `p` is on.
        let (proj, (tri, _)) =
            mesh.project_local_point_and_get_location_with_max_dist(p, false, max_dist)?;
        let face = mesh.triangle(tri).normal().unwrap_or(Vec3::Y);
        return Some(signed(p, &proj, face));
    }
    if let Some(compound) = shape.as_compound() {
        // The deepest part wins; the caller re-queries after resolving it.
        let mut best: Option<(Vec3, Vec3, f32)> = None;
        for ((part_pose, part), aabb) in compound.shapes().iter().zip(compound.aabbs()) {
            if aabb.distance_to_local_point(p, true) > max_dist {
                continue;
            }
            let lp = part_pose.inverse_transform_point(p);
            if let Some((q, n, d)) = local_closest(part.as_ref(), lp, max_dist)
                && best.is_none_or(|b| d < b.2)
            {
                best = Some((part_pose.transform_point(q), part_pose.rotation * n, d));
            }
        }
        return best;
    }
    if let Some(h) = shape.as_halfspace() {
        let d = h.normal.dot(p);
        return (d <= max_dist).then_some((p - h.normal * d, h.normal, d));
    }
    // solid = false: a point inside is projected onto the boundary (with is_inside set),
    // rather than onto itself.
    let proj = shape.project_local_point(p, false);
    let delta = p - proj.point;
    let hit = if delta.length_squared() > 1e-18 {
        signed(p, &proj, Vec3::Y)
    } else {
        // Exactly on the surface: push away from the shape's middle.
        let fallback = (p - shape.compute_local_aabb().center()).normalize_or(Vec3::Y);
        signed(p, &proj, fallback)
    };
    (hit.2 <= max_dist).then_some(hit)
}

/// Turns a projection into (point, outward normal, signed distance); `fallback` is the normal
/// when `p` lies exactly on the surface.
fn signed(p: Vec3, proj: &PointProjection, fallback: Vec3) -> (Vec3, Vec3, f32) {
    let delta = p - proj.point;
    let len = delta.length();
    if len <= 1e-9 {
        return (proj.point, fallback, 0.0);
    }
    if proj.is_inside {
        (proj.point, -delta / len, -len)
    } else {
        (proj.point, delta / len, len)
    }
}

#[cfg(test)]
mod tests {
    use glam::Quat;

    use super::*;
    use crate::mesh::TriangleMesh;
    use crate::shape::CompoundPart;

    fn at(shape: ShapeDesc, position: DVec3) -> Collider {
        Collider::new(&ColliderDesc::new(shape).at(position)).expect("valid collider")
    }

    /// Signed distance and normal of a point outside and a point inside, per shape.
    #[test]
    fn signed_distance_and_normal_for_every_shape() {
        let cube_points: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .map(|v| v * 2.0 - DVec3::ONE)
            .collect();
        // The same cube as a closed triangle mesh (vertex i has coordinates from its bits).
        let cube = TriangleMesh::new(
            cube_points.clone(),
            vec![
                [0, 4, 6],
                [0, 6, 2],
                [1, 3, 7],
                [1, 7, 5],
                [0, 1, 5],
                [0, 5, 4],
                [2, 6, 7],
                [2, 7, 3],
                [0, 2, 3],
                [0, 3, 1],
                [4, 5, 7],
                [4, 7, 6],
            ],
        )
        .expect("cube mesh");
        let up = DVec3::Y * 10.0;
        let shapes = [
            ShapeDesc::Sphere { radius: 1.0 },
            ShapeDesc::Cuboid {
                half_extents: DVec3::ONE,
            },
            ShapeDesc::Capsule {
                half_height: 0.5,
                radius: 0.5,
            },
            ShapeDesc::HalfSpace { normal: DVec3::Y },
            ShapeDesc::ConvexHull {
                points: cube_points,
            },
            ShapeDesc::Compound(vec![
                CompoundPart::at(DVec3::new(0.0, 0.5, 0.0), ShapeDesc::Sphere { radius: 0.5 }),
                CompoundPart::at(
                    DVec3::new(0.0, -2.0, 0.0),
                    ShapeDesc::Cuboid {
                        half_extents: DVec3::splat(0.5),
                    },
                ),
            ]),
            ShapeDesc::TriMesh(cube),
        ];
        for shape in shapes {
            let kind = shape.kind();
            // The half-space's surface passes through its origin: lift it to match the others.
            let lift = if kind == "half-space" {
                DVec3::Y
            } else {
                DVec3::ZERO
            };
            let c = at(shape, up + lift);
            // Top surface of every shape is at y = 1 (local) → 11 (world).
            let above = c
                .closest(up + DVec3::new(0.0, 1.3, 0.0), 1.0)
                .unwrap_or_else(|| panic!("{kind}: nothing near"));
            assert!((above.distance - 0.3).abs() < 1e-4, "{kind}: {above:?}");
            assert!(
                (above.normal - DVec3::Y).length() < 1e-4,
                "{kind}: {above:?}"
            );
            let inside = c
                .closest(up + DVec3::new(0.0, 0.9, 0.0), 1.0)
                .expect("inside");
            assert!((inside.distance + 0.1).abs() < 1e-4, "{kind}: {inside:?}");
            assert!(
                (inside.normal - DVec3::Y).length() < 1e-4,
                "{kind}: {inside:?}"
            );
            assert!(
                (inside.point - (up + DVec3::Y)).length() < 1e-4,
                "{kind}: {inside:?}"
            );
        }
    }

    #[test]
    fn world_pose_follows_rest_pose_and_motion() {
        let desc = ColliderDesc::new(ShapeDesc::Sphere { radius: 0.1 })
            .at(DVec3::new(0.0, 1.0, 0.0))
            .rotated(DQuat::from_rotation_y(0.5))
            .moving(Motion::Linear {
                velocity: DVec3::new(2.0, 0.0, 0.0),
            });
        let mut c = Collider::new(&desc).expect("valid collider");
        c.set_time(0.2, 0.25);
        let (position, rotation) = c.world_pose();
        assert!(
            (position - DVec3::new(0.5, 1.0, 0.0)).length() < 1e-12,
            "{position:?}"
        );
        assert!(rotation.angle_between(DQuat::from_rotation_y(0.5)) < 1e-7);
        let m = c.world_matrix();
        let origin = m.transform_point3(Vec3::ZERO);
        assert!(
            (origin - Vec3::new(0.5, 1.0, 0.0)).length() < 1e-6,
            "{origin:?}"
        );
        let x = m.transform_vector3(Vec3::X);
        assert!((x - Quat::from_rotation_y(0.5) * Vec3::X).length() < 1e-6);
        // parry's f32 pose, which the queries of hulls and compounds use, agrees.
        let (t, r) = (c.pose().translation, c.pose().rotation);
        assert!(m.abs_diff_eq(Mat4::from_rotation_translation(r, t), 1e-6));
    }

    /// A deforming mesh's animation is evaluated once a frame, at its end; across the frame's
    /// substeps its vertices move linearly from where the last frame left them to there,
    /// reaching the animation's output to the bit at the frame's end.
    #[test]
    fn a_deforming_mesh_moves_linearly_across_each_frame() {
        use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
        let calls = Arc::new(AtomicUsize::new(0));
        let counted = calls.clone();
        // Far from linear in time: each vertex scaled by 1 + t².
        let grow = move |t: f64, rest: &[DVec3], out: &mut [DVec3]| {
            counted.fetch_add(1, Relaxed);
            for (o, v) in out.iter_mut().zip(rest) {
                *o = *v * (1.0 + t * t);
            }
        };
        let desc = ColliderDesc::new(ShapeDesc::TriMesh(TriangleMesh::icosphere(0.5, 1)));
        let mut c = Collider::deforming(&desc, Arc::new(grow)).expect("deforming mesh");
        let rest = c.mesh().expect("a mesh").rest().to_vec();
        let (frames, substeps, dt) = (3, 4, 0.1);
        calls.store(0, Relaxed);
        for f in 0..frames {
            let (t0, t1) = (f as f64 * dt, (f + 1) as f64 * dt);
            for k in 0..substeps {
                let (a, b) = (k as f64 / substeps as f64, (k + 1) as f64 / substeps as f64);
                c.set_time_in_frame(t0 + a * dt, t0 + b * dt, t1);
                let s = (1.0 + t0 * t0) + ((1.0 + t1 * t1) - (1.0 + t0 * t0)) * b;
                for (v, r) in c.mesh_vertices().expect("vertices").iter().zip(&rest) {
                    let want = *r * s;
                    if k + 1 == substeps {
                        assert_eq!(*v, *r * (1.0 + t1 * t1), "frame {f}'s end");
                    } else {
                        assert!((*v - want).length() < 1e-14, "frame {f}, substep {k}");
                    }
                }
            }
        }
        assert_eq!(calls.load(Relaxed), frames, "one evaluation a frame");
    }
}
