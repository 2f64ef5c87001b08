//! PBD: projection scaled by a stiffness in [0, 1], whose effect depends on iterations and h.

use super::Strategy;
use crate::constraints::Rule;

/// Position Based Dynamics (Müller et al. 2007), with k applied to every projection.
pub(crate) struct Pbd;

impl Strategy for Pbd {
    fn rule(&self, _h: f64) -> Option<Rule> {
        Some(Rule::Pbd)
    }
}
