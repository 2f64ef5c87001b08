//! The state a mesh collider keeps per particle of one chunk (or run): its candidate list
//! ([`ChunkLists`]) and its certificate ([`Certificates`]).

use glam::DVec3;

use super::riding::Riding;

/// The candidate lists of one mesh collider for one chunk of particles.
#[derive(Clone, Debug, Default)]
pub(crate) struct ChunkLists {
    /// Where each particle was when its list was built (collider frame).
    pub(super) anchor: Vec<DVec3>,
    /// The list holds every triangle within this distance of the anchor; NaN: no list.
    pub(super) radius: Vec<f64>,
    /// The surface's travel bound before the substep of the build.
    pub(super) travel: Vec<f64>,
    /// How far the nearest triangle lay from the anchor at the build, at most (infinite:
    /// not known).
    pub(super) nearest: Vec<f64>,
    /// Whether the anchor was inside the closed mesh.
    pub(super) inside: Vec<bool>,
    /// The particle's position after the last projection (collider frame, end pose).
    pub(super) last: Vec<DVec3>,
    /// The triangle each particle touched last (tested first: it tightens the search), or
    /// `u32::MAX`.
    pub(super) hint: Vec<u32>,
    /// Each particle's list: `tris[start .. start + len]`.
    pub(super) range: Vec<(u32, u32)>,
    /// On a deforming mesh, the length of each list's guard (the unlisted triangles its
    /// riding certificate bounds), stored after it: `tris[start + len ..][.. guard]`.
    pub(super) guard: Vec<u32>,
    /// On a deforming mesh, each list's riding certificate.
    pub(super) riding: Vec<Riding>,
    /// The last frame in which a riding certificate was made for a list of the chunk (0:
    /// none): where that is not the current frame, no certificate of the chunk holds, and
    /// none is read.
    pub(super) riding_frame: u64,
    /// A build's guard, before it joins the arena.
    pub(super) scratch: Vec<u32>,
    /// The lists, end to end; rebuilt lists are appended and the arena compacted when half
    /// of it is stale.
    pub(super) tris: Vec<u32>,
    /// Entries in use.
    pub(super) live: usize,
    /// The arena's spare buffer, for compaction.
    pub(super) spare: Vec<u32>,
    /// Lists built so far.
    pub builds: u64,
    /// Each particle's certificate (`certified`).
    pub(crate) certs: Certificates,
    /// The block test's queue of particles for the face test (`list_run`), kept between
    /// runs for its allocation.
    pub(super) queue: Vec<usize>,
}

impl ChunkLists {
    /// Lists for `n` particles, all to be built.
    pub fn new(n: usize) -> Self {
        Self {
            anchor: vec![DVec3::ZERO; n],
            radius: vec![f64::NAN; n],
            travel: vec![0.0; n],
            nearest: vec![f64::INFINITY; n],
            inside: vec![false; n],
            last: vec![DVec3::ZERO; n],
            hint: vec![u32::MAX; n],
            range: vec![(0, 0); n],
            guard: vec![0; n],
            riding: vec![Riding::NONE; n],
            riding_frame: 0,
            scratch: Vec::new(),
            tris: Vec::new(),
            live: 0,
            spare: Vec::new(),
            builds: 0,
            certs: Certificates::new(n),
            queue: Vec::new(),
        }
    }

    /// Triangles listed (guards included), over all particles of the chunk.
    pub fn entries(&self) -> usize {
        self.live
    }

    /// [`Self::compact`] once half the arena (or more) is stale.
    pub fn tidy(&mut self) {
        if self.tris.len() > 2 * self.live + 64 {
            self.compact();
        }
    }

    /// Drops stale entries and puts the lists back in particle order (the contact loop then
    /// reads the arena front to back).
    pub fn compact(&mut self) {
        if self.tris.len() == self.live {
            return;
        }
        let mut fresh = std::mem::take(&mut self.spare);
        fresh.clear();
        for (r, &guard) in self.range.iter_mut().zip(&self.guard) {
            let s = fresh.len() as u32;
            fresh.extend_from_slice(&self.tris[r.0 as usize..(r.0 + r.1 + guard) as usize]);
            *r = (s, r.1);
        }
        self.spare = std::mem::replace(&mut self.tris, fresh);
    }
}

/// A certificate's face where no triangle lay within ψ: the particle is clear.
pub(crate) const CLEAR: u32 = u32::MAX;

/// A certificate's face where none could be made: the particle goes to the lists.
pub(crate) const NO_FACE: u32 = u32::MAX - 1;

/// The certificates of one chunk (or run) of particles, per particle, in struct-of-arrays
/// (the block test loads each field of a block's lanes as one vector).
#[derive(Clone, Debug, Default)]
pub(crate) struct Certificates {
    /// The anchors, per axis.
    pub(super) anchor: [Vec<f64>; 3],
    /// ψ plus the surface's travel bound before the substep of the build (NaN: none).
    pub(super) reach: Vec<f64>,
    /// The face, [`CLEAR`] or [`NO_FACE`].
    pub(super) face: Vec<u32>,
    /// For a clear certificate, the nearest triangle its search found ([`NO_FACE`]: none
    /// within its reach): where the next certificate looks first.
    pub(super) near: Vec<u32>,
    /// A clear ball the block test found about a particle hovering over its face: its centre
    /// per axis, then its radius less r plus the surface's travel bound when it was found
    /// (NaN: none). No triangle was within r plus that radius of the centre.
    pub(super) hover: [Vec<f64>; 4],
    /// Certificates made so far.
    pub builds: u64,
}

impl Certificates {
    /// Certificates for `n` particles, none made.
    pub fn new(n: usize) -> Self {
        Self {
            anchor: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            reach: vec![f64::NAN; n],
            face: vec![NO_FACE; n],
            near: vec![NO_FACE; n],
            hover: [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![f64::NAN; n]],
            builds: 0,
        }
    }

    /// Particle `j`'s anchor.
    #[inline]
    pub(super) fn anchor_of(&self, j: usize) -> DVec3 {
        DVec3::new(self.anchor[0][j], self.anchor[1][j], self.anchor[2][j])
    }

    /// Sets particle `j`'s certificate (and drops its hover ball): anchor, reach, face and,
    /// for a clear one, the nearest triangle found.
    pub(super) fn set(&mut self, j: usize, anchor: DVec3, reach: f64, (face, near): (u32, u32)) {
        for k in 0..3 {
            self.anchor[k][j] = anchor[k];
        }
        self.reach[j] = reach;
        self.face[j] = face;
        self.near[j] = near;
        self.hover[3][j] = f64::NAN;
    }

    /// Whether particle `j`'s certificate still covers a particle of thickness `r` at `x`
    /// (the mesh's frame) with the surface's travel bound now `travel`: every triangle off
    /// its face's ring (every triangle, if clear) at least r away.
    #[inline]
    pub(super) fn covers(&self, j: usize, x: DVec3, (r, travel): (f64, f64)) -> bool {
        let slack = self.reach[j] - travel - r;
        slack >= 0.0 && (x - self.anchor_of(j)).length_squared() <= slack * slack
    }

    /// Sets particle `j`'s hover ball: about `centre`, no triangle within r + `room` at the
    /// surface's travel bound `travel`.
    pub(super) fn set_hover(&mut self, j: usize, centre: DVec3, room: f64, travel: f64) {
        for k in 0..3 {
            self.hover[k][j] = centre[k];
        }
        self.hover[3][j] = room * (1.0 - 1e-9) + travel;
    }
}
