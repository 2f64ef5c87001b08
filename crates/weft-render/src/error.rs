//! Renderer errors.

/// What can go wrong setting up the GPU or reading an image back.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No graphics adapter could be found (no GPU and no software rasteriser).
    #[error(
        "no graphics adapter available ({0}); install Mesa (lavapipe or llvmpipe) or set WGPU_BACKEND"
    )]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("cannot create a graphics device: {0}")]
    Device(String),
    /// The window surface cannot be used.
    #[error("window surface: {0}")]
    Surface(String),
    /// Reading back or encoding an image failed.
    #[error("image: {0}")]
    Image(String),
}
