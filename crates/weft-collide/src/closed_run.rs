//! The push-out and friction of a still half-space or ball (a [`Surface`] that does not move
//! during the substep) for a run of particles side by side:
//! struct-of-arrays, a block of [`LANES`] particles per step, every branch a select, so the
//! compiler keeps a block in vector registers. Each particle's arithmetic is that of the
//! reach test and `resolve_one` (closest point, push to the thickness, Coulomb friction),
//! operation for operation and in the same order, so the bits are the same; a particle
//! changes only if the scalar path would have moved it.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use multiversion::multiversion;
use weft_solver::{Contacts, SimdPath};

use crate::analytic::TINY;
use crate::collider::Collider;
use crate::friction::{Friction, push_lanes};
use crate::reach::{BALL_SLACK, Reach, Surface};

/// Particles per block: eight f64, one AVX-512 register or two AVX2 ones.
const LANES: usize = 8;

/// `c`'s surface, if its reach at the current pose is a half-space or ball and it does not move
/// during the substep: what [`resolve_still`] takes.
pub(crate) fn still_surface(c: &Collider, reach: &Reach) -> Option<Surface> {
    match *reach {
        Reach::Surface(s) if c.poses64().2 => Some(s),
        _ => None,
    }
}

/// A run of consecutive particles, struct-of-arrays, as `resolve_still` moves them.
pub(crate) struct Run<'a> {
    /// Positions per axis, moved in place.
    pub x: [&'a mut [f64]; 3],
    /// Positions at the substep's start, per axis.
    pub prev: [&'a [f64]; 3],
    /// Inverse masses: a pinned particle (0) is left alone.
    pub w: &'a [f64],
    /// Thickness of each particle (m).
    pub r: &'a [f64],
}

/// Pushes every free particle of `run` within its thickness of `surface` out to that distance
/// and applies `friction` against the still surface; returns the contacts and the deepest.
/// Compiled for kernel path `path` (the solver's: every path gives the same bits).
pub(crate) fn resolve_still(
    surface: Surface,
    friction: Friction,
    run: Run<'_>,
    path: SimdPath,
) -> Contacts {
    match path {
        SimdPath::Avx512 => run_avx512(surface, friction, run),
        SimdPath::Avx2 => run_avx2(surface, friction, run),
        SimdPath::Neon => run_neon(surface, friction, run),
        SimdPath::Scalar => run_scalar(surface, friction, run),
    }
}

/// [`resolve_still`] compiled for AVX-512 (the baseline build where the CPU lacks it).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx512dq+avx2+fma"))]
fn run_avx512<'a>(surface: Surface, friction: Friction, run: Run<'a>) -> Contacts {
    run_body(surface, friction, run)
}

/// [`resolve_still`] compiled for AVX2 and FMA.
#[multiversion(targets("x86_64+avx2+fma"))]
fn run_avx2<'a>(surface: Surface, friction: Friction, run: Run<'a>) -> Contacts {
    run_body(surface, friction, run)
}

/// [`resolve_still`] compiled for NEON.
#[multiversion(targets("aarch64+neon"))]
fn run_neon<'a>(surface: Surface, friction: Friction, run: Run<'a>) -> Contacts {
    run_body(surface, friction, run)
}

/// [`resolve_still`] compiled for the baseline target.
#[inline(never)]
fn run_scalar(surface: Surface, friction: Friction, run: Run<'_>) -> Contacts {
    run_body(surface, friction, run)
}

#[inline(always)]
fn run_body(surface: Surface, friction: Friction, run: Run<'_>) -> Contacts {
    let Run { x, prev, w, r } = run;
    let n = w.len();
    let [x0, x1, x2] = x;
    let x = [&mut x0[..n], &mut x1[..n], &mut x2[..n]];
    let prev = [&prev[0][..n], &prev[1][..n], &prev[2][..n]];
    let r = &r[..n];
    let mut total = Contacts::default();
    let full = n - n % LANES;
    for s in (0..full).step_by(LANES) {
        let mut xb = [[0.0; LANES]; 3];
        let mut pb = [[0.0; LANES]; 3];
        for a in 0..3 {
            xb[a].copy_from_slice(&x[a][s..s + LANES]);
            pb[a].copy_from_slice(&prev[a][s..s + LANES]);
        }
        let wb: [f64; LANES] = std::array::from_fn(|l| w[s + l]);
        let rb: [f64; LANES] = std::array::from_fn(|l| r[s + l]);
        let tally = block(&surface, friction, &mut xb, &pb, &wb, &rb);
        if tally.contacts > 0 {
            for a in 0..3 {
                x[a][s..s + LANES].copy_from_slice(&xb[a]);
            }
        }
        total = total.merge(tally);
    }
    for i in full..n {
        let mut xb = [[x[0][i]], [x[1][i]], [x[2][i]]];
        let pb = [[prev[0][i]], [prev[1][i]], [prev[2][i]]];
        total = total.merge(block(&surface, friction, &mut xb, &pb, &[w[i]], &[r[i]]));
        for a in 0..3 {
            x[a][i] = xb[a][0];
        }
    }
    total
}

