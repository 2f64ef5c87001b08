//! The Cusick drape test (BS 5058, ISO 9073-9): a disc of fabric, 30 cm across, clamped
//! between two 18 cm support discs, drapes under its own weight; the drape coefficient is the
//! share of the free annulus its shadow still covers, DC = (A − A_s)/(A₀ − A_s) with A the
//! shadow's area seen from straight above, A₀ the flat specimen's and A_s the support's
//! (Cusick 1968). 1 is a fabric that does not drape at all, 0 one that hangs straight down.
//!
//! The specimen is a grid cut to a disc ([`ClothMesh::cut_disc`]): the cells whose centre lies
//! within the radius, the corners outside it moved onto the circle, every particle within the
//! support's radius pinned where it lies (the clamp). The shadow is measured by rasterizing the
//! triangles' projections onto the horizontal plane ([`shadow_area`]), which counts overlapping
//! folds once, as a shadow does.

use glam::{DVec2, DVec3};

use crate::cloth::{ClothMesh, Mass};
use crate::error::MeshError;

/// Pairs of particles (stretch or shear constraints).
type Pairs = Vec<[u32; 2]>;

/// The specimen's radius: a 30 cm disc (m).
pub const SPECIMEN_RADIUS: f64 = 0.15;

/// The support discs' radius: 18 cm across (m).
pub const SUPPORT_RADIUS: f64 = 0.09;

/// Pixels across the specimen's diameter when its shadow is rasterized: 0.3 mm pixels on the
/// 30 cm disc, so a pixel's share of the annulus is below 2e-6.
pub const SHADOW_PIXELS: usize = 1000;

impl ClothMesh {
    /// The part of this flat mesh within `radius` of `center` (the triangles whose centroid
    /// lies within it, their corners beyond it moved radially onto the circle), its masses
    /// lumped again from `mass`, every particle within `clamp` of `center` pinned besides the
    /// surviving pins. Returns the new mesh and each old vertex's new index (`None` where cut
    /// away). The cut mesh has no grid; cut from one, it keeps the grid's pairs (see
    /// [`grid_pairs`]), otherwise every edge is a stretch pair.
    pub fn cut_disc(
        &self,
        center: DVec3,
        radius: f64,
        clamp: f64,
        mass: Mass,
    ) -> Result<(ClothMesh, Vec<Option<u32>>), MeshError> {
        let inside = |p: DVec3| p.distance(center) <= radius;
        let keep: Vec<bool> = (self.triangles.iter())
            .map(|t| inside(t.map(|i| self.positions[i as usize]).iter().sum::<DVec3>() / 3.0))
            .collect();
        let kept: Vec<[u32; 3]> = (self.triangles.iter().zip(&keep))
            .filter_map(|(t, &k)| k.then_some(*t))
            .collect();
        let mut map = vec![None; self.positions.len()];
        let mut positions = Vec::new();
        for t in &kept {
            for &i in t {
                if map[i as usize].is_none() {
                    map[i as usize] = Some(positions.len() as u32);
                    let p = self.positions[i as usize];
                    let r = p.distance(center);
                    positions.push(if r > radius {
                        center + (p - center) * (radius / r)
                    } else {
                        p
                    });
                }
            }
        }
        let triangles: Vec<[u32; 3]> = kept
            .iter()
            .map(|t| t.map(|i| map[i as usize].unwrap_or(0)))
            .collect();
        let mut pinned: Vec<u32> = self
            .pinned
            .iter()
            .filter_map(|&i| map.get(i as usize).copied().flatten())
            .collect();
        pinned.extend(
            positions
                .iter()
                .enumerate()
                .filter(|(_, p)| p.distance(center) <= clamp)
                .map(|(i, _)| i as u32),
        );
        pinned.sort_unstable();
        pinned.dedup();
        let mut mesh = ClothMesh::from_triangles(positions, triangles, mass, pinned)?;
        if let Some((stretch, shear)) = self.grid_pairs(&keep, &map) {
            (mesh.stretch, mesh.shear) = (stretch, shear);
        }
        Ok((mesh, map))
    }

