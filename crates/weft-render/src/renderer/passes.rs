//! The passes of a frame: the shadow map from the light, then the main pass (sky, ground,
//! lit surfaces, wireframe, particles, drag markers), resolved from MSAA when it is on.

use glam::UVec2;

use super::Renderer;
use super::resources::copy_into;
use super::staging::count;
use crate::camera::Camera;
use crate::scene::RenderOptions;
use crate::tile::Tile;
use crate::uniforms::{self, Globals, GlobalsInput};

impl Renderer {
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
        self.render_tile(device, encoder, target, Tile::whole(size), camera, options);
    }

    /// Draws `tile` of the image into `target` (`tile.size` pixels): the camera frames the
    /// whole image, the target holds only its tile. `weft render` draws big images this way.
    pub fn render_tile(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        tile: Tile,
        camera: &Camera,
        options: &RenderOptions,
    ) {
        self.res.ensure_targets(device, tile.size.max(UVec2::ONE));
        let light_view_proj = uniforms::light_view_proj(self.staging.focus, self.ground_height);
        let globals = Globals::new(&GlobalsInput {
            camera,
            tile,
            light_view_proj,
            shadows: options.shadows,
            grid: options.grid,
            ground_height: self.ground_height,
            grid_spacing: self.staging.grid_spacing.unwrap_or(0.1),
            encode_srgb: !self.res.color_format.is_srgb(),
        });
        // Uniforms go through the encoder (render has no queue): a staging copy each frame.
        copy_into(
            device,
            encoder,
            &self.res.globals,
            bytemuck::bytes_of(&globals),
        );
        copy_into(
            device,
            encoder,
            &self.res.light,
            bytemuck::bytes_of(&light_view_proj.to_cols_array()),
        );
        // The shadow map depends on the scene, not the tile: drawn with an image's first tile
        // (a cover starts at the top left), kept for the rest.
        if options.shadows && tile.origin == UVec2::ZERO {
            self.shadow_pass(encoder);
        }
        self.main_pass(encoder, target, options);
    }

    /// Depth from the light into the shadow map.
    fn shadow_pass(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("weft shadow"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.res.shadow_view,
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
        pass.set_pipeline(&self.res.pipelines.shadow);
        pass.set_bind_group(0, &self.res.shadow_bind, &[]);
        self.draw_surfaces(&mut pass);
    }

    /// The scene from the camera into `target`.
    fn main_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        options: &RenderOptions,
    ) {
        let Some(t) = &self.res.targets else {
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
        let (res, staged) = (&self.res, &self.staging);
        pass.set_bind_group(0, &res.main_bind, &[]);
        pass.set_pipeline(&res.pipelines.sky);
        pass.draw(0..3, 0..1);
        pass.set_pipeline(&res.pipelines.ground);
        pass.draw(0..6, 0..1);
        pass.set_pipeline(&res.pipelines.lit);
        self.draw_surfaces(&mut pass);
        if options.wireframe && staged.wire_count > 0 {
            pass.set_pipeline(&res.pipelines.lines);
            pass.set_vertex_buffer(0, res.lines.slice(..));
            pass.draw(0..staged.wire_count, 0..1);
        }
        if options.particles && staged.particle_count > 0 {
            pass.set_pipeline(&res.pipelines.points);
            pass.set_vertex_buffer(0, res.points.slice(..));
            pass.draw(0..6, 0..staged.particle_count);
        }
        if !staged.overlay_lines.is_empty() {
            pass.set_pipeline(&res.pipelines.overlay_lines);
            pass.set_vertex_buffer(0, res.lines.slice(..));
            pass.draw(staged.overlay_lines.clone(), 0..1);
        }
        if !staged.markers.is_empty() {
            pass.set_pipeline(&res.pipelines.overlay_points);
            pass.set_vertex_buffer(0, res.points.slice(..));
            pass.draw(0..6, staged.markers.clone());
        }
    }

    /// Cloths (indexed) and colliders, with whichever pipeline is set.
    fn draw_surfaces(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.staging.vertices.is_empty() {
            return;
        }
        pass.set_vertex_buffer(0, self.res.lit_vertices.slice(..));
        if !self.staging.indices.is_empty() {
            pass.set_index_buffer(self.res.lit_indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..count(self.staging.indices.len()), 0, 0..1);
        }
        if !self.staging.collider_vertices.is_empty() {
            pass.draw(self.staging.collider_vertices.clone(), 0..1);
        }
    }
}
