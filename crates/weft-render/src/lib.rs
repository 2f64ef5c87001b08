//! Weft's wgpu renderer: lit two-sided cloth with a shadow map, colliders, a ground grid,
//! optional wireframe and particle views, and the dragged-particle marker — drawn into a
//! window surface or an [`Offscreen`] target through the same [`Renderer::render`].
//!
//! The renderer only reads the solver's particle positions (as [`FrameData`]); it never
//! mutates simulation state.

mod camera;
mod error;
mod geometry;
mod gpu;
mod offscreen;
mod pipelines;
mod renderer;
mod scene;
mod tile;
mod uniforms;

pub use camera::{Camera, Ray};
pub use error::RenderError;
pub use gpu::Gpu;
pub use offscreen::{OFFSCREEN_FORMAT, Offscreen, TILE_MAX};
pub use renderer::Renderer;
pub use scene::{ClothTopology, FrameData, RenderOptions, SceneMeshes, TriMesh};
pub use tile::Tile;
pub use uniforms::{cloth_colour, sun_direction};

/// Re-export of wgpu, so users name the same types.
pub use wgpu;
