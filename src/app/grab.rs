//! Grabbing a cloth particle with the mouse: pick it along the cursor ray, hold it with
//! weft-sim's grab (the one Python's `Simulation.grab` uses) and drag it in the camera-facing
//! plane through the hit point.

use weft_solver::glam::DVec3;

use crate::app::picking::{Ray, pick, ray_plane};
use weft_sim::Simulation;

/// A particle held by the user.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grab {
    /// Scene cloth index.
    pub cloth: usize,
    /// Particle index within that cloth.
    pub particle: usize,
    /// The solver group holding the cloth.
    pub group: usize,
    /// Particle index in that group's solver.
    pub global: usize,
    /// A point of the drag plane (the hit point).
    pub plane_point: DVec3,
    /// The particle's offset from the hit point when grabbed (kept while dragging, so the
    /// particle does not jump to the cursor).
    pub offset: DVec3,
    /// The drag plane's normal (the camera's view direction).
    pub plane_normal: DVec3,
    /// Where the particle is being dragged to.
    pub target: DVec3,
}

impl Grab {
    /// Casts `ray` at every cloth; on a hit, grabs the hit triangle's vertex nearest the hit
    /// point. `view_dir` is the camera's forward direction (the drag plane's normal).
    pub fn start(sim: &mut Simulation, ray: &Ray, view_dir: DVec3) -> Option<Grab> {
        let (cloth, hit) = (0..sim.scene.cloths.len())
            .filter_map(|i| {
                let tris = &sim.scene.cloths[i].mesh.triangles;
                pick(ray, sim.cloth_positions(i), tris).map(|h| (i, h))
            })
            .min_by(|a, b| a.1.t.total_cmp(&b.1.t))?;
        let (group, global) = sim.grab(cloth, hit.particle).ok()?;
        let at = sim.cloth_positions(cloth)[hit.particle];
        Some(Grab {
            cloth,
            particle: hit.particle,
            group,
            global,
            plane_point: hit.point,
            offset: at - hit.point,
            plane_normal: view_dir,
            target: at,
        })
    }

    /// Moves the target to where `ray` meets the drag plane (kept if the ray misses it).
    pub fn drag(&mut self, sim: &mut Simulation, ray: &Ray) {
        if let Some(p) = ray_plane(ray, self.plane_point, self.plane_normal) {
            let target = p + self.offset;
            if sim.drag_to(target).is_ok() {
                self.target = target;
            }
        }
    }

    /// Lets go: the particle gets its mass back and keeps its drag velocity.
    pub fn release(self, sim: &mut Simulation) {
        sim.release();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::picking::Ray;

    /// A 5 × 5 vertical cloth (1 m, x ∈ [−0.5, 0.5], y ∈ [1, 2], z = 0), pinned on its top
    /// edge, no gravity: it stays flat unless dragged.
    const FLAT: &str = r#"
[sim]
dt = "1/60"
substeps = 10
gravity = [0.0, 0.0, 0.0]

[cloth.a]
resolution = [5, 5]
size = [1.0, 1.0]
center = [0.0, 1.5, 0.0]
mass = 0.25
pins = ["top"]
"#;

    fn sim(text: &str, method: &str) -> Simulation {
        let set = [format!("sim.method=\"{method}\"")
            .parse()
            .expect("override")];
        let scene =
            weft_scene::from_text("flat.toml", text, &set, &weft_scene::DirFiles(".".into()))
                .expect("scene");
        Simulation::new(scene).expect("solvers")
    }

    fn towards(from: DVec3, to: DVec3) -> Ray {
        Ray {
            origin: from,
            dir: to - from,
        }
    }

    #[test]
    fn a_ray_grabs_the_particle_nearest_the_hit_in_every_method() {
        for method in ["xpbd", "pbd", "mass-spring"] {
            let mut s = sim(FLAT, method);
            let x = s.cloth_positions(0).to_vec();
            // Aim a little off particle 12 (the centre) from in front.
            let aim = x[12] + DVec3::new(0.04, -0.03, 0.0);
            let ray = towards(aim + DVec3::new(0.3, 0.2, 3.0), aim);
            let g = Grab::start(&mut s, &ray, -DVec3::Z).expect("hits");
            assert_eq!((g.cloth, g.particle), (0, 12), "{method}");
            let solver = &s.groups[g.group].solver;
            assert_eq!(solver.grabbed().map(|(i, _)| i), Some(g.global));
            assert_eq!(solver.particles().inv_masses[g.global], 0.0);
            // A ray beside the cloth grabs nothing.
            let miss = towards(DVec3::new(2.0, 1.5, 3.0), DVec3::new(2.0, 1.5, 0.0));
            g.release(&mut s);
            assert_eq!(Grab::start(&mut s, &miss, -DVec3::Z), None);
        }
    }

    #[test]
    fn dragging_moves_the_particle_to_the_target_and_release_keeps_the_velocity() {
        for method in ["xpbd", "pbd", "mass-spring"] {
            let mut s = sim(FLAT, method);
            let eye = DVec3::new(0.0, 1.5, 3.0);
            let start = s.cloth_positions(0)[12];
            let (group, global) = s.locate(0, 12).expect("particle 12");
            let w = s.groups[group].solver.particles().inv_masses[global];
            assert!(w > 0.0);
            let mut g = Grab::start(&mut s, &towards(eye, start), -DVec3::Z).expect("hits");
            assert_eq!((g.group, g.global), (group, global));
            // Drag 0.2 m to the right in the plane z = 0 over one frame.
            let goal = start + DVec3::new(0.2, 0.0, 0.0);
            g.drag(&mut s, &towards(eye, goal));
            assert!((g.target - goal).length() < 1e-9, "{method}: {}", g.target);
            s.step().expect("steps");
            let at = s.cloth_positions(0)[12];
            assert!((at - goal).length() < 1e-6, "{method}: {at} vs {goal}");
            // Released: mass back, and it leaves with the speed of the last substep of the
            // drag, (0.2 m / 10 substeps) / (1/600 s) = 12 m/s along x.
            g.release(&mut s);
            let solver = &s.groups[0].solver;
            assert_eq!(solver.particles().inv_masses[g.global], w);
            assert_eq!(solver.grabbed(), None);
            let v = solver.particles().velocities[g.global];
            assert!(
                (v - DVec3::new(12.0, 0.0, 0.0)).length() < 1e-6,
                "{method}: {v}"
            );
        }
    }

    #[test]
    fn every_group_of_a_multi_method_scene_can_be_grabbed() {
        let text = format!(
            "{FLAT}\n[cloth.b]\nmethod = \"pbd\"\nresolution = [5, 5]\nsize = [1.0, 1.0]\ncenter = [3.0, 1.5, 0.0]\nmass = 0.25\npins = [\"top\"]\n"
        );
        let mut s = sim(&text, "xpbd");
        assert_eq!(s.groups.len(), 2);
        let target = s.cloth_positions(1)[6];
        let g = Grab::start(
            &mut s,
            &towards(target + DVec3::new(0.0, 0.0, 2.0), target),
            -DVec3::Z,
        )
        .expect("hits cloth b");
        assert_eq!((g.cloth, g.particle), (1, 6));
        assert_eq!(s.locate(1, 6), Some((g.group, g.global)));
        assert_eq!(
            s.groups[g.group].solver.grabbed().map(|(i, _)| i),
            Some(g.global)
        );
        let other = 1 - g.group;
        assert_eq!(s.groups[other].solver.grabbed(), None);
    }
}
