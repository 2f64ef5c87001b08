//! Scenes as code, sized by parameter, for this crate's benches, examples and the tests that
//! need a size or setting no shipped scene has: each returns a solver and the collision world
//! to step it with (`solver.step_with(&mut world)`). A test of a scene Weft ships reads its
//! file in `assets/scenes` through weft-scene instead (`crates/weft-scene/tests/`).

use std::path::PathBuf;

use glam::DVec3;
use weft_solver::{
    ClothMesh, ClothParams, Family, Forces, GridDesc, Mass, Method, Orientation, Settings, Solver,
    SolverBuilder,
};

use crate::collider::ColliderDesc;
use crate::error::CollideError;
use crate::friction::Friction;
use crate::self_collision::SelfCollisionParams;
use crate::shape::ShapeDesc;
use crate::world::CollisionWorld;

/// Settings and cloth parameters under which `method` is stable for the scenarios' cloths.
///
/// Bending uses the bend-distance family; the dihedral family (swept symmetrically, so it no
/// longer gains energy) is exercised by `tests/integration/dihedral_drape.rs`.
/// Mass-spring is explicit: its springs are softened and its substeps raised so that
/// ω h < 2 holds for the stiffest spring (ω = √(k_eff/m) of the lightest particle).
pub fn method_setup(method: Method) -> (Settings, ClothParams) {
    let mut settings = Settings {
        method,
        ..Settings::default()
    };
    let mut params = ClothParams::default()
        .edit(Family::BendDihedral, |f| f.enabled = false)
        .edit(Family::BendDistance, |f| f.enabled = true);
    match method {
        Method::Xpbd => {}
        Method::Pbd => settings.iterations = 4,
        Method::MassSpring | Method::ImplicitMassSpring => {
            settings.substeps = 40;
            params = params
                .edit(Family::Stretch, |f| {
                    f.spring_stiffness = 400.0;
                    f.spring_damping = 0.05;
                })
                .edit(Family::Shear, |f| {
                    f.spring_stiffness = 100.0;
                    f.spring_damping = 0.02;
                })
                .edit(Family::BendDistance, |f| f.spring_stiffness = 2.0);
        }
    }
    (settings, params)
}

/// Forces for the scenarios: gravity and a little air damping so cloths settle.
pub fn scenario_forces() -> Forces {
    Forces {
        damping: 1.0,
        ..Forces::default()
    }
}

fn solver_error(e: impl std::fmt::Display) -> CollideError {
    CollideError::Solver(e.to_string())
}

fn build_one(
    method: Method,
    name: &str,
    mesh: &ClothMesh,
    thickness: f64,
) -> Result<Solver, CollideError> {
    let (settings, params) = method_setup(method);
    let mut builder = SolverBuilder::new(settings, scenario_forces()).map_err(solver_error)?;
    builder
        .add_cloth(name, mesh, params, thickness)
        .map_err(solver_error)?;
    Ok(builder.build())
}

/// A horizontal square sheet (`n`×`n`, `size` m, `mass` kg) centred at height `y`, as a solver.
fn falling_sheet(
    method: Method,
    n: usize,
    size: f64,
    y: f64,
    mass: f64,
) -> Result<Solver, CollideError> {
    let mesh = GridDesc {
        resolution: (n, n),
        size: (size, size),
        center: DVec3::new(0.0, y, 0.0),
        orientation: Orientation::Horizontal,
        mass: Mass::Total(mass),
        pins: vec![],
    }
    .build()
    .map_err(solver_error)?;
    build_one(method, "cloth", &mesh, THICKNESS)
}

/// The colliders of [`icosphere_drop`] and [`sphere_drop`] without their ground, each alone in
/// a world for its solver (see [`collider_alone`]): the 20,480-triangle mesh and the analytic
/// ball of the same radius.
pub fn balls_alone(
    mesh_solver: &Solver,
    sphere_solver: &Solver,
) -> Result<(CollisionWorld, CollisionWorld), CollideError> {
    let mesh = crate::mesh::TriangleMesh::icosphere(SPHERE_RADIUS, ICOSPHERE_SUBDIVISIONS);
    Ok((
        collider_alone(ShapeDesc::TriMesh(mesh), mesh_solver)?,
        collider_alone(
            ShapeDesc::Sphere {
                radius: SPHERE_RADIUS,
            },
            sphere_solver,
        )?,
    ))
}

