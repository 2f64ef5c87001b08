//! Offscreen rendering on whatever adapter `Gpu::headless` finds (in CI: Mesa's software
//! rasterisers; set `WGPU_BACKEND=vulkan` for lavapipe or `gl` for llvmpipe). There is no
//! skipping: without an adapter these tests fail.

use glam::{DVec3, Mat4, UVec2, Vec2, Vec3};
use image::{Rgba, RgbaImage};
use weft_render::{
    Camera, ClothTopology, FrameData, Gpu, Offscreen, RenderOptions, Renderer, SceneMeshes, TriMesh,
};

const SIZE: UVec2 = UVec2::new(160, 120);
const N: usize = 9;

/// A 1 m square in the z = 0 plane centred on (0, 1, 0), counter-clockwise seen from +Z (its
/// front faces +Z).
fn square() -> (ClothTopology, Vec<DVec3>) {
    let mut positions = Vec::new();
    for j in 0..N {
        for i in 0..N {
            let u = i as f64 / (N - 1) as f64;
            let v = j as f64 / (N - 1) as f64;
            positions.push(DVec3::new(u - 0.5, 0.5 + v, 0.0));
        }
    }
    let mut triangles = Vec::new();
    for j in 0..N - 1 {
        for i in 0..N - 1 {
            let a = (j * N + i) as u32;
            let (b, c, d) = (a + 1, a + N as u32 + 1, a + N as u32);
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (
        ClothTopology {
            particle_count: positions.len(),
            triangles,
        },
        positions,
    )
}

/// A cube of half-side `h` centred on the origin (outward winding).
fn cube(h: f32) -> TriMesh {
    let positions: Vec<Vec3> = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { -h } else { h },
                if i & 2 == 0 { -h } else { h },
                if i & 4 == 0 { -h } else { h },
            )
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    TriMesh {
        positions,
        indices: quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect(),
    }
}

fn gpu() -> Gpu {
    match Gpu::headless() {
        Ok(g) => g,
        Err(e) => panic!("offscreen tests need an adapter (e.g. Mesa lavapipe): {e}"),
    }
}

struct Shot<'a> {
    camera: Camera,
    collider_pose: Option<Mat4>,
    options: RenderOptions,
    highlight: Option<(usize, usize)>,
    drag_target: Option<Vec3>,
    flip: bool,
    gpu: &'a Gpu,
}

impl<'a> Shot<'a> {
    fn new(gpu: &'a Gpu, eye: Vec3) -> Self {
        Self {
            camera: Camera::looking_at(eye, Vec3::new(0.0, 1.0, 0.0)),
            collider_pose: None,
            options: RenderOptions::default(),
            highlight: None,
            drag_target: None,
            flip: false,
            gpu,
        }
    }

    fn take(&self) -> RgbaImage {
        let (mut topology, positions) = square();
        if self.flip {
            for t in &mut topology.triangles {
                t.swap(1, 2);
            }
        }
        let colliders = if self.collider_pose.is_some() {
            vec![cube(0.1)]
        } else {
            vec![]
        };
        let scene = SceneMeshes {
            cloths: vec![topology],
            colliders,
        };
        let target = Offscreen::new(&self.gpu.device, SIZE);
        let mut r = Renderer::new(&self.gpu.device, target.format(), &scene);
        let cloths = [&positions[..]];
        let poses: Vec<Mat4> = self.collider_pose.into_iter().collect();
        r.update(
            &self.gpu.queue,
            &FrameData {
                cloths: &cloths,
                collider_poses: &poses,
                highlight: self.highlight,
                drag_target: self.drag_target,
            },
        );
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        r.render(
            &self.gpu.device,
            &mut encoder,
            target.view(),
            SIZE,
            &self.camera,
            &self.options,
        );
        self.gpu.queue.submit([encoder.finish()]);
        target.read(self.gpu).expect("readback")
    }
}

fn is_front(p: &Rgba<u8>) -> bool {
    let [r, g, b, _] = p.0.map(i32::from);
    r > g + 40 && r > b + 60
}

fn is_back(p: &Rgba<u8>) -> bool {
    let [r, g, b, _] = p.0.map(i32::from);
    b > r + 50 && b > g + 20
}

