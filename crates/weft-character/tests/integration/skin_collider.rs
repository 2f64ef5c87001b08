//! A skinned mesh as a deforming collider (`SkinCollider`): the collision world's vertices are
//! `SkinnedMesh::skin(t)` at every frame's end and move linearly between those over the
//! frame's substeps, and cloth meets the animated body without
//! crossing it: the glTF simple_skin fixture's sheet (open) swinging through a hanging
//! curtain, and a closed skinned box swinging under a falling cloth.

use std::path::PathBuf;
use std::sync::Arc;

use crate::common::triangle::closest;
use crate::common::watch::Watch;
use glam::{DQuat, DVec3};
use weft_character::files::read_skinned_gltf;
use weft_character::skin::{ChannelValues, SkinCollider, SkinnedMesh};
use weft_collide::{CollisionWorld, Friction};
use weft_solver::{
    ClothMesh, ClothParams, Edge, Forces, GridDesc, Mass, Orientation, Particles, Pin, Settings,
    Solver, SolverBuilder, SubstepContext,
};

const THICKNESS: f64 = 0.01;

/// The simple_skin fixture with its animation sped up 4× and turned from a bend about z (in
/// the sheet's own plane) into a swing about x: the upper half swings out of the plane, to
/// +z (90° at 0.25 s), back, and to −z.
fn swinging(mut mesh: SkinnedMesh) -> SkinnedMesh {
    for c in &mut mesh.channels {
        for t in &mut c.times {
            *t *= 0.25;
        }
        if let ChannelValues::Rotation(keys) = &mut c.values {
            for q in keys.iter_mut() {
                *q = DQuat::from_xyzw(q.z, 0.0, 0.0, q.w).normalize();
            }
        }
    }
    mesh
}

fn fixture() -> SkinnedMesh {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/characters/simple_skin.gltf");
    swinging(read_skinned_gltf(&path).expect("simple_skin.gltf"))
}

/// A closed box of 0.3 m × 2 m × 0.3 m skinned like the fixture's sheet (the fixture's
/// joints, inverse bind matrices and swing at the fixture's own pace, 90° at 1 s; joint 1's
/// weight y / 2), at x ∈ [−0.15, 0.15] after skinning: rings of four corners at
/// y = 0, 0.5, …, 2, closed by end caps.
fn skinned_box() -> SkinnedMesh {
    let mut mesh = fixture();
    for c in &mut mesh.channels {
        for t in &mut c.times {
            *t *= 4.0;
        }
    }
    let corners = [(-0.15, -0.15), (0.15, -0.15), (0.15, 0.15), (-0.15, 0.15)];
    mesh.positions.clear();
    mesh.influences.clear();
    for ring in 0..5 {
        let y = 0.5 * ring as f64;
        for (x, z) in corners {
            // The fixture's inverse bind matrices shift x by −0.5.
            mesh.positions.push(DVec3::new(x + 0.5, y, z));
            mesh.influences
                .push([(0, 1.0 - y / 2.0), (1, y / 2.0), (0, 0.0), (0, 0.0)]);
        }
    }
    let mut tris = Vec::new();
    for ring in 0..4u32 {
        for k in 0..4u32 {
            let (a, b) = (4 * ring + k, 4 * ring + (k + 1) % 4);
            let (c, d) = (a + 4, b + 4);
            // Counter-clockwise seen from outside (the corners run clockwise seen from +y).
            tris.push([a, c, b]);
            tris.push([b, c, d]);
        }
    }
    tris.push([0, 1, 2]);
    tris.push([0, 2, 3]);
    tris.push([16, 18, 17]);
    tris.push([16, 19, 18]);
    mesh.triangles = tris;
    mesh
}

fn solver(mesh: &ClothMesh) -> Solver {
    let mut builder = SolverBuilder::new(Settings::default(), Forces::default()).expect("settings");
    builder
        .add_cloth("cloth", mesh, ClothParams::default(), THICKNESS)
        .expect("cloth");
    builder.build()
}

/// Brute force over the triangles: distance to the surface, and the side (+1 / −1 along the
/// face normal) when the closest point is inside a face, else 0.
fn distance_and_side(p: DVec3, v: &[DVec3], tris: &[[u32; 3]]) -> (f64, f64) {
    let mut best = (f64::INFINITY, 0.0);
    for t in tris {
        let [a, b, c] = t.map(|i| v[i as usize]);
        let (q, face) = closest(p, a, b, c);
        let d = (p - q).length();
        if d < best.0 {
            let n = (b - a).cross(c - a);
            best = (d, if face { (p - q).dot(n).signum() } else { 0.0 });
        }
    }
    best
}