/// A world for `solver` with `shape` alone as its collider (at the origin, with the friction
/// of [`sphere_drop`]'s ball), stepped once on a copy of `solver` so that what it builds at its
/// first substep (a mesh's contact grid) exists.
pub fn collider_alone(shape: ShapeDesc, solver: &Solver) -> Result<CollisionWorld, CollideError> {
    let mut world = CollisionWorld::new(solver);
    world.add_collider(&ColliderDesc::new(shape).with_friction(Friction::new(0.8, 0.6)))?;
    solver.clone().step_with(&mut world).map_err(solver_error)?;
    Ok(world)
}

/// The ground: a half-space below y = `height` with friction.
pub fn ground(height: f64) -> ColliderDesc {
    ColliderDesc::new(ShapeDesc::HalfSpace { normal: DVec3::Y }).at(DVec3::Y * height)
}

/// Sphere radius of [`sphere_drop`] (m); its centre is the origin.
pub const SPHERE_RADIUS: f64 = 0.5;
/// Cloth thickness of [`sphere_drop`] (m).
pub const THICKNESS: f64 = 0.01;

/// A horizontal 1.6 m cloth (`n`×`n` particles, 0.4 kg) falls from 0.2 m above a static
/// sphere of radius 0.5 m at the origin that sits on the ground, and drapes over it.
pub fn sphere_drop(method: Method, n: usize) -> Result<(Solver, CollisionWorld), CollideError> {
    let solver = falling_sheet(method, n, 1.6, SPHERE_RADIUS + 0.2, 0.4)?;
    let mut world = CollisionWorld::new(&solver);
    world.add_collider(
        &ColliderDesc::new(ShapeDesc::Sphere {
            radius: SPHERE_RADIUS,
        })
        .with_friction(Friction::new(0.8, 0.6)),
    )?;
    world.add_collider(&ground(-SPHERE_RADIUS))?;
    Ok((solver, world))
}

/// A vertical strip (`columns`×`rows`, 0.3 m × 0.9 m) falls onto the ground from 5 cm,
/// buckles and folds onto itself. Thickness ≈ particle spacing, so
/// particle–particle contacts leave no gap for a particle to slip through.
pub fn self_fold(
    method: Method,
    columns: usize,
    rows: usize,
) -> Result<(Solver, CollisionWorld), CollideError> {
    let (width, height) = (0.3, 0.9);
    let spacing = (width / (columns.max(2) - 1) as f64).max(height / (rows.max(2) - 1) as f64);
    folding_sheet(method, "strip", (columns, rows), (width, height), spacing)
}

/// A vertical square curtain (`n`×`n`, 0.9 m, thickness = particle spacing) 5 cm above the
/// ground, with [`self_fold`]'s wavy sideways velocity: it buckles and folds onto itself in
/// layers, every particle ending in contact with the layer below or above it. Square cells,
/// so at any `n` each particle's in-plane neighbourhood is the same.
pub fn curtain_fold(method: Method, n: usize) -> Result<(Solver, CollisionWorld), CollideError> {
    let size = 0.9;
    folding_sheet(
        method,
        "curtain",
        (n, n),
        (size, size),
        size / (n.max(2) - 1) as f64,
    )
}

/// A vertical sheet of `resolution` particles and `size` m whose bottom edge is 5 cm above the
/// ground, on the ground with self-collision. A small wavy sideways velocity breaks the
/// symmetry so that it buckles into folds instead of balancing on its edge.
fn folding_sheet(
    method: Method,
    name: &str,
    resolution: (usize, usize),
    (width, height): (f64, f64),
    thickness: f64,
) -> Result<(Solver, CollisionWorld), CollideError> {
    let bottom = 0.05;
    let mesh = GridDesc {
        resolution,
        size: (width, height),
        center: DVec3::new(0.0, bottom + 0.5 * height, 0.0),
        orientation: Orientation::Vertical,
        mass: Mass::Total(0.2),
        pins: vec![],
    }
    .build()
    .map_err(solver_error)?;
    let mut solver = build_one(method, name, &mesh, thickness)?;
    let p = solver.particles_mut();
    for i in 0..p.len() {
        let y = p.positions[i].y - bottom;
        p.velocities[i].z = 0.3 * (std::f64::consts::TAU * y / 0.3).sin();
    }
    let mut world = CollisionWorld::new(&solver);
    world.add_collider(&ground(0.0))?;
    world.enable_self_collision(&solver, &[0], SelfCollisionParams::default())?;
    Ok((solver, world))
}

