//! Isometric bending: C = |Σᵢ kᵢ xᵢ| over the four vertices of an interior edge, with constant
//! weights from the flat rest shape (Bergou, Wardetzky, Harmon, Zorin and Grinspun 2006, "A
//! quadratic bending model for inextensible surfaces", §3).
//!
//! The weights are the hinge's cotangent weights, Kₐ = cot α₃ + cot α₄ = |e|²/(2A₁) for the
//! wing of triangle 1 (A₁ its area) and the like for the other wing, with the edge vertices'
//! weights fixed by Σ Kᵢ = 0 and Σ Kᵢ x̄ᵢ = 0 at rest: the one combination of four points in a
//! plane that every affine map of the plane (and every rigid motion of space) sends to zero.
//! Scaled by 1/√(A₁ + A₂), the energy ½ B C² summed over the edges is the plate energy
//! ½ B ∫ (κ₁ + κ₂)² dA of a surface bent without stretching: a sheet of equilateral triangles
//! rolled into a cylinder of curvature κ about any direction stores ½ B κ² per unit area (tested),
//! so the compliance is 1/B for any mesh resolution. The energy is quadratic in the positions,
//! its Hessian constant, and it needs no angle: one square root per projection.

use glam::DVec3;

use super::Shape;

/// Isometric bending of the hinge `[wing_a, wing_b, edge_0, edge_1]` (the order of
/// [`super::Dihedral`]), flat at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isometric {
    /// kᵢ = Kᵢ/√(A₁ + A₂) (1/m), in the hinge's particle order; they sum to zero.
    pub weights: [f64; 4],
}

impl Isometric {
    /// Σᵢ wᵢ kᵢ² for particles of inverse masses `w`: the multiplier step's Σ w|∇C|² on each
    /// axis, the same in every configuration (∇ᵢCₐ = kᵢ).
    pub fn stiffness(&self, w: [f64; 4]) -> f64 {
        (0..4)
            .map(|i| w[i] * self.weights[i] * self.weights[i])
            .sum()
    }

    /// The weights of the hinge at its rest positions `p`, or `None` when a triangle or the
    /// hinge is degenerate (area below 1e-24 m² or edge below 1e-9 m).
    ///
    /// A hinge that is not flat at rest gets the weights of its two triangles laid flat, so its
    /// rest shape is the unfolded one.
    pub fn at_rest(p: &[DVec3; 4]) -> Option<Self> {
        let [x1, x2, x3, x4] = *p;
        let e = x4 - x3;
        let e2 = e.length_squared();
        let a1 = 0.5 * (x1 - x3).cross(x1 - x4).length();
        let a2 = 0.5 * (x2 - x4).cross(x2 - x3).length();
        if a1 < 1e-24 || a2 < 1e-24 || e2 < 1e-18 {
            return None;
        }
        // Each wing's weight |e|²/(2A) and its split over the edge's ends: the wing's foot on the
        // edge line at x₃ + t (x₄ − x₃) balances it as −K (1 − t) at x₃ and −K t at x₄, so that
        // K (x_wing − foot) is perpendicular to the edge for both wings and the two cancel in
        // the plane (K₁ h₁ = |e|²/2 = K₂ h₂ with opposite directions once laid flat).
        let k1 = e2 / (2.0 * a1);
        let k2 = e2 / (2.0 * a2);
        let t1 = (x1 - x3).dot(e) / e2;
        let t2 = (x2 - x3).dot(e) / e2;
        let s = 1.0 / (a1 + a2).sqrt();
        Some(Self {
            weights: [
                k1 * s,
                k2 * s,
                -(k1 * (1.0 - t1) + k2 * (1.0 - t2)) * s,
                -(k1 * t1 + k2 * t2) * s,
            ],
        })
    }

    /// v = Σᵢ kᵢ xᵢ, the hinge's curvature vector (1/m · m).
    #[inline(always)]
    pub fn curvature(&self, p: &[DVec3; 4]) -> DVec3 {
        let k = self.weights;
        p[0] * k[0] + p[1] * k[1] + p[2] * k[2] + p[3] * k[3]
    }
}

impl Shape<4> for Isometric {
    /// The lane kernel projects C as the vector v, one multiplier per axis
    /// ([`super::isometric_lanes`]).
    const MULTIPLIERS: usize = 3;

    /// C = |v| and ∇ᵢC = kᵢ v/|v|; `None` where v vanishes (flat hinge: no direction).
    #[inline(always)]
    fn evaluate(&self, p: &[DVec3; 4]) -> Option<(f64, [DVec3; 4])> {
        let v = self.curvature(p);
        let c = v.length();
        if c < 1e-12 {
            return None;
        }
        let n = v / c;
        Some((c, self.weights.map(|k| n * k)))
    }

