//! Weft's cloth solver.
//!
//! One particle store ([`Particles`], struct-of-arrays), one coloured constraint set and one
//! substep loop ([`Solver::step_with`]) serve three methods ([`Method`]): XPBD, PBD and
//! mass-spring. Cloths come from grid or triangle-mesh builders; collisions plug in through
//! [`SubstepHook`]. The crate knows nothing of files, windows or rendering.
#![warn(missing_docs)]

mod builder;
mod chunk;
mod cloth;
mod coloring;
pub mod constraints;
mod domains;
pub mod driver;
mod error;
mod forces;
mod grid;
mod hook;
pub mod lane_ops;
mod material;
mod method;
mod methods;
mod motion;
mod params;
mod particles;
mod presets;
mod settings;
mod solver;
mod spring_defaults;
mod stability;
#[cfg(test)]
mod test_rand;
mod topology;

pub use builder::SolverBuilder;
pub use cloth::{ClothMesh, Mass};
pub use constraints::Residual;
pub use domains::{DomainStats, SIMD_ENV, SimdPath, UnknownSimdPath};
pub use driver::PinDriver;
pub use error::{BuildError, MeshError, ParamError, SolverError};
pub use forces::{Aero, Forces, Wind};
pub use grid::{Corner, Edge, GridDesc, Orientation, Pin};
pub use hook::{Contacts, ParticleContacts, ParticleRun, SubstepContext, SubstepHook};
pub use material::{Material, MaterialStiffness};
pub use method::{Method, UnknownMethod};
pub use motion::{KinematicPin, Motion, RigidTransform};
pub use params::{ClothParams, Family, FamilyParams};
pub use particles::Particles;
pub use presets::{PRESETS, preset, preset_names};
pub use settings::Settings;
pub use solver::{Cloth, Solver, StepStats};
pub use spring_defaults::{DEFAULT_SPRING_HW, DEFAULT_SPRING_SUBSTEP, stable_spring_defaults};
pub use stability::StabilityBound;
pub use topology::{EdgeWings, Topology};

/// Re-export of the math library, so users share our `DVec3`.
pub use glam;
