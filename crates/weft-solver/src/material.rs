//! Fabrics in physical units, and the constraint parameters every method derives from them.
//!
//! A [`Material`] gives an area density and three membrane/plate stiffnesses; [`Material::params`]
//! turns them into per-family parameters for a given mesh and time stepping, so the same fabric
//! behaves the same at any resolution:
//!
//! * **Stretch** (mesh edges): Van Gelder's spring constant for a triangulated membrane,
//!   k = E Σ A_t / |e|² over the triangles t beside edge e (Van Gelder 1998, "Approximate
//!   simulation of elastic membranes by triangulated spring meshes", J. Graphics Tools 3(2),
//!   eq. 8). On grids, whose quad diagonals carry the shear springs, the diagonals already add
//!   G to the lattice's C₁₁ (below), so the grid lines get E − G: a square lattice of edge
//!   springs k_s and diagonal springs k_d strained uniformly stores
//!   W = ½ k_s (ε_xx² + ε_yy²) + ½ k_d ((ε_xx + ε_yy)² + 4 ε_xy²) per unit area
//!   (Ostoja-Starzewski 2002, "Lattice models in micromechanics", Appl. Mech. Rev. 55(1), §2),
//!   i.e. C₁₁ = k_s + k_d and C₆₆ = k_d.
//! * **Shear** (both quad diagonals, length d, of a cell of area A): the same energy on a
//!   rectangular cell gives C₆₆ = 2 k_d A / d², so k_d = G d² / (2A) (= G on square cells).
//! * **Bending** (dihedral angle across each interior edge e, A_e the area of its two
//!   triangles): k_θ = B |e|² / A_e (N·m/rad), the edge weight of the discrete-shells energy
//!   (Grinspun et al. 2003, "Discrete shells", eq. 3, where |e|/h̄_e = 3|e|²/A_e; Bridson et al.
//!   2003 weight their bending force by |e|²/A_e too), scaled so that a grid bent into a
//!   cylinder of curvature κ about its grid lines stores ½ B κ² per unit area: there only the
//!   grid lines fold, by θ = κL, each for L² of cloth, so ½ k_θ θ² = ½ B κ² L² gives k_θ = B
//!   = B L²/A_e. The distance-based bending family is switched off.
//! * **…and corrected for the grid's own softness** by [`HINGE_RELAXATION`] = 5/4: the
//!   cylinder is not where the hinge energy is least. Letting the vertex heights relax (a
//!   periodic least-squares over the alternating-diagonal grid, 2×2 to 8×8 cells), bending
//!   about a grid line costs D₁₁ = 5/6 B with D₁₂ = −B/6 and D₂₂ = 5/6 B, so a strip with free
//!   edges (the cantilever test that defines B, ASTM D1388) bends at
//!   D₁₁ − D₁₂²/D₂₂ = 4/5 B. Scaling every hinge by 5/4 makes that strip bend at B (a sheet held
//!   cylindrical then at 25/24 B, 4 % stiff). Measured (`docs/validation.md`): implicit
//!   mass-spring's cotton cantilever at 39.6°, 41.7° and about 42.5° against the elastica's
//!   41.49° at 8, 16 and 32 segments (51.3°, 50.4°, 49.6° before).
//! * **Isometric bending instead, where it is soft**: when α/h² = 1/(B h²) is at least the
//!   median Σ wᵢ|∇ᵢC|² of the isometric hinges at rest (a projection removes at most half of a
//!   hinge's error), the quadratic isometric energy replaces the dihedral: C = |Σᵢ kᵢ xᵢ| with
//!   the hinge's cotangent weights scaled by 1/√A_e, whose ½ B C² summed over the edges is
//!   ½ B ∫ (κ₁ + κ₂)² dA for an unstretched surface (Bergou et al. 2006, "A quadratic bending
//!   model for inextensible surfaces"; see [`crate::constraints::Isometric`]), so its stiffness
//!   is B itself at any resolution (times [`HINGE_RELAXATION`], which it shares to first order
//!   on a flat mesh: the two energies agree there, ½ B (Σ kᵢ zᵢ)² per hinge). It costs a fraction of the dihedral's angle and gradient;
//!   stiffer than that, its in-plane part and the inextensible edges, solved one after the
//!   other, were measured to gain energy (`tests/integration/isometric_bending.rs`), so the
//!   dihedral stays there.
//!
//! Each family keeps one value per cloth (the median over its constraints, i.e. the interior
//! value on grids of square cells; boundary edges, which Van Gelder gives half, get the
//! interior value too, and on rectangular cells the two directions of grid lines share one). XPBD gets compliance α = 1/k; both mass-spring methods get k; PBD gets the
//! stiffness whose n iterations remove the fraction of C per substep that XPBD's first
//! iteration removes, f = s / (s + α/h²) with s = Σ wᵢ |∇ᵢC|² at rest (Macklin et al. 2016,
//! eq. 18), through Müller et al. 2007's k' = 1 − (1 − k)ⁿ: k = 1 − (1 − f)^{1/n}.

