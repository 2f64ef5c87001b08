//! External forces: gravity, wind (uniform drag and per-triangle aerodynamics), global damping.

use glam::DVec3;
use rayon::prelude::*;

use crate::chunk::CHUNK;
use crate::error::ParamError;
use crate::particles::Particles;

/// Per-triangle aerodynamic drag and lift coefficients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aero {
    /// Air density ρ (kg/m³).
    pub air_density: f64,
    /// Drag coefficient C_d.
    pub drag_coefficient: f64,
    /// Lift coefficient C_l.
    pub lift_coefficient: f64,
}

impl Default for Aero {
    fn default() -> Self {
        Self {
            air_density: 1.2,
            drag_coefficient: 1.0,
            lift_coefficient: 0.3,
        }
    }
}

/// A uniform wind field.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Wind {
    /// Wind velocity (m/s).
    pub velocity: DVec3,
    /// Uniform drag rate (1/s): each particle accelerates by `drag · (wind − v)`.
    pub drag: f64,
    /// Per-triangle aerodynamics, if any.
    pub aero: Option<Aero>,
}

/// Every external influence on the particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Forces {
    /// Gravitational acceleration (m/s²).
    pub gravity: DVec3,
    /// Wind.
    pub wind: Wind,
    /// Global velocity damping rate c (1/s): v ← v·e^(−c h) every substep.
    pub damping: f64,
}

impl Default for Forces {
    fn default() -> Self {
        Self {
            gravity: DVec3::new(0.0, -9.81, 0.0),
            wind: Wind::default(),
            damping: 0.0,
        }
    }
}

impl Forces {
    /// Checks every value is finite and non-negative where it must be.
    pub fn validate(&self) -> Result<(), ParamError> {
        let bad = |name: &str, value: f64, expected| ParamError {
            name: name.to_owned(),
            value,
            expected,
        };
        for (name, v) in [
            ("gravity", self.gravity),
            ("wind.velocity", self.wind.velocity),
        ] {
            if let Some(c) = v.to_array().into_iter().find(|c| !c.is_finite()) {
                return Err(bad(name, c, "finite"));
            }
        }
        let mut scalars = vec![("damping", self.damping), ("wind.drag", self.wind.drag)];
        if let Some(a) = self.wind.aero {
            scalars.extend([
                ("wind.air_density", a.air_density),
                ("wind.drag_coefficient", a.drag_coefficient),
                ("wind.lift_coefficient", a.lift_coefficient),
            ]);
        }
        match scalars
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v >= 0.0))
        {
            Some((name, v)) => Err(bad(name, v, "finite and >= 0")),
            None => Ok(()),
        }
    }

    /// Whether every particle's external acceleration depends on its own velocity alone
    /// ([`Forces::acceleration_of`]): no aerodynamic forces on triangles.
    pub(crate) fn per_particle(&self) -> bool {
        self.wind.aero.is_none()
    }

    /// Gravity and linear drag on a particle moving at `v`: g + c_d (v_wind − v) (m/s²).
    /// See [`crate::air::still_air`] for when it is g to the bit.
    #[inline(always)]
    pub(crate) fn acceleration_of(&self, v: DVec3) -> DVec3 {
        self.gravity + self.wind.drag * (self.wind.velocity - v)
    }

    /// Writes every particle's external acceleration (m/s²) into `accel`.
    pub(crate) fn accelerations(&self, p: &Particles, triangles: &[[u32; 3]], accel: &mut [DVec3]) {
        let wind = self.wind;
        // Per particle, in parallel (each result depends on that particle alone).
        accel
            .par_chunks_mut(CHUNK)
            .zip(p.velocities.par_chunks(CHUNK))
            .for_each(|(a, v)| {
                for (a, v) in a.iter_mut().zip(v) {
                    *a = self.acceleration_of(*v);
                }
            });
        if let Some(aero) = wind.aero {
            for t in triangles {
                let f = aero_force(aero, wind.velocity, p, t);
                for &i in t {
                    accel[i as usize] += f * (p.inv_masses[i as usize] / 3.0);
                }
            }
        }
    }
}

