//! The renderer: GPU buffers for a scene's meshes and the passes that draw them.

use glam::{Mat4, UVec2, Vec3};
use wgpu::util::DeviceExt;

use crate::camera::Camera;
use crate::geometry::{self, Bounds, SplitMesh};
use crate::pipelines::{DEPTH_FORMAT, LineVertex, LitVertex, Pipelines, PointInstance};
use crate::scene::{ClothTopology, FrameData, RenderOptions, SceneMeshes};
use crate::uniforms::{
    self, CLOTH_MATERIALS, COLLIDER_MATERIAL, Globals, GlobalsInput, SHADOW_SIZE,
};

/// Linear RGBA of wireframe edges.
const WIRE_COLOUR: [f32; 4] = [0.02, 0.02, 0.03, 0.45];
/// Linear RGBA and radius (px) of particles.
const PARTICLE: ([f32; 4], f32) = ([0.92, 0.92, 0.95, 1.0], 2.5);
/// Linear RGBA and radius (px) of the dragged particle.
const HIGHLIGHT: ([f32; 4], f32) = ([1.0, 0.78, 0.05, 1.0], 7.0);
/// Linear RGBA and radius (px) of the drag target.
const DRAG_TARGET: ([f32; 4], f32) = ([0.15, 0.85, 1.0, 1.0], 6.0);
/// Linear RGBA of the line from the dragged particle to its target.
const DRAG_LINE: [f32; 4] = [1.0, 0.78, 0.05, 0.9];

/// One cloth's place in the shared buffers.
struct ClothSlot {
    topology: ClothTopology,
    /// Checker coordinates, from the first positions seen unless set.
    uvs: Option<Vec<[f32; 2]>>,
    first_vertex: usize,
    edges: Vec<[u32; 2]>,
    material: u32,
}

/// One collider's place in the shared vertex buffer.
struct ColliderSlot {
    mesh: SplitMesh,
    first_vertex: usize,
    /// Local bounds, for the shadow focus; `None` for meshes too large to focus on.
    bounds: Option<Bounds>,
}

/// Size-dependent targets: depth, and the multisampled colour when MSAA is on.
struct Targets {
    size: UVec2,
    depth: wgpu::TextureView,
    msaa: Option<wgpu::TextureView>,
}

