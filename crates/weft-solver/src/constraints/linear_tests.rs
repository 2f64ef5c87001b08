//! Tests of the linearised springs: the rank-one shapes' weights against their own gradients
//! and Hessian products, and the rows the passes add up against a serial spring-by-spring
//! reference (the method's first, single-threaded form).

use glam::DVec3;

use super::*;
use crate::grid::{GridDesc, Orientation};
use crate::params::{ClothParams, Family};
use crate::settings::Settings;
use crate::test_rand::rng;
use crate::{Forces, SolverBuilder};

/// A 10² grid with every family `bending` allows (tethers, both in-plane families, bend
/// distance, and `bending`), crumpled and moving at random, with its state: constraints,
/// family parameters, positions, velocities.
pub(crate) fn crumpled(
    bending: Family,
) -> (ConstraintSet, Vec<FamilyParams>, Vec<DVec3>, Vec<DVec3>) {
    stretched(bending, 0.02, 10)
}

/// An `n`² grid as [`crumpled`]'s, stretched by 30 % and moved by up to `noise` (0: flat).
pub(crate) fn stretched(
    bending: Family,
    noise: f64,
    n: usize,
) -> (ConstraintSet, Vec<FamilyParams>, Vec<DVec3>, Vec<DVec3>) {
    let mesh = GridDesc {
        resolution: (n, n),
        orientation: Orientation::Horizontal,
        ..GridDesc::default()
    }
    .build()
    .expect("grid");
    let mut params = ClothParams::default();
    for (j, f) in [
        Family::Stretch,
        Family::Shear,
        Family::BendDistance,
        Family::Tether,
        bending,
    ]
    .into_iter()
    .enumerate()
    {
        let p = params.get_mut(f);
        p.enabled = true;
        p.spring_stiffness = 100.0 * (j + 1) as f64;
        p.spring_damping = 0.5 * j as f64;
    }
    let settings = Settings {
        method: crate::Method::ImplicitMassSpring,
        ..Settings::default()
    };
    let mut b = SolverBuilder::new(settings, Forces::default()).expect("settings");
    b.add_cloth("c", &mesh, params, 0.0).expect("cloth");
    let solver = b.build();
    let mut rnd = rng(0x3c6e_f372_fe94_f82b);
    let x: Vec<DVec3> = solver
        .particles()
        .positions
        .iter()
        // Stretched by 30 % about the origin (tethers taut) and crumpled.
        .map(|p| *p * 1.3 + DVec3::new(rnd(), rnd(), rnd()) * noise)
        .collect();
    let v: Vec<DVec3> = x.iter().map(|_| DVec3::new(rnd(), rnd(), rnd())).collect();
    let params = (solver.cloth_params(0).expect("one cloth"))
        .groups(settings.iterations)
        .to_vec();
    (solver.constraints().clone(), params, x, v)
}

/// Serial reference of a block: per spring, out += (a_k k + a_c c) ∇C(∇C·p) + a_k k C⁺ ∇²C p
/// (through [`Shape::curvature_product`]), and f += −(k C + c Ċ) ∇C.
#[allow(clippy::too_many_arguments)]
fn reference<const N: usize, S: Shape<N>>(
    block: &Block<N, S>,
    params: &[FamilyParams],
    x: &[DVec3],
    v: &[DVec3],
    (a_k, a_c): (f64, f64),
    p: &[DVec3],
    out: &mut [DVec3],
    f: &mut [DVec3],
) {
    for s in 0..block.particles.len() {
        let fp = &params[block.group[s] as usize];
        let idx = block.particles[s];
        let pos = idx.map(|i| x[i as usize]);
        let Some((c, grad)) = fp.enabled.then(|| block.shapes[s].evaluate(&pos)).flatten() else {
            continue;
        };
        let dp = idx.map(|i| p[i as usize]);
        let g_dot: f64 = (0..N).map(|k| grad[k].dot(dp[k])).sum();
        let c_dot: f64 = (0..N).map(|k| grad[k].dot(v[idx[k] as usize])).sum();
        let sk = (a_k * fp.spring_stiffness + a_c * fp.spring_damping) * g_dot;
        let hp = block.shapes[s].curvature_product(&pos, &dp);
        let force = -(fp.spring_stiffness * c + fp.spring_damping * c_dot);
        for k in 0..N {
            let mut add = grad[k] * sk;
            if c > 0.0 && fp.spring_stiffness > 0.0 {
                add += hp[k] * (a_k * fp.spring_stiffness * c);
            }
            out[idx[k] as usize] += add;
            f[idx[k] as usize] += grad[k] * force;
        }
    }
}

