//! The window: winit's event loop (ApplicationHandler), the weft renderer and the egui
//! overlay drawn to its surface (`surface.rs`), and the mouse and keyboard wired to the
//! session (`command.rs`) and the camera.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::{UVec2, Vec2};
use weft_render::{Camera, FrameData, Gpu, RenderOptions, Renderer};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow};
use winit::window::{Window, WindowId};

use crate::app::camera::ViewCamera;
use crate::app::input::{self, Action, DragMode};
use crate::app::labels;
use crate::app::panel::{self, PanelState};
use crate::app::picking::Ray;
use crate::app::session::Session;
use crate::app::surface::WindowSurface;
use crate::view;

/// Width of the side panel (points) in a window wide enough for it.
pub const PANEL_WIDTH: f32 = 300.0;

/// The side panel's width in a window `window` points wide: [`PANEL_WIDTH`], but never
/// more than 60% of the window (the 3-D view keeps the rest).
pub fn panel_width(window: f32) -> f32 {
    PANEL_WIDTH.min(0.6 * window).max(0.0)
}

/// How the window opens and when it closes by itself.
#[derive(Clone, Debug)]
pub struct WindowConfig {
    /// Inner size in pixels.
    pub size: (u32, u32),
    /// Quit after this many simulated frames.
    pub exit_after_frames: Option<u64>,
    /// Start paused.
    pub paused: bool,
    /// A fixed initial camera `(eye, target)` instead of the automatic framing.
    pub camera: Option<(glam::Vec3, glam::Vec3)>,
}

/// Everything that exists only while the window does.
struct Gfx {
    window: Arc<Window>,
    surface: WindowSurface,
    gpu: Gpu,
    renderer: Renderer,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
}

/// The viewer.
pub struct App {
    session: Session,
    config: WindowConfig,
    stop: Arc<AtomicBool>,
    gfx: Option<Gfx>,
    egui: egui::Context,
    cam: ViewCamera,
    options: RenderOptions,
    /// Whether the cloths' labels are drawn in the 3-D view.
    labels: bool,
    panel: PanelState,
    show_panel: bool,
    show_help: bool,
    cursor: Option<Vec2>,
    drag: Option<(DragMode, MouseButton)>,
    shift: bool,
    last_frame: Option<Instant>,
    /// The first frame's start and the frames drawn since.
    drawn: Option<(Instant, u64)>,
    /// Set when the loop must end with an error (no adapter, a failed log write).
    pub error: Option<anyhow::Error>,
    /// Whether SIGINT/SIGTERM ended the session.
    pub interrupted: bool,
}

impl App {
    /// Frames drawn and the frames a second they came at, once two have been drawn.
    pub fn frame_rate(&self) -> Option<(u64, f64)> {
        let (start, n) = self.drawn?;
        let seconds = start.elapsed().as_secs_f64();
        (n > 1 && seconds > 0.0).then(|| (n, (n - 1) as f64 / seconds))
    }

    /// A viewer of `session`; `stop` is raised by the signal handler.
    pub fn new(
        session: Session,
        config: WindowConfig,
        stop: Arc<AtomicBool>,
        panel: PanelState,
    ) -> Self {
        let camera = match config.camera {
            Some((eye, target)) => Camera::looking_at(eye, target),
            None => Camera::default(),
        };
        let cam = ViewCamera::new(camera, &session.sim);
        let labels = session.sim.scene.cloths.len() > 1;
        Self {
            session,
            config,
            stop,
            gfx: None,
            egui: egui::Context::default(),
            cam,
            labels,
            options: RenderOptions {
                wireframe: false,
                particles: false,
                grid: true,
                shadows: true,
            },
            panel,
            show_panel: true,
            show_help: false,
            cursor: None,
            drag: None,
            shift: false,
            last_frame: None,
            drawn: None,
            error: None,
            interrupted: false,
        }
    }

    /// The session (to finish its log once the loop has ended).
    pub fn session_mut(&mut self) -> &mut Session {
        &mut self.session
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        event_loop.exit();
    }

