//! The built-in default scene: a cloth hanging from its two top corners.

use weft_solver::glam::DVec3;
use weft_solver::{
    ClothParams, Corner, Forces, GridDesc, Mass, Method, Orientation, Pin, Settings, Solver,
    SolverBuilder,
};

/// Builds the default scene: a 1 m × 1 m, 0.2 kg cloth of 32 × 32 particles pinned at its top corners.
pub fn hanging(method: Method) -> anyhow::Result<Solver> {
    let mesh = GridDesc {
        resolution: (32, 32),
        size: (1.0, 1.0),
        center: DVec3::new(0.0, 1.5, 0.0),
        orientation: Orientation::Vertical,
        mass: Mass::Total(0.2),
        pins: vec![Pin::Corner(Corner::TopLeft), Pin::Corner(Corner::TopRight)],
    }
    .build()?;
    let settings = Settings {
        method,
        ..Settings::default()
    };
    let forces = Forces {
        damping: 0.1,
        ..Forces::default()
    };
    let mut builder = SolverBuilder::new(settings, forces)?;
    builder.add_cloth("cloth", &mesh, ClothParams::default(), 0.005)?;
    Ok(builder.build())
}
