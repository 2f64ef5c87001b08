//! The window's wgpu surface, as wgpu's examples keep it (their `SurfaceWrapper`): created
//! with an adapter that can draw to it, configured to the window's size, reconfigured when the
//! window is resized or the surface is lost.

use std::sync::Arc;

use glam::UVec2;
use weft_render::Gpu;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

/// A configured surface of one window.
pub struct WindowSurface {
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
}

impl WindowSurface {
    /// The surface of `window`, and the GPU that draws to it: an sRGB format where offered,
    /// vsync.
    pub fn new(event_loop: &ActiveEventLoop, window: Arc<Window>) -> anyhow::Result<(Self, Gpu)> {
        let display = event_loop.owned_display_handle();
        let mut desc =
            wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(display));
        if wgpu::Backends::from_env().is_none() {
            desc.backends = wgpu::Backends::all();
        }
        let instance = wgpu::Instance::new(desc);
        let size = window.inner_size();
        let surface = instance.create_surface(window)?;
        let gpu = Gpu::for_surface(instance, &surface).map_err(|e| {
            anyhow::anyhow!(
                "no graphics adapter can draw to this window ({e}); `weft run` simulates without one"
            )
        })?;
        let caps = surface.get_capabilities(&gpu.adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(wgpu::TextureFormat::is_srgb)
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| anyhow::anyhow!("the window surface offers no format"))?;
        let mut config = surface
            .get_default_config(&gpu.adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| anyhow::anyhow!("the adapter cannot draw to this window's surface"))?;
        config.format = format;
        config.present_mode = wgpu::PresentMode::AutoVsync;
        surface.configure(&gpu.device, &config);
        Ok((Self { surface, config }, gpu))
    }

    /// The format frames are drawn in.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.config.format
    }

    /// The size frames are drawn at (pixels).
    pub fn size(&self) -> UVec2 {
        UVec2::new(self.config.width, self.config.height)
    }

    /// Follows the window to `width` × `height` pixels (a zero size, a minimised window, is
    /// ignored).
    pub fn resize(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        if width > 0 && height > 0 {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(device, &self.config);
        }
    }

    /// The next frame's texture, or `None` when there is none to draw this time (the surface
    /// was outdated or lost, and is reconfigured for the next frame).
    pub fn acquire(&mut self, device: &wgpu::Device) -> Option<wgpu::SurfaceTexture> {
        match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Some(t),
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(device, &self.config);
                None
            }
            _ => None,
        }
    }
}
