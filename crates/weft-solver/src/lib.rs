//! Weft's cloth solver.
//!
//! One particle store ([`Particles`], struct-of-arrays), one coloured constraint set and one
//! substep loop ([`Solver::step_with`]) serve four methods ([`Method`]): XPBD, PBD, explicit
//! mass-spring and implicit mass-spring. Cloths come from grid or triangle-mesh builders;
//! collisions plug in through [`SubstepHook`]. The crate knows nothing of files, windows or
//! rendering. The kernel paths and lane operations come from `weft-simd`.
//!
//! The crate's modules:
//!
//! - `particles`: the particle store, struct-of-arrays state shared by every method.
//! - `cloth`: cloth geometry before it enters a solver: a triangle mesh with masses and pins.
//! - `grid`: rectangular grid cloths: resolution, size, placement, mass and pins.
//! - `topology`: unique edges and the wing vertices across each interior edge.
//! - `params`: constraint families and their per-method parameters, with their range checks.
//! - `material`: fabrics in physical units, and the parameters every method derives from them.
//! - `presets`: fabric presets from published Kawabata (KES-F) measurements and Wang et al.
//!   2011's ten measured fabrics (warp, weft and bias).
//! - `fabric`: a material from a textile lab's measurements, and the virtual cantilever that
//!   reads its bending length back.
//! - `cantilever`: the cantilever bending test's strip, clamp and chord angle.
//! - `elastica`: the heavy elastica, the exact shape of the cantilever bending test.
//! - `cusick`: the Cusick drape test: a fabric disc clamped and draped, and its drape coefficient.
//! - `spring_defaults`: spring constants scaled to the cloth, stable for the explicit springs.
//! - `stability`: the explicit springs' highest mode and the largest stable substep.
//! - `coloring`: greedy graph colouring of the constraints.
//! - `constraints`: the constraint set, its shapes, blocks and lane kernels.
//! - `domains`: domain decomposition of the distance constraints for parallel SIMD sweeps.
//! - `method`: the four methods and the strategy each plugs into the step loop.
//! - `methods`: one small strategy per method, and the `Strategy` trait.
//! - `sparse`: sparse linear algebra for the spring methods: force rows, vectors, blocks, PCG.
//! - `forces`: gravity, wind, aerodynamics and damping.
//! - `air`: when the air leaves a particle's acceleration at gravity, so a kernel may skip drag.
//! - `motion`: prescribed rigid motions for kinematic pins (and colliders elsewhere).
//! - `driver`: driven pins, placed by something outside the solver at every substep.
//! - `chunk`: the task size of the per-particle parallel loops.
//! - `awake`: keeps the pool's other workers awake through a run of short parallel passes.
//! - `solver`: the [`Solver`] and its step loop, fused and general.
//! - `builder`: [`SolverBuilder`], which assembles cloths, constraints and pins into a solver.
//! - `settings`: time stepping settings.
//! - `hook`: the seam through which collisions act inside each substep.
//! - `error`: the crate's errors.
//! - `test_rand` (tests only): a seeded random source for unit tests.
#![warn(missing_docs)]

mod air;
mod awake;
mod builder;
mod cantilever;
mod chunk;
mod cloth;
mod coloring;
pub mod constraints;
mod cusick;
mod domains;
pub mod driver;
mod elastica;
mod error;
mod fabric;
mod forces;
mod grid;
mod hook;
mod material;
mod method;
mod methods;
mod motion;
mod params;
mod particles;
mod presets;
mod settings;
mod solver;
mod sparse;
mod spring_defaults;
mod stability;
#[cfg(test)]
mod test_rand;
mod topology;

pub use builder::SolverBuilder;
pub use cantilever::{Cantilever, STRIP_WIDTH};
pub use cloth::{ClothMesh, Mass};
pub use constraints::Residual;
pub use cusick::{Drape, SHADOW_PIXELS, SPECIMEN_RADIUS, SUPPORT_RADIUS, shadow_area};
pub use domains::DomainStats;
pub use driver::PinDriver;
pub use elastica::{Elastica, MAX_LOAD as ELASTICA_MAX_LOAD, bending_length};
pub use error::{BuildError, MeshError, ParamError, SolverError};
pub use fabric::{
    ASTM_STRIP_LENGTH, CantileverReading, FabricError, FabricMeasurements, KES_LOAD, load_at_chord,
    virtual_cantilever,
};
pub use forces::{Aero, Forces, Wind};
pub use grid::{Corner, Edge, GridDesc, Orientation, Pin};
pub use hook::{Contacts, ParticleContacts, ParticleRun, SubstepContext, SubstepHook};
pub use material::{HINGE_RELAXATION, Material, MaterialStiffness};
pub use method::{Method, UnknownMethod};
pub use motion::{KinematicPin, Motion, RigidTransform};
pub use params::{Anisotropy, ClothParams, Direction, Family, FamilyParams, GROUPS_PER_CLOTH};
pub use particles::Particles;
pub use presets::{PRESETS, preset, preset_names};
pub use settings::{DEFAULT_CG_MAX_ITERATIONS, DEFAULT_CG_TOLERANCE, Settings};
pub use solver::{Cloth, Solver, StepStats};
pub use spring_defaults::{DEFAULT_SPRING_HW, DEFAULT_SPRING_SUBSTEP, stable_spring_defaults};
pub use stability::StabilityBound;
pub use topology::{EdgeWings, Topology};
pub use weft_simd::{SIMD_ENV, SimdPath, UnknownSimdPath};

/// Re-export of the math library, so users share our `DVec3`.
pub use glam;
