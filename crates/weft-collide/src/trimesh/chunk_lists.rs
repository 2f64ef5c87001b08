//! The state a mesh collider keeps per particle of one chunk (or run): its candidate list
//! ([`ChunkLists`]).

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
