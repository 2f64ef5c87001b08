//! Turning mesh-level cloth contact on and off in a world, and what it did.

use weft_solver::Solver;

use super::CollisionWorld;
use crate::cloth_contact::{ClothContact, ClothContactParams, ClothContactStats};
use crate::error::CollideError;

impl CollisionWorld {
    /// Turns on mesh-level contact among `cloths` (within and between them: vertex–triangle
    /// and edge–edge within the thickness, and the continuous check that no substep creates a
    /// crossing), taking the solver's current positions as the rest state.
    pub fn enable_cloth_contact(
        &mut self,
        solver: &Solver,
        cloths: &[usize],
        params: ClothContactParams,
    ) -> Result<(), CollideError> {
        self.cloth_contact = Some(ClothContact::new(solver, cloths, params, &self.thickness)?);
        Ok(())
    }

    /// Turns cloth contact off.
    pub fn disable_cloth_contact(&mut self) {
        self.cloth_contact = None;
    }

    /// What cloth contact did in the last substep, or `None` when it is off.
    pub fn cloth_contact_stats(&self) -> Option<ClothContactStats> {
        self.cloth_contact.as_ref().map(ClothContact::stats)
    }
}
