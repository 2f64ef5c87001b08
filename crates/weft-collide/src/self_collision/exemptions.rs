//! Which pairs self-collision leaves to the cloth's own constraints: pairs of one cloth that
//! lie within a fold length at rest, or share a triangle (see the parent module's doc).

use glam::DVec3;

/// Cloth length a sheet `t` thick folds over when its two layers touch, as a multiple of
/// `t`: its mid-surface bends through half a circle of diameter `t`, π t / 2 long.
const FOLD: f64 = std::f64::consts::FRAC_PI_2;

/// What decides whether a pair is exempt: the members' rest positions and cloths.
///
/// A pair is exempt when both particles belong to one cloth and lie at most
/// [`Exemptions::apart`] apart at rest. The test runs on tags (see [`Exemptions::tag`]): the
/// rest positions with each cloth moved away from the others, so that one distance test,
/// inside the grid's search, both leaves exempt pairs out and keeps every pair of two cloths.
#[derive(Clone, Debug)]
pub(super) struct Exemptions {
    /// Rest positions (global index; only members are meaningful).
    rest: Vec<DVec3>,
    /// Cloth of each particle (global index).
    cloth: Vec<u32>,
    /// The longest triangle edge at rest (m).
    longest_edge: f64,
    /// The largest extent of the members' rest box (m).
    extent: f64,
    /// Every particle's tag, for the distance in `tags_for` (NaN before the first).
    tags: Vec<DVec3>,
    tags_for: f64,
}

impl Exemptions {
    /// Exemptions for particles at rest at `rest` in cloths `cloth` (global index; `u32::MAX`
    /// for non-members), whose longest triangle edge is `longest_edge` and whose rest box's
    /// largest extent is `extent` (m).
    pub(super) fn new(rest: Vec<DVec3>, cloth: Vec<u32>, longest_edge: f64, extent: f64) -> Self {
        Self {
            rest,
            cloth,
            longest_edge,
            extent,
            tags: Vec::new(),
            tags_for: f64::NAN,
        }
    }

    /// The rest distance up to which a pair of one cloth is exempt for largest thickness `t`:
    /// the longer of [`FOLD`] · t and the longest edge (so that every pair sharing a triangle
    /// is), with a margin of 10⁻⁶ for rounding.
    pub(super) fn apart(&self, t: f64) -> f64 {
        (FOLD * t).max(self.longest_edge) * (1.0 + 1e-6)
    }

    /// Particle `i`'s tag for exemption distance `apart`: its rest position moved along x by
    /// its cloth's index times one rest extent and twice `apart`, so that two cloths' tags are
    /// always more than `apart` apart.
    #[inline(always)]
    fn tag(&self, i: usize, apart: f64) -> DVec3 {
        let gap = self.extent + 2.0 * apart;
        let mut tag = self.rest[i];
        tag.x += f64::from(self.cloth[i]) * gap;
        tag
    }

    /// The distance pair `(a, b)` must keep (their mean thickness), or `None` if it is exempt
    /// for exemption distance `apart`.
    pub(super) fn target(&self, a: u32, b: u32, thickness: &[f64], apart: f64) -> Option<f64> {
        let (a, b) = (a as usize, b as usize);
        (self.tag(a, apart).distance_squared(self.tag(b, apart)) > apart * apart)
            .then(|| 0.5 * (thickness[a] + thickness[b]))
    }

    /// Every particle's tag for exemption distance `apart` (made once per distance).
    pub(super) fn tags(&mut self, apart: f64) -> &[DVec3] {
        if self.tags_for != apart {
            self.tags = (0..self.rest.len()).map(|i| self.tag(i, apart)).collect();
            self.tags_for = apart;
        }
        &self.tags
    }
}
