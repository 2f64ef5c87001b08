//! The renderer's GPU resources: pipelines, uniform and vertex buffers, the shadow map and its
//! bind groups, and the size-dependent depth and multisampled targets.

use glam::{Mat4, UVec2};
use wgpu::util::DeviceExt;

use super::staging::Staging;
use crate::pipelines::{DEPTH_FORMAT, LineVertex, LitVertex, Pipelines, PointInstance};
use crate::uniforms::{Globals, SHADOW_SIZE};

/// Size-dependent targets: depth, and the multisampled colour when MSAA is on.
pub(super) struct Targets {
    pub(super) size: UVec2,
    pub(super) depth: wgpu::TextureView,
    pub(super) msaa: Option<wgpu::TextureView>,
}

/// Everything the renderer holds on the GPU.
pub(super) struct Resources {
    pub(super) color_format: wgpu::TextureFormat,
    pub(super) samples: u32,
    pub(super) pipelines: Pipelines,
    pub(super) globals: wgpu::Buffer,
    pub(super) light: wgpu::Buffer,
    pub(super) main_bind: wgpu::BindGroup,
    pub(super) shadow_bind: wgpu::BindGroup,
    pub(super) shadow_view: wgpu::TextureView,
    pub(super) lit_vertices: wgpu::Buffer,
    pub(super) lit_indices: wgpu::Buffer,
    pub(super) lines: wgpu::Buffer,
    pub(super) points: wgpu::Buffer,
    pub(super) targets: Option<Targets>,
}

/// A vertex or instance buffer of `bytes` (at least 64).
fn buffer(
    device: &wgpu::Device,
    label: &str,
    bytes: usize,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (bytes.max(64) as u64).next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT),
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl Resources {
    /// The pipelines for `color_format` (4× MSAA where both it and the depth format allow),
    /// and buffers sized for `staging`'s layout.
    pub(super) fn new(
        device: &wgpu::Device,
        color_format: wgpu::TextureFormat,
        staging: &Staging,
    ) -> Self {
        let features = color_format.guaranteed_format_features(device.features());
        let depth_features = DEPTH_FORMAT.guaranteed_format_features(device.features());
        let msaa = wgpu::TextureFormatFeatureFlags::MULTISAMPLE_X4;
        let samples = if features.flags.contains(msaa) && depth_features.flags.contains(msaa) {
            4
        } else {
            1
        };
        let pipelines = Pipelines::new(device, color_format, samples);
        let vertex = wgpu::BufferUsages::VERTEX;
        let lit_vertices = buffer(
            device,
            "weft lit vertices",
            staging.vertices.len() * size_of::<LitVertex>(),
            vertex,
        );
        let indices = &staging.indices;
        let lit_indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("weft cloth indices"),
            contents: bytemuck::cast_slice(if indices.is_empty() {
                &[0u32; 4]
            } else {
                &indices[..]
            }),
            usage: wgpu::BufferUsages::INDEX,
        });
        let lines = buffer(
            device,
            "weft lines",
            (2 * staging.edge_count() + 2) * size_of::<LineVertex>(),
            vertex,
        );
        let points = buffer(
            device,
            "weft points",
            (staging.particle_total() + 2) * size_of::<PointInstance>(),
            vertex,
        );

        let uniform = wgpu::BufferUsages::UNIFORM;
        let globals = buffer(device, "weft globals", size_of::<Globals>(), uniform);
        let light = buffer(device, "weft light", size_of::<Mat4>(), uniform);
        let shadow_tex = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("weft shadow map"),
            size: wgpu::Extent3d {
                width: SHADOW_SIZE,
                height: SHADOW_SIZE,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let shadow_view = shadow_tex.create_view(&wgpu::TextureViewDescriptor::default());
        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("weft shadow"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let main_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("weft main"),
            layout: &pipelines.main_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: globals.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&shadow_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&shadow_sampler),
                },
            ],
        });
        let shadow_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("weft shadow"),
            layout: &pipelines.shadow_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: light.as_entire_binding(),
            }],
        });
        Self {
            color_format,
            samples,
            pipelines,
            globals,
            light,
            main_bind,
            shadow_bind,
            shadow_view,
            lit_vertices,
            lit_indices,
            lines,
            points,
            targets: None,
        }
    }

    /// Uploads what `staging` holds.
    pub(super) fn upload(&self, queue: &wgpu::Queue, staging: &Staging) {
        if !staging.vertices.is_empty() {
            queue.write_buffer(
                &self.lit_vertices,
                0,
                bytemuck::cast_slice(&staging.vertices),
            );
        }
        if !staging.lines.is_empty() {
            queue.write_buffer(&self.lines, 0, bytemuck::cast_slice(&staging.lines));
        }
        if !staging.points.is_empty() {
            queue.write_buffer(&self.points, 0, bytemuck::cast_slice(&staging.points));
        }
    }

    /// Makes the depth (and multisampled colour) targets `size` pixels, unless they are.
    pub(super) fn ensure_targets(&mut self, device: &wgpu::Device, size: UVec2) {
        if self.targets.as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        let make = |label, format, samples| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width: size.x,
                        height: size.y,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                    view_formats: &[],
                })
                .create_view(&wgpu::TextureViewDescriptor::default())
        };
        self.targets = Some(Targets {
            size,
            depth: make("weft depth", DEPTH_FORMAT, self.samples),
            msaa: (self.samples > 1)
                .then(|| make("weft msaa colour", self.color_format, self.samples)),
        });
    }
}

/// Copies `bytes` into `dst` through a staging buffer recorded on `encoder`.
pub(super) fn copy_into(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    dst: &wgpu::Buffer,
    bytes: &[u8],
) {
    let staging = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("weft uniform staging"),
        contents: bytes,
        usage: wgpu::BufferUsages::COPY_SRC,
    });
    encoder.copy_buffer_to_buffer(&staging, 0, dst, 0, bytes.len() as u64);
}
