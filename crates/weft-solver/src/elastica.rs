//! The heavy elastica: the exact shape of a clamped strip bending under its own weight, the
//! reference of the cantilever bending test (ASTM D1388).
//!
//! A strip of bending rigidity B (N·m) and weight w per unit area (N/m²) is clamped level at
//! s = 0 and overhangs by L. With φ(s) the angle of its tangent below the horizontal at arc
//! length s, the moment of the weight beyond s is B φ'(s) = ∫ₛᴸ w (x(t) − x(s)) dt, whose
//! derivative is the heavy elastica (Peirce 1930, "The 'handle' of cloth as a measurable
//! quantity", J. Textile Inst. 21, T377, eq. for the cantilever; Love, "A treatise on the
//! mathematical theory of elasticity", §263):
//!
//!   B φ''(s) = −w (L − s) cos φ,   φ(0) = 0 (clamped level),   φ'(L) = 0 (free end).
//!
//! In σ = s/L it is φ'' = −λ (1 − σ) cos φ with the one parameter λ = w L³ / B = (L/c)³,
//! c = (B/w)^(1/3) the bending length. It is solved by shooting: RK4 from σ = 0 for a guess
//! p = φ'(0), and bisection on p, since φ'(1) = p − λ ∫ (1 − σ) cos φ dσ rises with p (a larger
//! p bends the strip more, so cos φ is smaller) and changes sign on [0, λ/2]. At L = 2c
//! (λ = 8) the chord from the clamp to the tip falls at 41.49° below the horizontal, the
//! angle of the test's inclined plane (41.5°).

/// The largest load parameter solved: beyond it the strip hangs nearly straight down, a weak
/// shot curls back past the vertical, and φ'(1) is no longer monotone in φ'(0) (at λ = 100 the
/// chord falls at 69°).
pub const MAX_LOAD: f64 = 100.0;

/// RK4 steps along the strip: the chord angle converges as n⁻⁴, below 1e-9° here.
const STEPS: usize = 2000;

/// The solved shape of a cantilevered strip, in units of its overhang L.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elastica {
    /// λ = w L³ / B = (L/c)³.
    pub load: f64,
    /// Curvature at the clamp times L: φ'(0) in σ = s/L.
    pub root_curvature: f64,
    /// Horizontal reach of the tip from the clamp, over L.
    pub tip_x: f64,
    /// Drop of the tip below the clamp, over L.
    pub tip_drop: f64,
    /// Tangent angle at the tip below the horizontal (rad).
    pub tip_slope: f64,
}

impl Elastica {
    /// The strip of load parameter `load` = w L³ / B, or `None` unless 0 ≤ `load` ≤
    /// [`MAX_LOAD`].
    pub fn solve(load: f64) -> Option<Self> {
        if !(0.0..=MAX_LOAD).contains(&load) {
            return None;
        }
        let (mut lo, mut hi) = (0.0, 0.5 * load);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if shoot(load, mid).end_curvature < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let p = 0.5 * (lo + hi);
        let end = shoot(load, p);
        Some(Self {
            load,
            root_curvature: p,
            tip_x: end.x,
            tip_drop: end.drop,
            tip_slope: end.phi,
        })
    }

    /// The strip of bending rigidity `bending` (N·m) and weight per area `weight` (N/m²)
    /// overhanging by `overhang` (m), or `None` when w L³ / B is not within 0 ..= [`MAX_LOAD`].
    pub fn of_strip(bending: f64, weight: f64, overhang: f64) -> Option<Self> {
        Self::solve(weight * overhang.powi(3) / bending)
    }

    /// Angle of the chord from the clamp to the tip below the horizontal (rad).
    pub fn chord_angle(&self) -> f64 {
        self.tip_drop.atan2(self.tip_x)
    }
}

/// The bending length c = (B/w)^(1/3) (m) of a fabric of bending rigidity `bending` (N·m) and
/// weight per area `weight` (N/m²) (ASTM D1388; Peirce 1930).
pub fn bending_length(bending: f64, weight: f64) -> f64 {
    (bending / weight).cbrt()
}

/// State at σ = 1 of one shot.
struct End {
    phi: f64,
    end_curvature: f64,
    x: f64,
    drop: f64,
}

