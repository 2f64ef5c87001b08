//! The CPU side of a frame: the scene's meshes laid out in the shared buffers once, then each
//! frame's cloth vertices (positions, normals, checker coordinates), collider vertices at
//! their poses, wireframe lines, particles and the drag markers, staged for upload, with the
//! bounds the shadow map focuses on. Nothing here needs a GPU.

use std::ops::Range;

use glam::{Mat4, Vec3};

use super::focus;
use crate::geometry::{self, Bounds, SplitMesh};
use crate::pipelines::{LineVertex, LitVertex, PointInstance};
use crate::scene::{ClothTopology, FrameData, SceneMeshes, TriMesh};
use crate::uniforms::{CLOTH_MATERIALS, COLLIDER_MATERIAL};

/// Linear RGBA of wireframe edges.
const WIRE_COLOUR: [f32; 4] = [0.02, 0.02, 0.03, 0.45];
/// Linear RGBA and radius (px) of particles.
const PARTICLE: ([f32; 4], f32) = ([0.92, 0.92, 0.95, 1.0], 2.5);
/// Linear RGBA and radius (px) of the dragged particle.
const HIGHLIGHT: ([f32; 4], f32) = ([1.0, 0.78, 0.05, 1.0], 7.0);
/// Linear RGBA and radius (px) of the drag target.
const DRAG_TARGET: ([f32; 4], f32) = ([0.15, 0.85, 1.0, 1.0], 6.0);
/// Linear RGBA of the line from the dragged particle to its target.
const DRAG_LINE: [f32; 4] = [1.0, 0.78, 0.05, 0.9];