use std::collections::HashMap;

use glam::DVec3;

use crate::cloth::ClothMesh;
use crate::constraints::{Dihedral, Isometric, Shape};
use crate::error::ParamError;
use crate::params::{Anisotropy, ClothParams, Family};
use crate::settings::Settings;
use crate::topology::Topology;

/// The factor on every bending hinge's stiffness that makes a free strip of the
/// alternating-diagonal grid bend at the material's B: 1/(D₁₁ − D₁₂²/D₂₂) = 1/(4/5) (see the
/// module documentation).
pub const HINGE_RELAXATION: f64 = 1.25;

/// The shares of a free grid strip's bending stiffness carried by the hinges across it, the
/// diagonal hinges and the hinges along it (summing to 1): raising each family alone by
/// ±10 % on the cantilever strip of 8 cells (cotton) moved the strip's effective B by
/// 0.165 / 0.036 of that under XPBD and 0.074 / 0.032 under implicit mass-spring (whose
/// linearised hinges lean less on the diagonals); the diagonals' share is their mean.
pub const HINGE_SHARES: [f64; 3] = [0.846, 0.12, 0.034];

/// A fabric in physical units; warp and weft are the grid's rows and columns
/// ([`crate::Direction`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Area density (kg/m²).
    pub density: f64,
    /// Membrane stretch stiffness E·thickness along the warp, the 2-D Young's modulus (N/m).
    pub stretch: f64,
    /// Membrane in-plane shear stiffness G·thickness (N/m).
    pub shear: f64,
    /// Bending stiffness per unit width of a strip along the warp, B (N·m).
    pub bending: f64,
    /// Stretch stiffness along the weft (N/m).
    pub stretch_weft: f64,
    /// Bending stiffness of a strip along the weft (N·m).
    pub bending_weft: f64,
    /// Bending stiffness of a strip cut on the bias, at 45° (N·m).
    pub bending_bias: f64,
}

impl Material {
    /// A fabric with the same stretch and bending in every direction.
    pub const fn isotropic(density: f64, stretch: f64, shear: f64, bending: f64) -> Self {
        Self {
            density,
            stretch,
            shear,
            bending,
            stretch_weft: stretch,
            bending_weft: bending,
            bending_bias: bending,
        }
    }

    /// Whether stretch and bending are the same in every direction.
    pub fn is_isotropic(&self) -> bool {
        self.stretch_weft == self.stretch
            && self.bending_weft == self.bending
            && self.bending_bias == self.bending
    }

    /// The same fabric along `direction`: its stretch and bending as warp values (stretch on
    /// the bias is the mean of warp and weft).
    pub fn along(&self, direction: crate::Direction) -> Material {
        let (stretch, bending) = match direction {
            crate::Direction::Warp => (self.stretch, self.bending),
            crate::Direction::Weft => (self.stretch_weft, self.bending_weft),
            crate::Direction::Bias => (0.5 * (self.stretch + self.stretch_weft), self.bending_bias),
        };
        Material::isotropic(self.density, stretch, self.shear, bending)
    }

    /// The bending of each hinge family of a grid that makes a free strip along the warp
    /// bend at `bending` and one along the weft at `bending_weft`, the diagonal hinges taking
    /// `bending_bias` (see [`HINGE_SHARES`]): with shares (a, b, c) of the hinges across the
    /// strip, the diagonals and the hinges along it, a warp strip bends at
    /// a k_warp + b k_bias + c k_weft and a weft strip at a k_weft + b k_bias + c k_warp; the
    /// 2 × 2 system is solved for k_warp and k_weft (each kept at least a tenth of its
    /// target). The same material back where it is isotropic.
    pub fn grid_hinges(&self) -> Material {
        if self.bending_weft == self.bending && self.bending_bias == self.bending {
            return *self;
        }
        let [a, b, c] = HINGE_SHARES;
        let (r_warp, r_weft) = (
            self.bending - b * self.bending_bias,
            self.bending_weft - b * self.bending_bias,
        );
        let det = a * a - c * c;
        let k_warp = (a * r_warp - c * r_weft) / det;
        let k_weft = (a * r_weft - c * r_warp) / det;
        Material {
            bending: k_warp.max(0.1 * self.bending),
            bending_weft: k_weft.max(0.1 * self.bending_weft),
            ..*self
        }
    }

