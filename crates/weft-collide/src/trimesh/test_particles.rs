//! Particles about a mesh, and positions per axis, for the block paths' tests.

use glam::DVec3;
use weft_solver::{Contacts, ParticleRun, SimdPath};

use super::MeshGeometry;
use crate::analytic_vs_parry::Rng;

/// Positions, per axis.
pub(crate) type Axes = [Vec<f64>; 3];

/// The nearest points of mesh `g` to `n` points spread over the square of half-width `half`
/// at height `y` above the origin, with the direction to each from its nearest point.
pub(crate) fn under(
    g: &MeshGeometry,
    rng: &mut Rng,
    n: usize,
    (half, y): (f64, f64),
) -> Vec<(DVec3, DVec3)> {
    (0..n)
        .map(|_| {
            let above = DVec3::new(
                2.0 * half * rng.next() - half,
                y,
                2.0 * half * rng.next() - half,
            );
            let p = g.nearest(above, f64::INFINITY).expect("nearest");
            (p.closest.point, p.normal)
        })
        .collect()
}

/// Particles about mesh `g`: near its surface on either side, on it, deep inside (one in
/// six), and far away (one in five), thickness `r`.
pub(crate) fn about(g: &MeshGeometry, rng: &mut Rng, n: usize, r: f64) -> Vec<DVec3> {
    (0..n)
        .map(|k| {
            if k % 5 == 0 {
                return rng.cube(1.5);
            }
            let dir = rng.cube(1.0).normalize_or(DVec3::Y);
            let p = g.nearest(dir, f64::INFINITY).expect("nearest");
            let h = if k % 6 == 0 { -3.0 } else { 2.5 * rng.next() };
            p.closest.point + p.normal * r * h
        })
        .collect()
}

/// `p` per axis.
pub(crate) fn axes(p: &[DVec3]) -> Axes {
    [0, 1, 2].map(|k| p.iter().map(|v| v[k]).collect())
}

/// The sum of `f(k, run)` over the runs `runs[k]` (first particle, end) of the particles at
/// `x` (moved in place), at `prev` at the substep's start, inverse masses `w`, kernel `path`.
pub(crate) fn over_runs(
    x: &mut Axes,
    (prev, w): (&Axes, &[f64]),
    runs: &[(usize, usize)],
    path: SimdPath,
    mut f: impl FnMut(usize, ParticleRun<'_>) -> Contacts,
) -> Contacts {
    let mut total = Contacts::default();
    for (k, &(s, e)) in runs.iter().enumerate() {
        let [x0, x1, x2] = x;
        let run = ParticleRun {
            start: s,
            x: [&mut x0[s..e], &mut x1[s..e], &mut x2[s..e]],
            prev: [0, 1, 2].map(|a| &prev[a][s..e]),
            w: &w[s..e],
            path,
        };
        total = total.merge(f(k, run));
    }
    total
}

/// Asserts that the positions `a` and `b` (per axis) and the totals `got` and `expected` agree
/// to the bit (`what` names the case).
pub(crate) fn assert_same_bits(
    a: &[DVec3],
    b: &Axes,
    (got, expected): (Contacts, Contacts),
    what: &str,
) {
    for (j, p) in a.iter().enumerate() {
        for k in 0..3 {
            assert_eq!(
                p[k].to_bits(),
                b[k][j].to_bits(),
                "{what}, particle {j}, axis {k}"
            );
        }
    }
    assert_eq!(got.contacts, expected.contacts, "{what}: contacts");
    assert_eq!(got.swept, expected.swept, "{what}: swept");
    assert_eq!(
        got.depth.to_bits(),
        expected.depth.to_bits(),
        "{what}: depth"
    );
}
