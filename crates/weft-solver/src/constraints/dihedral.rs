//! Dihedral bending: C = θ − θ₀ across an interior edge, with the gradients of
//! Bridson et al. 2003 ("Simulation of clothing with folds and wrinkles", §4).

use std::f64::consts::PI;

use glam::DVec3;

use super::Shape;

/// Bending across edge (x₃, x₄) between triangles (x₁, x₃, x₄) and (x₂, x₄, x₃).
///
/// Particle order is `[wing_a, wing_b, edge_0, edge_1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dihedral {
    /// Rest dihedral angle θ₀ (rad).
    pub rest: f64,
}

impl Dihedral {
    /// Signed dihedral angle θ at `p`, in (−π, π]; 0 when both triangles are coplanar.
    pub fn angle(p: &[DVec3; 4]) -> Option<f64> {
        Frame::new(p).map(|f| f.angle())
    }
}

/// The unnormalised normals and hinge of one dihedral, computed once per evaluation.
struct Frame {
    /// N₁ = (x₁ − x₃) × (x₁ − x₄).
    n1: DVec3,
    /// N₂ = (x₂ − x₄) × (x₂ − x₃).
    n2: DVec3,
    /// |N₁|².
    q1: f64,
    /// |N₂|².
    q2: f64,
    /// E = x₄ − x₃.
    e: DVec3,
    /// |E|.
    le: f64,
}

impl Frame {
    /// The frame at `p`, or `None` when a triangle or the hinge is degenerate.
    #[inline(always)]
    fn new(p: &[DVec3; 4]) -> Option<Self> {
        let [x1, x2, x3, x4] = *p;
        let n1 = (x1 - x3).cross(x1 - x4);
        let n2 = (x2 - x4).cross(x2 - x3);
        let e = x4 - x3;
        let (q1, q2, le) = (n1.length_squared(), n2.length_squared(), e.length());
        if q1 < 1e-24 || q2 < 1e-24 || le < 1e-9 {
            return None;
        }
        Some(Self {
            n1,
            n2,
            q1,
            q2,
            e,
            le,
        })
    }

    /// θ = atan2((n̂₁ × n̂₂)·ê, n̂₁·n̂₂) (Bridson et al. 2003, §4), on the unit normals and hinge
    /// (the same operations, hence the same bits, as before the frame was shared with the
    /// gradient).
    #[inline(always)]
    fn angle(&self) -> f64 {
        let (n1, n2) = (self.n1 / self.q1.sqrt(), self.n2 / self.q2.sqrt());
        n1.cross(n2).dot(self.e / self.le).atan2(n1.dot(n2))
    }
}

impl Shape<4> for Dihedral {
    // Inlined into the projection, so that C and ∇C stay in registers instead of being returned
    // through memory (a measurable share of the dihedral block's time).
    #[inline(always)]
    fn evaluate(&self, p: &[DVec3; 4]) -> Option<(f64, [DVec3; 4])> {
        let [x1, x2, x3, x4] = *p;
        let f = Frame::new(p)?;
        let mut c = f.angle() - self.rest;
        if c > PI {
            c -= 2.0 * PI;
        } else if c <= -PI {
            c += 2.0 * PI;
        }
        // Bridson et al. 2003: u₁ = |E| N₁/|N₁|², u₂ = |E| N₂/|N₂|²,
        // u₃ = (x₁ − x₄)·E/|E| N₁/|N₁|² + (x₂ − x₄)·E/|E| N₂/|N₂|²,
        // u₄ = −(x₁ − x₃)·E/|E| N₁/|N₁|² − (x₂ − x₃)·E/|E| N₂/|N₂|².
        // With θ measured as above, ∂θ/∂xᵢ = −uᵢ (checked against finite differences in tests).
        let (m1, m2) = (f.n1 / f.q1, f.n2 / f.q2);
        let le = f.le;
        let u1 = le * m1;
        let u2 = le * m2;
        let u3 = (x1 - x4).dot(f.e) / le * m1 + (x2 - x4).dot(f.e) / le * m2;
        let u4 = -(x1 - x3).dot(f.e) / le * m1 - (x2 - x3).dot(f.e) / le * m2;
        Some((c, [-u1, -u2, -u3, -u4]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> [DVec3; 4] {
        [
            DVec3::new(0.3, 1.0, 0.2),
            DVec3::new(-0.1, -0.9, 0.4),
            DVec3::new(-0.5, 0.05, 0.0),
            DVec3::new(0.6, -0.1, 0.1),
        ]
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let shape = Dihedral { rest: 0.1 };
        for p in [sample(), sample().map(|v| v * 2.0 + DVec3::X)] {
            let (_, grad) = shape.evaluate(&p).expect("not degenerate");
            for k in 0..4 {
                for axis in 0..3 {
                    let h = 1e-3;
                    let (mut a, mut b) = (p, p);
                    a[k][axis] += h;
                    b[k][axis] -= h;
                    let fd = (Dihedral::angle(&a).expect("ok") - Dihedral::angle(&b).expect("ok"))
                        / (2.0 * h);
                    assert!(
                        (fd - grad[k][axis]).abs() < 2e-2 * (1.0 + fd.abs()),
                        "vertex {k} axis {axis}: finite difference {fd}, analytic {}",
                        grad[k][axis]
                    );
                }
            }
            let sum: DVec3 = grad.iter().sum();
            assert!(
                sum.length() < 1e-4,
                "gradients must sum to zero (translation invariance)"
            );
        }
    }

    #[test]
    fn flat_pair_has_zero_angle_and_folding_changes_sign() {
        let flat = [
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
        ];
        assert!(Dihedral::angle(&flat).expect("ok").abs() < 1e-6);
        let mut up = flat;
        up[1].z = 0.5;
        let mut down = flat;
        down[1].z = -0.5;
        let (a, b) = (
            Dihedral::angle(&up).expect("ok"),
            Dihedral::angle(&down).expect("ok"),
        );
        assert!(a * b < 0.0 && (a + b).abs() < 1e-6, "{a} vs {b}");
    }
}
