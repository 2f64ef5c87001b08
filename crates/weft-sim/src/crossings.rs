//! Cloth crossings measured on a scene's solvers: how many mesh edges pass through a triangle
//! they share no vertex with, and how close non-adjacent elements come, by weft-collide's
//! independent count ([`weft_collide::crossings::measure`]), which shares nothing with contact.
//!
//! Cloths of one solver share its particle store and meet only each other, so each solver's
//! cloths are measured together (crossings between them count) and the solvers' counts are
//! summed. A garment's seams join vertices that are distinct particles: from the start, each
//! seam's particles are one vertex for adjacency (the sewn mesh), each measured where it is, so
//! the two sides of a seam, which pass each other's neighbours as the seam closes, are neither
//! "crossings" nor a "closest approach" of zero.

use std::fmt;

use weft_collide::crossings::{measure, measure_joined};
use weft_scene::{Scene, SolverGroup};
use weft_solver::glam::DVec3;

/// The reach of the closest approach, in multiples of the largest cloth thickness of a solver:
/// contact keeps non-adjacent elements a thickness apart, so a few thicknesses show how near
/// the layers come without counting the mesh's own spacing on every frame.
pub const REACH_THICKNESSES: f64 = 3.0;

/// The crossings of one frame, summed over the scene's solvers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CrossingStats {
    /// Edge–triangle crossings between elements that share no vertex.
    pub crossings: usize,
    /// The closest approach between non-adjacent elements (m), when below `reach`.
    pub closest: Option<f64>,
    /// How far the closest approach was looked for (m): [`REACH_THICKNESSES`] times the
    /// largest thickness of a measured solver's cloths.
    pub reach: f64,
}

/// One solver's mesh as it is measured: its triangles, each seam's particles one vertex.
#[derive(Clone, Debug)]
pub(crate) struct SolverMesh {
    mesh: Measured,
}

/// Triangles over the solver's particles, with each particle's vertex (the smallest particle
/// its seams join it to; itself without seams).
#[derive(Clone, Debug)]
struct Measured {
    vertex: Vec<u32>,
    triangles: Vec<[u32; 3]>,
}

impl Measured {
    /// The mesh of `triangles` over `n` particles with each seam's particles as one vertex
    /// (each class of joined particles named by its smallest particle), each particle measured
    /// where it is: a seam that has opened a little neither makes nor hides a crossing.
    fn sewn(n: usize, triangles: &[[u32; 3]], seams: &[[u32; 2]]) -> Self {
        let mut rep: Vec<u32> = (0..n as u32).collect();
        for &[a, b] in seams {
            union(&mut rep, a, b);
        }
        Self {
            vertex: (0..n as u32).map(|v| find(&rep, v)).collect(),
            triangles: triangles.to_vec(),
        }
    }

    fn measure(&self, x: &[DVec3], reach: f64) -> weft_collide::crossings::Crossings {
        measure_joined(x, &self.triangles, &self.vertex, reach)
    }
}

impl SolverMesh {
    /// The mesh of `group`'s cloths, with the seams `scene` gives them.
    pub(crate) fn new(scene: &Scene, group: &SolverGroup) -> Self {
        let cloths = group.solver.cloths();
        let triangles: Vec<[u32; 3]> = cloths
            .iter()
            .flat_map(|c| c.triangles.iter().copied())
            .collect();
        let n = group.solver.particles().len();
        let mut seams = Vec::new();
        for (j, &i) in group.cloths.iter().enumerate() {
            let spec = &scene.cloths[i];
            let start = cloths[j].particles.start as u32;
            seams.extend(spec.seams.iter().map(|&[a, b]| [start + a, start + b]));
        }
        let mesh = Measured::sewn(n, &triangles, &seams);
        Self { mesh }
    }

    /// Measures `group`'s cloths at their present positions.
    pub(crate) fn measure(&self, group: &SolverGroup) -> CrossingStats {
        let thickest = group
            .solver
            .cloths()
            .iter()
            .map(|c| c.thickness)
            .fold(0.0, f64::max);
        let reach = REACH_THICKNESSES * thickest;
        let m = self
            .mesh
            .measure(&group.solver.particles().positions, reach);
        CrossingStats {
            crossings: m.crossings,
            closest: m.closest,
            reach,
        }
    }
}

fn find(rep: &[u32], mut v: u32) -> u32 {
    while rep[v as usize] != v {
        v = rep[v as usize];
    }
    v
}

fn union(rep: &mut [u32], a: u32, b: u32) {
    let (a, b) = (find(rep, a), find(rep, b));
    let (lo, hi) = (a.min(b), a.max(b));
    rep[hi as usize] = lo;
}

/// Sums the solvers' measures into one frame's statistics.
pub(crate) fn combine(parts: impl IntoIterator<Item = CrossingStats>) -> CrossingStats {
    parts
        .into_iter()
        .fold(CrossingStats::default(), |acc, s| CrossingStats {
            crossings: acc.crossings + s.crossings,
            closest: closer(acc.closest, s.closest),
            reach: acc.reach.max(s.reach),
        })
}