/// The pixel rectangle covered by the square's corners, shrunk by `margin` (inside) or grown.
fn cloth_rect(camera: &Camera) -> (Vec2, Vec2) {
    let corners = [
        Vec3::new(-0.5, 0.5, 0.0),
        Vec3::new(0.5, 0.5, 0.0),
        Vec3::new(0.5, 1.5, 0.0),
        Vec3::new(-0.5, 1.5, 0.0),
    ];
    let px: Vec<Vec2> = corners
        .iter()
        .map(|&c| {
            camera
                .project(c, SIZE)
                .expect("corner in front of the camera")
        })
        .collect();
    let lo = px.iter().fold(Vec2::splat(f32::MAX), |a, &b| a.min(b));
    let hi = px.iter().fold(Vec2::splat(f32::MIN), |a, &b| a.max(b));
    (lo, hi)
}

/// Fractions of pixels inside (shrunk by 3 px) and outside (grown by 3 px) the cloth's
/// rectangle that `test` accepts.
fn fractions(img: &RgbaImage, camera: &Camera, test: fn(&Rgba<u8>) -> bool) -> (f64, f64) {
    let (lo, hi) = cloth_rect(camera);
    let (mut inside, mut n_in, mut outside, mut n_out) = (0, 0, 0, 0);
    for (x, y, p) in img.enumerate_pixels() {
        let c = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        if c.cmpgt(lo + 3.0).all() && c.cmplt(hi - 3.0).all() {
            n_in += 1;
            inside += usize::from(test(p));
        } else if c.cmplt(lo - 3.0).any() || c.cmpgt(hi + 3.0).any() {
            n_out += 1;
            outside += usize::from(test(p));
        }
    }
    assert!(
        n_in > 500 && n_out > 500,
        "the cloth covers part of the view"
    );
    (inside as f64 / n_in as f64, outside as f64 / n_out as f64)
}

#[test]
fn front_colour_where_the_cloth_projects_and_back_colour_from_behind() {
    let gpu = gpu();
    let front = Shot::new(&gpu, Vec3::new(0.0, 1.2, 2.2));
    let img = front.take();
    // Not blank: many distinct colours.
    let distinct: std::collections::HashSet<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 50, "{} distinct colours", distinct.len());
    assert!(img.pixels().all(|p| p.0[3] == 255), "opaque");

    let (inside, outside) = fractions(&img, &front.camera, is_front);
    assert!(inside > 0.97, "front colour on {inside:.3} of the cloth");
    assert!(outside < 0.01, "front colour on {outside:.3} outside it");
    let (back_inside, _) = fractions(&img, &front.camera, is_back);
    assert!(back_inside < 0.01);

    // From behind: the back colour, and no front colour anywhere.
    let behind = Shot::new(&gpu, Vec3::new(0.0, 1.2, -2.2));
    let img = behind.take();
    let (inside, _) = fractions(&img, &behind.camera, is_back);
    assert!(inside > 0.97, "back colour on {inside:.3} of the cloth");
    let (front_inside, front_outside) = fractions(&img, &behind.camera, is_front);
    assert!(front_inside < 0.01 && front_outside < 0.01);

    // Flipping the winding from the front shows the back too.
    let mut flipped = Shot::new(&gpu, Vec3::new(0.0, 1.2, 2.2));
    flipped.flip = true;
    let img = flipped.take();
    let (inside, _) = fractions(&img, &flipped.camera, is_back);
    assert!(
        inside > 0.97,
        "back colour on {inside:.3} of the flipped cloth"
    );
}

#[test]
fn colliders_markers_and_overlays_draw_where_they_project() {
    let gpu = gpu();
    let mut shot = Shot::new(&gpu, Vec3::new(0.0, 1.0, 2.2));
    // A 0.2 m cube in front of the cloth, moved there by its pose.
    let at = Vec3::new(0.25, 1.0, 0.3);
    shot.collider_pose = Some(Mat4::from_translation(at));
    shot.highlight = Some((0, 0)); // the corner particle at (-0.5, 0.5, 0)
    shot.drag_target = Some(Vec3::new(-0.3, 0.7, 0.4));
    shot.options = RenderOptions {
        wireframe: true,
        particles: true,
        grid: true,
        shadows: true,
    };
    let img = shot.take();
    let pixel = |p: Vec3| {
        let px = shot.camera.project(p, SIZE).expect("visible");
        *img.get_pixel(px.x as u32, px.y as u32)
    };
    // The cube: neutral grey (no cloth hue) where it is, the cloth colour beside it.
    let cube = pixel(at + Vec3::new(0.0, 0.0, 0.1));
    let [r, g, b, _] = cube.0.map(i32::from);
    assert!(
        (r - b).abs() < 40 && (r - g).abs() < 40,
        "cube pixel {cube:?}"
    );
    assert!(is_front(&pixel(Vec3::new(-0.15, 1.25, 0.0))));
    // The dragged particle: a yellow disc; the target: a cyan one.
    let marker = pixel(Vec3::new(-0.5, 0.5, 0.0));
    let [r, g, b, _] = marker.0.map(i32::from);
    assert!(r > 200 && g > 160 && b < 120, "highlight {marker:?}");
    let target = pixel(Vec3::new(-0.3, 0.7, 0.4));
    let [r, g, b, _] = target.0.map(i32::from);
    assert!(b > 200 && g > 160 && r < 140, "drag target {target:?}");
}