    fn init(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Gfx> {
        let (w, h) = self.config.size;
        let attrs = Window::default_attributes()
            .with_title(format!("Weft — {}", self.session.sim.scene.name))
            .with_inner_size(PhysicalSize::new(w, h));
        let window = Arc::new(event_loop.create_window(attrs)?);
        let (surface, gpu) = WindowSurface::new(event_loop, Arc::clone(&window))?;
        let (format, size) = (surface.format(), surface.size());
        let (renderer, _) = view::renderer_for(&gpu.device, format, &self.session.sim);
        if self.config.camera.is_none() {
            let scale = window.scale_factor() as f32;
            let covered = if self.show_panel {
                panel_width(size.x as f32 / scale) * scale
            } else {
                0.0
            };
            self.cam.frame(&self.session.sim, size, covered);
        }
        let egui_state = egui_winit::State::new(
            self.egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        eprintln!(
            "weft: {}: window {}x{} on {}",
            self.session.sim.scene.name,
            size.x,
            size.y,
            gpu.describe()
        );
        Ok(Gfx {
            window,
            surface,
            gpu,
            renderer,
            egui_state,
            egui_renderer,
        })
    }

    fn size(&self) -> UVec2 {
        self.gfx
            .as_ref()
            .map_or(UVec2::new(self.config.size.0, self.config.size.1), |g| {
                g.surface.size()
            })
    }

    /// Pixels at the window's right that the side panel covers (0 when it is hidden).
    fn covered(&self) -> f32 {
        let scale = self
            .gfx
            .as_ref()
            .map_or(1.0, |g| g.window.scale_factor() as f32);
        if self.show_panel {
            panel_width(self.size().x as f32 / scale) * scale
        } else {
            0.0
        }
    }

    fn ray(&self, cursor: Vec2) -> Ray {
        let r = self.cam.camera.ray(cursor, self.size());
        Ray {
            origin: r.origin.as_dvec3(),
            dir: r.dir.as_dvec3(),
        }
    }

    fn act(&mut self, action: Action, event_loop: &ActiveEventLoop) {
        match action {
            Action::Command(c) => {
                if let Err(e) = c.apply(&mut self.session, &mut self.panel.error) {
                    self.fail(event_loop, e);
                }
            }
            Action::ToggleWireframe => self.options.wireframe = !self.options.wireframe,
            Action::ToggleParticles => self.options.particles = !self.options.particles,
            Action::ToggleHelp => self.show_help = !self.show_help,
            Action::TogglePanel => self.show_panel = !self.show_panel,
            Action::FrameScene => {
                let (size, covered) = (self.size(), self.covered());
                self.cam.frame(&self.session.sim, size, covered);
            }
            Action::ToggleFollow => self.cam.follow = !self.cam.follow && self.cam.can_follow(),
            Action::ToggleLabels => self.labels = !self.labels,
            Action::Quit => event_loop.exit(),
        }
    }

    fn rebuild_scene(&mut self) {
        let size = self.size();
        self.cam = ViewCamera::new(self.cam.camera, &self.session.sim);
        let covered = self.covered();
        self.cam.frame(&self.session.sim, size, covered);
        self.labels = self.session.sim.scene.cloths.len() > 1;
        if let Some(g) = self.gfx.as_mut() {
            let (renderer, _) =
                view::renderer_for(&g.gpu.device, g.surface.format(), &self.session.sim);
            g.renderer = renderer;
            g.window
                .set_title(&format!("Weft — {}", self.session.sim.scene.name));
        }
    }

    fn mouse_button(&mut self, button: MouseButton, state: ElementState) {
        match state {
            ElementState::Pressed => {
                if self.egui.is_pointer_over_egui() || self.drag.is_some() {
                    return;
                }
                let Some(mode) = input::drag_mode(button, self.shift) else {
                    return;
                };
                if mode == DragMode::Grab {
                    let Some(c) = self.cursor else { return };
                    let ray = self.ray(c);
                    let forward = self.cam.camera.forward().as_dvec3();
                    if !self.session.grab(&ray, forward) {
                        return;
                    }
                }
                self.drag = Some((mode, button));
            }
            ElementState::Released => {
                if let Some((mode, b)) = self.drag
                    && b == button
                {
                    if mode == DragMode::Grab {
                        self.session.release();
                    }
                    self.drag = None;
                }
            }
        }
    }

    fn cursor_moved(&mut self, to: Vec2) {
        let from = self.cursor.replace(to);
        let d = from.map_or(Vec2::ZERO, |f| to - f);
        match self.drag.map(|(m, _)| m) {
            Some(DragMode::Grab) => {
                let ray = self.ray(to);
                self.session.drag(&ray);
            }
            Some(DragMode::Orbit) => self.cam.camera.orbit(d.x, d.y),
            Some(DragMode::Pan) => self.cam.camera.pan(d.x, d.y, self.size()),
            None => {}
        }
    }

    fn frame(&mut self, event_loop: &ActiveEventLoop) {
        let now = Instant::now();
        if let Some(last) = self.last_frame.replace(now) {
            self.session.stats.frame_ms = (now - last).as_secs_f64() * 1e3;
        }
        self.drawn.get_or_insert((now, 0)).1 += 1;
        if let Err(e) = self.session.advance(self.config.exit_after_frames) {
            return self.fail(event_loop, e);
        }
        self.cam.track(&self.session.sim);
        if let Some(n) = self.config.exit_after_frames
            && self.session.frames >= n
        {
            event_loop.exit();
        }
        if let Err(e) = self.draw() {
            self.fail(event_loop, e);
        }
    }

    fn draw(&mut self) -> anyhow::Result<()> {
        let Some(g) = self.gfx.as_mut() else {
            return Ok(());
        };
        // The overlay first: the panel may change the scene or the view options.
        let raw = g.egui_state.take_egui_input(&g.window);
        let session = &mut self.session;
        let panel_state = &mut self.panel;
        let mut controls = panel::ViewControls {
            options: &mut self.options,
            camera: &mut self.cam,
            labels: &mut self.labels,
        };
        let (show_panel, show_help) = (self.show_panel, self.show_help);
        let size = g.surface.size();
        let mut outcome = panel::Outcome::default();
        let output = self.egui.run_ui(raw, |ui| {
            if show_panel {
                egui::Panel::right("weft-panel")
                    .exact_size(panel_width(ui.ctx().content_rect().width()))
                    .resizable(false)
                    .show(ui, |ui| {
                        outcome = panel::show(ui, session, panel_state, &mut controls);
                    });
            }
            if *controls.labels {
                let painter = ui.painter_at(ui.available_rect_before_wrap());
                let ppp = ui.ctx().pixels_per_point();
                labels::paint(&painter, &session.sim, &controls.camera.camera, size, ppp);
            }
            help_overlay(ui.ctx(), show_help);
        });
        g.egui_state
            .handle_platform_output(&g.window, output.platform_output);
        let jobs = self.egui.tessellate(output.shapes, output.pixels_per_point);
        // Texture uploads first (they must happen even when no frame can be drawn), frees
        // after painting.
        let mut textures = output.textures_delta;
        for (id, deltas) in textures.set.drain() {
            for delta in deltas {
                g.egui_renderer
                    .update_texture(&g.gpu.device, &g.gpu.queue, id, &delta);
            }
        }
        let free: Vec<egui::TextureId> = textures.free.drain().collect();
        let result = self.paint(&jobs, output.pixels_per_point, outcome);
        if let Some(g) = self.gfx.as_mut() {
            for id in &free {
                g.egui_renderer.free_texture(id);
            }
        }
        result
    }

    /// Applies the panel's requests, then draws the scene and the overlay and presents.
    fn paint(
        &mut self,
        jobs: &[egui::ClippedPrimitive],
        pixels_per_point: f32,
        outcome: panel::Outcome,
    ) -> anyhow::Result<()> {
        if let Some(c) = outcome.command {
            c.apply(&mut self.session, &mut self.panel.error)?;
        }
        if outcome.scene_changed {
            self.rebuild_scene();
        } else if outcome.frame {
            let (size, covered) = (self.size(), self.covered());
            self.cam.frame(&self.session.sim, size, covered);
        }
        let Some(g) = self.gfx.as_mut() else {
            return Ok(());
        };
        let sim = &self.session.sim;
        let cloths: Vec<&[weft_solver::glam::DVec3]> = (0..sim.scene.cloths.len())
            .map(|i| sim.cloth_positions(i))
            .collect();
        let poses = view::frame_poses(sim);
        view::refresh_deformed(&mut g.renderer, sim);
        let grab = self.session.grab;
        g.renderer.update(
            &g.gpu.queue,
            &FrameData {
                cloths: &cloths,
                collider_poses: &poses,
                highlight: grab.map(|g| (g.cloth, g.particle)),
                drag_target: grab.map(|g| g.target.as_vec3()),
            },
        );
        let Some(texture) = g.surface.acquire(&g.gpu.device) else {
            return Ok(());
        };
        let view = texture
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let size = g.surface.size();
        let mut encoder = g
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("weft frame"),
            });
        g.renderer.render(
            &g.gpu.device,
            &mut encoder,
            &view,
            size,
            &self.cam.camera,
            &self.options,
        );
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.x, size.y],
            pixels_per_point,
        };
        let extra = g.egui_renderer.update_buffers(
            &g.gpu.device,
            &g.gpu.queue,
            &mut encoder,
            jobs,
            &screen,
        );
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            g.egui_renderer
                .render(&mut pass.forget_lifetime(), jobs, &screen);
        }
        g.gpu
            .queue
            .submit(extra.into_iter().chain(std::iter::once(encoder.finish())));
        g.window.pre_present_notify();
        g.gpu.queue.present(texture);
        Ok(())
    }
}