/// [`reference`] over every block: ((a_k K + a_c D) p, the spring forces).
pub(crate) fn reference_all(
    cs: &ConstraintSet,
    params: &[FamilyParams],
    x: &[DVec3],
    v: &[DVec3],
    a: (f64, f64),
    p: &[DVec3],
) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut out = vec![DVec3::ZERO; x.len()];
    let mut f = vec![DVec3::ZERO; x.len()];
    reference(&cs.distance, params, x, v, a, p, &mut out, &mut f);
    reference(&cs.dihedral, params, x, v, a, p, &mut out, &mut f);
    reference(&cs.isometric, params, x, v, a, p, &mut out, &mut f);
    reference(&cs.tethers, params, x, v, a, p, &mut out, &mut f);
    reference(&cs.seams, &cs.seam_params, x, v, a, p, &mut out, &mut f);
    (out, f)
}

fn close(a: DVec3, b: DVec3, scale: f64) -> bool {
    (a - b).length() <= 1e-11 * scale.max(1.0)
}

#[test]
fn rank_one_shapes_have_the_gradient_and_hessian_their_coefficients_give() {
    let mut rnd = rng(0x1234_5678_9abc_def1);
    let mut r3 = || DVec3::new(rnd(), rnd(), rnd());
    fn check<const N: usize, S: RankOne<N>>(s: S, p: [DVec3; N], dp: [DVec3; N]) {
        let a = s.coefficients();
        let u: DVec3 = (0..N).map(|m| p[m] * a[m]).sum();
        let (len, n) = (u.length(), u.normalize());
        let (c, grad) = s.evaluate(&p).expect("active");
        assert_eq!(s.value(len), Some(c), "C from ℓ");
        let want = s.curvature_product(&p, &dp);
        let du: DVec3 = (0..N).map(|m| dp[m] * a[m]).sum();
        let t = (du - n * n.dot(du)) / len;
        for k in 0..N {
            assert!((grad[k] - n * a[k]).length() < 1e-12, "∇C {k}");
            let got = t * a[k];
            assert!((want[k] - got).length() < 1e-12, "{k}: {} {got}", want[k]);
        }
    }
    for _ in 0..20 {
        let p2 = [r3(), r3()];
        let d2 = [r3(), r3()];
        check(Distance { rest: 0.1 }, p2, d2);
        check(Tether { max_length: 0.0 }, p2, d2);
        let slack = Tether { max_length: 100.0 };
        assert_eq!(slack.evaluate(&p2), None);
        assert_eq!(
            slack.value((p2[0] - p2[1]).length()),
            None,
            "a slack tether"
        );
        let seam = Seam {
            gap: 0.1,
            closing_time: 1.0,
            rest: 0.05,
        };
        check(seam, p2, d2);
        let p4 = [r3(), r3(), r3(), r3()];
        let d4 = [r3(), r3(), r3(), r3()];
        let iso = Isometric {
            weights: [1.0, 2.0, -1.25, -1.75],
        };
        check(iso, p4, d4);
    }
}

/// How the distance springs are linearised: by the general passes, or by stencil on a path.
#[derive(Clone, Copy, Debug)]
enum Passes {
    General,
    Stencil(SimdPath),
}

