//! One small strategy per method.

mod mass_spring;
mod pbd;
mod xpbd;

pub(crate) use mass_spring::MassSpring;
pub(crate) use pbd::Pbd;
pub(crate) use xpbd::Xpbd;
