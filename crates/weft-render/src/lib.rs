//! Weft's wgpu renderer: lit two-sided cloth with a shadow map, colliders, a ground grid,
//! optional wireframe and particle views, and the dragged-particle marker — drawn into a
//! window surface or an [`Offscreen`] target through the same [`Renderer::render`].
//!
//! The renderer only reads the solver's particle positions (as [`FrameData`]); it never
//! mutates simulation state.
//!
//! The crate's modules:
//!
//! - `camera`: the orbit camera around a target, and rays from pixels and back.
//! - `error`: renderer errors.
//! - `geometry`: CPU-side geometry: cloth normals, collider meshes, wireframe edges and bounds.
//! - `gpu`: adapter, device and queue.
//! - `offscreen`: an offscreen colour target read back as an image.
//! - `pipelines`: render pipelines, bind group layouts and vertex layouts.
//! - `renderer`: the renderer: meshes staged on the CPU, uploaded, and drawn by its passes.
//! - `scene`: what the renderer draws: a scene's fixed meshes and the per-frame state.
//! - `tile`: a rectangle of a larger image drawn on its own, so big renders go a tile at a time.
//! - `uniforms`: the main pass's uniform block, the material palette and the sun.

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
