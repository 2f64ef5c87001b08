//! One particle against a body's parts: the swept test in each part's moving frame, and the
//! contact planes found at its current position and projected on.

use glam::DVec3;

use super::grid::PartGrid;
use super::motion::MovingPart;
use crate::friction::Friction;

/// A part near the particle: its tangent plane at the point nearest the particle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plane {
    /// Closest surface point.
    pub point: DVec3,
    /// Outward unit normal there.
    pub normal: DVec3,
    /// The part (its motion over the substep gives the surface's displacement, for friction).
    pub part: u16,
}

/// Steps of sphere tracing before a grazing path is given up.
const TRACE_STEPS: usize = 48;

/// Rounds over one particle's planes (a particle in the crease of two overlapping parts is
/// pushed out of one into the other; a few rounds settle it).
const ROUNDS: usize = 4;

/// How far a particle of thickness `r` may move relative to a part in one substep without
/// being swept: half its thickness (a path that short cannot cross the surface unseen — the
/// contact planes, found within two thicknesses, catch it).
fn slow(r: f64) -> f64 {
    0.5 * r.max(1e-6)
}

/// Sweeps the particle's substep path against every candidate part, in each part's moving
/// frame: the start `prev` carried rigidly with the part to the substep's end, then the segment
/// from there to `x` traced against the part's end geometry. A hit puts the particle a
/// thickness `r` outside the surface where it met it (so a fast limb pushes it ahead instead
/// of passing through it). Returns how many parts stopped it.
///
/// `here` are the candidates at `x`. A particle that itself moved less than [`slow`] can
/// only be crossed by a part that moved more, which the grid (grown by each part's travel)
/// lists at `x`; a faster particle also takes the candidates at `prev`.
pub(crate) fn sweep(
    parts: &[MovingPart],
    grid: &PartGrid,
    here: &[u16],
    prev: DVec3,
    x: &mut DVec3,
    r: f64,
) -> usize {
    let slow = slow(r);
    let own = (*x - prev).length_squared() <= slow * slow;
    let before: &[u16] = if own { &[] } else { grid.candidates(prev) };
    if here.is_empty() && before.is_empty() {
        return 0;
    }
    let mut swept = 0;
    let extra = before.iter().filter(|k| !here.contains(k));
    for &k in here.iter().chain(extra) {
        let part = &parts[k as usize];
        if own && part.travel <= slow {
            continue;
        }
        let from = part.carry(prev);
        if (*x - from).length_squared() <= slow * slow {
            continue;
        }
        if let Some((t, n)) = part.cone.sweep(from, *x, 1e-3 * r, TRACE_STEPS) {
            *x = from + (*x - from) * t + n * r;
            swept += 1;
        }
    }
    swept
}

/// The contact planes of the particle at `x`: every part of `candidates` whose surface lies
/// within `reach` of it, or which holds it.
pub(crate) fn planes(
    parts: &[MovingPart],
    candidates: &[u16],
    x: DVec3,
    reach: f64,
    out: &mut Vec<Plane>,
) {
    for &k in candidates {
        if let Some(c) = parts[k as usize].cone.contact_within(x, reach) {
            out.push(Plane {
                point: c.point,
                normal: c.normal,
                part: k,
            });
        }
    }
}

/// Projects one particle (its planes `planes` of `parts`) to a thickness `r` outside every
/// plane, with Coulomb friction against each surface's motion (Macklin et al. 2014, eq. 24):
/// the relative tangential displacement over the substep, (x − x_prev) − shift, is cancelled
/// or reduced, shift being how far the plane's surface point moved with its part.
///
/// Each plane is a supporting plane of a convex part, so a particle `r` outside it is at least
/// `r` from the part. Returns (contacts resolved, deepest overlap).
pub(crate) fn project(
    parts: &[MovingPart],
    planes: &[Plane],
    prev: DVec3,
    x: &mut DVec3,
    r: f64,
    friction: Friction,
) -> (usize, f64) {
    let (mut contacts, mut deepest) = (0, 0.0f64);
    let tolerance = 1e-6 * r.max(1e-3);
    for _ in 0..ROUNDS {
        let mut moved = false;
        for p in planes {
            let depth = r - p.normal.dot(*x - p.point);
            if depth <= tolerance {
                continue;
            }
            *x += p.normal * depth;
            let shift = parts[usize::from(p.part)].displacement_at(p.point);
            let rel = (*x - prev) - shift;
            let tangential = rel - p.normal * p.normal.dot(rel);
            *x -= friction.correction(tangential, depth);
            contacts += 1;
            deepest = deepest.max(depth);
            moved = true;
        }
        if !moved || planes.len() == 1 {
            break;
        }
    }
    (contacts, deepest)
}
