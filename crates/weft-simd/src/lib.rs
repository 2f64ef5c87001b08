//! The kernel paths Weft's vector kernels run on, and the lane operations they share.
//!
//! [`SimdPath`] names an instruction set (AVX-512, AVX2, NEON or none), picked from the CPU or
//! forced by the `WEFT_SIMD` environment variable; the lane operations ([`on_path`],
//! [`LaneKernel`], [`load`], [`store`], [`Ops`], [`V3`]) run one kernel over `L` f64 lanes of
//! that path. Every width runs the same IEEE operations in the same order, so the path changes
//! the speed, never the bits. The solver's constraint sweep and the collision crate's contact
//! kernels both build on this crate, which depends on neither.
//!
//! Its modules: `path` (the instruction sets and how one is picked) and `lanes` (the lane
//! operations and the kernel trait).

mod lanes;
mod path;

pub use lanes::*;
pub use path::{SIMD_ENV, SimdPath, UnknownSimdPath};
