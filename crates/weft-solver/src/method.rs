//! The three simulation methods and the strategy each plugs into the shared step loop.

use std::fmt;
use std::str::FromStr;

use glam::DVec3;

use crate::constraints::{ConstraintSet, Rule};
use crate::methods::{MassSpring, Pbd, Xpbd};
use crate::params::FamilyParams;
use crate::particles::Particles;

/// A simulation method; all three share one particle store, constraint set and step loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Extended Position Based Dynamics (Macklin et al. 2016): compliance, substeps.
    #[default]
    Xpbd,
    /// Position Based Dynamics (Müller et al. 2007): stiffness in [0, 1], iterations.
    Pbd,
    /// Mass-spring with semi-implicit (symplectic) Euler.
    MassSpring,
}

impl Method {
    /// Every method.
    pub const ALL: [Method; 3] = [Method::Xpbd, Method::Pbd, Method::MassSpring];

    /// The scene-file name: `xpbd`, `pbd` or `mass-spring`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Xpbd => "xpbd",
            Method::Pbd => "pbd",
            Method::MassSpring => "mass-spring",
        }
    }

    /// The strategy that implements this method.
    pub(crate) fn strategy(self) -> &'static dyn Strategy {
        match self {
            Method::Xpbd => &Xpbd,
            Method::Pbd => &Pbd,
            Method::MassSpring => &MassSpring,
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Method::Xpbd => "XPBD",
            Method::Pbd => "PBD",
            Method::MassSpring => "mass-spring",
        })
    }
}

/// A method name that is not `xpbd`, `pbd` or `mass-spring`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown method `{0}`: expected `xpbd`, `pbd` or `mass-spring`")]
pub struct UnknownMethod(pub String);

impl FromStr for Method {
    type Err = UnknownMethod;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownMethod(s.to_owned()))
    }
}

/// What distinguishes one method inside the shared substep loop.
pub(crate) trait Strategy: Sync {
    /// Adds internal (constraint) accelerations before integration; `force` is scratch.
    fn add_internal_forces(
        &self,
        _constraints: &ConstraintSet,
        _particles: &Particles,
        _params: &[FamilyParams],
        _force: &mut [DVec3],
        _accel: &mut [DVec3],
    ) {
    }

    /// Starts a substep.
    fn begin_substep(&self, _constraints: &mut ConstraintSet) {}

    /// How constraints are projected with substep `h`, or `None` when they are not projected.
    fn rule(&self, h: f64) -> Option<Rule>;
}
