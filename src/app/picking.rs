//! Mouse picking, pure geometry: a ray against a cloth's triangles (Möller–Trumbore) and
//! against the camera-facing drag plane.

use weft_solver::glam::DVec3;

/// A ray `origin + t · dir`, t ≥ 0 (`dir` need not be unit length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point (the camera eye).
    pub origin: DVec3,
    /// Direction.
    pub dir: DVec3,
}

impl Ray {
    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.dir
    }
}

/// Where a ray hit a cloth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f64,
    /// The hit point.
    pub point: DVec3,
    /// Index of the hit triangle.
    pub triangle: usize,
    /// The vertex of that triangle nearest the hit point (the cloth's own index).
    pub particle: usize,
}

/// Ray–triangle intersection (Möller and Trumbore, "Fast, Minimum Storage Ray/Triangle
/// Intersection", 1997), two-sided: the ray parameter t > 0 of the hit, if any.
pub fn ray_triangle(ray: &Ray, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let e1 = b - a;
    let e2 = c - a;
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    // Parallel to the plane, or a degenerate triangle.
    if det.abs() <= 1e-12 * e1.length() * e2.length() * ray.dir.length() {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = ray.dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0 && t.is_finite()).then_some(t)
}

/// The nearest hit of `ray` on the mesh `positions` / `triangles`, and the hit triangle's
/// vertex nearest the hit point.
pub fn pick(ray: &Ray, positions: &[DVec3], triangles: &[[u32; 3]]) -> Option<Hit> {
    let mut best: Option<(f64, usize)> = None;
    for (k, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| positions.get(i as usize).copied());
        let (Some(a), Some(b), Some(c)) = (a, b, c) else {
            continue;
        };
        if let Some(t) = ray_triangle(ray, a, b, c)
            && best.is_none_or(|(bt, _)| t < bt)
        {
            best = Some((t, k));
        }
    }
    let (t, triangle) = best?;
    let point = ray.at(t);
    let particle = triangles[triangle]
        .iter()
        .map(|&i| i as usize)
        .min_by(|&i, &j| {
            let di = positions[i].distance_squared(point);
            let dj = positions[j].distance_squared(point);
            di.total_cmp(&dj)
        })?;
    Some(Hit {
        t,
        point,
        triangle,
        particle,
    })
}