    /// For a grid ([`crate::GridDesc::build`]: quad q's triangles are 2q and 2q + 1, its
    /// diagonals shear pairs 2q and 2q + 1) of which the triangles `keep` are kept, the cut
    /// mesh's pairs under new indices `map`: stretch on the grid lines that kept triangles
    /// hold, shear on both diagonals of each whole quad and on the split diagonal of a half
    /// quad. A woven fabric shears far more easily than it stretches (the materials' shear
    /// modulus): with every edge a stretch pair, the diagonals held the disc's shear at the
    /// stretch stiffness and its drape coefficient moved with the resolution (cotton under
    /// XPBD 0.46 at 20 cells, 0.74 at 40; now 0.75 and 0.72). `None` for a mesh that is not
    /// such a grid.
    fn grid_pairs(&self, keep: &[bool], map: &[Option<u32>]) -> Option<(Pairs, Pairs)> {
        let quads = self.shear.len() / 2;
        let grid = self.grid.is_some() && self.triangles.len() == 2 * quads && quads > 0;
        if !grid {
            return None;
        }
        let new = |[a, b]: [u32; 2]| Some([map[a as usize]?, map[b as usize]?]);
        let edge = |t: [u32; 3], [a, b]: [u32; 2]| t.contains(&a) && t.contains(&b);
        let mut diagonal = Vec::new();
        let mut shear = Vec::new();
        for q in 0..quads {
            let (t, d) = (
                [2 * q, 2 * q + 1],
                [self.shear[2 * q], self.shear[2 * q + 1]],
            );
            let split = |t: usize| d.into_iter().filter(move |&p| edge(self.triangles[t], p));
            diagonal.extend(split(t[0]));
            match (keep[t[0]], keep[t[1]]) {
                (true, true) => shear.extend(d),
                (true, false) => shear.extend(split(t[0])),
                (false, true) => shear.extend(split(t[1])),
                (false, false) => {}
            }
        }
        let key = |[a, b]: [u32; 2]| [a.min(b), a.max(b)];
        let mut diagonals: Vec<[u32; 2]> = diagonal.into_iter().map(key).collect();
        diagonals.sort_unstable();
        let mut stretch: Pairs = (self.triangles.iter().zip(keep))
            .filter(|&(_, &k)| k)
            .flat_map(|(t, _)| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]].map(key))
            .filter(|p| diagonals.binary_search(p).is_err())
            .collect();
        stretch.sort_unstable();
        stretch.dedup();
        let all = |pairs: Vec<[u32; 2]>| pairs.into_iter().map(new).collect::<Option<Vec<_>>>();
        Some((all(stretch)?, all(shear)?))
    }
}

/// The area (m²) of the shadow `triangles` at `positions` cast on the horizontal (x–z) plane
/// from straight above, rasterized on square pixels of side `pixel` (m): a pixel counts when
/// its centre lies in some triangle's projection, so folds lying over each other count once.
pub fn shadow_area(positions: &[DVec3], triangles: &[[u32; 3]], pixel: f64) -> f64 {
    let flat: Vec<DVec2> = positions.iter().map(|p| DVec2::new(p.x, p.z)).collect();
    let (lo, hi) = flat.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let usable = pixel.is_finite() && pixel > 0.0 && lo.is_finite() && hi.is_finite();
    if !usable {
        return 0.0;
    }
    let cells = ((hi - lo) / pixel).ceil().as_uvec2() + 1;
    let (nx, nz) = (cells.x as usize, cells.y as usize);
    let mut covered = vec![false; nx * nz];
    for t in triangles {
        let [a, b, c] = t.map(|i| flat[i as usize]);
        let area2 = (b - a).perp_dot(c - a);
        if area2 == 0.0 {
            continue;
        }
        let (tlo, thi) = (a.min(b).min(c), a.max(b).max(c));
        let first = ((tlo - lo) / pixel - 0.5)
            .ceil()
            .max(DVec2::ZERO)
            .as_uvec2();
        let last = ((thi - lo) / pixel - 0.5).floor().as_uvec2();
        for j in first.y..=last.y.min(nz as u32 - 1) {
            for i in first.x..=last.x.min(nx as u32 - 1) {
                let p = lo + (DVec2::new(f64::from(i), f64::from(j)) + 0.5) * pixel;
                // Edge functions of the same sign as the triangle's orientation: inside.
                let e = [(a, b), (b, c), (c, a)].map(|(u, v)| (v - u).perp_dot(p - u) * area2);
                if e.iter().all(|&x| x >= 0.0) {
                    covered[j as usize * nx + i as usize] = true;
                }
            }
        }
    }
    covered.iter().filter(|&&c| c).count() as f64 * pixel * pixel
}