/// Integrates (φ, φ', x, y) from σ = 0 with φ'(0) = `p` by classic RK4.
fn shoot(load: f64, p: f64) -> End {
    let f = |s: f64, y: [f64; 4]| -> [f64; 4] {
        let (sin, cos) = y[0].sin_cos();
        [y[1], -load * (1.0 - s) * cos, cos, sin]
    };
    let h = 1.0 / STEPS as f64;
    let mut y = [0.0, p, 0.0, 0.0];
    let add = |y: [f64; 4], k: [f64; 4], a: f64| std::array::from_fn(|i| y[i] + a * k[i]);
    for i in 0..STEPS {
        let s = i as f64 * h;
        let k1 = f(s, y);
        let k2 = f(s + 0.5 * h, add(y, k1, 0.5 * h));
        let k3 = f(s + 0.5 * h, add(y, k2, 0.5 * h));
        let k4 = f(s + h, add(y, k3, h));
        y = std::array::from_fn(|j| y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
    }
    End {
        phi: y[0],
        end_curvature: y[1],
        x: y[2],
        drop: y[3],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_twice_the_bending_length_the_chord_falls_at_41_5_degrees() {
        // ASTM D1388's inclined plane: 41.5°; the heavy elastica at L = 2c: 41.49°.
        let e = Elastica::solve(8.0).expect("in range");
        let deg = e.chord_angle().to_degrees();
        assert!((deg - 41.49).abs() < 0.05, "{deg}°");
        // The free end carries no moment, and the strip stays inextensible (tip within L).
        assert!(shoot(8.0, e.root_curvature).end_curvature.abs() < 1e-9);
        assert!(e.tip_x.hypot(e.tip_drop) < 1.0);
        // Scale-free: a strip of the same L/c gives the same angle in any units.
        let strip = Elastica::of_strip(7.8e-6, 0.13 * 9.81, 2.0 * bending_length(7.8e-6, 1.2753))
            .expect("in range");
        assert!((strip.chord_angle().to_degrees() - deg).abs() < 1e-9);
    }

    #[test]
    fn a_light_load_deflects_as_linear_beam_theory_says() {
        // Euler–Bernoulli under uniform load: tip deflection w L⁴/(8B), i.e. λ/8 of L, and
        // root curvature w L²/(2B) = λ/2 (Timoshenko & Gere, "Mechanics of materials", table G-1).
        for load in [1e-4, 1e-3, 1e-2] {
            let e = Elastica::solve(load).expect("in range");
            assert!(
                (e.tip_drop / (load / 8.0) - 1.0).abs() < 1e-3,
                "λ = {load}: drop {}",
                e.tip_drop
            );
            assert!((e.root_curvature / (load / 2.0) - 1.0).abs() < 1e-3);
            // The tip slope w L³/(6B).
            assert!((e.tip_slope / (load / 6.0) - 1.0).abs() < 1e-3);
        }
    }

    #[test]
    fn peirces_formula_gives_the_bending_length_within_a_few_percent() {
        // Peirce's empirical fit c = L (cos(θ/2) / (8 tan θ))^(1/3) (Peirce 1930; ASTM D1388
        // §10), θ the chord angle: within 3 % of the exact c for 10° ≤ θ ≤ 55°.
        for load in [1.5, 3.0, 5.0, 8.0, 12.0] {
            let e = Elastica::solve(load).expect("in range");
            let theta = e.chord_angle();
            let c_exact = load.cbrt().recip();
            let c_peirce = ((0.5 * theta).cos() / (8.0 * theta.tan())).cbrt();
            assert!(
                (c_peirce / c_exact - 1.0).abs() < 0.03,
                "λ = {load}, θ = {:.2}°: {c_peirce} vs {c_exact}",
                theta.to_degrees()
            );
        }
    }

    #[test]
    fn heavier_strips_droop_further_toward_vertical() {
        let angles: Vec<f64> = [0.5, 2.0, 8.0, 30.0, 100.0]
            .map(|l| Elastica::solve(l).expect("in range").chord_angle())
            .to_vec();
        assert!(angles.windows(2).all(|w| w[0] < w[1]), "{angles:?}");
        assert!(angles[4] < std::f64::consts::FRAC_PI_2);
        assert_eq!(Elastica::solve(0.0).expect("in range").tip_drop, 0.0);
        assert!(Elastica::solve(-1.0).is_none() && Elastica::solve(f64::NAN).is_none());
        assert!(Elastica::solve(MAX_LOAD * 1.01).is_none());
    }
}