/// Draws one scene; create it once, then [`update`](Self::update) and
/// [`render`](Self::render) every frame.
pub struct Renderer {
    color_format: wgpu::TextureFormat,
    samples: u32,
    pipelines: Pipelines,
    globals: wgpu::Buffer,
    light: wgpu::Buffer,
    main_bind: wgpu::BindGroup,
    shadow_bind: wgpu::BindGroup,
    shadow_view: wgpu::TextureView,
    lit_vertices: wgpu::Buffer,
    lit_indices: wgpu::Buffer,
    cloth_index_count: u32,
    collider_vertices: std::ops::Range<u32>,
    lines: wgpu::Buffer,
    points: wgpu::Buffer,
    cloths: Vec<ClothSlot>,
    colliders: Vec<ColliderSlot>,
    staging: Vec<LitVertex>,
    line_data: Vec<LineVertex>,
    point_data: Vec<PointInstance>,
    wire_count: u32,
    overlay_lines: std::ops::Range<u32>,
    particle_count: u32,
    markers: std::ops::Range<u32>,
    scratch_pos: Vec<Vec3>,
    scratch_normal: Vec<Vec3>,
    targets: Option<Targets>,
    focus: Bounds,
    ground_height: f32,
    grid_spacing: Option<f32>,
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

fn count(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

impl Renderer {
    /// Creates the pipelines and buffers for `scene`, drawing into targets of `color_format`
    /// (an sRGB format is best; others get the sRGB curve applied in the shader).
    pub fn new(
        device: &wgpu::Device,
        color_format: wgpu::TextureFormat,
        scene: &SceneMeshes,
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

        // Cloth vertices first, then colliders (split at creases), in one buffer.
        let mut next = 0usize;
        let mut indices: Vec<u32> = Vec::new();
        let cloths: Vec<ClothSlot> = scene
            .cloths
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let n = c.particle_count;
                let triangles: Vec<[u32; 3]> = c
                    .triangles
                    .iter()
                    .copied()
                    .filter(|t| t.iter().all(|&v| (v as usize) < n))
                    .collect();
                indices.extend(
                    triangles
                        .iter()
                        .flatten()
                        .map(|&v| count(next + v as usize)),
                );
                let slot = ClothSlot {
                    uvs: None,
                    edges: geometry::unique_edges(&triangles),
                    topology: ClothTopology {
                        particle_count: n,
                        triangles,
                    },
                    first_vertex: next,
                    material: count(i) % CLOTH_MATERIALS,
                };
                next += n;
                slot
            })
            .collect();
        let collider_start = next;
        let colliders: Vec<ColliderSlot> = scene
            .colliders
            .iter()
            .map(|m| {
                let mesh = SplitMesh::new(m);
                let mut b = Bounds::default();
                m.positions.iter().for_each(|&p| b.add(p));
                let slot = ColliderSlot {
                    first_vertex: next,
                    bounds: (!b.is_empty() && b.sphere().1 < 25.0).then_some(b),
                    mesh,
                };
                next += slot.mesh.len();
                slot
            })
            .collect();
        let vertex = wgpu::BufferUsages::VERTEX;
        let lit_vertices = buffer(
            device,
            "weft lit vertices",
            next * size_of::<LitVertex>(),
            vertex,
        );
        let lit_indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("weft cloth indices"),
            contents: bytemuck::cast_slice(if indices.is_empty() {
                &[0u32; 4]
            } else {
                &indices[..]
            }),
            usage: wgpu::BufferUsages::INDEX,
        });
        let edge_count: usize = cloths.iter().map(|c| c.edges.len()).sum();
        let particles: usize = cloths.iter().map(|c| c.topology.particle_count).sum();
        let lines = buffer(
            device,
            "weft lines",
            (2 * edge_count + 2) * size_of::<LineVertex>(),
            vertex,
        );
        let points = buffer(
            device,
            "weft points",
            (particles + 2) * size_of::<PointInstance>(),
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
            cloth_index_count: count(indices.len()),
            collider_vertices: count(collider_start)..count(next),
            lines,
            points,
            cloths,
            colliders,
            staging: vec![LitVertex::default(); next],
            line_data: Vec::new(),
            point_data: Vec::new(),
            wire_count: 0,
            overlay_lines: 0..0,
            particle_count: 0,
            markers: 0..0,
            scratch_pos: Vec::new(),
            scratch_normal: Vec::new(),
            targets: None,
            focus: Bounds::default(),
            ground_height: 0.0,
            grid_spacing: None,
        }
    }

    /// The colour format this renderer draws into.
    pub fn color_format(&self) -> wgpu::TextureFormat {
        self.color_format
    }

    /// Samples per pixel of the main pass (4 with MSAA, else 1).
    pub fn sample_count(&self) -> u32 {
        self.samples
    }

    /// Puts the ground plane (and its grid) at height `y` (m); 0 by default.
    pub fn set_ground_height(&mut self, y: f32) {
        if y.is_finite() {
            self.ground_height = y;
        }
    }

    /// Sets the minor grid spacing (m; major lines every 10). By default it is chosen from
    /// the size of the scene at the first update.
    pub fn set_grid_spacing(&mut self, spacing: f32) {
        if spacing.is_finite() && spacing > 0.0 {
            self.grid_spacing = Some(spacing);
        }
    }

    /// Sets cloth `cloth`'s checker coordinates (one per particle; 1 = the cloth's longer
    /// side). By default they are the planar projection of the first positions it is given.
    /// Ignored when the count does not match.
    pub fn set_cloth_uvs(&mut self, cloth: usize, uvs: &[glam::Vec2]) {
        if let Some(slot) = self.cloths.get_mut(cloth)
            && uvs.len() == slot.topology.particle_count
        {
            slot.uvs = Some(uvs.iter().map(|v| v.to_array()).collect());
        }
    }

    /// Bounds of the cloths and (bounded) colliders at the last update.
    pub fn scene_bounds(&self) -> Option<(Vec3, Vec3)> {
        (!self.focus.is_empty()).then_some((self.focus.min, self.focus.max))
    }

    /// Uploads the frame's positions, per-vertex normals and collider poses. Cloths whose
    /// position count does not match their topology keep their previous positions.
    pub fn update(&mut self, queue: &wgpu::Queue, frame: &FrameData) {
        let mut cloth_bounds = Bounds::default();
        self.line_data.clear();
        self.point_data.clear();
        for (i, slot) in self.cloths.iter_mut().enumerate() {
            let Some(src) = frame.cloths.get(i) else {
                continue;
            };
            if src.len() != slot.topology.particle_count {
                continue;
            }
            geometry::to_f32(src, &mut self.scratch_pos);
            let uvs = slot
                .uvs
                .get_or_insert_with(|| geometry::planar_uvs(&self.scratch_pos));
            geometry::vertex_normals(
                &self.scratch_pos,
                &slot.topology.triangles,
                &mut self.scratch_normal,
            );
            let out = &mut self.staging[slot.first_vertex..slot.first_vertex + src.len()];
            for (((v, p), n), uv) in out
                .iter_mut()
                .zip(&self.scratch_pos)
                .zip(&self.scratch_normal)
                .zip(uvs.iter())
            {
                *v = LitVertex {
                    pos: p.to_array(),
                    normal: n.to_array(),
                    material: slot.material,
                    uv: *uv,
                };
                cloth_bounds.add(*p);
            }
            for e in &slot.edges {
                for v in e {
                    self.line_data.push(LineVertex {
                        pos: self.scratch_pos[*v as usize].to_array(),
                        colour: WIRE_COLOUR,
                    });
                }
            }
            for p in &self.scratch_pos {
                self.point_data.push(PointInstance {
                    pos: p.to_array(),
                    colour: PARTICLE.0,
                    size_px: PARTICLE.1,
                });
            }
        }
        // Colliders near the cloth (or all bounded ones when there is no cloth) focus the
        // shadow map.
        let mut near = cloth_bounds;
        if !near.is_empty() {
            let (c, r) = near.sphere();
            near = Bounds {
                min: c - Vec3::splat(2.0 * r.max(0.5)),
                max: c + Vec3::splat(2.0 * r.max(0.5)),
            };
        }
        let mut focus = cloth_bounds;
        for (i, slot) in self.colliders.iter().enumerate() {
            let pose = frame
                .collider_poses
                .get(i)
                .copied()
                .unwrap_or(Mat4::IDENTITY);
            let normal_matrix = Mat4::from_mat3(glam::Mat3::from_mat4(pose).inverse().transpose());
            let out = &mut self.staging[slot.first_vertex..slot.first_vertex + slot.mesh.len()];
            for ((v, p), n) in out
                .iter_mut()
                .zip(&slot.mesh.positions)
                .zip(&slot.mesh.normals)
            {
                *v = LitVertex {
                    pos: pose.transform_point3(*p).to_array(),
                    normal: normal_matrix
                        .transform_vector3(*n)
                        .normalize_or_zero()
                        .to_array(),
                    material: COLLIDER_MATERIAL,
                    uv: [-1.0, -1.0],
                };
            }
            if let Some(b) = slot.bounds {
                let corners = [
                    b.min,
                    b.max,
                    Vec3::new(b.min.x, b.max.y, b.min.z),
                    Vec3::new(b.max.x, b.min.y, b.max.z),
                    Vec3::new(b.min.x, b.min.y, b.max.z),
                    Vec3::new(b.max.x, b.max.y, b.min.z),
                    Vec3::new(b.min.x, b.max.y, b.max.z),
                    Vec3::new(b.max.x, b.min.y, b.min.z),
                ];
                let w = geometry::transformed_bounds(&corners, &pose);
                focus = focus.union(if near.is_empty() {
                    w
                } else {
                    w.intersect(near)
                });
            }
        }
        self.focus = focus;
        if self.grid_spacing.is_none() && !focus.is_empty() {
            // A power of ten about a twentieth of the scene's size: ~0.1 m for a 1 m cloth.
            let size = 2.0 * focus.sphere().1;
            self.grid_spacing = Some(10f32.powf((size.max(1e-3)).log10().round()) / 10.0);
        }
        self.wire_count = count(self.line_data.len());
        self.particle_count = count(self.point_data.len());

        // The dragged particle and its target.
        let dragged = frame.highlight.and_then(|(c, p)| {
            frame
                .cloths
                .get(c)
                .and_then(|x| x.get(p))
                .map(|x| x.as_vec3())
        });
        let line_start = self.line_data.len();
        let marker_start = self.point_data.len();
        if let (Some(a), Some(b)) = (dragged, frame.drag_target) {
            for p in [a, b] {
                self.line_data.push(LineVertex {
                    pos: p.to_array(),
                    colour: DRAG_LINE,
                });
            }
        }
        if let Some(t) = frame.drag_target {
            self.point_data.push(PointInstance {
                pos: t.to_array(),
                colour: DRAG_TARGET.0,
                size_px: DRAG_TARGET.1,
            });
        }
        if let Some(a) = dragged {
            self.point_data.push(PointInstance {
                pos: a.to_array(),
                colour: HIGHLIGHT.0,
                size_px: HIGHLIGHT.1,
            });
        }
        self.overlay_lines = count(line_start)..count(self.line_data.len());
        self.markers = count(marker_start)..count(self.point_data.len());

        if !self.staging.is_empty() {
            queue.write_buffer(&self.lit_vertices, 0, bytemuck::cast_slice(&self.staging));
        }
        if !self.line_data.is_empty() {
            queue.write_buffer(&self.lines, 0, bytemuck::cast_slice(&self.line_data));
        }
        if !self.point_data.is_empty() {
            queue.write_buffer(&self.points, 0, bytemuck::cast_slice(&self.point_data));
        }
    }

    /// Draws the last uploaded frame into `target` (`size` pixels), clearing it and the
    /// renderer's own depth buffer (re-created when `size` changes). The window and the
    /// offscreen recorder both draw through here.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: UVec2,
        camera: &Camera,
        options: &RenderOptions,
    ) {
        let size = size.max(UVec2::ONE);
        self.ensure_targets(device, size);
        let light_view_proj = uniforms::light_view_proj(self.focus, self.ground_height);
        let globals = Globals::new(&GlobalsInput {
            camera,
            size,
            light_view_proj,
            shadows: options.shadows,
            grid: options.grid,
            ground_height: self.ground_height,
            grid_spacing: self.grid_spacing.unwrap_or(0.1),
            encode_srgb: !self.color_format.is_srgb(),
        });
        // Uniforms go through the encoder (render has no queue): a staging copy each frame.
        copy_into(device, encoder, &self.globals, bytemuck::bytes_of(&globals));
        copy_into(
            device,
            encoder,
            &self.light,
            bytemuck::bytes_of(&light_view_proj.to_cols_array()),
        );

        if options.shadows {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("weft shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.shadow_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipelines.shadow);
            pass.set_bind_group(0, &self.shadow_bind, &[]);
            self.draw_surfaces(&mut pass);
        }

        let Some(t) = &self.targets else {
            return;
        };
        let (view, resolve) = match &t.msaa {
            Some(m) => (m, Some(target)),
            None => (target, None),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("weft main"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: if resolve.is_some() {
                        wgpu::StoreOp::Discard
                    } else {
                        wgpu::StoreOp::Store
                    },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &self.main_bind, &[]);
        pass.set_pipeline(&self.pipelines.sky);
        pass.draw(0..3, 0..1);
        pass.set_pipeline(&self.pipelines.ground);
        pass.draw(0..6, 0..1);
        pass.set_pipeline(&self.pipelines.lit);
        self.draw_surfaces(&mut pass);
        if options.wireframe && self.wire_count > 0 {
            pass.set_pipeline(&self.pipelines.lines);
            pass.set_vertex_buffer(0, self.lines.slice(..));
            pass.draw(0..self.wire_count, 0..1);
        }
        if options.particles && self.particle_count > 0 {
            pass.set_pipeline(&self.pipelines.points);
            pass.set_vertex_buffer(0, self.points.slice(..));
            pass.draw(0..6, 0..self.particle_count);
        }
        if !self.overlay_lines.is_empty() {
            pass.set_pipeline(&self.pipelines.overlay_lines);
            pass.set_vertex_buffer(0, self.lines.slice(..));
            pass.draw(self.overlay_lines.clone(), 0..1);
        }
        if !self.markers.is_empty() {
            pass.set_pipeline(&self.pipelines.overlay_points);
            pass.set_vertex_buffer(0, self.points.slice(..));
            pass.draw(0..6, self.markers.clone());
        }
    }

    /// Cloths (indexed) and colliders, with whichever pipeline is set.
    fn draw_surfaces(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.staging.is_empty() {
            return;
        }
        pass.set_vertex_buffer(0, self.lit_vertices.slice(..));
        if self.cloth_index_count > 0 {
            pass.set_index_buffer(self.lit_indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.cloth_index_count, 0, 0..1);
        }
        if !self.collider_vertices.is_empty() {
            pass.draw(self.collider_vertices.clone(), 0..1);
        }
    }

    fn ensure_targets(&mut self, device: &wgpu::Device, size: UVec2) {
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
fn copy_into(
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