/// The springs linearised at (`x`, `v`) with warm start `x0` by `passes`: the springs and
/// each particle's row sums.
fn linearized(
    cs: &ConstraintSet,
    params: &[FamilyParams],
    (x, v, x0): (&[DVec3], &[DVec3], &[DVec3]),
    h: f64,
    passes: Passes,
) -> (Springs, Vec<RowSums>) {
    let mut springs = Springs::default();
    springs.order(cs, x.len());
    assert!(springs.stencil.is_some(), "a grid's springs form a stencil");
    let path = match passes {
        Passes::General => {
            springs.without_stencil();
            SimdPath::widest()
        }
        Passes::Stencil(path) => path,
    };
    let mut sums = vec![RowSums::default(); x.len()];
    let st = State {
        x,
        v,
        h,
        x0: Some(x0),
    };
    cs.linearize(params, st, &mut springs, &mut sums, path);
    (springs, sums)
}

/// (A − M) p through the product pass, on the path of `passes`.
fn product(cs: &ConstraintSet, springs: &mut Springs, p: &[DVec3], passes: Passes) -> Vec<DVec3> {
    let path = match passes {
        Passes::General => SimdPath::widest(),
        Passes::Stencil(path) => path,
    };
    let mut q = vec![DVec3::ZERO; p.len()];
    cs.spring_product(springs, p, &mut q, path);
    q
}

/// Random vectors, one per particle.
fn random_vectors(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rnd = rng(seed);
    (0..n).map(|_| DVec3::new(rnd(), rnd(), rnd())).collect()
}

#[test]
fn rows_summed_by_the_passes_match_the_serial_springs() {
    let passes = [Passes::General, Passes::Stencil(SimdPath::widest())];
    for (bending, passes) in [Family::BendDihedral, Family::BendIsometric]
        .into_iter()
        .flat_map(|b| passes.map(|p| (b, p)))
    {
        let (cs, params, x, v) = crumpled(bending);
        let n = x.len();
        let h = 1e-3;
        let x0 = random_vectors(n, 0x0bad_cafe_f00d_0001);
        let (mut springs, sums) = linearized(&cs, &params, (&x, &v, &x0), h, passes);
        // A − M applied to x₀, and to a fresh vector through the product pass.
        let (want_ax, f) = reference_all(&cs, &params, &x, &v, (h * h, h), &x0);
        let (kv, _) = reference_all(&cs, &params, &x, &v, (h * h, 0.0), &v);
        let q = product(&cs, &mut springs, &x0, passes);
        let scale = want_ax.iter().map(|a| a.length()).fold(0.0, f64::max);
        let mut curved = 0;
        for i in 0..n {
            let ax = sums[i].ax;
            assert!(
                close(ax, want_ax[i], scale),
                "{bending:?} {passes:?} row {i}: {ax} {}",
                want_ax[i]
            );
            assert!(close(q[i], want_ax[i], scale));
            let b = sums[i].b;
            let want_b = f[i] * h - kv[i];
            assert!(
                close(b, want_b, scale),
                "{bending:?} row {i}: b {b} {want_b}"
            );
            // The diagonal block: A − M applied to a vector at particle i alone, read at i.
            let d = sums[i].d;
            for e in [DVec3::X, DVec3::Y, DVec3::Z] {
                let mut p = vec![DVec3::ZERO; n];
                p[i] = e;
                let (col, _) = reference_all(&cs, &params, &x, &v, (h * h, h), &p);
                assert!(close(d.mul(e), col[i], scale), "{bending:?} diag {i}");
            }
            curved += usize::from(d.0[3] != 0.0);
        }
        assert!(curved > n / 2, "most rows have off-axis coupling: {curved}");
        assert!(
            springs.isometric.iter().any(|r| r.kappa > 0.0) || bending != Family::BendIsometric
        );
    }
}

