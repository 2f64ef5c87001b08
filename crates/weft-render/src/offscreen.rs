//! An offscreen colour target read back as an image.

use glam::UVec2;

use crate::camera::Camera;
use crate::error::RenderError;
use crate::gpu::Gpu;
use crate::renderer::Renderer;
use crate::scene::RenderOptions;
use crate::tile::Tile;

/// The largest tile [`Offscreen::capture`] draws at once (px a side): 1 Mpx, tens of
/// milliseconds on a software rasteriser, so a stop between tiles is honoured well within a
/// second even on a loaded machine.
pub const TILE_MAX: u32 = 1024;

/// The offscreen colour format: 8-bit sRGB, the same colour path as a window surface.
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// An offscreen colour target of `size` pixels, read back as an RGBA image.
pub struct Offscreen {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    size: UVec2,
}

impl Offscreen {
    /// A target for [`capture`](Self::capture)s of images of `full` pixels: one tile's size.
    pub fn for_image(device: &wgpu::Device, full: UVec2) -> Self {
        Self::new(device, full.max(UVec2::ONE).min(UVec2::splat(TILE_MAX)))
    }

    /// Draws `renderer`'s last uploaded frame as an image of `full` pixels, a tile of this
    /// target's size at a time, asking `stopped` before each tile: `Ok(None)` when it says
    /// stop. The tiles' images are the one image's pixels (see [`Tile::clip_from_full`]).
    pub fn capture(
        &self,
        gpu: &Gpu,
        renderer: &mut Renderer,
        camera: &Camera,
        options: &RenderOptions,
        full: UVec2,
        stopped: &dyn Fn() -> bool,
    ) -> Result<Option<image::RgbaImage>, RenderError> {
        let full = full.max(UVec2::ONE);
        if self.size != full.min(UVec2::splat(TILE_MAX)) {
            return Err(RenderError::Image(format!(
                "a {}x{} target cannot capture a {}x{} image",
                self.size.x, self.size.y, full.x, full.y
            )));
        }
        let mut image = image::RgbaImage::new(full.x, full.y);
        for tile in Tile::cover(full, TILE_MAX) {
            if stopped() {
                return Ok(None);
            }
            let mut encoder = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("weft tile"),
                });
            renderer.render_tile(&gpu.device, &mut encoder, &self.view, tile, camera, options);
            gpu.queue.submit([encoder.finish()]);
            let part = self.read(gpu)?;
            image::imageops::replace(
                &mut image,
                &part,
                i64::from(tile.origin.x),
                i64::from(tile.origin.y),
            );
        }
        Ok(Some(image))
    }

    /// A target of `size` pixels (each side at least 1).
    pub fn new(device: &wgpu::Device, size: UVec2) -> Self {
        let size = size.max(UVec2::ONE);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("weft offscreen colour"),
            size: wgpu::Extent3d {
                width: size.x,
                height: size.y,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: OFFSCREEN_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        Self {
            texture,
            view,
            size,
        }
    }

    /// The view to render into.
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// The colour format (sRGB).
    pub fn format(&self) -> wgpu::TextureFormat {
        OFFSCREEN_FORMAT
    }

    /// The size in pixels.
    pub fn size(&self) -> UVec2 {
        self.size
    }

    /// Copies the target back to the CPU (waits for the GPU) as sRGB-encoded RGBA.
    pub fn read(&self, gpu: &Gpu) -> Result<image::RgbaImage, RenderError> {
        let (w, h) = (self.size.x, self.size.y);
        let row = 4 * w;
        let padded =
            row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("weft readback"),
            size: u64::from(padded) * u64::from(h),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("weft readback"),
            });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        gpu.queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            // The receiver outlives the poll below; a failed send only means it gave up.
            let _ = tx.send(r);
        });
        gpu.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Image(format!("waiting for the GPU: {e}")))?;
        rx.recv()
            .map_err(|e| RenderError::Image(format!("readback never completed: {e}")))?
            .map_err(|e| RenderError::Image(format!("cannot map the readback buffer: {e}")))?;
        let mut pixels = Vec::with_capacity((row * h) as usize);
        {
            let data = buffer
                .get_mapped_range(..)
                .map_err(|e| RenderError::Image(format!("cannot read the readback buffer: {e}")))?;
            for y in 0..h as usize {
                let start = y * padded as usize;
                pixels.extend_from_slice(&data[start..start + row as usize]);
            }
        }
        buffer.unmap();
        image::RgbaImage::from_raw(w, h, pixels)
            .ok_or_else(|| RenderError::Image("readback size mismatch".into()))
    }
}
