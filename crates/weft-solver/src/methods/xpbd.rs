//! XPBD: multipliers reset every substep, projection with compliance α̃ = α/h².

use super::Strategy;
use crate::constraints::{ConstraintSet, Rule};

/// Extended Position Based Dynamics (Macklin, Müller, Chentanez 2016).
pub(crate) struct Xpbd;

impl Strategy for Xpbd {
    fn begin_substep(&self, constraints: &mut ConstraintSet) {
        constraints.reset_multipliers();
    }

    fn rule(&self, h: f64) -> Option<Rule> {
        Some(Rule::Xpbd { h })
    }
}
