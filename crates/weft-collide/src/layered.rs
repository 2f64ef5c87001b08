//! Scenes of thin cloth layers as code, for cloth contact's tests and benches: two sheets
//! draped over a ball, a sheet dropped onto another, a ball swept through a stack, a twisted
//! sheet. Each returns a solver and a world with mesh-level cloth contact on among all its
//! cloths (`contact: false` leaves it off, for a side-by-side cost).

use glam::DVec3;
use weft_solver::{
    ClothMesh, GridDesc, Mass, Method, Motion, Orientation, Pin, Solver, SolverBuilder,
};

use crate::cloth_contact::ClothContactParams;
use crate::collider::ColliderDesc;
use crate::error::CollideError;
use crate::friction::Friction;
use crate::scenarios::{ground, method_setup, scenario_forces};
use crate::shape::ShapeDesc;
use crate::world::CollisionWorld;

/// Thickness of the thin sheets (m).
pub const THIN: f64 = 0.002;

/// A horizontal square sheet (`n`×`n` particles, `size` m, 0.1 kg per m²) centred at `center`.
pub fn sheet(
    n: usize,
    size: f64,
    center: DVec3,
    pins: Vec<Pin>,
) -> Result<ClothMesh, CollideError> {
    GridDesc {
        resolution: (n, n),
        size: (size, size),
        center,
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.1 * size * size),
        pins,
    }
    .build()
    .map_err(solver_error)
}

/// A solver of `meshes` as separate cloths, `thickness` thick, under `method`'s scenario setup.
pub fn solver_of(
    method: Method,
    meshes: &[ClothMesh],
    thickness: f64,
) -> Result<SolverBuilder, CollideError> {
    let (settings, params) = method_setup(method);
    let mut builder = SolverBuilder::new(settings, scenario_forces()).map_err(solver_error)?;
    for (k, mesh) in meshes.iter().enumerate() {
        builder
            .add_cloth(format!("sheet{k}"), mesh, params, thickness)
            .map_err(solver_error)?;
    }
    Ok(builder)
}

fn solver_error(e: impl std::fmt::Display) -> CollideError {
    CollideError::Solver(e.to_string())
}

/// A world for `solver` with `colliders`, and cloth contact among every cloth if `contact`.
fn world_of(
    solver: &Solver,
    colliders: &[ColliderDesc],
    contact: bool,
) -> Result<CollisionWorld, CollideError> {
    let mut world = CollisionWorld::new(solver);
    for c in colliders {
        world.add_collider(c)?;
    }
    if contact {
        let all: Vec<usize> = (0..solver.cloths().len()).collect();
        world.enable_cloth_contact(solver, &all, ClothContactParams::default())?;
    }
    Ok(world)
}

/// Radius of the ball of [`layers_on_ball`] (m).
pub const BALL: f64 = 0.25;

/// Two sheets (`n`×`n`, `size` m, [`THIN`] thick) 3 cm apart, the lower 5 cm above a ball
/// of radius [`BALL`] that sits on the ground: they fall onto it and drape in two layers.
pub fn layers_on_ball(
    method: Method,
    n: usize,
    size: f64,
    contact: bool,
) -> Result<(Solver, CollisionWorld), CollideError> {
    let low = BALL + 0.05;
    let meshes = [
        sheet(n, size, DVec3::Y * low, vec![])?,
        sheet(n, size, DVec3::Y * (low + 0.03), vec![])?,
    ];
    let solver = solver_of(method, &meshes, THIN)?.build();
    let ball = ColliderDesc::new(ShapeDesc::Sphere { radius: BALL })
        .with_friction(Friction::new(0.8, 0.6));
    let world = world_of(&solver, &[ball, ground(-BALL)], contact)?;
    Ok((solver, world))
}