/// Aerodynamic force on one triangle (N), split equally over its corners by the caller.
///
/// With relative air velocity u = v̄ − v_wind, unit normal n turned to face u, cos θ = n·û:
/// drag D = −½ ρ C_d A |u|² cos θ û, lift L = ½ ρ C_l A |u|² cos θ sin θ l̂ with
/// l̂ = (n × û) × û normalised (Keckeisen et al. 2004, "Interactive cloth simulation in
/// virtual environments", §3.2).
fn aero_force(aero: Aero, wind: DVec3, p: &Particles, t: &[u32; 3]) -> DVec3 {
    let [a, b, c] = t.map(|i| p.positions[i as usize]);
    let v_mean = t.iter().map(|&i| p.velocities[i as usize]).sum::<DVec3>() / 3.0;
    let u = v_mean - wind;
    let speed = u.length();
    let cross = (b - a).cross(c - a);
    let twice_area = cross.length();
    if speed < 1e-6 || twice_area < 1e-12 {
        return DVec3::ZERO;
    }
    let u_hat = u / speed;
    let mut n = cross / twice_area;
    if n.dot(u_hat) < 0.0 {
        n = -n;
    }
    let cos = n.dot(u_hat);
    let q = 0.5 * aero.air_density * 0.5 * twice_area * speed * speed;
    let drag = -q * aero.drag_coefficient * cos * u_hat;
    let lift_dir = n.cross(u_hat).cross(u_hat);
    let lift = if lift_dir.length_squared() > 1e-12 {
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        q * aero.lift_coefficient * cos * sin * lift_dir.normalize()
    } else {
        DVec3::ZERO
    };
    drag + lift
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_triangle(v: DVec3) -> Particles {
        let mut p = Particles::default();
        for x in [DVec3::ZERO, DVec3::X, DVec3::Z] {
            p.push(x, 1.0);
        }
        p.velocities.fill(v);
        p
    }

    #[test]
    fn aero_drag_opposes_motion_through_still_air_and_is_quadratic() {
        let aero = Aero {
            lift_coefficient: 0.0,
            ..Aero::default()
        };
        let f1 = aero_force(aero, DVec3::ZERO, &one_triangle(-DVec3::Y), &[0, 1, 2]);
        let f2 = aero_force(
            aero,
            DVec3::ZERO,
            &one_triangle(-2.0 * DVec3::Y),
            &[0, 1, 2],
        );
        // Face-on: |F| = ½ ρ C_d A |u|² with A = ½ m².
        assert!((f1 - DVec3::Y * 0.5 * 1.2 * 0.5).length() < 1e-5, "{f1}");
        assert!((f2.y / f1.y - 4.0).abs() < 1e-4);
        // Edge-on motion feels nothing.
        let f = aero_force(aero, DVec3::ZERO, &one_triangle(DVec3::X), &[0, 1, 2]);
        assert!(f.length() < 1e-6);
    }

    #[test]
    fn lift_is_perpendicular_to_the_relative_wind() {
        let aero = Aero::default();
        let u = DVec3::new(1.0, -1.0, 0.0);
        let f = aero_force(
            Aero {
                drag_coefficient: 0.0,
                ..aero
            },
            DVec3::ZERO,
            &one_triangle(u),
            &[0, 1, 2],
        );
        // ½ρA|u|² C_l cos θ sin θ = 0.6 · 0.3 · 0.5 = 0.09 N at 45°.
        assert!((f.length() - 0.09).abs() < 1e-4, "{f}");
        assert!(f.dot(u).abs() < 1e-5, "lift {f} not perpendicular to {u}");
    }

    #[test]
    fn nan_wind_is_rejected() {
        let mut f = Forces::default();
        f.wind.velocity.x = f64::NAN;
        assert_eq!(
            f.validate().expect_err("must be rejected").name,
            "wind.velocity"
        );
        f = Forces {
            damping: -1.0,
            ..Forces::default()
        };
        assert_eq!(f.validate().expect_err("must be rejected").name, "damping");
    }
}