/// The closer of two closest approaches, either of which may be missing (nothing in reach).
pub fn closer(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// Whether cloth can meet cloth in `scene`: self-collision is on for some cloth, or a solver
/// holds two cloths or more. Only then are crossings measured by default.
pub fn cloth_meets_cloth(scene: &Scene, groups: &[SolverGroup]) -> bool {
    scene
        .self_collision
        .as_ref()
        .is_some_and(|s| !s.cloths.is_empty())
        || groups.iter().any(|g| g.cloths.len() >= 2)
}

/// Cloth that crosses itself or another cloth before anything has moved.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StartCrossing {
    /// The cloth.
    pub cloth: String,
    /// The other cloth, or `None` when the cloth crosses itself.
    pub other: Option<String>,
    /// Edge–triangle crossings between them.
    pub crossings: usize,
}

impl fmt::Display for StartCrossing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.other {
            None => write!(
                f,
                "cloth `{}` starts crossing itself ({} edge–triangle crossings)",
                self.cloth, self.crossings
            )?,
            Some(o) => write!(
                f,
                "cloths `{}` and `{o}` start crossing each other ({} edge–triangle crossings)",
                self.cloth, self.crossings
            )?,
        }
        f.write_str("; contact cannot undo a crossing it did not cause, the run goes on")
    }
}

