//! weft-solver's integration tests, one module a subject, linked into one test binary.
//!
//! One binary instead of one per file keeps the test build small on disk and quick to link.

mod common;

mod cantilever;
mod cusick;
mod determinism;
mod dihedral_energy;
mod driven_pins;
mod explicit_stencil;
mod features;
mod free_fall;
mod hanging_cloth;
mod hanging_mass;
mod implicit;
mod isometric_bending;
mod materials;
mod oscillator;
mod simd_paths;
mod small_steps;
mod stability;
mod stop;
