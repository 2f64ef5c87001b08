//! Images drawn a tile at a time are the image drawn whole: big renders are tiled so that a
//! stop between tiles is honoured at once (see `Offscreen::capture`).

use glam::{DVec3, UVec2, Vec3};
use image::RgbaImage;
use weft_render::{
    Camera, ClothTopology, FrameData, Gpu, OFFSCREEN_FORMAT, Offscreen, RenderOptions, Renderer,
    SceneMeshes, TILE_MAX, Tile,
};

/// A 1 m wavy cloth of n × n particles about (0, 1, 0), facing +Z, and its renderer.
fn renderer(gpu: &Gpu) -> Renderer {
    let n = 12;
    let mut positions = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (u, v) = (i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64);
            positions.push(DVec3::new(u - 0.5, 0.5 + v, 0.1 * (6.0 * u).sin()));
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as u32;
            let (b, c, d) = (a + 1, a + n as u32 + 1, a + n as u32);
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let scene = SceneMeshes {
        cloths: vec![ClothTopology {
            particle_count: positions.len(),
            triangles,
        }],
        colliders: vec![],
    };
    let mut r = Renderer::new(&gpu.device, OFFSCREEN_FORMAT, &scene);
    let cloths = [&positions[..]];
    r.update(
        &gpu.queue,
        &FrameData {
            cloths: &cloths,
            highlight: Some((0, 40)),
            ..FrameData::default()
        },
    );
    r
}

fn gpu() -> Gpu {
    match Gpu::headless() {
        Ok(g) => g,
        Err(e) => panic!("tile tests need an adapter (e.g. Mesa lavapipe): {e}"),
    }
}

/// Every layer on: sky, ground grid, shadows, wireframe, particle squares, the marker.
fn options() -> RenderOptions {
    RenderOptions {
        wireframe: true,
        particles: true,
        grid: true,
        shadows: true,
    }
}

fn camera() -> Camera {
    Camera::looking_at(Vec3::new(0.8, 1.4, 2.2), Vec3::new(0.0, 1.0, 0.0))
}

/// Draws `tile` into a target of its size and reads it back.
fn draw(gpu: &Gpu, r: &mut Renderer, tile: Tile) -> RgbaImage {
    let target = Offscreen::new(&gpu.device, tile.size);
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
    r.render_tile(
        &gpu.device,
        &mut encoder,
        target.view(),
        tile,
        &camera(),
        &options(),
    );
    gpu.queue.submit([encoder.finish()]);
    target.read(gpu).expect("readback")
}

/// Pixels whose channels differ by more than 2 levels, and the worst channel difference.
fn differences(a: &RgbaImage, b: &RgbaImage) -> (usize, u8) {
    assert_eq!(a.dimensions(), b.dimensions());
    let mut count = 0;
    let mut worst = 0;
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d = (0..4).map(|c| p.0[c].abs_diff(q.0[c])).max().unwrap_or(0);
        worst = worst.max(d);
        count += usize::from(d > 2);
    }
    (count, worst)
}

#[test]
fn tiles_put_together_are_the_whole_image() {
    let gpu = gpu();
    let mut r = renderer(&gpu);
    let full = UVec2::new(300, 200);
    let whole = draw(&gpu, &mut r, Tile::whole(full));
    let mut tiled = RgbaImage::new(full.x, full.y);
    let tiles = Tile::cover(full, 128);
    assert_eq!(tiles.len(), 6);
    for tile in tiles {
        let part = draw(&gpu, &mut r, tile);
        image::imageops::replace(
            &mut tiled,
            &part,
            i64::from(tile.origin.x),
            i64::from(tile.origin.y),
        );
    }
    // The picture is not uniform: cloth, sky and ground all show.
    let distinct: std::collections::HashSet<[u8; 4]> = whole.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 50, "{} colours", distinct.len());
    // Rasterising through another clip matrix may round a pixel's edge coverage differently;
    // nothing else may differ.
    let (count, worst) = differences(&whole, &tiled);
    let pixels = (full.x * full.y) as usize;
    assert!(
        count * 200 < pixels,
        "{count} of {pixels} pixels differ, worst by {worst}"
    );
}

#[test]
fn a_capture_is_drawn_in_tiles_and_stops_between_them() {
    let gpu = gpu();
    let mut r = renderer(&gpu);
    // Wider than one tile: two tiles, the second moved back to end at the image's edge.
    let full = UVec2::new(TILE_MAX + 60, 48);
    assert_eq!(Tile::cover(full, TILE_MAX).len(), 2);
    let target = Offscreen::for_image(&gpu.device, full);
    assert_eq!(target.size(), UVec2::new(TILE_MAX, 48));
    let captured = target
        .capture(&gpu, &mut r, &camera(), &options(), full, &|| false)
        .expect("capture")
        .expect("not stopped");
    let whole = draw(&gpu, &mut r, Tile::whole(full));
    let (count, worst) = differences(&whole, &captured);
    let pixels = (full.x * full.y) as usize;
    assert!(
        count * 200 < pixels,
        "{count} of {pixels} pixels differ, worst by {worst}"
    );

    // A stop raised after the first tile leaves the rest undrawn and returns nothing.
    let asked = std::cell::Cell::new(0);
    let stopped = || {
        asked.set(asked.get() + 1);
        asked.get() > 1
    };
    let none = target
        .capture(&gpu, &mut r, &camera(), &options(), full, &stopped)
        .expect("capture");
    assert!(none.is_none());
    assert_eq!(asked.get(), 2);
    // A target of another size is refused, not drawn into.
    let small = Offscreen::new(&gpu.device, UVec2::new(16, 16));
    assert!(
        small
            .capture(&gpu, &mut r, &camera(), &options(), full, &|| false)
            .is_err()
    );
}
