//! One small strategy per method.

mod explicit_lanes;
mod implicit_mass_spring;
mod mass_spring;
mod pbd;
mod spring_work;
mod strategy;
mod xpbd;

pub(crate) use explicit_lanes::{LaneState, Part, Scratch, Step, step_part};
pub(crate) use implicit_mass_spring::ImplicitMassSpring;
pub(crate) use mass_spring::MassSpring;
pub(crate) use pbd::Pbd;
pub(crate) use spring_work::SpringWork;
pub(crate) use strategy::{ForcePass, Strategy};
pub(crate) use xpbd::Xpbd;