/// Where `ray` meets the plane through `point` with normal `normal`, if it does (in front).
pub fn ray_plane(ray: &Ray, point: DVec3, normal: DVec3) -> Option<DVec3> {
    let denom = ray.dir.dot(normal);
    if denom.abs() <= 1e-12 * ray.dir.length() * normal.length() {
        return None;
    }
    let t = (point - ray.origin).dot(normal) / denom;
    (t > 0.0 && t.is_finite()).then(|| ray.at(t))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n × n grid of unit spacing in the plane z = 0, x and y in [0, n − 1], two
    /// triangles per quad, row-major vertices.
    fn grid(n: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let pos = (0..n * n)
            .map(|i| DVec3::new((i % n) as f64, (i / n) as f64, 0.0))
            .collect();
        let mut tris = Vec::new();
        for r in 0..n - 1 {
            for c in 0..n - 1 {
                let i = (r * n + c) as u32;
                let n = n as u32;
                tris.push([i, i + 1, i + n + 1]);
                tris.push([i, i + n + 1, i + n]);
            }
        }
        (pos, tris)
    }

    fn towards(origin: DVec3, target: DVec3) -> Ray {
        Ray {
            origin,
            dir: target - origin,
        }
    }

    #[test]
    fn a_ray_through_a_triangle_hits_it_at_the_right_distance() {
        let ray = towards(DVec3::new(0.2, 0.3, 5.0), DVec3::new(0.2, 0.3, 0.0));
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let t = ray_triangle(&ray, a, b, c).expect("hits");
        assert!((ray.at(t) - DVec3::new(0.2, 0.3, 0.0)).length() < 1e-12);
        // From behind (two-sided), and missing just outside the hypotenuse.
        let back = towards(DVec3::new(0.2, 0.3, -5.0), DVec3::new(0.2, 0.3, 0.0));
        assert!(ray_triangle(&back, a, b, c).is_some());
        let out = towards(DVec3::new(0.51, 0.51, 5.0), DVec3::new(0.51, 0.51, 0.0));
        assert_eq!(ray_triangle(&out, a, b, c), None);
        // Pointing away from the triangle.
        let away = Ray {
            origin: DVec3::new(0.2, 0.3, 5.0),
            dir: DVec3::Z,
        };
        assert_eq!(ray_triangle(&away, a, b, c), None);
        // Parallel to its plane.
        let flat = Ray {
            origin: DVec3::new(-1.0, 0.1, 0.0),
            dir: DVec3::X,
        };
        assert_eq!(ray_triangle(&flat, a, b, c), None);
    }

    #[test]
    fn picking_a_flat_grid_returns_the_vertex_nearest_the_hit() {
        let (pos, tris) = grid(5);
        // Oblique ray aimed near vertex (3, 2) = index 13, slightly off it.
        let aim = DVec3::new(3.1, 1.8, 0.0);
        let ray = towards(DVec3::new(-2.0, 4.0, 6.0), aim);
        let hit = pick(&ray, &pos, &tris).expect("hits the grid");
        assert!((hit.point - aim).length() < 1e-9, "{:?}", hit.point);
        assert_eq!(hit.particle, 13);
        // Near (1, 3) = 16.
        let hit = pick(
            &towards(DVec3::new(1.2, 2.6, 3.0), DVec3::new(0.9, 3.2, 0.0)),
            &pos,
            &tris,
        )
        .expect("hits");
        assert_eq!(hit.particle, 16);
    }

    #[test]
    fn the_nearest_of_two_layers_is_picked() {
        let (mut pos, tris) = grid(3);
        // A second copy of the grid at z = 1, in front of the first as seen from z = 5.
        let n = pos.len() as u32;
        let front: Vec<DVec3> = pos.iter().map(|p| *p + DVec3::Z).collect();
        pos.extend(front);
        let mut all = tris.clone();
        all.extend(tris.iter().map(|t| t.map(|i| i + n)));
        let ray = towards(DVec3::new(1.0, 1.0, 5.0), DVec3::new(1.05, 0.95, 0.0));
        let hit = pick(&ray, &pos, &all).expect("hits");
        assert_eq!(hit.particle, 4 + n as usize);
        assert!((hit.point.z - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_ray_that_misses_picks_nothing() {
        let (pos, tris) = grid(4);
        let beside = towards(DVec3::new(5.0, 5.0, 3.0), DVec3::new(3.5, 4.0, 0.0));
        assert_eq!(pick(&beside, &pos, &tris), None);
        let parallel = Ray {
            origin: DVec3::new(-1.0, 1.5, 0.5),
            dir: DVec3::X,
        };
        assert_eq!(pick(&parallel, &pos, &tris), None);
        assert_eq!(pick(&beside, &[], &[]), None);
    }

    #[test]
    fn the_drag_plane_meets_the_ray_where_expected() {
        let ray = towards(DVec3::new(0.0, 0.0, 10.0), DVec3::new(1.0, 2.0, 0.0));
        let p = ray_plane(&ray, DVec3::new(0.0, 0.0, 5.0), DVec3::Z).expect("meets");
        assert!((p - DVec3::new(0.5, 1.0, 5.0)).length() < 1e-12);
        assert_eq!(ray_plane(&ray, DVec3::new(0.0, 0.0, 20.0), DVec3::Z), None);
        let along = Ray {
            origin: DVec3::ZERO,
            dir: DVec3::X,
        };
        assert_eq!(ray_plane(&along, DVec3::Z, DVec3::Z), None);
    }
}
