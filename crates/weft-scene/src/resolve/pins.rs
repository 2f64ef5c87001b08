//! A cloth's `pins` and `held` lists: names and vertex indices checked and turned into the
//! solver's pins (a grid's) or vertex indices (a mesh's).

use weft_solver::{Corner, Edge, Pin};

use super::Checker;
use crate::schema::PinSpec;

/// The solver's pin for a grid pin's name.
fn named_pin(name: &str) -> Option<Pin> {
    Some(match name {
        "top-left" => Pin::Corner(Corner::TopLeft),
        "top-right" => Pin::Corner(Corner::TopRight),
        "bottom-left" => Pin::Corner(Corner::BottomLeft),
        "bottom-right" => Pin::Corner(Corner::BottomRight),
        "top" => Pin::Edge(Edge::Top),
        "bottom" => Pin::Edge(Edge::Bottom),
        "left" => Pin::Edge(Edge::Left),
        "right" => Pin::Edge(Edge::Right),
        _ => return None,
    })
}

/// A mesh cloth's pins under `key`: vertex indices only (a bad entry is reported).
pub(super) fn mesh_pins(c: &mut Checker<'_>, key: &str, specs: &[PinSpec]) -> Vec<u32> {
    let mut indices = Vec::new();
    for (i, p) in specs.iter().enumerate() {
        match p {
            PinSpec::Index(v) if *v >= 0 && *v <= u32::MAX as i64 => indices.push(*v as u32),
            PinSpec::Index(v) => c.bad(&format!("{key}[{i}]"), format!("bad index {v}")),
            PinSpec::Named(n) => c.bad(
                &format!("{key}[{i}]"),
                format!("`{n}`: a mesh cloth is pinned by vertex index only"),
            ),
        }
    }
    indices
}

/// An `nx` × `ny` grid's pins under `key`: corners, edges or vertex indices (a bad entry is
/// reported).
pub(super) fn grid_pins(
    c: &mut Checker<'_>,
    key: &str,
    specs: &[PinSpec],
    nx: i64,
    ny: i64,
) -> Vec<Pin> {
    let mut pins = Vec::new();
    for (i, p) in specs.iter().enumerate() {
        let key = format!("{key}[{i}]");
        match p {
            PinSpec::Named(n) => match named_pin(n) {
                Some(pin) => pins.push(pin),
                None => c.bad(
                    &key,
                    format!(
                        "unknown pin `{n}`: expected top-left, top-right, bottom-left, \
                         bottom-right, top, bottom, left, right or a vertex index"
                    ),
                ),
            },
            PinSpec::Index(v) if *v >= 0 && *v < nx.saturating_mul(ny) => {
                pins.push(Pin::Index(*v as u32))
            }
            PinSpec::Index(v) => c.bad(
                &key,
                format!(
                    "vertex {v} does not exist (the grid has {})",
                    nx.max(0).saturating_mul(ny.max(0))
                ),
            ),
        }
    }
    pins
}