    /// (∇²C) dp = kᵢ (I − n nᵀ) (Σⱼ kⱼ dpⱼ) / |v|.
    fn curvature_product(&self, p: &[DVec3; 4], dp: &[DVec3; 4]) -> [DVec3; 4] {
        let v = self.curvature(p);
        let c = v.length();
        if c < 1e-12 {
            return [DVec3::ZERO; 4];
        }
        let n = v / c;
        let dv = self.curvature(dp);
        let h = (dv - n * n.dot(dv)) / c;
        self.weights.map(|k| h * k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hinge() -> [DVec3; 4] {
        [
            DVec3::new(0.2, 0.9, 0.0),
            DVec3::new(0.7, -0.6, 0.0),
            DVec3::new(-0.4, 0.05, 0.0),
            DVec3::new(0.8, -0.1, 0.0),
        ]
    }

    #[test]
    fn affine_maps_of_the_rest_hinge_and_rigid_motions_have_no_curvature() {
        let rest = hinge();
        let shape = Isometric::at_rest(&rest).expect("not degenerate");
        assert!(shape.weights.iter().sum::<f64>().abs() < 1e-12);
        let affine =
            |p: DVec3| DVec3::new(1.3 * p.x + 0.4 * p.y + 2.0, -0.2 * p.x + 0.7 * p.y, 5.0);
        let rotation = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
        let rigid = |p: DVec3| rotation * p + DVec3::new(3.0, -4.0, 0.5);
        for moved in [rest.map(affine), rest.map(rigid)] {
            let v = shape.curvature(&moved);
            assert!(v.length() < 1e-12, "{v}");
        }
        // Folding the hinge is seen.
        let mut folded = rest;
        folded[0].z = 0.1;
        assert!(shape.curvature(&folded).length() > 1e-2);
    }

    #[test]
    fn gradient_and_curvature_match_finite_differences() {
        let shape = Isometric::at_rest(&hinge()).expect("not degenerate");
        let mut p = hinge();
        p[0].z = 0.3;
        p[1].z = 0.2;
        p[3] += DVec3::new(0.05, 0.02, -0.1);
        let (_, grad) = shape.evaluate(&p).expect("bent");
        let dp = [
            DVec3::new(0.1, -0.2, 0.3),
            DVec3::new(-0.3, 0.1, 0.2),
            DVec3::new(0.2, 0.2, -0.1),
            DVec3::new(0.0, -0.1, 0.4),
        ];
        let h = 1e-6;
        let at = |s: f64| -> [DVec3; 4] { std::array::from_fn(|i| p[i] + dp[i] * s) };
        let c = |q: &[DVec3; 4]| shape.evaluate(q).expect("bent").0;
        let fd = (c(&at(h)) - c(&at(-h))) / (2.0 * h);
        let analytic: f64 = (0..4).map(|i| grad[i].dot(dp[i])).sum();
        assert!((fd - analytic).abs() < 1e-7, "{fd} vs {analytic}");
        let g = |q: &[DVec3; 4]| shape.evaluate(q).expect("bent").1;
        let (gp, gm) = (g(&at(h)), g(&at(-h)));
        let hp = shape.curvature_product(&p, &dp);
        for i in 0..4 {
            let fd = (gp[i] - gm[i]) / (2.0 * h);
            assert!(
                (fd - hp[i]).length() < 1e-6,
                "vertex {i}: {fd} vs {}",
                hp[i]
            );
        }
    }

    #[test]
    fn a_small_fold_costs_the_discrete_shell_weight() {
        // Turning wing a by θ about the edge gives |v| = |e| θ/√(A₁ + A₂) to first order, the
        // discrete-shells energy ½ B |e|² θ²/(A₁ + A₂).
        let rest = hinge();
        let shape = Isometric::at_rest(&rest).expect("not degenerate");
        let (e0, e1) = (rest[2], rest[3]);
        let axis = (e1 - e0).normalize();
        let theta = 1e-4;
        let turn = glam::DQuat::from_axis_angle(axis, theta);
        let mut p = rest;
        p[0] = e0 + turn * (rest[0] - e0);
        let a = |x: DVec3| 0.5 * (x - e0).cross(x - e1).length();
        let want = (e1 - e0).length() * theta / (a(rest[0]) + a(rest[1])).sqrt();
        let got = shape.curvature(&p).length();
        assert!((got / want - 1.0).abs() < 1e-3, "{got} vs {want}");
    }
}