    /// Checks every value is finite and positive.
    pub fn validate(&self) -> Result<(), ParamError> {
        for (name, value) in [
            ("density", self.density),
            ("stretch", self.stretch),
            ("shear", self.shear),
            ("bending", self.bending),
            ("stretch_weft", self.stretch_weft),
            ("bending_weft", self.bending_weft),
            ("bending_bias", self.bending_bias),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ParamError {
                    name: format!("material.{name}"),
                    value,
                    expected: "finite and > 0",
                });
            }
        }
        Ok(())
    }

    /// Per-constraint stiffness of each family on `mesh` (see the module documentation).
    pub fn stiffness(&self, mesh: &ClothMesh) -> MaterialStiffness {
        let p = &mesh.positions;
        let area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        };
        let mut beside: HashMap<(u32, u32), f64> = HashMap::new();
        for t in &mesh.triangles {
            let at = area(t);
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *beside.entry((a.min(b), a.max(b))).or_default() += at;
            }
        }
        let len2 = |a: u32, b: u32| p[a as usize].distance_squared(p[b as usize]);
        let e_edges = if mesh.shear.is_empty() {
            self.stretch
        } else {
            // At least a tenth of E, where a knit's G rivals its E.
            (self.stretch - self.shear).max(0.1 * self.stretch)
        };
        let stretch: Vec<f64> = mesh
            .stretch
            .iter()
            .filter_map(|&[a, b]| {
                let at = beside.get(&(a.min(b), a.max(b)))?;
                Some(e_edges * at / len2(a, b))
            })
            .collect();
        let cell = match mesh.grid {
            Some((nx, ny)) if nx > 1 && ny > 1 => {
                mesh.triangles.iter().map(area).sum::<f64>() / ((nx - 1) * (ny - 1)) as f64
            }
            // Cut from a grid (`ClothMesh::cut_disc`): two triangles a cell, as inside it.
            None if !mesh.shear.is_empty() => {
                2.0 * median(mesh.triangles.iter().map(area).collect()).unwrap_or(0.0)
            }
            _ => 0.0,
        };
        let shear: Vec<f64> = mesh
            .shear
            .iter()
            .filter(|_| cell > 0.0)
            .map(|&[a, b]| self.shear * len2(a, b) / (2.0 * cell))
            .collect();
        let topo = Topology::new(&mesh.triangles);
        let bending: Vec<f64> = topo
            .wings
            .iter()
            .filter_map(|w| {
                let [a, b] = w.edge;
                let ae = beside.get(&(a.min(b), a.max(b)))?;
                Some(HINGE_RELAXATION * self.bending * len2(a, b) / ae)
            })
            .collect();
        MaterialStiffness {
            stretch: median(stretch),
            shear: median(shear),
            bending: median(bending),
            isometric: (!topo.wings.is_empty()).then_some(HINGE_RELAXATION * self.bending),
        }
    }

    /// Constraint parameters of every method for `mesh` stepped with `settings`, starting from
    /// `base` (its tether family and damping values are kept).
    pub fn params(&self, mesh: &ClothMesh, settings: &Settings, base: &ClothParams) -> ClothParams {
        let hinged = if mesh.grid.is_some() {
            self.grid_hinges()
        } else {
            *self
        };
        // Each direction's per-constraint stiffness; weft and bias become ratios to the warp's.
        let [k, weft, bias] = crate::Direction::ALL.map(|d| hinged.along(d).stiffness(mesh));
        let ratio = |of: fn(&MaterialStiffness) -> Option<f64>, d: &MaterialStiffness| match (
            of(d),
            of(&k),
        ) {
            (Some(a), Some(b)) if b > 0.0 && a > 0.0 => a / b,
            _ => 1.0,
        };
        let anisotropy = |of: fn(&MaterialStiffness) -> Option<f64>| Anisotropy {
            weft: ratio(of, &weft),
            bias: ratio(of, &bias),
        };
        let h = settings.h();
        let n = f64::from(settings.iterations.max(1));
        let w: Vec<f64> = mesh
            .masses
            .iter()
            .map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 })
            .collect();
        let rest_dihedral = rest_weights_dihedral(mesh, &w);
        let rest_isometric = median(
            isometric_hinges(mesh)
                .iter()
                .map(|(idx, shape)| shape.stiffness(idx.map(|i| w[i as usize])))
                .collect(),
        );
        let rest_distance = |pairs: &[[u32; 2]]| {
            median(
                pairs
                    .iter()
                    .map(|&[a, b]| w[a as usize] + w[b as usize])
                    .collect(),
            )
        };
        let mut out = *base;
        let mut set = |family: Family, k: Option<f64>, s: Option<f64>| {
            let p = out.get_mut(family);
            let Some(k) = k else {
                p.enabled = false;
                return;
            };
            p.enabled = true;
            p.spring_stiffness = k;
            p.compliance = if k > 0.0 { 1.0 / k } else { f64::MAX };
            let s = s.unwrap_or(0.0);
            let f = if k > 0.0 {
                s / (s + 1.0 / (k * h * h))
            } else {
                0.0
            };
            p.pbd_stiffness = (1.0 - (1.0 - f).powf(1.0 / n)).clamp(0.0, 1.0);
        };
        set(Family::Stretch, k.stretch, rest_distance(&mesh.stretch));
        set(Family::Shear, k.shear, rest_distance(&mesh.shear));
        set(Family::BendDistance, None, None);
        // Soft only where the stiffest direction is.
        let stiffest = [k.isometric, weft.isometric, bias.isometric]
            .into_iter()
            .flatten()
            .reduce(f64::max);
        let soft = match (stiffest, rest_isometric) {
            (Some(b), Some(s)) => 1.0 / (b * h * h) >= s,
            _ => false,
        };
        if soft {
            set(Family::BendDihedral, None, None);
            set(Family::BendIsometric, k.isometric, rest_isometric);
        } else {
            set(Family::BendDihedral, k.bending, rest_dihedral);
            set(Family::BendIsometric, None, None);
        }
        out.anisotropy[Family::Stretch.index()] = anisotropy(|m| m.stretch);
        out.anisotropy[Family::Shear.index()] = Anisotropy::ISOTROPIC;
        out.anisotropy[Family::BendDihedral.index()] = anisotropy(|m| m.bending);
        out.anisotropy[Family::BendIsometric.index()] = anisotropy(|m| m.isometric);
        out
    }
}

