//! A candidate list's second certificate on a deforming mesh, one that rides with the
//! surface: it bounds how the triangles move relative to a reference motion near the particle
//! rather than how far any vertex of the mesh moves, so a particle carried along by the
//! surface (a cape on a jumping body) keeps its list for the rest of the frame while the
//! surface around it holds its shape.
//!
//! Over a frame every vertex v moves linearly, v(w) = v(w₀) + (w − w₀) dᵥ (w the fraction of
//! the frame, [`MeshGeometry::begin_frame`]). A point o riding from the anchor a (the particle
//! when the list was built, at w₀) with the reference motion d, o(w) = a + (w − w₀) d, is at
//! least
//!
//! |a − u(w₀)| − (w − w₀) maxᵥ |dᵥ − d|    (v over u's corners)
//!
//! from triangle u at w (every point of u moves by a convex combination of its corners'
//! motions), and the particle at x is as far less |x − o(w)|. The list's own triangles are
//! checked exactly at every substep; every other triangle is
//!
//! - in the guard (kept after the list): farther than `near` from a at w₀, its corners'
//!   motions within `spread` of d; or
//! - farther than `far` from o(w) until the frame's end (`MeshGeometry::within_riding`).
//!
//! A certificate lasts to the end of the frame it was made in.

use glam::DVec3;

use super::MeshGeometry;

/// Room left for rounding: the vertices between frame ends are computed in f64 from the same
/// start and motion, a few ulps off the line (m, per metre of extent).
const ROUNDING: f64 = 1e-9;

/// A riding certificate (see the module's docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Riding {
    /// The frame it is for ([`MeshGeometry::frame_id`]); 0: none.
    pub frame: u64,
    /// The frame fraction at which the list was built.
    pub w0: f64,
    /// The anchor: the particle then.
    pub anchor: DVec3,
    /// The reference motion over the frame.
    pub motion: DVec3,
    /// The guard's corners' motions over the frame lie within this of `motion`.
    pub spread: f64,
    /// The guard's triangles were farther than this from the anchor at `w0`.
    pub near: f64,
    /// Every other unlisted triangle stays farther than this from the riding point.
    pub far: f64,
}

impl Riding {
    /// No certificate.
    pub const NONE: Self = Self {
        frame: 0,
        w0: 0.0,
        anchor: DVec3::ZERO,
        motion: DVec3::ZERO,
        spread: 0.0,
        near: 0.0,
        far: 0.0,
    };

    /// The certificate of a list just built at `x` (the end of the current substep) by
    /// [`MeshGeometry::within_riding`] with radii `near` and `far`, reference `motion` and the
    /// guard's `spread`.
    pub fn new(
        g: &MeshGeometry,
        x: DVec3,
        motion: DVec3,
        spread: f64,
        (near, far): (f64, f64),
    ) -> Self {
        let slack = ROUNDING * (1.0 + g.extent);
        Self {
            frame: g.frame_id,
            w0: g.frame_span.1,
            anchor: x,
            motion,
            spread: spread * (1.0 + 1e-12) + slack,
            near: near * (1.0 - 1e-12) - slack,
            far: far * (1.0 - 1e-12) - slack,
        }
    }

    /// Whether the certificate holds for a particle at `x` at the end of the current substep
    /// on a path from `from` (at the substep's start if `fresh`, else also at its end) with
    /// thickness `r`: no unlisted triangle is within r of either point, nor of the path
    /// between them while it moves.
    #[inline]
    pub fn holds(&self, g: &MeshGeometry, x: DVec3, from: DVec3, fresh: bool, r: f64) -> bool {
        let (w_before, w) = g.frame_span;
        let w_from = if fresh { w_before } else { w };
        // Made in this frame, for a path that starts no earlier.
        if self.frame != g.frame_id || self.frame == 0 || w_from < self.w0 {
            return false;
        }
        let off2 =
            |p: DVec3, at: f64| (p - (self.anchor + self.motion * (at - self.w0))).length_squared();
        // The path's offset from the riding point is linear over the substep, as the
        // triangles' motions: its largest is at an end.
        let room = (self.near - r - (w - self.w0) * self.spread).min(self.far - r);
        room >= 0.0 && off2(x, w).max(off2(from, w_from)) <= room * room
    }
}