/// Generalised winding number of a closed mesh about p (van Oosterom & Strackee 1983): 1
/// inside, 0 outside.
fn winding(p: DVec3, v: &[DVec3], tris: &[[u32; 3]]) -> f64 {
    let mut sum = 0.0;
    for t in tris {
        let [a, b, c] = t.map(|i| v[i as usize] - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}

/// Runs the world and, after every substep, checks the collider's vertices against
/// `SkinnedMesh::skin` (at the frame's end, to the bit; before it, on the line from the
/// frame's start to its end, where the substep's end lies in time) and hands the particles
/// and those vertices to `check`; returns the number of substeps.
fn run(
    solver: &mut Solver,
    world: &mut CollisionWorld,
    mesh: &SkinnedMesh,
    frames: usize,
    mut check: impl FnMut(&SubstepContext, &Particles, &[DVec3]) + Send,
) -> usize {
    let mut substeps = 0;
    let mut hook = Watch {
        world,
        check: |ctx: &SubstepContext, p: &Particles, w: &CollisionWorld| {
            let got = w.colliders()[0].mesh_vertices().expect("a mesh collider");
            let end = mesh.skin(ctx.frame_end);
            let start_time = ctx.time - ctx.h * f64::from(ctx.substep + 1);
            let start = mesh.skin(start_time);
            let f = (ctx.time - start_time) / (ctx.frame_end - start_time);
            assert_eq!(got.len(), end.len());
            for (k, ((g, a), b)) in got.iter().zip(&start).zip(&end).enumerate() {
                let want = if ctx.time == ctx.frame_end {
                    *b
                } else {
                    *a + (*b - *a) * f
                };
                let off = (*g - want).length();
                assert!(
                    off <= 1e-12 * (1.0 + want.length())
                        && (ctx.time != ctx.frame_end || off == 0.0),
                    "t = {}: collider vertex {k} at {g}, skinned and interpolated at {want}",
                    ctx.time
                );
            }
            substeps += 1;
            check(ctx, p, got);
        },
    };
    for frame in 0..frames {
        if let Err(e) = solver.step_with(&mut hook) {
            panic!("frame {frame}: {e}");
        }
    }
    substeps
}

fn world_with(solver: &Solver, skinned: &SkinnedMesh) -> CollisionWorld {
    let collider = SkinCollider::new(skinned.clone());
    let desc = collider
        .desc()
        .expect("a valid mesh")
        .with_friction(Friction::new(0.5, 0.4));
    let mut world = CollisionWorld::new(solver);
    world
        .add_deforming_mesh(&desc, Arc::new(collider))
        .expect("deforming collider");
    world
}

/// The fixture's sheet (open) swings its upper half through a 0.6 m curtain hanging 0.15 m
/// in front of it (pinned above the sheet's reach): over the swing, no particle whose
/// closest point is inside a face changes side from one substep to the next, and every such
/// particle ends its substeps at least 0.9 thickness from the sheet.
#[test]
fn a_swinging_skinned_sheet_never_crosses_a_hanging_curtain() {
    let mesh = fixture();
    let curtain = GridDesc {
        resolution: (24, 24),
        size: (0.6, 0.6),
        center: DVec3::new(0.0, 2.0, 0.15),
        orientation: Orientation::Vertical,
        mass: Mass::Total(0.1),
        pins: vec![Pin::Edge(Edge::Top)],
    }
    .build()
    .expect("grid");
    let mut solver = solver(&curtain);
    let mut world = world_with(&solver, &mesh);
    let tris = mesh.triangles.clone();
    let mut side = vec![0.0; curtain.positions.len()];
    let (mut flips, mut nearest, mut pushed) = (0usize, f64::INFINITY, 0usize);
    // 0.5 s: to +z (90° at 0.25 s) and back.
    let substeps = run(&mut solver, &mut world, &mesh, 30, |_, p, v| {
        for (i, x) in p.positions.iter().enumerate() {
            let (d, s) = distance_and_side(*x, v, &tris);
            if s != 0.0 {
                nearest = nearest.min(d);
                flips += usize::from(side[i] * s < 0.0);
                pushed += usize::from(s > 0.0 && x.z > 0.2);
            }
            side[i] = s;
        }
    });
    println!("{substeps} substeps: {flips} crossings, nearest {nearest:.5} m, {pushed} pushed");
    assert_eq!(flips, 0, "particles crossed the skinned sheet");
    assert!(
        nearest >= 0.9 * THICKNESS,
        "a particle ended a substep {nearest} m from the sheet"
    );
    assert!(pushed > 100, "the sheet never pushed the curtain");
}

/// A 0.5 m cloth falls on the top of a closed skinned box while it tilts to +z (0.5 s, to
/// 45°) and drapes and slides over it: no particle
/// ends a substep inside it by more than the thickness (inside: winding number ½ or more).
#[test]
fn cloth_on_a_swinging_closed_skinned_box_stays_outside() {
    let mesh = skinned_box();
    let cloth = GridDesc {
        resolution: (20, 20),
        size: (0.5, 0.5),
        center: DVec3::new(0.0, 2.05, 0.0),
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.1),
        pins: vec![],
    }
    .build()
    .expect("grid");
    let mut solver = solver(&cloth);
    let mut world = world_with(&solver, &mesh);
    let tris = mesh.triangles.clone();
    // Wound outward: the winding number is 1 at the box's centre.
    let w = winding(DVec3::new(0.0, 0.5, 0.0), &mesh.skin(0.0), &tris);
    assert!((w - 1.0).abs() < 1e-9, "winding number {w} inside the box");
    let (mut deepest, mut touching) = (0.0f64, 0usize);
    run(&mut solver, &mut world, &mesh, 30, |_, p, v| {
        for x in &p.positions {
            let (d, _) = distance_and_side(*x, v, &tris);
            if winding(*x, v, &tris) > 0.5 {
                deepest = deepest.max(d);
            } else {
                touching += usize::from(d < 1.5 * THICKNESS);
            }
        }
    });
    println!("deepest inside {deepest:.5} m; {touching} particle-substeps touching");
    assert!(
        deepest <= THICKNESS,
        "a particle ended a substep {deepest} m inside the box"
    );
    assert!(touching > 1000, "the cloth never rested on the box");
}
