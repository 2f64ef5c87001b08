//! Same scene, same result, bit for bit: twice in a row and with 1 or 2 worker threads.

use weft_collide::scenarios::{self_fold, sphere_drop};
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

/// Sphere drop at 48² (2304 particles, so several parallel chunks of particle–collider
/// contacts): the same positions bit for bit with 1 and 4 worker threads.
fn sphere_drop_in_pool(threads: usize) -> (Vec<DVec3>, usize) {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(|| {
            let (mut solver, mut world) = sphere_drop(Method::Xpbd, 48).expect("scenario");
            let mut contacts = 0;
            for _ in 0..40 {
                contacts += solver.step_with(&mut world).expect("step").contacts;
            }
            (solver.particles().positions.clone(), contacts)
        })
}

#[test]
fn sphere_drop_is_bitwise_repeatable_across_thread_counts() {
    let (a, contacts) = sphere_drop_in_pool(1);
    let (b, _) = sphere_drop_in_pool(4);
    // The cloth must have reached the sphere, or there is nothing to compare.
    assert!(contacts > 1000, "only {contacts} contacts");
    assert!(
        a.iter().zip(&b).all(|(x, y)| x.to_array() == y.to_array()),
        "1 vs 4 threads differ"
    );
}

/// A cloth on the 20,480-triangle icosphere and one on the deforming ball (several chunks of
/// particles, candidate lists rebuilt in parallel): the same positions bit for bit with 1 and
/// 2 worker threads.
fn meshes_in_pool(threads: usize) -> (Vec<DVec3>, usize) {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(|| {
            let mut out = Vec::new();
            let mut contacts = 0;
            for build in [
                weft_collide::scenarios::icosphere_drop,
                weft_collide::scenarios::breathing_drop,
            ] {
                let (mut solver, mut world) = build(Method::Xpbd, 40).expect("scenario");
                for _ in 0..40 {
                    contacts += solver.step_with(&mut world).expect("step").contacts;
                }
                out.extend_from_slice(&solver.particles().positions);
            }
            (out, contacts)
        })
}

#[test]
fn mesh_contacts_are_bitwise_repeatable_across_thread_counts() {
    let (a, contacts) = meshes_in_pool(1);
    let (b, _) = meshes_in_pool(2);
    assert!(contacts > 1000, "only {contacts} contacts");
    assert!(
        a.iter().zip(&b).all(|(x, y)| x.to_array() == y.to_array()),
        "1 vs 2 threads differ"
    );
}