/// Every cloth that crosses itself, and every pair of cloths of one solver that cross each
/// other, at the solvers' present positions (their start, before a first step). A pair's count
/// is the count of the two cloths measured together less each one's own.
pub fn start_crossings(scene: &Scene, groups: &[SolverGroup]) -> Vec<StartCrossing> {
    let mut found = Vec::new();
    for g in groups {
        let x = &g.solver.particles().positions;
        let cloths = g.solver.cloths();
        let own: Vec<usize> = cloths
            .iter()
            .map(|c| measure(x, &c.triangles, 0.0).crossings)
            .collect();
        let name = |j: usize| scene.cloths[g.cloths[j]].name.clone();
        for (j, &n) in own.iter().enumerate() {
            if n > 0 {
                found.push(StartCrossing {
                    cloth: name(j),
                    other: None,
                    crossings: n,
                });
            }
        }
        for a in 0..cloths.len() {
            for b in a + 1..cloths.len() {
                let both: Vec<[u32; 3]> = cloths[a]
                    .triangles
                    .iter()
                    .chain(&cloths[b].triangles)
                    .copied()
                    .collect();
                let n = measure(x, &both, 0.0)
                    .crossings
                    .saturating_sub(own[a] + own[b]);
                if n > 0 {
                    found.push(StartCrossing {
                        cloth: name(a),
                        other: Some(name(b)),
                        crossings: n,
                    });
                }
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Simulation;

    /// A 5 × 5 horizontal sheet `floor` (0.4 m, 0.1 m cells, at y = 1) and a one-cell vertical
    /// square `blade` (5 cm) through the cell [0, 0.1]² off every diagonal, no gravity: the
    /// blade's two upright sides and its diagonal each pierce one of the cell's triangles, and
    /// the cell's diagonal pierces the blade (at x = 0.05, off the blade's own diagonal): 4.
    fn pierced(extra: &str) -> Simulation {
        let text = format!(
            "[sim]\ndt = \"1/60\"\nsubsteps = 2\ngravity = [0.0, 0.0, 0.0]\n\n\
             [cloth.floor]\nresolution = [5, 5]\nsize = [0.4, 0.4]\norientation = \"horizontal\"\n\
             center = [0.0, 1.0, 0.0]\nmass = 0.1\n\n\
             [cloth.blade]\nresolution = [2, 2]\nsize = [0.05, 0.05]\norientation = \"vertical\"\n\
             center = [0.06, 0.995, 0.05]\nmass = 0.01\n{extra}"
        );
        let scene = weft_scene::from_text(
            "pierced.toml",
            &text,
            &[],
            &weft_scene::DirFiles(".".into()),
        )
        .expect("scene");
        Simulation::new(scene).expect("solvers")
    }

    #[test]
    fn a_cloth_through_another_is_counted_in_every_frame_and_warned_of_at_the_start() {
        let mut sim = pierced("");
        assert!(sim.measures_crossings(), "two cloths of one solver");
        assert_eq!(
            sim.start_crossings(),
            &[StartCrossing {
                cloth: "blade".into(),
                other: Some("floor".into()),
                crossings: 4,
            }]
        );
        let warning = sim.start_crossings()[0].to_string();
        assert!(
            warning.contains("`blade` and `floor`") && warning.contains("(4 edge–triangle"),
            "{warning}"
        );
        for _ in 0..3 {
            let s = sim.step().expect("steps");
            let c = s.crossings.expect("measured");
            assert_eq!(c.crossings, 4, "frame {}", s.frame);
            // Three times the thicker cloth's default 5 mm.
            assert_eq!(c.reach, 0.015);
            // The blade's upright side at x = 0.035 passes 0.015 / √2 from the cell's diagonal.
            let d = c.closest.expect("within reach");
            assert!(d > 0.0 && d <= 0.015 / 2f64.sqrt() + 1e-12, "{d}");
        }
        // Lifted clear of the floor: nothing crosses, and nothing comes within reach.
        let lifted: Vec<DVec3> = sim
            .cloth_positions(0)
            .iter()
            .map(|p| *p + DVec3::Y)
            .collect();
        sim.set_cloth_positions(0, &lifted).expect("finite");
        let c = sim.stats(0.0, 0).crossings.expect("measured");
        assert_eq!((c.crossings, c.closest), (0, None));
        sim.set_measure_crossings(false);
        assert_eq!(sim.stats(0.0, 0).crossings, None, "turned off");
    }

    #[test]
    fn crossings_are_measured_where_cloth_can_meet_cloth_or_when_asked() {
        let one = crate::tests::sim("xpbd", "[0.0, 0.0, 0.0]");
        assert!(!one.measures_crossings(), "one cloth, no self-collision");
        assert_eq!(one.stats(0.0, 0).crossings, None);
        assert!(one.start_crossings().is_empty());
        // Two cloths of different methods: two solvers, they never meet.
        let apart = pierced("method = \"pbd\"\n");
        assert!(!apart.measures_crossings());
        assert!(apart.start_crossings().is_empty(), "they never meet");
        let mut asked = crate::tests::sim("xpbd", "[0.0, 0.0, 0.0]");
        asked.set_measure_crossings(true);
        let c = asked.stats(0.0, 0).crossings.expect("asked for");
        assert_eq!(c.crossings, 0);
    }

    #[test]
    fn each_particle_is_measured_where_it_is() {
        // A flat triangle, a far triangle, and a small one whose corner 6 lies under the
        // first and is sewn to the far corner 3 (the seam still open): the small triangle's
        // two edges from 6 cross the first. Moving 6 onto its seam partner, as measuring the
        // joined vertex at one place would, hides both.
        let x = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(3.0, 1.0, 0.0),
            DVec3::new(0.2, 0.2, -0.02),
            DVec3::new(0.25, 0.2, 0.02),
            DVec3::new(0.3, 0.25, 0.02),
        ];
        let triangles = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]];
        let sewn = Measured::sewn(9, &triangles, &[[3, 6]]);
        assert_eq!(sewn.measure(&x, 0.0).crossings, 2);
        let mut moved = x.clone();
        moved[6] = moved[3];
        assert_eq!(sewn.measure(&moved, 0.0).crossings, 0);
    }

    #[test]
    fn the_two_sides_of_a_closed_seam_are_one_vertex() {
        // Two triangles sharing no particle, glued along an edge by a seam of two pairs, and
        // a stray particle 7 on nothing: open, the seam's sides coincide (closest approach 0);
        // sewn, the two are one quad over particles 0, 1, 2, 5 and nothing non-adjacent is
        // within reach.
        let mut x = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
        ];
        let triangles = vec![[0, 1, 2], [3, 5, 4]];
        let open = measure(&x, &triangles, 0.5);
        assert_eq!(open.closest, Some(0.0), "the seam's sides coincide");
        let sewn = Measured::sewn(6, &triangles, &[[3, 1], [2, 4]]);
        assert_eq!(sewn.vertex, [0, 1, 2, 1, 2, 5]);
        assert_eq!(sewn.measure(&x, 0.5).closest, None);
        assert_eq!(
            Measured::sewn(6, &triangles, &[[0, 5]])
                .measure(&x, 0.5)
                .closest,
            Some(0.0)
        );
        // A seam that collapses a triangle drops it: an upright triangle whose edge 3–4
        // pierces a small flat one, and which the flat one's edge 1–2 pierces, crosses it
        // twice until 3 and 4 are sewn.
        let pierce = [
            DVec3::new(0.45, 0.45, 0.0),
            DVec3::new(0.56, 0.45, 0.0),
            DVec3::new(0.45, 0.56, 0.0),
            DVec3::new(0.5, 0.5, -0.1),
            DVec3::new(0.5, 0.5, 0.1),
            DVec3::new(5.0, 5.0, 5.0),
        ];
        let both = [[0, 1, 2], [3, 4, 5]];
        assert_eq!(measure(&pierce, &both, 0.0).crossings, 2);
        let collapsed = Measured::sewn(6, &both, &[[3, 4]]);
        assert_eq!(collapsed.measure(&pierce, 0.0).crossings, 0);
        // Folded shut along the seam's diagonal, the sewn quad's far corner comes back 1 cm
        // over the first triangle's corner: within reach again (a hair under 1 cm, to the
        // slanted second triangle).
        x[5] = DVec3::new(0.0, 0.0, 0.01);
        let d = sewn.measure(&x, 0.5).closest.expect("folded");
        assert!(d > 0.0099 && d <= 0.01, "{d}");
    }
}