/// The OBJ mesh shipped with the project: a bumpy blob of radius ≈ 0.4 m (1280 triangles).
pub fn blob_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes/blob.obj")
}

/// A horizontal 1.2 m cloth (`n`×`n`) falls onto the triangle-mesh blob loaded from
/// [`blob_path`], which rests on the ground with its centre at y = 0.45 m.
pub fn mesh_drop(method: Method, n: usize) -> Result<(Solver, CollisionWorld), CollideError> {
    let solver = falling_sheet(method, n, 1.2, 1.0, 0.3)?;
    let mut world = CollisionWorld::new(&solver);
    world.add_collider(
        &ColliderDesc::new(ShapeDesc::from_obj(blob_path(), 1.0)?)
            .at(DVec3::Y * 0.45)
            .with_friction(Friction::new(0.8, 0.6)),
    )?;
    world.add_collider(&ground(0.0))?;
    Ok((solver, world))
}

/// Subdivisions of [`icosphere_drop`]'s mesh: 20 · 4⁵ = 20,480 triangles.
pub const ICOSPHERE_SUBDIVISIONS: u32 = 5;

/// [`sphere_drop`] with the sphere as a triangle mesh: an icosphere of radius
/// [`SPHERE_RADIUS`] and 20,480 triangles ([`ICOSPHERE_SUBDIVISIONS`]) at the origin, on the
/// ground; the same cloth falls onto it.
pub fn icosphere_drop(method: Method, n: usize) -> Result<(Solver, CollisionWorld), CollideError> {
    let solver = falling_sheet(method, n, 1.6, SPHERE_RADIUS + 0.2, 0.4)?;
    let mut world = CollisionWorld::new(&solver);
    world.add_collider(
        &ColliderDesc::new(ShapeDesc::TriMesh(crate::mesh::TriangleMesh::icosphere(
            SPHERE_RADIUS,
            ICOSPHERE_SUBDIVISIONS,
        )))
        .with_friction(Friction::new(0.8, 0.6)),
    )?;
    world.add_collider(&ground(-SPHERE_RADIUS))?;
    Ok((solver, world))
}

/// A breathing, rippling ball: each vertex of an icosphere (radius [`SPHERE_RADIUS`], 5,120
/// triangles) moves along its direction by 4 % of the radius · sin(2π (1 Hz · t + 2 y)), a
/// deforming mesh; the cloth of [`sphere_drop`] (`n`×`n`) falls onto it, and the ground.
pub fn breathing_drop(method: Method, n: usize) -> Result<(Solver, CollisionWorld), CollideError> {
    let solver = falling_sheet(method, n, 1.6, SPHERE_RADIUS + 0.25, 0.4)?;
    let mut world = CollisionWorld::new(&solver);
    let ball = crate::mesh::TriangleMesh::icosphere(SPHERE_RADIUS, 4);
    let breathe = |t: f64, rest: &[DVec3], out: &mut [DVec3]| {
        for (o, v) in out.iter_mut().zip(rest) {
            let phase = std::f64::consts::TAU * (t + 2.0 * v.y);
            *o = *v * (1.0 + 0.04 * phase.sin());
        }
    };
    world.add_deforming_mesh(
        &ColliderDesc::new(ShapeDesc::TriMesh(ball)).with_friction(Friction::new(0.8, 0.6)),
        std::sync::Arc::new(breathe),
    )?;
    world.add_collider(&ground(-1.1 * SPHERE_RADIUS))?;
    Ok((solver, world))
}