/// One block of `L` particles: positions `x` moved in place; returns the contacts and the
/// deepest (0 when none; nothing is swept).
#[inline(always)]
fn block<const L: usize>(
    surface: &Surface,
    friction: Friction,
    x: &mut [[f64; L]; 3],
    prev: &[[f64; L]; 3],
    w: &[f64; L],
    r: &[f64; L],
) -> Contacts {
    // The closest point's signed distance and normal, and whether the reach test and the
    // closed form's distance test both pass (`Reach::may_touch`, `Analytic::closest`).
    let mut distance = [0.0; L];
    let mut normal = [[0.0; L]; 3];
    let mut near = [false; L];
    match *surface {
        Surface::Plane { n, at } => {
            for l in 0..L {
                // n · (x − at), glam's dot order.
                let d = n.x * (x[0][l] - at.x) + n.y * (x[1][l] - at.y) + n.z * (x[2][l] - at.z);
                distance[l] = d;
                near[l] = d <= r[l];
                for a in 0..3 {
                    normal[a][l] = n[a];
                }
            }
        }
        Surface::Ball {
            centre,
            radius,
            pole,
        } => {
            for l in 0..L {
                let v = [x[0][l] - centre.x, x[1][l] - centre.y, x[2][l] - centre.z];
                let len2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                let reach = (radius + r[l]) * (1.0 + BALL_SLACK);
                let len = len2.sqrt();
                let d = len - radius;
                distance[l] = d;
                near[l] = len2 <= reach * reach && d <= r[l];
                let inner = len > TINY;
                for a in 0..3 {
                    normal[a][l] = if inner { v[a] / len } else { pole[a] };
                }
            }
        }
    }
    // Each step a loop of its own over the lanes, every branch a select: the compiler
    // vectorises each.
    let mut depth = [0.0; L];
    let mut push = [false; L];
    for l in 0..L {
        depth[l] = r[l] - distance[l];
        push[l] = (w[l] != 0.0) & near[l] & (depth[l] > 1e-6 * r[l].max(1e-3));
    }
    if !push.contains(&true) {
        return Contacts::default();
    }
    // Pushed out along the normal, then friction on the slip since the substep's start
    // relative to the still surface.
    let [n0, n1, n2] = &normal;
    (*x, _) = push_lanes(friction, x, prev, [n0, n1, n2], &depth, &push);
    let mut tally = Contacts::default();
    for l in 0..L {
        if push[l] {
            tally.contacts += 1;
            tally.depth = tally.depth.max(depth[l]);
        }
    }
    tally
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::collider::ColliderDesc;
    use crate::shape::ShapeDesc;
    use crate::test_rand::rand;
    use crate::world::resolve_one;

    /// Positions, previous positions (per axis), inverse masses and thicknesses of a run.
    type Particles = ([Vec<f64>; 3], [Vec<f64>; 3], Vec<f64>, Vec<f64>);

    /// Particles about `c`'s surface: at random in a box around it, and placed along the
    /// normal between 2r inside and 2r outside, some at rest (no slip), some pinned, one at a
    /// ball's centre; thickness about 1 cm.
    fn particles(c: &Collider, n: usize, seed: u64) -> Particles {
        let mut state = seed;
        let (mut x, mut prev) = ([(); 3].map(|_| Vec::new()), [(); 3].map(|_| Vec::new()));
        let (mut w, mut r) = (Vec::new(), Vec::new());
        for i in 0..n {
            let ri = 0.005 + 0.01 * rand(&mut state);
            let random = DVec3::new(rand(&mut state), rand(&mut state), rand(&mut state));
            let mut xi = random * 1.2;
            if i % 3 != 0 {
                let s = c
                    .closest(xi, f64::INFINITY)
                    .expect("closed-form shapes answer");
                xi = s.point + s.normal * (2.0 * ri * rand(&mut state));
            }
            if i == 17 {
                xi = c.poses64().0.translation;
            }
            let motion = DVec3::new(rand(&mut state), rand(&mut state), rand(&mut state));
            let pi = if i % 5 == 0 { xi } else { xi - motion * 0.02 };
            for a in 0..3 {
                x[a].push(xi[a]);
                prev[a].push(pi[a]);
            }
            w.push(if i % 7 == 0 { 0.0 } else { 1.0 });
            r.push(ri);
        }
        (x, prev, w, r)
    }

    #[test]
    fn a_run_moves_each_particle_as_the_one_particle_path_does_bit_for_bit() {
        let tilted = DQuat::from_rotation_z(0.3) * DQuat::from_rotation_x(-0.7);
        let shapes = [
            ShapeDesc::HalfSpace {
                normal: DVec3::new(0.2, 1.0, -0.1).normalize(),
            },
            ShapeDesc::Sphere { radius: 0.4 },
        ];
        let frictions = [
            Friction::new(0.8, 0.6),
            Friction::new(0.0, 0.0),
            Friction::new(3.0, 2.0),
        ];
        for (k, shape) in shapes.into_iter().enumerate() {
            for friction in frictions {
                let desc = ColliderDesc::new(shape.clone())
                    .at(DVec3::new(0.1, -0.2, 0.3))
                    .rotated(tilted)
                    .with_friction(friction);
                let c = Collider::new(&desc).expect("valid collider");
                let reach = Reach::of(&c, None);
                let surface = still_surface(&c, &reach).expect("a still plane or ball");
                // 1003: full blocks and a remainder.
                let (x, prev, w, r) = particles(&c, 1003, 11 + k as u64);
                let (mut expected, mut contacts, mut deepest) = (x.clone(), 0, 0.0f64);
                for i in 0..w.len() {
                    let mut p = DVec3::new(x[0][i], x[1][i], x[2][i]);
                    let before = DVec3::new(prev[0][i], prev[1][i], prev[2][i]);
                    if w[i] != 0.0 && reach.may_touch(p, r[i]) {
                        let (n, depth) = resolve_one(&c, false, before, &mut p, r[i]);
                        contacts += n;
                        deepest = deepest.max(depth);
                    }
                    for a in 0..3 {
                        expected[a][i] = p[a];
                    }
                }
                for path in [
                    SimdPath::Avx512,
                    SimdPath::Avx2,
                    SimdPath::Neon,
                    SimdPath::Scalar,
                ] {
                    let mut x = x.clone();
                    let [x0, x1, x2] = &mut x;
                    let run = Run {
                        x: [x0, x1, x2],
                        prev: [&prev[0], &prev[1], &prev[2]],
                        w: &w,
                        r: &r,
                    };
                    let total = resolve_still(surface, friction, run, path);
                    for a in 0..3 {
                        let same = (x[a].iter().zip(&expected[a]))
                            .all(|(p, q)| p.to_bits() == q.to_bits());
                        assert!(same, "{shape:?}, {friction:?}, {path:?}: axis {a} differs");
                    }
                    assert_eq!(total.contacts, contacts, "{shape:?}, {path:?}");
                    assert_eq!(total.depth.to_bits(), deepest.to_bits(), "{shape:?}");
                }
                // Some particles touched and some did not.
                assert!(contacts > 200 && contacts < 900, "{shape:?}: {contacts}");
            }
        }
    }

    #[test]
    fn only_still_planes_and_balls_take_the_run() {
        let moving = ColliderDesc::new(ShapeDesc::Sphere { radius: 0.4 })
            .moving(weft_solver::Motion::Linear { velocity: DVec3::X });
        let mut c = Collider::new(&moving).expect("valid");
        c.set_time(0.0, 0.01);
        assert_eq!(
            still_surface(&c, &Reach::of(&c, None)),
            None,
            "a moving ball"
        );
        let capsule = ColliderDesc::new(ShapeDesc::Capsule {
            half_height: 0.2,
            radius: 0.1,
        });
        let c = Collider::new(&capsule).expect("valid");
        assert_eq!(still_surface(&c, &Reach::of(&c, None)), None, "a capsule");
        let ball = ColliderDesc::new(ShapeDesc::Sphere { radius: 0.4 });
        let c = Collider::new(&ball).expect("valid");
        assert!(matches!(
            still_surface(&c, &Reach::of(&c, None)),
            Some(Surface::Ball { .. })
        ));
    }
}
