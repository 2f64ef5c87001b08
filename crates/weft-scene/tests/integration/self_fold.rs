//! The shipped `self_fold.toml`: a towel on the floor is folded over onto itself by its pinned
//! edge; under every method the layers stay a thickness apart and nothing crosses the floor.

use crate::common;

use weft_solver::Method;

#[test]
fn the_shipped_towel_folds_with_layers_apart_and_stays_above_the_floor() {
    let path = common::scenes_dir().join("self_fold.toml");
    // 4 s, the edge 144° over. At 5 s the scene lays the pinned (kinematic) edge exactly onto
    // the far edge on the floor, squeezing the layers between pins and floor, which neither
    // gives way (0.017 m apart at 300 frames): the scene's motion, not self-collision.
    let frames = 240;
    for method in Method::ALL {
        let mut groups = common::with_method(&path, method, &[]);
        let g = &mut groups[0];
        let thickness = g.solver.cloths()[0].thickness;
        let tolerance = 0.1 * thickness;
        let rest = g.solver.particles().positions.clone();
        let mut lowest = f64::INFINITY;
        common::run_watched(g, frames, |_, p| {
            for x in &p.positions {
                lowest = lowest.min(x.y);
            }
        });
        let world = g.world.as_ref().expect("floor and self-collision");
        let p = g.solver.particles();
        let n = p.len() as u32;
        // Every pair the self-collision is meant to separate by a full thickness.
        let mut closest = f64::INFINITY;
        let mut far_in_rest = 0;
        for a in 0..n {
            for b in a + 1..n {
                let Some(Some(target)) = world.self_collision_target(a, b) else {
                    continue; // exempt: near each other along the cloth
                };
                assert_eq!(target, thickness, "({a}, {b})");
                let d = p.positions[a as usize].distance(p.positions[b as usize]);
                closest = closest.min(d);
                // Folded layers: far apart along the cloth, touching in space.
                if d < 1.5 * thickness && rest[a as usize].distance(rest[b as usize]) > 0.3 {
                    far_in_rest += 1;
                }
            }
        }
        println!(
            "{method}: thickness {thickness:.4} m; closest non-neighbour pair {closest:.4} m; \
             {far_in_rest} pairs of folded layers; lowest particle {lowest:.4} m; KE {:.2e} J",
            p.kinetic_energy()
        );
        assert!(
            lowest >= thickness - tolerance,
            "{method}: a particle reached y = {lowest} (floor at 0, thickness {thickness})"
        );
        assert!(
            closest >= thickness - tolerance,
            "{method}: two non-neighbour particles are {closest} m apart (thickness {thickness})"
        );
        assert!(
            far_in_rest > 100,
            "{method}: only {far_in_rest} pairs 0.3 m apart at rest touch: no fold"
        );
    }
}
