//! The four simulation methods and the strategy each plugs into the shared step loop.

use std::fmt;
use std::str::FromStr;

use crate::methods::{ImplicitMassSpring, MassSpring, Pbd, Strategy, Xpbd};

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