/// A Cusick specimen as measured: its flat shadow and its support's area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drape {
    /// The flat specimen's shadow A₀ (m²).
    pub rest_area: f64,
    /// The support's area A_s = π r_s² (m²).
    pub support_area: f64,
    /// The rasterizer's pixel (m).
    pub pixel: f64,
}

impl Drape {
    /// The specimen `triangles` at its flat `rest` positions, clamped within `support` (m) of
    /// its centre; `radius` (m) sets the pixel ([`SHADOW_PIXELS`] across the diameter).
    pub fn new(rest: &[DVec3], triangles: &[[u32; 3]], radius: f64, support: f64) -> Self {
        let pixel = 2.0 * radius / SHADOW_PIXELS as f64;
        Self {
            rest_area: shadow_area(rest, triangles, pixel),
            support_area: std::f64::consts::PI * support * support,
            pixel,
        }
    }

    /// The drape coefficient (A − A_s)/(A₀ − A_s) of the specimen at `positions` (Cusick
    /// 1968; 1 flat, 0 hanging straight down).
    pub fn coefficient(&self, positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
        let area = shadow_area(positions, triangles, self.pixel);
        (area - self.support_area) / (self.rest_area - self.support_area)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{GridDesc, Orientation};

    /// The specimen's square of `n` × `n` cells, before the cut.
    fn square(n: usize) -> ClothMesh {
        GridDesc {
            resolution: (n + 1, n + 1),
            size: (2.0 * SPECIMEN_RADIUS, 2.0 * SPECIMEN_RADIUS),
            center: DVec3::ZERO,
            orientation: Orientation::Horizontal,
            mass: Mass::Density(0.2),
            pins: Vec::new(),
        }
        .build()
        .expect("grid")
    }

    fn disc(n: usize) -> ClothMesh {
        square(n)
            .cut_disc(
                DVec3::ZERO,
                SPECIMEN_RADIUS,
                SUPPORT_RADIUS,
                Mass::Density(0.2),
            )
            .expect("disc")
            .0
    }

    #[test]
    fn a_cut_disc_has_the_specimen_s_area_and_a_clamped_support() {
        for n in [16, 24, 40] {
            let m = disc(n);
            let full = std::f64::consts::PI * SPECIMEN_RADIUS * SPECIMEN_RADIUS;
            // A polygon inscribed in the circle, and no corner outside it.
            assert!(
                m.area() < full && m.area() > 0.97 * full,
                "{n}: {}",
                m.area()
            );
            assert!(
                m.positions
                    .iter()
                    .all(|p| p.length() <= SPECIMEN_RADIUS * (1.0 + 1e-12))
            );
            assert!((m.total_mass() - 0.2 * m.area()).abs() < 1e-12);
            // Every particle of the support, and no other, is pinned.
            for (i, p) in m.positions.iter().enumerate() {
                let clamped = p.length() <= SUPPORT_RADIUS;
                assert_eq!(m.pinned.binary_search(&(i as u32)).is_ok(), clamped);
            }
        }
    }

    #[test]
    fn a_disc_cut_from_a_grid_keeps_grid_lines_as_stretch_and_diagonals_as_shear() {
        for n in [16, 24] {
            let m = disc(n);
            let key = |[a, b]: [u32; 2]| [a.min(b), a.max(b)];
            let stretch: std::collections::BTreeSet<_> =
                m.stretch.iter().map(|&p| key(p)).collect();
            let shear: std::collections::BTreeSet<_> = m.shear.iter().map(|&p| key(p)).collect();
            assert_eq!(stretch.len(), m.stretch.len(), "{n}: a stretch pair twice");
            assert_eq!(shear.len(), m.shear.len(), "{n}: a shear pair twice");
            assert!(stretch.is_disjoint(&shear), "{n}");
            // Every edge of the mesh is held by one pair.
            for t in &m.triangles {
                for e in [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]] {
                    let e = key(e);
                    assert!(
                        stretch.contains(&e) || shear.contains(&e),
                        "{n}: edge {e:?}"
                    );
                }
            }
            // Away from the rim (where corners moved onto the circle) stretch pairs lie along
            // the grid's lines and shear pairs across its cells, both diagonals of each cell.
            let at = |i: u32| m.positions[i as usize];
            let inner =
                |[a, b]: [u32; 2]| at(a).length().max(at(b).length()) < 0.8 * SPECIMEN_RADIUS;
            let along = |[a, b]: [u32; 2]| {
                let d = at(b) - at(a);
                d.x.abs() < 1e-12 || d.z.abs() < 1e-12
            };
            let (inner_stretch, inner_shear): (Vec<_>, Vec<_>) = (
                stretch.iter().copied().filter(|&p| inner(p)).collect(),
                shear.iter().copied().filter(|&p| inner(p)).collect(),
            );
            assert!(inner_stretch.iter().all(|&p| along(p)), "{n}");
            assert!(inner_shear.iter().all(|&p| !along(p)), "{n}");
            // About one cell per particle inside, two diagonals a cell.
            let inner_particles = (m.positions.iter())
                .filter(|p| p.length() < 0.8 * SPECIMEN_RADIUS)
                .count();
            assert!(
                inner_shear.len() > inner_particles,
                "{n}: {} shear pairs for {inner_particles} particles",
                inner_shear.len()
            );
        }
    }

