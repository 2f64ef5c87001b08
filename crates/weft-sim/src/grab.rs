//! Holding one particle of a cloth and dragging it: the viewer's mouse drag and Python's
//! `Simulation.grab`. The held particle gets inverse mass 0 and is moved to the drag target
//! over the next frame's substeps; released, it gets its mass back and keeps the velocity of
//! the last substep of the drag.

use weft_solver::glam::DVec3;

use crate::{SimError, Simulation};

impl Simulation {
    /// The solver group and solver-global index of particle `particle` of scene cloth `cloth`.
    pub fn locate(&self, cloth: usize, particle: usize) -> Option<(usize, usize)> {
        self.groups.iter().enumerate().find_map(|(g, group)| {
            let j = group.cloths.iter().position(|&c| c == cloth)?;
            let range = &group.solver.cloths().get(j)?.particles;
            (particle < range.len()).then_some((g, range.start + particle))
        })
    }

    /// Holds particle `particle` of scene cloth `cloth` where it is (releasing any particle
    /// held before, in any solver); returns its solver group and solver-global index.
    pub fn grab(&mut self, cloth: usize, particle: usize) -> Result<(usize, usize), SimError> {
        let (group, global) = self.locate(cloth, particle).ok_or_else(|| {
            let name = self.scene.cloths.get(cloth).map(|c| c.name.clone());
            SimError::NoSuchParticle {
                cloth: name.unwrap_or_else(|| format!("#{cloth}")),
                index: particle,
                count: self.cloth_positions_len(cloth),
            }
        })?;
        self.release();
        self.groups[group].solver.grab(global)?;
        Ok((group, global))
    }

    /// The held particle, as (scene cloth, particle within it, drag target), if any.
    pub fn held(&self) -> Option<(usize, usize, DVec3)> {
        self.groups.iter().find_map(|g| {
            let (global, target) = g.solver.grabbed()?;
            g.solver
                .cloths()
                .iter()
                .zip(&g.cloths)
                .find(|(c, _)| c.particles.contains(&global))
                .map(|(c, &i)| (i, global - c.particles.start, target))
        })
    }

    /// Moves the held particle toward `target` (m) over the next frame's substeps; a target
    /// that is not finite is refused. Without a held particle nothing happens.
    pub fn drag_to(&mut self, target: DVec3) -> Result<(), SimError> {
        if !target.is_finite() {
            return Err(SimError::BadValue {
                key: "target".into(),
                expected: "three finite numbers (m)".into(),
                got: format!("{target}"),
            });
        }
        for g in &mut self.groups {
            if g.solver.grabbed().is_some() {
                g.solver.drag_to(target);
            }
        }
        Ok(())
    }

    /// Lets the held particle go (if any): its mass comes back and it keeps its drag velocity.
    pub fn release(&mut self) {
        for g in &mut self.groups {
            g.solver.release();
        }
    }

    /// Particles of scene cloth `cloth` (0 for a cloth that does not exist).
    fn cloth_positions_len(&self, cloth: usize) -> usize {
        if cloth < self.scene.cloths.len() {
            self.cloth_positions(cloth).len()
        } else {
            0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::sim;

    #[test]
    fn a_grabbed_particle_follows_its_target_and_keeps_its_velocity_when_released() {
        let mut s = sim("xpbd", "[0.0, 0.0, 0.0]");
        let start = s.cloth_positions(0)[12];
        let (group, global) = s.grab(0, 12).expect("grabs");
        assert_eq!(s.locate(0, 12), Some((group, global)));
        assert_eq!(s.groups[group].solver.particles().inv_masses[global], 0.0);
        let goal = start + DVec3::new(0.2, 0.0, 0.0);
        s.drag_to(goal).expect("finite");
        assert_eq!(s.held(), Some((0, 12, goal)));
        s.step().expect("steps");
        assert!((s.cloth_positions(0)[12] - goal).length() < 1e-6);
        s.release();
        assert_eq!(s.held(), None);
        let v = s.groups[group].solver.particles().velocities[global];
        assert!((v - DVec3::new(12.0, 0.0, 0.0)).length() < 1e-6, "{v}");
        assert!(s.groups[group].solver.particles().inv_masses[global] > 0.0);
    }

    #[test]
    fn a_missing_particle_or_a_target_that_is_not_finite_is_refused() {
        let mut s = sim("xpbd", "[0.0, 0.0, 0.0]");
        let e = s.grab(0, 25).expect_err("25 particles");
        assert_eq!(
            e.to_string(),
            "cloth `a` has 25 particles: there is no particle 25"
        );
        assert!(s.grab(1, 0).is_err(), "no second cloth");
        s.grab(0, 3).expect("grabs");
        let e = s.drag_to(DVec3::new(f64::NAN, 0.0, 0.0)).expect_err("NaN");
        assert!(e.to_string().contains("finite"), "{e}");
        assert_eq!(s.held().map(|h| h.1), Some(3), "still held, target kept");
    }
}
