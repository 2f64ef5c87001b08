//! Where the shadow map looks and how fine the ground grid is, from the bounds of what was
//! staged: the cloths, and the colliders near them.

use glam::{Mat4, Vec3};

use crate::geometry::{self, Bounds};

/// Colliders within this box focus the shadow map: the cloths' bounding sphere grown to twice
/// its radius (at least 1 m across), or nothing (every collider counts) without cloths.
pub(super) fn near(cloths: Bounds) -> Bounds {
    if cloths.is_empty() {
        return cloths;
    }
    let (c, r) = cloths.sphere();
    Bounds {
        min: c - Vec3::splat(2.0 * r.max(0.5)),
        max: c + Vec3::splat(2.0 * r.max(0.5)),
    }
}

/// The part of a collider with local bounds `b`, placed at `pose`, that the shadow map must
/// cover: its world box, clipped to `near` when there are cloths.
pub(super) fn collider(b: Bounds, pose: &Mat4, near: Bounds) -> Bounds {
    let corners = [
        b.min,
        b.max,
        Vec3::new(b.min.x, b.max.y, b.min.z),
        Vec3::new(b.max.x, b.min.y, b.max.z),
        Vec3::new(b.min.x, b.min.y, b.max.z),
        Vec3::new(b.max.x, b.max.y, b.min.z),
        Vec3::new(b.min.x, b.max.y, b.max.z),
        Vec3::new(b.max.x, b.min.y, b.min.z),
    ];
    let w = geometry::transformed_bounds(&corners, pose);
    if near.is_empty() {
        w
    } else {
        w.intersect(near)
    }
}

/// The minor grid spacing for a scene of bounds `focus`: a power of ten about a twentieth of
/// its size (~0.1 m for a 1 m cloth).
pub(super) fn grid_spacing(focus: Bounds) -> f32 {
    let size = 2.0 * focus.sphere().1;
    10f32.powf((size.max(1e-3)).log10().round()) / 10.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(lo: f32, hi: f32) -> Bounds {
        Bounds {
            min: Vec3::splat(lo),
            max: Vec3::splat(hi),
        }
    }

    #[test]
    fn colliders_far_from_the_cloth_are_clipped_and_the_grid_follows_the_size() {
        let cloth = cube(-0.5, 0.5);
        let near = near(cloth);
        // A 100 m floor under a 1 m cloth: only the part near the cloth counts.
        let floor = collider(cube(-50.0, 50.0), &Mat4::IDENTITY, near);
        assert!(floor.max.x < 5.0 && floor.min.x > -5.0, "{floor:?}");
        // Without cloths a collider counts whole, moved by its pose.
        let moved = collider(
            cube(-1.0, 1.0),
            &Mat4::from_translation(Vec3::X * 10.0),
            near_none(),
        );
        assert_eq!((moved.min.x, moved.max.x), (9.0, 11.0));
        assert_eq!(grid_spacing(cube(-0.5, 0.5)), 0.1);
        assert_eq!(grid_spacing(cube(-5.0, 5.0)), 1.0);
    }

    fn near_none() -> Bounds {
        near(Bounds::default())
    }
}
