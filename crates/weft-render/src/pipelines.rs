//! Render pipelines, bind group layouts and vertex layouts.

use bytemuck::{Pod, Zeroable};

/// Depth format of the main pass and the shadow map.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A vertex of a lit surface (world space).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct LitVertex {
    /// Position (m).
    pub pos: [f32; 3],
    /// Unit normal.
    pub normal: [f32; 3],
    /// Palette index.
    pub material: u32,
    /// Texture coordinates of the cloth's checker (negative: untextured).
    pub uv: [f32; 2],
}

/// A vertex of a line.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct LineVertex {
    /// Position (m).
    pub pos: [f32; 3],
    /// Linear RGBA.
    pub colour: [f32; 4],
}

/// One point marker (an instance).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PointInstance {
    /// Position (m).
    pub pos: [f32; 3],
    /// Linear RGBA.
    pub colour: [f32; 4],
    /// Radius on screen (px).
    pub size_px: f32,
}

/// Every pipeline of the renderer.
pub struct Pipelines {
    /// Globals, shadow map and its sampler.
    pub main_layout: wgpu::BindGroupLayout,
    /// The sun's matrix only.
    pub shadow_layout: wgpu::BindGroupLayout,
    /// Depth-only surfaces into the shadow map.
    pub shadow: wgpu::RenderPipeline,
    /// Background gradient.
    pub sky: wgpu::RenderPipeline,
    /// Ground and grid.
    pub ground: wgpu::RenderPipeline,
    /// Lit surfaces.
    pub lit: wgpu::RenderPipeline,
    /// Depth-tested lines (wireframe).
    pub lines: wgpu::RenderPipeline,
    /// Lines drawn over everything (drag line).
    pub overlay_lines: wgpu::RenderPipeline,
    /// Depth-tested points (particles).
    pub points: wgpu::RenderPipeline,
    /// Points drawn over everything (drag markers).
    pub overlay_points: wgpu::RenderPipeline,
}

const LIT_ATTRS: [wgpu::VertexAttribute; 4] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Uint32, 3 => Float32x2];
const LINE_ATTRS: [wgpu::VertexAttribute; 2] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x4];
const POINT_ATTRS: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x4, 2 => Float32];
const SHADOW_ATTRS: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];

fn layout<T>(
    attributes: &'static [wgpu::VertexAttribute],
    step: wgpu::VertexStepMode,
) -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<T>() as u64,
        step_mode: step,
        attributes,
    }
}

fn depth(
    write: bool,
    compare: wgpu::CompareFunction,
    bias: wgpu::DepthBiasState,
) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: wgpu::StencilState::default(),
        bias,
    })
}

/// Options of one main-pass pipeline.
struct Spec<'a> {
    label: &'a str,
    vs: &'a str,
    fs: &'a str,
    buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    topology: wgpu::PrimitiveTopology,
    depth_write: bool,
    depth_compare: wgpu::CompareFunction,
    blend: Option<wgpu::BlendState>,
}

