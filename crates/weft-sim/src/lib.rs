//! A Weft scene run: its solvers stepped in lockstep one frame at a time ([`Simulation`]),
//! what each frame did ([`FrameStats`]), and a character's body posed for the renderer, the
//! log and the export ([`body`]).

pub mod body;
mod simulation;

pub use simulation::{FrameStats, Simulation};