#[test]
fn resizing_the_target_recreates_depth_and_keeps_the_picture() {
    let gpu = gpu();
    let (topology, positions) = square();
    let scene = SceneMeshes {
        cloths: vec![topology],
        colliders: vec![],
    };
    let mut r = Renderer::new(&gpu.device, weft_render::OFFSCREEN_FORMAT, &scene);
    let cloths = [&positions[..]];
    r.update(
        &gpu.queue,
        &FrameData {
            cloths: &cloths,
            ..FrameData::default()
        },
    );
    let camera = Camera::looking_at(Vec3::new(0.0, 1.0, 2.5), Vec3::new(0.0, 1.0, 0.0));
    for size in [UVec2::new(64, 48), UVec2::new(96, 96)] {
        let target = Offscreen::new(&gpu.device, size);
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        r.render(
            &gpu.device,
            &mut encoder,
            target.view(),
            size,
            &camera,
            &RenderOptions::default(),
        );
        gpu.queue.submit([encoder.finish()]);
        let img = target.read(&gpu).expect("readback");
        assert_eq!(img.dimensions(), (size.x, size.y));
        // The centre of the view is the cloth's centre.
        assert!(is_front(img.get_pixel(size.x / 2, size.y / 2)));
    }
}

/// Mean luminance-ish (sum of channels) of the 5×5 pixels around `p`.
fn brightness(img: &RgbaImage, p: Vec2) -> f64 {
    let mut sum = 0.0;
    for dy in -2..=2 {
        for dx in -2..=2 {
            let px = img.get_pixel((p.x as i32 + dx) as u32, (p.y as i32 + dy) as u32);
            sum += f64::from(px.0[0]) + f64::from(px.0[1]) + f64::from(px.0[2]);
        }
    }
    sum / 25.0
}

#[test]
fn the_shadow_falls_on_the_ground_along_the_sunlight() {
    let gpu = gpu();
    // A horizontal 1 m square at y = 1 over the ground at y = 0, seen from high above.
    let (topology, mut positions) = square();
    for p in &mut positions {
        *p = DVec3::new(p.x, 1.0, p.y - 1.0);
    }
    let scene = SceneMeshes {
        cloths: vec![topology],
        colliders: vec![],
    };
    let camera = Camera::looking_at(Vec3::new(0.0, 7.0, 0.5), Vec3::ZERO);
    let shot = |shadows: bool| {
        let target = Offscreen::new(&gpu.device, SIZE);
        let mut r = Renderer::new(&gpu.device, target.format(), &scene);
        let cloths = [&positions[..]];
        r.update(
            &gpu.queue,
            &FrameData {
                cloths: &cloths,
                ..FrameData::default()
            },
        );
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        let options = RenderOptions {
            grid: false,
            shadows,
            ..RenderOptions::default()
        };
        r.render(
            &gpu.device,
            &mut encoder,
            target.view(),
            SIZE,
            &camera,
            &options,
        );
        gpu.queue.submit([encoder.finish()]);
        target.read(&gpu).expect("readback")
    };
    let (lit, unlit) = (shot(true), shot(false));
    // The square's centre carried down along the sunlight, and the mirror point towards the
    // sun, where the ground stays lit.
    let sun = weft_render::sun_direction();
    let offset = -sun / sun.y; // from height 1 to the ground
    let shadow = camera
        .project(Vec3::new(0.0, 1.0, 0.0) + offset, SIZE)
        .expect("visible");
    let sunny = camera
        .project(Vec3::new(-offset.x, 0.0, -offset.z), SIZE)
        .expect("visible");
    let (s_on, s_off) = (brightness(&lit, shadow), brightness(&unlit, shadow));
    let (l_on, l_off) = (brightness(&lit, sunny), brightness(&unlit, sunny));
    assert!(
        s_on < 0.8 * s_off,
        "shadowed ground {s_on:.0} vs {s_off:.0} without shadows"
    );
    assert!(
        (l_on - l_off).abs() < 6.0,
        "sunny ground {l_on:.0} vs {l_off:.0}"
    );
}
