//! The four simulation methods and the strategy each plugs into the shared step loop.

use std::fmt;
use std::str::FromStr;

use glam::DVec3;

use crate::constraints::{ConstraintSet, Rule};
use crate::methods::{ImplicitMassSpring, MassSpring, Pbd, Xpbd};
use crate::params::FamilyParams;
use crate::particles::Particles;

/// A simulation method; all four share one particle store, constraint set and step loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Extended Position Based Dynamics (Macklin et al. 2016): compliance, substeps.
    #[default]
    Xpbd,
    /// Position Based Dynamics (Müller et al. 2007): stiffness in [0, 1], iterations.
    Pbd,
    /// Mass-spring with semi-implicit (symplectic) Euler.
    MassSpring,
    /// Mass-spring with backward Euler, one Newton step and conjugate gradients (Baraff &
    /// Witkin 1998).
    ImplicitMassSpring,
}

impl Method {
    /// Every method.
    pub const ALL: [Method; 4] = [
        Method::Xpbd,
        Method::Pbd,
        Method::MassSpring,
        Method::ImplicitMassSpring,
    ];

    /// The scene-file name: `xpbd`, `pbd`, `mass-spring` or `implicit-mass-spring`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Xpbd => "xpbd",
            Method::Pbd => "pbd",
            Method::MassSpring => "mass-spring",
            Method::ImplicitMassSpring => "implicit-mass-spring",
        }
    }

    /// Whether the method integrates spring forces explicitly, so its substep is limited by
    /// the springs' highest mode ([`crate::StabilityBound`]).
    pub fn is_explicit(self) -> bool {
        self == Method::MassSpring
    }

    /// The strategy that implements this method.
    pub(crate) fn strategy(self) -> &'static dyn Strategy {
        match self {
            Method::Xpbd => &Xpbd,
            Method::Pbd => &Pbd,
            Method::MassSpring => &MassSpring,
            Method::ImplicitMassSpring => &ImplicitMassSpring,
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Method::Xpbd => "XPBD",
            Method::Pbd => "PBD",
            Method::MassSpring => "mass-spring",
            Method::ImplicitMassSpring => "implicit mass-spring",
        })
    }
}

/// A method name that is not `xpbd`, `pbd`, `mass-spring` or `implicit-mass-spring`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown method `{0}`: expected `xpbd`, `pbd`, `mass-spring` or `implicit-mass-spring` \
     (or `implicit`)"
)]
pub struct UnknownMethod(pub String);

impl FromStr for Method {
    type Err = UnknownMethod;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s || (s == "implicit" && *m == Method::ImplicitMassSpring))
            .ok_or_else(|| UnknownMethod(s.to_owned()))
    }
}

/// What distinguishes one method inside the shared substep loop.
pub(crate) trait Strategy: Sync {
    /// Adds internal (constraint) accelerations for substep `h` before integration, on top of
    /// the external ones in `accel`; `force` is scratch.
    fn add_internal_forces(
        &self,
        _constraints: &ConstraintSet,
        _particles: &Particles,
        _params: &[FamilyParams],
        _h: f64,
        _force: &mut [DVec3],
        _accel: &mut [DVec3],
    ) {
    }

    /// Whether [`Strategy::add_internal_forces`] adds anything (the mass-spring methods); without
    /// internal forces the general loop computes the external accelerations inside its
    /// integration pass.
    fn has_internal_forces(&self) -> bool {
        false
    }

    /// Starts a substep.
    fn begin_substep(&self, _constraints: &mut ConstraintSet) {}

    /// How constraints are projected with substep `h`, or `None` when they are not projected.
    fn rule(&self, h: f64) -> Option<Rule>;
}