/// The help overlay: every shortcut and mouse binding, or a one-line hint.
fn help_overlay(ctx: &egui::Context, open: bool) {
    let area = egui::Area::new(egui::Id::unique("weft-help"))
        .anchor(egui::Align2::LEFT_TOP, egui::vec2(10.0, 10.0))
        .interactable(false);
    area.show(ctx, |ui| {
        egui::Frame::popup(ui.style()).show(ui, |ui| {
            if !open {
                ui.label("H: help");
                return;
            }
            ui.label(egui::RichText::new("Keys").strong());
            egui::Grid::new("help-keys").show(ui, |ui| {
                for (k, what) in input::SHORTCUTS.iter().chain(input::MOUSE) {
                    ui.label(*k);
                    ui.label(*what);
                    ui.end_row();
                }
            });
        });
    });
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        match self.init(event_loop) {
            Ok(g) => {
                self.gfx = Some(g);
                self.session.clock.set_paused(self.config.paused);
                self.session.clock.restart();
                event_loop.set_control_flow(ControlFlow::Poll);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        // A bound key is the viewer's unless a text field is being edited: egui never sees
        // it, so Tab does not move its focus and Space does not press a focused widget.
        let viewer_key = match &event {
            WindowEvent::KeyboardInput { event: k, .. } => {
                input::action_for(&k.logical_key).is_some() && !self.egui.text_edit_focused()
            }
            _ => false,
        };
        let consumed = match self.gfx.as_mut() {
            Some(g) if !viewer_key => g.egui_state.on_window_event(&g.window, &event).consumed,
            _ => false,
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(s) => {
                if let Some(g) = self.gfx.as_mut() {
                    g.surface.resize(&g.gpu.device, s.width, s.height);
                }
            }
            WindowEvent::RedrawRequested => self.frame(event_loop),
            WindowEvent::ModifiersChanged(m) => self.shift = m.state().shift_key(),
            WindowEvent::KeyboardInput { event, .. } => {
                if viewer_key
                    && event.state == ElementState::Pressed
                    && !event.repeat
                    && let Some(a) = input::action_for(&event.logical_key)
                {
                    // A button or list the panel had focused lets it go.
                    self.egui.memory_mut(|m| {
                        if let Some(id) = m.focused() {
                            m.surrender_focus(id);
                        }
                    });
                    self.act(a, event_loop);
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor_moved(Vec2::new(position.x as f32, position.y as f32));
            }
            WindowEvent::CursorLeft { .. } => {}
            // A press egui took (a click on the panel) is not a grab or a camera drag.
            WindowEvent::MouseInput { state, button, .. }
                if !(consumed && state == ElementState::Pressed) =>
            {
                self.mouse_button(button, state);
            }
            WindowEvent::MouseWheel { delta, .. } if !self.egui.is_pointer_over_egui() => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.cam.camera.zoom(steps);
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.stop.load(Ordering::SeqCst) {
            self.interrupted = true;
            event_loop.exit();
            return;
        }
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }
}
