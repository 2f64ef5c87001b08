//! A long strip falls onto the ground and folds onto itself: layers stay a thickness apart and
//! nothing crosses the ground.

mod common;

use weft_collide::scenarios::self_fold;
use weft_solver::Method;

#[test]
fn folded_strip_keeps_layers_apart_and_stays_above_ground() {
    let (columns, rows) = (10, 30);
    for method in Method::ALL {
        let (mut solver, mut world) = self_fold(method, columns, rows).expect("scenario builds");
        let thickness = solver.cloths()[0].thickness;
        let tolerance = 0.1 * thickness;
        let mut lowest = f64::INFINITY;
        let rest = solver.particles().positions.clone();
        common::run(&mut solver, &mut world, 150, |_, p| {
            for x in &p.positions {
                lowest = lowest.min(x.y);
            }
        });
        let p = solver.particles();
        let n = p.len() as u32;
        // Every pair the self-collision is meant to separate by a full thickness.
        let mut closest = f64::INFINITY;
        let mut touching = 0;
        let mut far_in_rest = 0;
        for a in 0..n {
            for b in a + 1..n {
                let Some(Some(target)) = world.self_collision_target(a, b) else {
                    continue; // exempt: near each other along the cloth
                };
                assert_eq!(target, thickness, "({a}, {b})");
                let d = p.positions[a as usize].distance(p.positions[b as usize]);
                closest = closest.min(d);
                if d < 1.5 * thickness {
                    touching += 1;
                    // Folded layers: far apart along the cloth, touching in space.
                    if rest[a as usize].distance(rest[b as usize]) > 4.0 * thickness {
                        far_in_rest += 1;
                    }
                }
            }
        }
        let height = p.positions.iter().map(|x| x.y).fold(f64::MIN, f64::max);
        println!(
            "{method}: thickness {thickness:.4} m; closest non-neighbour pair {closest:.4} m; \
             {touching} pairs within 1.5 thickness, {far_in_rest} of them folded layers; lowest particle {lowest:.4} m; top {height:.3} m; \
             KE {:.2e} J; stats {:?}",
            p.kinetic_energy(),
            world.stats()
        );
        assert!(
            lowest >= thickness - tolerance,
            "{method}: a particle reached y = {lowest} (ground at 0, thickness {thickness})"
        );
        assert!(
            closest >= thickness - tolerance,
            "{method}: two non-neighbour particles are {closest} m apart (thickness {thickness})"
        );
        // It did fold: the strip lies low and many distant-at-rest pairs touch.
        assert!(height < 0.3, "{method}: strip still stands {height} m tall");
        assert!(
            far_in_rest > 20,
            "{method}: only {far_in_rest} pairs far apart at rest touch: no fold"
        );
    }
}
