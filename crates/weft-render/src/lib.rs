//! Weft's wgpu renderer (work in progress).