/// Per-constraint stiffness of a material on one mesh (median over each family).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialStiffness {
    /// Stretch springs (N/m); `None` without such constraints.
    pub stretch: Option<f64>,
    /// Shear springs (N/m).
    pub shear: Option<f64>,
    /// Dihedral springs (N·m/rad).
    pub bending: Option<f64>,
    /// Isometric bending stiffness, [`HINGE_RELAXATION`] B (N·m); `None` without interior
    /// edges.
    pub isometric: Option<f64>,
}

/// Every interior edge's particles `[wing_a, wing_b, edge_0, edge_1]` and isometric shape at
/// rest (degenerate hinges left out, as the solver builder leaves them out).
fn isometric_hinges(mesh: &ClothMesh) -> Vec<([u32; 4], Isometric)> {
    let topo = Topology::new(&mesh.triangles);
    let p = &mesh.positions;
    topo.wings
        .iter()
        .filter_map(|wing| {
            let idx = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
            Some((idx, Isometric::at_rest(&idx.map(|i| p[i as usize]))?))
        })
        .collect()
}

/// Median of Σ wᵢ |∇ᵢθ|² over the dihedral constraints at rest.
fn rest_weights_dihedral(mesh: &ClothMesh, w: &[f64]) -> Option<f64> {
    let topo = Topology::new(&mesh.triangles);
    let p = &mesh.positions;
    median(
        topo.wings
            .iter()
            .filter_map(|wing| {
                let idx = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
                let pos: [DVec3; 4] = idx.map(|i| p[i as usize]);
                let rest = Dihedral::angle(&pos)?;
                let (_, g) = Dihedral { rest }.evaluate(&pos)?;
                Some(
                    (0..4)
                        .map(|k| w[idx[k] as usize] * g[k].length_squared())
                        .sum(),
                )
            })
            .collect(),
    )
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GridDesc, Mass};

    const CLOTH: Material = Material::isotropic(0.2, 1000.0, 50.0, 1e-5);

    fn grid(n: usize, size: (f64, f64)) -> ClothMesh {
        GridDesc {
            resolution: (n, n),
            size,
            mass: Mass::Density(0.2),
            ..GridDesc::default()
        }
        .build()
        .expect("grid")
    }

    #[test]
    fn spring_constants_do_not_depend_on_resolution_but_bending_is_per_edge() {
        for n in [8, 16, 64] {
            let k = CLOTH.stiffness(&grid(n, (1.0, 1.0)));
            let (s, g, b) = (
                k.stretch.expect("edges"),
                k.shear.expect("diagonals"),
                k.bending.expect("hinges"),
            );
            assert!((s - 950.0).abs() < 1e-9, "n = {n}: stretch {s}");
            assert!((g - 50.0).abs() < 1e-9, "n = {n}: shear {g}");
            // k_θ = 5/4 B |e|²/A_e = 5/4 B on square cells' grid lines.
            assert!((b - 1.25e-5).abs() < 1e-15, "n = {n}: bending {b}");
        }
    }

    #[test]
    fn grid_hinges_give_each_strip_its_own_bending() {
        assert_eq!(CLOTH.grid_hinges(), CLOTH);
        let m = Material {
            bending_weft: 2e-5,
            bending_bias: 1.5e-5,
            ..CLOTH
        };
        let k = m.grid_hinges();
        let [a, b, c] = HINGE_SHARES;
        assert!((a + b + c - 1.0).abs() < 1e-12);
        let warp = a * k.bending + b * k.bending_bias + c * k.bending_weft;
        let weft = a * k.bending_weft + b * k.bending_bias + c * k.bending;
        assert!((warp - 1e-5).abs() < 1e-18 && (weft - 2e-5).abs() < 1e-18);
        assert_eq!(k.bending_bias, 1.5e-5);
        // Past what the shares can hold, each hinge keeps a tenth of its target.
        let extreme = Material {
            bending_weft: 1e-3,
            ..CLOTH
        };
        assert_eq!(extreme.grid_hinges().bending, 0.1 * 1e-5);
    }

    #[test]
    fn rectangular_cells_keep_the_shear_modulus() {
        // Cells twice as wide as tall: every diagonal gets G d²/(2A). (The grid lines get
        // (E−G)·Ly/Lx and (E−G)·Lx/Ly; one value per family can hold only one of them, which is
        // why square cells are the ones that keep E exactly.)
        let k = CLOTH.stiffness(&grid(9, (2.0, 1.0)));
        let (lx, ly) = (0.25, 0.125);
        let shear = k.shear.expect("diagonals");
        assert!((shear - 50.0 * (lx * lx + ly * ly) / (2.0 * lx * ly)).abs() < 1e-9);
    }

    #[test]
    fn xpbd_gets_inverse_stiffness_and_pbd_the_same_fraction_per_substep() {
        let mesh = grid(16, (1.0, 1.0));
        let s1 = Settings {
            iterations: 1,
            ..Settings::default()
        };
        let p1 = CLOTH.params(&mesh, &s1, &ClothParams::default());
        let st = p1.get(Family::Stretch);
        assert!((st.compliance * st.spring_stiffness - 1.0).abs() < 1e-12);
        // Soft per substep (1/(B h²) ≫ Σ w|∇C|²): isometric bending of stiffness B.
        assert!(!p1.get(Family::BendDistance).enabled && !p1.get(Family::BendDihedral).enabled);
        let bend = p1.get(Family::BendIsometric);
        assert!(bend.enabled && (bend.compliance * 1.25e-5 - 1.0).abs() < 1e-12);
        assert_eq!(bend.spring_stiffness, 1.25e-5);
        // A board-stiff fabric on a fine, light grid is stiff per substep: the dihedral.
        let board = Material::isotropic(0.2, 1000.0, 50.0, 1.0);
        let fine = board.params(&grid(64, (0.1, 0.1)), &s1, &ClothParams::default());
        assert!(fine.get(Family::BendDihedral).enabled && !fine.get(Family::BendIsometric).enabled);
        // More iterations: a smaller k per projection, the same fraction per substep.
        let s4 = Settings {
            iterations: 4,
            ..Settings::default()
        };
        let p4 = CLOTH.params(&mesh, &s4, &ClothParams::default());
        let (k1, k4) = (st.pbd_stiffness, p4.get(Family::Stretch).pbd_stiffness);
        assert!(k4 < k1);
        assert!(((1.0 - (1.0 - k4).powi(4)) - k1).abs() < 1e-12);
    }
}
