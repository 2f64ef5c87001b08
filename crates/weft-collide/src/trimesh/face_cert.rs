//! What the contact grid's first test reads of one triangle ([`FaceCert`], its fields laid
//! out for block loads), and what the test decides for a particle ([`Placement`],
//! [`Settled`]).

use glam::DVec3;

use super::frame::MeshFrame;

/// What the first test reads of one triangle, in f64, two cache lines: a corner, the unit
/// normal, the in-plane dual basis of the edges (barycentric coordinates β = u · (x − a),
/// γ = v · (x − a) of x's projection) and the clearance, as one array so that a block reads
/// each field of its lanes' triangles together.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct FaceCert(pub(super) [f64; 16]);

/// Where each field of a [`FaceCert`] starts: corner a, unit normal n, the dual vectors u and
/// v (each three axes), then the clearance.
pub(super) const A: usize = 0;
pub(super) const N: usize = 3;
pub(super) const U: usize = 6;
pub(super) const V: usize = 9;
pub(super) const CLEAR: usize = 12;
/// Fields a block gathers.
pub(super) const FIELDS: usize = 13;

/// Projections nearer than this (barycentric) to an edge are left to the walk.
pub(super) const INSIDE: f64 = 1e-9;

impl FaceCert {
    /// The record of a triangle that settles nothing: every particle goes on to the walk.
    pub const NONE: Self = {
        let mut f = [0.0; 16];
        f[CLEAR] = -1.0;
        Self(f)
    };

    /// The record of the triangle with `corners`, unit `normal` and `clearance`: with
    /// e₁ = b − a, e₂ = c − a and m = e₁ × e₂, u = (e₂ × m) / |m|² and v = (m × e₁) / |m|²
    /// (so u · e₁ = v · e₂ = 1, u · e₂ = v · e₁ = 0, both in the plane). A degenerate triangle,
    /// or one so thin that rounding of β and γ at the clearance's reach could pass 10⁻¹²,
    /// settles nothing.
    pub fn new(corners: [DVec3; 3], normal: DVec3, clearance: f64) -> Self {
        let [a, b, c] = corners;
        let (e1, e2) = (b - a, c - a);
        let m = e1.cross(e2);
        let m2 = m.length_squared();
        if normal == DVec3::ZERO || m2.is_nan() || m2 <= 0.0 {
            return Self::NONE;
        }
        let (u, v) = (e2.cross(m) / m2, m.cross(e1) / m2);
        let reach = (u.length() + v.length()) * (clearance.max(0.0) + e1.length() + e2.length());
        if reach.is_nan() || reach >= 1e3 {
            return Self::NONE;
        }
        let mut f = [0.0; 16];
        for (at, w) in [(A, a), (N, normal), (U, u), (V, v)] {
            f[at..at + 3].copy_from_slice(&w.to_array());
        }
        f[CLEAR] = clearance;
        Self(f)
    }
}

/// A still mesh's pose as a block reads it: the world's frame, or a basis B (columns) and a
/// translation t, local = Bᵀ (x − t).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placement {
    /// Whether the pose is the world's frame.
    pub(super) identity: bool,
    /// B's columns.
    pub(super) basis: [[f64; 3]; 3],
    /// t.
    pub(super) shift: [f64; 3],
}

impl Placement {
    /// `frame`'s pose (its end pose; the mesh is still over the substep).
    pub fn of(frame: &MeshFrame<'_>) -> Self {
        let b = frame.pose.basis;
        Self {
            identity: frame.identity,
            basis: [b.x_axis, b.y_axis, b.z_axis].map(|c| c.to_array()),
            shift: frame.pose.translation.to_array(),
        }
    }
}

/// What the first test did with a lane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Settled {
    /// Not settled: the walk and the cell follow, from the particle as it was.
    #[default]
    Open,
    /// Clear, or pushed out of the face with room to spare: nothing more to do.
    Done,
    /// Pushed out of the face, then slipped far enough that the cell must be scanned.
    Rounds,
}