impl Pipelines {
    /// Builds every pipeline for `color_format` targets with `samples` samples per pixel.
    pub fn new(device: &wgpu::Device, color_format: wgpu::TextureFormat, samples: u32) -> Self {
        let scene = device.create_shader_module(wgpu::include_wgsl!("shaders/scene.wgsl"));
        let shadow_shader = device.create_shader_module(wgpu::include_wgsl!("shaders/shadow.wgsl"));
        let uniform = |binding, visibility| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let main_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("weft main"),
            entries: &[
                uniform(0, wgpu::ShaderStages::VERTEX_FRAGMENT),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
            ],
        });
        let shadow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("weft shadow"),
            entries: &[uniform(0, wgpu::ShaderStages::VERTEX)],
        });
        let main_pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("weft main"),
            bind_group_layouts: &[Some(&main_layout)],
            immediate_size: 0,
        });
        let shadow_pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("weft shadow"),
            bind_group_layouts: &[Some(&shadow_layout)],
            immediate_size: 0,
        });

        let shadow = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("weft shadow"),
            layout: Some(&shadow_pl),
            vertex: wgpu::VertexState {
                module: &shadow_shader,
                entry_point: Some("vs_shadow"),
                compilation_options: Default::default(),
                buffers: &[Some(layout::<LitVertex>(
                    &SHADOW_ATTRS,
                    wgpu::VertexStepMode::Vertex,
                ))],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: depth(
                true,
                wgpu::CompareFunction::LessEqual,
                wgpu::DepthBiasState {
                    constant: 2,
                    slope_scale: 2.0,
                    clamp: 0.0,
                },
            ),
            multisample: wgpu::MultisampleState::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });

        let alpha = Some(wgpu::BlendState::ALPHA_BLENDING);
        let make = |s: Spec| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(s.label),
                layout: Some(&main_pl),
                vertex: wgpu::VertexState {
                    module: &scene,
                    entry_point: Some(s.vs),
                    compilation_options: Default::default(),
                    buffers: s.buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: s.topology,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: depth(
                    s.depth_write,
                    s.depth_compare,
                    wgpu::DepthBiasState::default(),
                ),
                multisample: wgpu::MultisampleState {
                    count: samples,
                    ..Default::default()
                },
                fragment: Some(wgpu::FragmentState {
                    module: &scene,
                    entry_point: Some(s.fs),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: color_format,
                        blend: s.blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let tri = wgpu::PrimitiveTopology::TriangleList;
        let line = wgpu::PrimitiveTopology::LineList;
        let less = wgpu::CompareFunction::LessEqual;
        let always = wgpu::CompareFunction::Always;
        let lit_buf = [Some(layout::<LitVertex>(
            &LIT_ATTRS,
            wgpu::VertexStepMode::Vertex,
        ))];
        let line_buf = [Some(layout::<LineVertex>(
            &LINE_ATTRS,
            wgpu::VertexStepMode::Vertex,
        ))];
        let point_buf = [Some(layout::<PointInstance>(
            &POINT_ATTRS,
            wgpu::VertexStepMode::Instance,
        ))];
        Self {
            shadow,
            sky: make(Spec {
                label: "weft sky",
                vs: "vs_sky",
                fs: "fs_sky",
                buffers: &[],
                topology: tri,
                depth_write: false,
                depth_compare: always,
                blend: None,
            }),
            ground: make(Spec {
                label: "weft ground",
                vs: "vs_ground",
                fs: "fs_ground",
                buffers: &[],
                topology: tri,
                depth_write: true,
                depth_compare: less,
                blend: None,
            }),
            lit: make(Spec {
                label: "weft lit",
                vs: "vs_lit",
                fs: "fs_lit",
                buffers: &lit_buf,
                topology: tri,
                depth_write: true,
                depth_compare: less,
                blend: None,
            }),
            lines: make(Spec {
                label: "weft lines",
                vs: "vs_line",
                fs: "fs_line",
                buffers: &line_buf,
                topology: line,
                depth_write: false,
                depth_compare: less,
                blend: alpha,
            }),
            overlay_lines: make(Spec {
                label: "weft overlay lines",
                vs: "vs_line",
                fs: "fs_line",
                buffers: &line_buf,
                topology: line,
                depth_write: false,
                depth_compare: always,
                blend: alpha,
            }),
            points: make(Spec {
                label: "weft points",
                vs: "vs_point",
                fs: "fs_point",
                buffers: &point_buf,
                topology: tri,
                depth_write: true,
                depth_compare: less,
                blend: alpha,
            }),
            overlay_points: make(Spec {
                label: "weft overlay points",
                vs: "vs_point",
                fs: "fs_point",
                buffers: &point_buf,
                topology: tri,
                depth_write: false,
                depth_compare: always,
                blend: alpha,
            }),
            main_layout,
            shadow_layout,
        }
    }
}
