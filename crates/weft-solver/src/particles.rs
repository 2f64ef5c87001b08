//! The particle store: struct-of-arrays state shared by every method.

use glam::DVec3;

/// Particle state as struct-of-arrays; index `i` is the same particle in every array.
///
/// A pinned particle is one with inverse mass 0 and nothing else: no method moves it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    /// Current positions (m).
    pub positions: Vec<DVec3>,
    /// Positions at the start of the current substep (m).
    pub prev_positions: Vec<DVec3>,
    /// Velocities (m/s).
    pub velocities: Vec<DVec3>,
    /// Inverse masses (1/kg); 0 pins the particle.
    pub inv_masses: Vec<f64>,
}

impl Particles {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether the store holds no particle.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Appends a particle at rest with the given inverse mass (0 pins it).
    pub fn push(&mut self, position: DVec3, inv_mass: f64) {
        self.positions.push(position);
        self.prev_positions.push(position);
        self.velocities.push(DVec3::ZERO);
        self.inv_masses.push(inv_mass);
    }

    /// Total kinetic energy ½ Σ m v² of the free particles (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.velocities
            .iter()
            .zip(&self.inv_masses)
            .filter(|(_, w)| **w > 0.0)
            .map(|(v, w)| 0.5 * v.length_squared() / (*w))
            .sum()
    }

    /// Total momentum Σ m v of the free particles (kg·m/s).
    pub fn momentum(&self) -> DVec3 {
        self.velocities
            .iter()
            .zip(&self.inv_masses)
            .filter(|(_, w)| **w > 0.0)
            .map(|(v, w)| *v / *w)
            .sum()
    }
}