/// `n` as a draw count (saturating).
pub(super) fn count(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// One cloth's place in the shared buffers.
struct ClothSlot {
    topology: ClothTopology,
    /// Checker coordinates, from the first positions seen.
    uvs: Option<Vec<[f32; 2]>>,
    first_vertex: usize,
    edges: Vec<[u32; 2]>,
    material: u32,
}

/// One collider's place in the shared vertex buffer.
struct ColliderSlot {
    mesh: SplitMesh,
    first_vertex: usize,
    /// Local bounds, for the shadow focus; `None` for meshes too large to focus on.
    bounds: Option<Bounds>,
}

/// A frame's data staged for the GPU, and the layout it follows.
pub(super) struct Staging {
    cloths: Vec<ClothSlot>,
    colliders: Vec<ColliderSlot>,
    /// Cloth indices into `vertices` (fixed).
    pub(super) indices: Vec<u32>,
    /// The colliders' range of `vertices` (fixed).
    pub(super) collider_vertices: Range<u32>,
    /// Cloth vertices, then collider vertices.
    pub(super) vertices: Vec<LitVertex>,
    /// Wireframe edges, then the drag line.
    pub(super) lines: Vec<LineVertex>,
    /// Particles, then the drag markers.
    pub(super) points: Vec<PointInstance>,
    /// The wireframe's vertices: `lines[..wire_count]`.
    pub(super) wire_count: u32,
    /// The drag line's range of `lines`.
    pub(super) overlay_lines: Range<u32>,
    /// The particles: `points[..particle_count]`.
    pub(super) particle_count: u32,
    /// The drag markers' range of `points`.
    pub(super) markers: Range<u32>,
    /// Bounds of the cloths and the colliders near them at the last frame.
    pub(super) focus: Bounds,
    /// The minor grid spacing, chosen from the first frame with bounds.
    pub(super) grid_spacing: Option<f32>,
    scratch_pos: Vec<Vec3>,
    scratch_normal: Vec<Vec3>,
}

impl Staging {
    /// The layout for `scene`: cloth vertices first, then colliders (split at creases), in
    /// one buffer.
    pub(super) fn new(scene: &SceneMeshes) -> Self {
        let mut next = 0usize;
        let mut indices: Vec<u32> = Vec::new();
        let cloths: Vec<ClothSlot> = scene
            .cloths
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let n = c.particle_count;
                let triangles: Vec<[u32; 3]> = c
                    .triangles
                    .iter()
                    .copied()
                    .filter(|t| t.iter().all(|&v| (v as usize) < n))
                    .collect();
                indices.extend(
                    triangles
                        .iter()
                        .flatten()
                        .map(|&v| count(next + v as usize)),
                );
                let slot = ClothSlot {
                    uvs: None,
                    edges: geometry::unique_edges(&triangles),
                    topology: ClothTopology {
                        particle_count: n,
                        triangles,
                    },
                    first_vertex: next,
                    material: count(i) % CLOTH_MATERIALS,
                };
                next += n;
                slot
            })
            .collect();
        let collider_start = next;
        let colliders: Vec<ColliderSlot> = scene
            .colliders
            .iter()
            .map(|m| {
                let mesh = SplitMesh::new(m);
                let mut b = Bounds::default();
                m.positions.iter().for_each(|&p| b.add(p));
                let slot = ColliderSlot {
                    first_vertex: next,
                    bounds: (!b.is_empty() && b.sphere().1 < 25.0).then_some(b),
                    mesh,
                };
                next += slot.mesh.len();
                slot
            })
            .collect();
        Self {
            cloths,
            colliders,
            indices,
            collider_vertices: count(collider_start)..count(next),
            vertices: vec![LitVertex::default(); next],
            lines: Vec::new(),
            points: Vec::new(),
            wire_count: 0,
            overlay_lines: 0..0,
            particle_count: 0,
            markers: 0..0,
            focus: Bounds::default(),
            grid_spacing: None,
            scratch_pos: Vec::new(),
            scratch_normal: Vec::new(),
        }
    }

    /// Replaces collider `i`'s local mesh (a deforming mesh's vertices at this frame, drawn
    /// at the frame's pose from the next [`Self::stage`] on). The mesh must split into as
    /// many vertices as the one it replaces (the same triangles); otherwise, or for an
    /// index past the colliders, nothing changes. Returns whether it was replaced.
    pub(super) fn set_collider_mesh(&mut self, i: usize, mesh: &TriMesh) -> bool {
        let Some(slot) = self.colliders.get_mut(i) else {
            return false;
        };
        let split = SplitMesh::new(mesh);
        if split.len() != slot.mesh.len() {
            return false;
        }
        slot.mesh = split;
        true
    }

    /// Wireframe edges of every cloth.
    pub(super) fn edge_count(&self) -> usize {
        self.cloths.iter().map(|c| c.edges.len()).sum()
    }

    /// Particles of every cloth.
    pub(super) fn particle_total(&self) -> usize {
        self.cloths.iter().map(|c| c.topology.particle_count).sum()
    }

    /// Stages `frame`. Cloths whose position count does not match their topology keep their
    /// previous vertices.
    pub(super) fn stage(&mut self, frame: &FrameData) {
        let mut cloth_bounds = Bounds::default();
        self.lines.clear();
        self.points.clear();
        for (i, slot) in self.cloths.iter_mut().enumerate() {
            let Some(src) = frame.cloths.get(i) else {
                continue;
            };
            if src.len() != slot.topology.particle_count {
                continue;
            }
            geometry::to_f32(src, &mut self.scratch_pos);
            let uvs = slot
                .uvs
                .get_or_insert_with(|| geometry::planar_uvs(&self.scratch_pos));
            geometry::vertex_normals(
                &self.scratch_pos,
                &slot.topology.triangles,
                &mut self.scratch_normal,
            );
            let out = &mut self.vertices[slot.first_vertex..slot.first_vertex + src.len()];
            for (((v, p), n), uv) in out
                .iter_mut()
                .zip(&self.scratch_pos)
                .zip(&self.scratch_normal)
                .zip(uvs.iter())
            {
                *v = LitVertex {
                    pos: p.to_array(),
                    normal: n.to_array(),
                    material: slot.material,
                    uv: *uv,
                };
                cloth_bounds.add(*p);
            }
            for e in &slot.edges {
                for v in e {
                    self.lines.push(LineVertex {
                        pos: self.scratch_pos[*v as usize].to_array(),
                        colour: WIRE_COLOUR,
                    });
                }
            }
            for p in &self.scratch_pos {
                self.points.push(PointInstance {
                    pos: p.to_array(),
                    colour: PARTICLE.0,
                    size_px: PARTICLE.1,
                });
            }
        }
        // Colliders near the cloth (or all bounded ones when there is no cloth) focus the
        // shadow map.
        let near = focus::near(cloth_bounds);
        let mut focus = cloth_bounds;
        for (i, slot) in self.colliders.iter().enumerate() {
            let pose = frame
                .collider_poses
                .get(i)
                .copied()
                .unwrap_or(Mat4::IDENTITY);
            let normal_matrix = Mat4::from_mat3(glam::Mat3::from_mat4(pose).inverse().transpose());
            let out = &mut self.vertices[slot.first_vertex..slot.first_vertex + slot.mesh.len()];
            for ((v, p), n) in out
                .iter_mut()
                .zip(&slot.mesh.positions)
                .zip(&slot.mesh.normals)
            {
                *v = LitVertex {
                    pos: pose.transform_point3(*p).to_array(),
                    normal: normal_matrix
                        .transform_vector3(*n)
                        .normalize_or_zero()
                        .to_array(),
                    material: COLLIDER_MATERIAL,
                    uv: [-1.0, -1.0],
                };
            }
            if let Some(b) = slot.bounds {
                focus = focus.union(focus::collider(b, &pose, near));
            }
        }
        self.focus = focus;
        if self.grid_spacing.is_none() && !focus.is_empty() {
            self.grid_spacing = Some(focus::grid_spacing(focus));
        }
        self.wire_count = count(self.lines.len());
        self.particle_count = count(self.points.len());
        self.stage_drag(frame);
    }

    /// The dragged particle and its target: a line between them and a marker on each.
    fn stage_drag(&mut self, frame: &FrameData) {
        let dragged = frame.highlight.and_then(|(c, p)| {
            frame
                .cloths
                .get(c)
                .and_then(|x| x.get(p))
                .map(|x| x.as_vec3())
        });
        let line_start = self.lines.len();
        let marker_start = self.points.len();
        if let (Some(a), Some(b)) = (dragged, frame.drag_target) {
            for p in [a, b] {
                self.lines.push(LineVertex {
                    pos: p.to_array(),
                    colour: DRAG_LINE,
                });
            }
        }
        if let Some(t) = frame.drag_target {
            self.points.push(PointInstance {
                pos: t.to_array(),
                colour: DRAG_TARGET.0,
                size_px: DRAG_TARGET.1,
            });
        }
        if let Some(a) = dragged {
            self.points.push(PointInstance {
                pos: a.to_array(),
                colour: HIGHLIGHT.0,
                size_px: HIGHLIGHT.1,
            });
        }
        self.overlay_lines = count(line_start)..count(self.lines.len());
        self.markers = count(marker_start)..count(self.points.len());
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    /// Two cloths (a unit square of two triangles, and a second one with a triangle naming a
    /// missing particle) and a unit cube collider.
    fn scene() -> SceneMeshes {
        let square = ClothTopology {
            particle_count: 4,
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        let broken = ClothTopology {
            particle_count: 3,
            triangles: vec![[0, 1, 2], [0, 1, 7]],
        };
        let mut cube = TriMesh {
            positions: Vec::new(),
            indices: Vec::new(),
        };
        for z in [-0.5, 0.5] {
            for y in [-0.5, 0.5] {
                for x in [-0.5, 0.5] {
                    cube.positions.push(Vec3::new(x, y, z));
                }
            }
        }
        cube.indices = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        SceneMeshes {
            cloths: vec![square, broken],
            colliders: vec![cube],
        }
    }

    #[test]
    fn a_frame_is_laid_out_cloths_first_with_its_lines_points_and_markers() {
        let mut s = Staging::new(&scene());
        // Layout: 4 + 3 cloth vertices, then 36 collider corners; the triangle naming a
        // missing particle is dropped.
        assert_eq!(s.indices, vec![0, 1, 2, 0, 2, 3, 4, 5, 6]);
        assert_eq!(s.collider_vertices, 7..43);
        assert_eq!((s.edge_count(), s.particle_total()), (5 + 3, 7));
        let square = [
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        let wrong_count = [DVec3::ZERO; 2];
        let pose = Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0));
        s.stage(&FrameData {
            cloths: &[&square, &wrong_count],
            collider_poses: &[pose],
            highlight: Some((0, 2)),
            drag_target: Some(Vec3::new(1.0, 3.0, 0.0)),
        });
        // The square's vertices: its positions, the normal of its plane, its checker.
        for (v, p) in s.vertices[..4].iter().zip(&square) {
            assert_eq!(v.pos, p.as_vec3().to_array());
            assert_eq!(v.normal, [0.0, 0.0, 1.0]);
            assert_eq!(v.material, 0);
            assert!(v.uv[0] >= 0.0 && v.uv[1] >= 0.0);
        }
        // The second cloth's count does not match: its vertices stay as they were.
        assert!(s.vertices[4..7].iter().all(|v| v.pos == [0.0; 3]));
        // Collider corners at the pose, untextured, normals of unit length.
        for v in &s.vertices[7..] {
            assert_eq!(v.material, COLLIDER_MATERIAL);
            assert_eq!(v.uv, [-1.0, -1.0]);
            assert_eq!((v.pos[2] + 1.0).abs(), 0.5, "{:?}", v.pos);
            assert!((Vec3::from_array(v.normal).length() - 1.0).abs() < 1e-6);
        }
        // The square's 5 edges as lines, its 4 particles, then the drag line and markers.
        assert_eq!(s.wire_count, 10);
        assert_eq!(s.particle_count, 4);
        assert_eq!(s.overlay_lines, 10..12);
        assert_eq!(s.lines[10].pos, [1.0, 2.0, 0.0]);
        assert_eq!(s.lines[11].pos, [1.0, 3.0, 0.0]);
        assert_eq!(s.markers, 4..6);
        // The shadow focus covers the cloth and the part of the cube near it.
        assert!(
            s.focus.min.z < -1.0 && s.focus.max.y == 2.0,
            "{:?}",
            s.focus
        );
        let spacing = focus::grid_spacing(s.focus);
        assert_eq!(s.grid_spacing, Some(spacing));
        // A cloth a hundred times larger, without a drag: no markers, and the grid keeps the
        // spacing it was given first.
        let large = square.map(|p| p * 100.0);
        s.stage(&FrameData {
            cloths: &[&large],
            collider_poses: &[],
            highlight: None,
            drag_target: None,
        });
        assert!(s.overlay_lines.is_empty() && s.markers.is_empty());
        assert_ne!(focus::grid_spacing(s.focus), spacing);
        assert_eq!(s.grid_spacing, Some(spacing), "chosen once");
    }

    /// A deforming collider's new vertices replace its mesh and are drawn at the frame's
    /// pose; a mesh of another size leaves the old one in place.
    #[test]
    fn a_deforming_colliders_new_vertices_are_drawn_at_its_pose() {
        let mut s = Staging::new(&scene());
        let mut cube = scene().colliders.remove(0);
        for p in &mut cube.positions {
            *p *= 2.0;
        }
        assert!(s.set_collider_mesh(0, &cube));
        let pose = Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0));
        let frame = |s: &mut Staging| {
            s.stage(&FrameData {
                cloths: &[],
                collider_poses: &[pose],
                highlight: None,
                drag_target: None,
            })
        };
        frame(&mut s);
        for v in &s.vertices[7..] {
            assert_eq!((v.pos[2] + 1.0).abs(), 1.0, "{:?}", v.pos);
            assert_eq!(v.pos[0].abs(), 1.0, "{:?}", v.pos);
        }
        let mut fewer = cube.clone();
        fewer.indices.pop();
        assert!(!s.set_collider_mesh(0, &fewer));
        assert!(!s.set_collider_mesh(1, &cube));
        frame(&mut s);
        assert!(s.vertices[7..].iter().all(|v| v.pos[0].abs() == 1.0));
    }
}