/// A 0.5 m sheet (`n`×`n`, [`THIN`] thick) flat on the ground, and another dropped flat onto
/// it from `height` m, turned a little so the two grids do not line up.
pub fn sheet_onto_sheet(
    method: Method,
    n: usize,
    height: f64,
) -> Result<(Solver, CollisionWorld), CollideError> {
    let lower = sheet(n, 0.5, DVec3::Y * THIN, vec![])?;
    let mut upper = sheet(n, 0.5, DVec3::new(0.01, height, 0.007), vec![])?;
    let turn = weft_solver::glam::DQuat::from_rotation_y(0.3);
    for v in &mut upper.positions {
        *v = DVec3::new(0.0, height, 0.0) + turn * (*v - DVec3::new(0.0, height, 0.0));
    }
    let solver = solver_of(method, &[lower, upper], THIN)?.build();
    let world = world_of(&solver, &[ground(0.0)], true)?;
    Ok((solver, world))
}

/// Three 0.6 m sheets (`n`×`n`, [`THIN`] thick) 1 cm apart, each held at its four corners,
/// and a ball of radius 0.1 m below them oscillating up through the stack and back (0.2 m
/// amplitude at 1.5 Hz: up to 1.9 m/s, several thicknesses a substep).
pub fn ball_through_stack(
    method: Method,
    n: usize,
) -> Result<(Solver, CollisionWorld), CollideError> {
    use weft_solver::Corner;
    let corners = || {
        [
            Corner::TopLeft,
            Corner::TopRight,
            Corner::BottomLeft,
            Corner::BottomRight,
        ]
        .map(Pin::Corner)
        .to_vec()
    };
    let meshes: Vec<ClothMesh> = (0..3)
        .map(|k| sheet(n, 0.6, DVec3::Y * (0.01 * k as f64), corners()))
        .collect::<Result<_, _>>()?;
    let solver = solver_of(method, &meshes, THIN)?.build();
    let ball = ColliderDesc::new(ShapeDesc::Sphere { radius: 0.1 })
        .at(DVec3::Y * -0.12)
        .moving(Motion::Oscillate {
            amplitude: DVec3::Y * 0.2,
            frequency: 1.5,
        })
        .with_friction(Friction::new(0.5, 0.4));
    let world = world_of(&solver, &[ball], true)?;
    Ok((solver, world))
}

/// A 1 m sheet (`n`×`n`, `thickness` thick) held along its left edge, its right edge turned
/// about the sheet's axis (x, through its centre) at half a turn a second, as Newton's
/// `cloth_twist`: the sheet winds into a rope that presses against itself.
pub fn twist(
    method: Method,
    n: usize,
    thickness: f64,
    contact: bool,
) -> Result<(Solver, CollisionWorld), CollideError> {
    let center = DVec3::Y * 0.5;
    let mesh = sheet(
        n,
        1.0,
        center,
        vec![weft_solver::Pin::Edge(weft_solver::Edge::Left)],
    )?;
    let mut builder = solver_of(method, &[mesh], thickness)?;
    let turn = Motion::Rotate {
        pivot: center,
        axis: DVec3::X,
        angular_velocity: std::f64::consts::PI,
    };
    for j in 0..n {
        let v = (j * n + n - 1) as u32;
        builder
            .add_kinematic_pin(0, v, turn)
            .map_err(solver_error)?;
    }
    let solver = builder.build();
    let world = world_of(&solver, &[], contact)?;
    Ok((solver, world))
}

/// Two 0.2 m sheets (`n`×`n`, [`THIN`] thick): the lower 5 cm above the ground, the upper
/// `gap` m above it, moved sideways by `offset`, turned by `turn` about y and tilted by `tilt`
/// about x; both fall onto the ground.
pub fn two_sheets(
    method: Method,
    n: usize,
    gap: f64,
    offset: DVec3,
    turn: f64,
    tilt: f64,
) -> Result<(Solver, CollisionWorld), CollideError> {
    let low = 0.05;
    let lower = sheet(n, 0.2, DVec3::Y * low, vec![])?;
    let centre = DVec3::Y * (low + gap + 0.1 * tilt.abs()) + offset;
    let mut upper = sheet(n, 0.2, centre, vec![])?;
    let q = weft_solver::glam::DQuat::from_rotation_y(turn)
        * weft_solver::glam::DQuat::from_rotation_x(tilt);
    for v in &mut upper.positions {
        *v = centre + q * (*v - centre);
    }
    let solver = solver_of(method, &[lower, upper], THIN)?.build();
    let world = world_of(&solver, &[ground(0.0)], true)?;
    Ok((solver, world))
}