#[test]
fn parts_in_parallel_sum_as_the_serial_springs_on_any_thread_count() {
    // 64² particles: the distance springs are cut into particle ranges, some straddling.
    let (cs, params, x, v) = stretched(Family::BendIsometric, 0.02, 64);
    let order = PassOrder::new(&cs.distance, x.len());
    let parts = order.bounds.len() - 1;
    assert!(parts >= 2, "{parts} ranges");
    assert!(
        order.springs.len() > order.starts[parts],
        "some springs straddle"
    );
    let (n, h) = (x.len(), 1e-3);
    let x0 = random_vectors(n, 0x0bad_cafe_f00d_0003);
    let run = |threads: usize, passes: Passes| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let (mut springs, sums) = linearized(&cs, &params, (&x, &v, &x0), h, passes);
            let q = product(&cs, &mut springs, &x0, passes);
            let rows: Vec<[DVec3; 3]> = sums
                .iter()
                .map(|r| [r.b, r.ax, r.d.mul(DVec3::ONE)])
                .collect();
            (rows, q)
        })
    };
    let (want_ax, f) = reference_all(&cs, &params, &x, &v, (h * h, h), &x0);
    let (kv, _) = reference_all(&cs, &params, &x, &v, (h * h, 0.0), &v);
    let scale = want_ax.iter().map(|a| a.length()).fold(0.0, f64::max);
    let stencil = run(1, Passes::Stencil(SimdPath::Scalar));
    for passes in [Passes::General, Passes::Stencil(SimdPath::widest())] {
        let (rows, q) = run(1, passes);
        assert_eq!(
            (rows.clone(), q.clone()),
            run(2, passes),
            "{passes:?}: 1 and 2 threads"
        );
        for i in 0..n {
            assert!(
                close(q[i], want_ax[i], scale),
                "{passes:?}: product row {i}"
            );
            assert!(
                close(rows[i][1], want_ax[i], scale),
                "{passes:?}: A x0 row {i}"
            );
            let b = f[i] * h - kv[i];
            assert!(close(rows[i][0], b, scale), "{passes:?}: b row {i}");
        }
        if let Passes::Stencil(path) = passes {
            assert_eq!((rows, q), stencil, "{path:?} and scalar lanes, same bits");
        }
    }
}

#[test]
fn a_flat_isometric_hinge_keeps_its_stiffness_in_the_system() {
    let (cs, params, x, v) = stretched(Family::BendIsometric, 0.0, 10);
    let n = x.len();
    let h = 1e-3;
    let x0 = random_vectors(n, 0x0bad_cafe_f00d_0002);
    let passes = Passes::Stencil(SimdPath::widest());
    let (mut springs, sums) = linearized(&cs, &params, (&x, &v, &x0), h, passes);
    let q = product(&cs, &mut springs, &x0, passes);
    // The reference has no term for a hinge without a direction: add h² k a aᵀ ⊗ I by hand.
    let (mut want_ax, f) = reference_all(&cs, &params, &x, &v, (h * h, h), &x0);
    let (mut kv, _) = reference_all(&cs, &params, &x, &v, (h * h, 0.0), &v);
    let iso = &cs.isometric;
    for s in 0..iso.particles.len() {
        let (idx, a) = (iso.particles[s], iso.shapes[s].weights);
        let flat = iso.shapes[s].curvature(&idx.map(|i| x[i as usize]));
        assert!(flat.length() < 1e-12, "hinge {s} is flat: {flat}");
        let hhk = h * h * params[iso.group[s] as usize].spring_stiffness;
        let (u0, uv) = (weighted(&a, &idx, &x0), weighted(&a, &idx, &v));
        for m in 0..4 {
            want_ax[idx[m] as usize] += u0 * (hhk * a[m]);
            kv[idx[m] as usize] += uv * (hhk * a[m]);
        }
    }
    assert!(!iso.particles.is_empty());
    let scale = want_ax.iter().map(|a| a.length()).fold(0.0, f64::max);
    for i in 0..n {
        assert!(
            close(q[i], want_ax[i], scale),
            "row {i}: {} {}",
            q[i],
            want_ax[i]
        );
        assert!(close(sums[i].ax, want_ax[i], scale), "row {i}: A x0");
        let want_b = f[i] * h - kv[i];
        assert!(
            close(sums[i].b, want_b, scale),
            "row {i}: b {} {want_b}",
            sums[i].b
        );
    }
}
