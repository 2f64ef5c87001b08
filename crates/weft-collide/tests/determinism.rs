//! Same scene, same result, bit for bit: twice in a row and with 1 or 2 worker threads.

use weft_collide::scenarios::self_fold;
use weft_solver::Method;
use weft_solver::glam::DVec3;

fn run() -> Vec<DVec3> {
    let (mut solver, mut world) = self_fold(Method::Xpbd, 10, 30).expect("scenario");
    for _ in 0..60 {
        solver.step_with(&mut world).expect("step");
    }
    solver.particles().positions.clone()
}

fn in_pool(threads: usize) -> Vec<DVec3> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(run)
}

#[test]
fn self_fold_is_bitwise_repeatable_across_thread_counts() {
    let a = in_pool(1);
    let b = in_pool(2);
    let c = run();
    assert!(
        a.iter().zip(&b).all(|(x, y)| x.to_array() == y.to_array()),
        "1 vs 2 threads differ"
    );
    assert!(
        a.iter().zip(&c).all(|(x, y)| x.to_array() == y.to_array()),
        "runs differ"
    );
}
