//! The character's body as posed shapes: each part of a kinematic body (a round cone, a
//! capsule or a sphere) placed in its own frame, centred between its end spheres with its
//! local y axis from the first end to the second and turning with the bone that carries it.
//! One pose for the renderer, the `/colliders` and `/colliders/state` channels and the export.
//!
//! - `mesh`: a body part's surface as triangles in its own frame, a surface of revolution.

pub mod mesh;

use weft_collide::{BodyPart, KinematicBody};
use weft_solver::glam::{DQuat, DVec3};

use crate::Simulation;

/// One body part at one instant, in its own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartPose {
    /// World position of the part's centre, halfway between its end points (m).
    pub position: DVec3,
    /// World orientation of the part's frame: its local y axis runs from `a` to `b`; about
    /// that axis it turns with the carrying bone.
    pub rotation: DQuat,
    /// First end point, centre of the sphere of radius `r0` (world, m).
    pub a: DVec3,
    /// Second end point, centre of the sphere of radius `r1` (world, m).
    pub b: DVec3,
    /// Radius at `a` (m).
    pub r0: f64,
    /// Radius at `b` (m).
    pub r1: f64,
}

impl PartPose {
    /// The pose of `part`: its round cone's end points and radii, its centre, and the bone's
    /// rotation turned so that local y points from `a` to `b` (the bone's own rotation for a
    /// sphere).
    pub fn of(part: &BodyPart) -> Self {
        let c = part.shape;
        let axis = c.b - c.a;
        let rotation = match axis.try_normalize() {
            // The axis in the bone's frame is fixed, so this turn is too: the part is rigid
            // in its bone's frame and its mesh can be made once.
            Some(dir) => {
                let local = part.rotation.inverse() * dir;
                (part.rotation * DQuat::from_rotation_arc(DVec3::Y, local)).normalize()
            }
            None => part.rotation,
        };
        Self {
            position: 0.5 * (c.a + c.b),
            rotation,
            a: c.a,
            b: c.b,
            r0: c.ra,
            r1: c.rb,
        }
    }

    /// Half the distance between the end points (m).
    pub fn half_height(&self) -> f64 {
        0.5 * (self.b - self.a).length()
    }

    /// Whether both end points coincide (a sphere of radius `r0`).
    pub fn is_sphere(&self) -> bool {
        self.a == self.b
    }

    /// Whether both radii are equal (a capsule).
    pub fn is_capsule(&self) -> bool {
        self.r0 == self.r1
    }

    /// The part's world transform (f32, for the renderer).
    pub fn matrix(&self) -> glam::Mat4 {
        glam::Mat4::from_rotation_translation(
            self.rotation.as_quat().normalize(),
            self.position.as_vec3(),
        )
    }
}

/// The name a body part is logged under: `body/<index in the body table>`.
pub fn part_name(part: usize) -> String {
    format!("body/{part}")
}

/// Every part of the scene's character, named, as the collision world meets it now: its
/// [`KinematicBody`] parts at the solvers' time (the end of the last substep; the character's
/// clock is the solvers'). Empty for a scene without a character.
pub fn parts(sim: &Simulation) -> Vec<(String, PartPose)> {
    let (Some(spec), Some(group)) = (&sim.scene.character, sim.groups.first()) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    spec.character.parts_at(group.solver.time(), &mut out);
    out.iter()
        .enumerate()
        .map(|(i, p)| (part_name(i), PartPose::of(p)))
        .collect()
}

/// The name the skinned glTF character's body is logged under.
pub const MODEL_NAME: &str = "body/model";

/// The scene's skinned glTF character (`[character] model`) as the collision world meets it
/// now: the deforming collider's vertices (skinned and placed at the end of the last substep,
/// the solvers' time), and its triangles. `None` for a scene without one.
pub fn model_mesh(sim: &Simulation) -> Option<(&[DVec3], &[[u32; 3]])> {
    let m = sim.scene.model.as_ref()?;
    let world = sim.groups.first()?.world.as_ref()?;
    let body = world.colliders().iter().find(|c| c.is_deforming())?;
    Some((body.mesh_vertices()?, &m.skin.mesh().triangles))
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_collide::RoundCone;

    #[test]
    fn the_local_y_axis_runs_from_a_to_b_and_turns_with_the_bone() {
        let bone = DQuat::from_rotation_z(0.4) * DQuat::from_rotation_x(-0.3);
        let (a, b) = (DVec3::new(1.0, 2.0, 0.5), DVec3::new(1.2, 1.7, 0.6));
        let part = BodyPart {
            shape: RoundCone::new(a, b, 0.05, 0.03),
            rotation: bone,
            translation: a,
        };
        let p = PartPose::of(&part);
        let h = p.half_height();
        assert!((p.position + p.rotation * DVec3::new(0.0, -h, 0.0) - a).length() < 1e-14);
        assert!((p.position + p.rotation * DVec3::new(0.0, h, 0.0) - b).length() < 1e-14);
        // Turning the bone about the cone's axis turns the part with it.
        let spin = DQuat::from_axis_angle((b - a).normalize(), 0.7);
        let q = PartPose::of(&BodyPart {
            rotation: spin * bone,
            ..part
        });
        assert!(q.rotation.angle_between(spin * p.rotation) < 1e-12);
        assert!(!p.is_sphere() && !p.is_capsule());
    }
}
