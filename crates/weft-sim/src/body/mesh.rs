//! A body part's surface as triangles in its own frame (see [`super::PartPose`]): a round
//! cone — two spheres joined by the cone tangent to both — as a surface of revolution about
//! the local y axis, its end spheres centred at y = ∓`half_height`.

use glam::Vec3;

/// Segments around the axis.
const AROUND: usize = 32;
/// Rings from pole to pole over a whole sphere.
const RINGS: usize = 16;

/// The ring of the tangent cone on each end sphere: the angle α above the equator of the
/// outward normal where the cone touches both spheres, sin α = (r0 − r1) / (2 h) (the line
/// between the touching points is then perpendicular to that normal). `None` when one sphere
/// holds the other (no cone).
pub fn tangent_angle(r0: f64, r1: f64, half_height: f64) -> Option<f64> {
    let d = 2.0 * half_height;
    (d > (r0 - r1).abs()).then(|| ((r0 - r1) / d).asin())
}

/// The surface of a round cone with radii `r0` at y = −`half_height` and `r1` at
/// y = +`half_height`: vertices and counter-clockwise triangles (outward normals).
pub fn round_cone(r0: f64, r1: f64, half_height: f64) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    use std::f64::consts::FRAC_PI_2;
    // The profile (distance from the axis, height), from the bottom pole to the top one.
    let mut profile: Vec<(f64, f64)> = Vec::new();
    let mut arc = |centre: f64, r: f64, from: f64, to: f64, first: bool| {
        let steps = ((to - from) / std::f64::consts::PI * RINGS as f64)
            .ceil()
            .max(1.0) as usize;
        for k in usize::from(!first)..=steps {
            let th = from + (to - from) * k as f64 / steps as f64;
            profile.push((r * th.cos(), centre + r * th.sin()));
        }
    };
    match tangent_angle(r0, r1, half_height) {
        Some(alpha) => {
            arc(-half_height, r0, -FRAC_PI_2, alpha, true);
            arc(half_height, r1, alpha, FRAC_PI_2, false);
        }
        // One sphere inside the other: the larger is the surface.
        None if r0 >= r1 => arc(-half_height, r0, -FRAC_PI_2, FRAC_PI_2, true),
        None => arc(half_height, r1, -FRAC_PI_2, FRAC_PI_2, true),
    }
    let last = profile.len() - 1;
    let mut positions = vec![Vec3::new(0.0, profile[0].1 as f32, 0.0)];
    for &(rho, y) in &profile[1..last] {
        for j in 0..AROUND {
            let phi = std::f64::consts::TAU * j as f64 / AROUND as f64;
            positions.push(Vec3::new(
                (rho * phi.cos()) as f32,
                y as f32,
                (rho * phi.sin()) as f32,
            ));
        }
    }
    positions.push(Vec3::new(0.0, profile[last].1 as f32, 0.0));
    let rings = last - 1;
    let at = |ring: usize, j: usize| (1 + ring * AROUND + j % AROUND) as u32;
    let top = (positions.len() - 1) as u32;
    let mut triangles = Vec::new();
    for j in 0..AROUND {
        triangles.push([0, at(0, j), at(0, j + 1)]);
        for i in 0..rings - 1 {
            triangles.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
            triangles.push([at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)]);
        }
        triangles.push([top, at(rings - 1, j + 1), at(rings - 1, j)]);
    }
    (positions, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_collide::RoundCone;
    use weft_solver::glam::DVec3;

    /// Every vertex lies on the round cone's surface (closed-form distance from weft-collide),
    /// and every triangle faces away from the axis.
    fn check(r0: f64, r1: f64, h: f64) {
        let cone = RoundCone::new(DVec3::new(0.0, -h, 0.0), DVec3::new(0.0, h, 0.0), r0, r1);
        let (positions, triangles) = round_cone(r0, r1, h);
        for p in &positions {
            let d = cone.signed_distance(p.as_dvec3());
            assert!(d.abs() < 1e-6, "{p} is {d} m off the surface");
        }
        for t in &triangles {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0;
            // Outward: away from the nearest point of the axis segment.
            let axis = Vec3::new(0.0, centre.y.clamp(-h as f32, h as f32), 0.0);
            assert!(n.dot(centre - axis) > 0.0, "triangle {t:?} faces inward");
        }
    }

    #[test]
    fn the_mesh_lies_on_the_round_cone_and_faces_out() {
        check(0.05, 0.03, 0.15);
        check(0.03, 0.06, 0.1);
        check(0.04, 0.04, 0.2);
        check(0.08, 0.02, 0.01); // one sphere holds the other
    }

    #[test]
    fn a_sphere_is_a_whole_ball() {
        let (positions, triangles) = round_cone(0.1, 0.1, 0.0);
        let r = positions.iter().map(|p| p.length()).fold(0.0, f32::max);
        assert!((r - 0.1).abs() < 1e-6);
        assert_eq!(triangles.len(), 2 * AROUND * (RINGS - 1));
    }
}
