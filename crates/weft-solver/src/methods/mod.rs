//! One small strategy per method.
//!
//! Its modules:
//!
//! - `explicit_lanes`: explicit mass-spring's substep in lanes, a part of the particles at a time.
//! - `implicit_mass_spring`: implicit mass-spring: backward Euler, one Newton step, by conjugate
//!   gradients.
//! - `mass_spring`: mass-spring: constraint forces integrated with semi-implicit Euler.
//! - `pbd`: PBD: projection scaled by a stiffness, whose effect depends on iterations and substep.
//! - `spring_work`: what the spring methods keep between substeps.
//! - `strategy`: the strategy a method plugs into the shared substep loop.
//! - `xpbd`: XPBD: multipliers reset every substep, projection with substep-scaled compliance.

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
