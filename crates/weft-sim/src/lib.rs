//! A Weft scene run: its solvers stepped in lockstep one frame at a time ([`Simulation`]),
//! what each frame did ([`FrameStats`]), a held particle dragged about ([`grab`]), the live
//! controls the viewer and Python change between frames ([`control`]), a character's body
//! posed for the renderer, the log and the export ([`body`]), and garment seams that did not
//! close ([`seams`]).
//!
//! The crate's modules:
//!
//! - `body`: a character's body as posed shapes, for the renderer, the log and the export.
//! - `control`: live controls, named by the scene file's own keys, applied between frames.
//! - `crossings`: cloth crossings and near approaches measured on a scene's solvers.
//! - `error`: what a grab or a live control refuses, naming the key, the cloth or the value.
//! - `grab`: holding one particle of a cloth and dragging it.
//! - `seams`: a garment's seam pairs still apart once the seams were due to have closed.
//! - `simulation`: a scene's solvers stepped in lockstep, one frame at a time.

pub mod body;
pub mod control;
pub mod crossings;
mod error;
pub mod grab;
pub mod seams;
mod simulation;

pub use control::{Control, LIVE_KEYS, Value};
pub use crossings::{CrossingStats, StartCrossing};
pub use error::SimError;
pub use seams::{OpenSeams, SeamWatch};
pub use simulation::{FrameStats, Simulation};

#[cfg(test)]
pub(crate) mod tests {
    use crate::Simulation;

    /// A 5 × 5 vertical cloth `a` (1 m, x ∈ [−0.5, 0.5], y ∈ [1, 2], z = 0), pinned on its
    /// top edge, under `gravity`, stepped by `method`.
    pub fn sim(method: &str, gravity: &str) -> Simulation {
        let text = format!(
            "[sim]\nmethod = \"{method}\"\ndt = \"1/60\"\nsubsteps = 10\ngravity = {gravity}\n\n\
             [cloth.a]\nresolution = [5, 5]\nsize = [1.0, 1.0]\ncenter = [0.0, 1.5, 0.0]\n\
             mass = 0.25\npins = [\"top\"]\n"
        );
        let scene =
            weft_scene::from_text("flat.toml", &text, &[], &weft_scene::DirFiles(".".into()))
                .expect("scene");
        Simulation::new(scene).expect("solvers")
    }
}