    #[test]
    fn a_disc_has_its_grid_s_stretch_and_shear_stiffness() {
        // The fabric's shear modulus acts on the disc's diagonals as on the grid's: with the
        // cell unknown off a grid, it was lost (the disc then draped with no shear stiffness).
        let cotton = crate::preset("cotton").expect("preset");
        for n in [16, 24] {
            let (on_grid, on_disc) = (cotton.stiffness(&square(n)), cotton.stiffness(&disc(n)));
            for (name, a, b) in [
                ("stretch", on_grid.stretch, on_disc.stretch),
                ("shear", on_grid.shear, on_disc.shear),
            ] {
                let (a, b) = (a.expect("grid"), b.expect("disc"));
                assert!(
                    (a - b).abs() < 1e-9 * a,
                    "{n}: {name} {a} on the grid, {b} on the disc"
                );
            }
        }
    }

    #[test]
    fn the_shadow_of_a_disc_is_its_area_and_folds_count_once() {
        let m = disc(24);
        let a = shadow_area(&m.positions, &m.triangles, 2.0 * SPECIMEN_RADIUS / 1000.0);
        assert!(
            (a - m.area()).abs() < 1e-3 * m.area(),
            "{a} vs {}",
            m.area()
        );
        // The same triangles twice over cast one shadow.
        let doubled: Vec<[u32; 3]> = m.triangles.iter().chain(&m.triangles).copied().collect();
        let b = shadow_area(&m.positions, &doubled, 2.0 * SPECIMEN_RADIUS / 1000.0);
        assert_eq!(a, b);
        // Folded up by 90° beyond |x| > 0.1, the annulus's shadow shrinks to the strip.
        let folded: Vec<DVec3> = m
            .positions
            .iter()
            .map(|p| {
                if p.x.abs() > 0.1 {
                    DVec3::new(0.1 * p.x.signum(), -(p.x.abs() - 0.1), p.z)
                } else {
                    *p
                }
            })
            .collect();
        let drape = Drape::new(&m.positions, &m.triangles, SPECIMEN_RADIUS, SUPPORT_RADIUS);
        let dc = drape.coefficient(&folded, &m.triangles);
        // The band |x| ≤ 0.1 of the disc: 2 (r² asin(0.1/r) + 0.1 √(r² − 0.01)).
        let r = SPECIMEN_RADIUS;
        let band = 2.0 * (r * r * (0.1 / r).asin() + 0.1 * (r * r - 0.01).sqrt());
        let expected = (band - drape.support_area) / (m.area() - drape.support_area);
        assert!((dc - expected).abs() < 0.02, "{dc} vs {expected}");
        assert!((drape.coefficient(&m.positions, &m.triangles) - 1.0).abs() < 1e-12);
    }
}
