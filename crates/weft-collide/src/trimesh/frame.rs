//! One mesh collider as every particle sees it in one projection ([`MeshFrame`]), what one
//! particle's contacts with it did ([`Outcome`]), and the skins and rounds the contact tiers
//! share. The candidate lists ([`super::candidates`]) and the contact grid
//! ([`super::grid_contacts`]) add their own methods to [`MeshFrame`].

use glam::DVec3;
use weft_solver::Contacts;

use super::MeshGeometry;
use super::chunk_lists::ChunkLists;
use crate::analytic::WorldPose;
use crate::friction::Friction;

/// Skin of a list, as a fraction of the particle's thickness r: lists are built with radius
/// r (1 + SKIN) beyond the particle's own substep path.
pub(crate) const SKIN: f64 = 0.5;

/// Width of a riding list's guard and reach (`riding`) beyond the list's radius, as a
/// fraction of the particle's thickness r.
pub(crate) const GUARD: f64 = 1.0;

/// Pushes per particle and projection (a push out of one face may land in another, in a
/// concave corner).
pub(crate) const ROUNDS: usize = 3;

/// One mesh collider as seen by every particle in one projection.
pub(crate) struct MeshFrame<'a> {
    /// The surface.
    pub geometry: &'a MeshGeometry,
    /// Collider pose at the end of the substep.
    pub pose: &'a WorldPose,
    /// Collider pose at its start.
    pub prev_pose: &'a WorldPose,
    /// Both poses are the identity: positions are used as they are.
    pub identity: bool,
    /// The pose did not change over the substep.
    pub still: bool,
    /// First projection of the substep: the path starts at the previous position, and the
    /// surface moves along it.
    pub fresh: bool,
    /// Coulomb friction of the collider.
    pub friction: Friction,
}

#[cfg(test)]
impl<'a> MeshFrame<'a> {
    /// A mesh at rest at `pose`, seen in a substep's first projection.
    pub(crate) fn still(g: &'a MeshGeometry, pose: &'a WorldPose, friction: Friction) -> Self {
        Self {
            geometry: g,
            pose,
            prev_pose: pose,
            identity: true,
            still: true,
            fresh: true,
            friction,
        }
    }
}

/// One particle of a run as each contact tier takes it: particle `j` of `lists` (its
/// candidate list and riding list), where it stood at the substep's start
/// (`prev`), where it is now (`x`, moved in place by the pushes) and its thickness `r`.
pub(crate) struct RunParticle<'a> {
    /// The run's candidate lists.
    pub lists: &'a mut ChunkLists,
    /// The particle's index in `lists`.
    pub j: usize,
    /// Its position at the substep's start (world frame).
    pub prev: DVec3,
    /// Its position now (world frame), moved in place.
    pub x: &'a mut DVec3,
    /// Its thickness (m).
    pub r: f64,
}

impl<'a> RunParticle<'a> {
    /// Particle `j` of `lists`, from `prev` to `x`, of thickness `r`.
    pub fn new(lists: &'a mut ChunkLists, j: usize, prev: DVec3, x: &'a mut DVec3, r: f64) -> Self {
        Self {
            lists,
            j,
            prev,
            x,
            r,
        }
    }
}

/// What one particle's contacts with one mesh did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Outcome {
    /// Pushes resolved.
    pub contacts: usize,
    /// Deepest overlap with the thickness shell (m).
    pub depth: f64,
    /// Crossings stopped.
    pub swept: usize,
}

impl From<Outcome> for Contacts {
    fn from(o: Outcome) -> Self {
        Self {
            contacts: o.contacts,
            swept: o.swept,
            depth: o.depth,
        }
    }
}

impl From<Contacts> for Outcome {
    fn from(c: Contacts) -> Self {
        Self {
            contacts: c.contacts,
            depth: c.depth,
            swept: c.swept,
        }
    }
}

impl MeshFrame<'_> {
    pub(super) fn to_local(&self, pose: &WorldPose, x: DVec3) -> DVec3 {
        if self.identity {
            x
        } else {
            pose.inverse_transform_point(x)
        }
    }

    pub(super) fn to_world_vector(&self, v: DVec3) -> DVec3 {
        if self.identity {
            v
        } else {
            self.pose.rotation * v
        }
    }

    /// How far the material point with barycentric weights `bary` on triangle `t` moved over
    /// the substep, in world space; exactly zero for a still surface.
    pub(super) fn surface_displacement(&self, t: usize, bary: [f64; 3]) -> DVec3 {
        let g = self.geometry;
        if self.still && !g.moving {
            return DVec3::ZERO;
        }
        let tri = g.triangles[t];
        let at = |v: &[DVec3]| (0..3).fold(DVec3::ZERO, |s, k| s + v[tri[k] as usize] * bary[k]);
        let (end, start) = (at(&g.end), at(&g.start));
        if self.identity {
            end - start
        } else {
            self.pose.transform_point(end) - self.prev_pose.transform_point(start)
        }
    }
}
