//! The Verlet list against brute force: every pair that can touch is listed, partial
//! updates and thinner skins keep it so, and a fold with the list is a fold with a fresh
//! search every sweep.

use glam::DVec3;
use rustc_hash::FxHashSet;
use weft_solver::{
    ClothParams, Forces, GridDesc, Mass, Method, Orientation, Particles, Settings, Solver,
    SolverBuilder, SubstepContext, SubstepHook,
};

use super::list::{PairList, pair_key};
use super::skin::{STEPS, Skin};
use super::{Clamp, SelfCollision, SelfCollisionParams};
use crate::grid::CellGrid;
use crate::scenarios::self_fold;
use crate::test_rand::rand;

const N: usize = 24;
const SPACING: f64 = 0.01;

/// A solver with `cloths` horizontal `n`×`n` sheets of `size` (m) at the same rest place,
/// each SPACING thick.
fn sheets(cloths: usize, n: usize, size: (f64, f64)) -> Solver {
    let mesh = GridDesc {
        resolution: (n, n),
        size,
        center: DVec3::ZERO,
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.1),
        pins: vec![],
    }
    .build()
    .expect("grid");
    let mut b = SolverBuilder::new(Settings::default(), Forces::default()).expect("builder");
    for k in 0..cloths {
        b.add_cloth(format!("cloth {k}"), &mesh, ClothParams::default(), SPACING)
            .expect("cloth");
    }
    b.build()
}

/// An N×N cloth of thickness = spacing (flat at rest), and positions accordion-folded in
/// layers of 4 rows 0.9 thickness apart, every particle jittered by up to 0.3 thickness:
/// a random folded configuration.
fn folded() -> (Solver, Vec<DVec3>, Vec<f64>) {
    let side = SPACING * (N - 1) as f64;
    let solver = sheets(1, N, (side, side));
    let mut seed = 7;
    let mut x = solver.particles().positions.clone();
    for j in 0..N {
        for i in 0..N {
            let (layer, k) = (j / 4, j % 4);
            let along = if layer % 2 == 0 { k } else { 3 - k };
            let jitter = DVec3::new(rand(&mut seed), rand(&mut seed), rand(&mut seed));
            x[j * N + i] = DVec3::new(
                i as f64 * SPACING,
                layer as f64 * 0.9 * SPACING,
                along as f64 * SPACING,
            ) + jitter * (0.3 * SPACING / 3f64.sqrt());
        }
    }
    let thickness = vec![SPACING; solver.particles().len()];
    (solver, x, thickness)
}

/// The whole list (`pairs` and `extra`), sorted by (a, b); asserts no pair is listed twice.
fn whole(sc: &SelfCollision) -> PairList {
    // The keys of the extra pairs are exactly its pairs.
    let keys: FxHashSet<u64> = (0..sc.list.extra.len())
        .map(|k| pair_key(sc.list.extra.a[k], sc.list.extra.b[k]))
        .collect();
    assert_eq!(
        keys, sc.list.in_extra,
        "the extra pairs' keys are not its pairs"
    );
    let mut all: Vec<(u32, u32, f64)> = sc
        .list
        .pairs
        .iter()
        .chain([&sc.list.extra])
        .flat_map(|l| (0..l.len()).map(move |k| (l.a[k], l.b[k], l.target[k])))
        .collect();
    all.sort_by_key(|&(a, b, _)| (a, b));
    assert!(
        all.windows(2).all(|w| (w[0].0, w[0].1) < (w[1].0, w[1].1)),
        "a pair is listed twice"
    );
    let mut out = PairList::default();
    for (a, b, t) in all {
        out.push(a, b, t);
    }
    out
}

/// Pairs listed by `sc` that touch at `x`.
fn listed_contacts(sc: &SelfCollision, x: &[DVec3]) -> Vec<(u32, u32)> {
    let PairList { a, b, target } = whole(sc);
    (0..a.len())
        .filter(|&k| x[a[k] as usize].distance(x[b[k] as usize]) < target[k])
        .map(|k| (a[k], b[k]))
        .collect()
}

/// Every non-exempt pair closer than `within(target)` at `x`, by brute force over all pairs.
fn brute_pairs(
    sc: &SelfCollision,
    x: &[DVec3],
    t: &[f64],
    within: impl Fn(f64) -> f64,
) -> Vec<(u32, u32)> {
    let n = x.len() as u32;
    let mut out = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            if let Some(target) = sc.target(a, b, t) {
                if x[a as usize].distance(x[b as usize]) < within(target) {
                    out.push((a, b));
                }
            }
        }
    }
    out
}

fn listed(sc: &SelfCollision) -> Vec<(u32, u32)> {
    let w = whole(sc);
    w.a.iter().copied().zip(w.b.iter().copied()).collect()
}

/// Asserts every non-exempt pair within t (1 + search margin) at `x` is listed, and that the
/// touching pairs are exactly the brute-force ones.
fn assert_complete(sc: &SelfCollision, x: &[DVec3], t: &[f64], when: &str) {
    let list = listed(sc);
    let guaranteed = SPACING;
    let missing: Vec<_> = brute_pairs(sc, x, t, |_| guaranteed)
        .into_iter()
        .filter(|p| list.binary_search(p).is_err())
        .collect();
    assert!(missing.is_empty(), "{when}: pairs missing: {missing:?}");
    assert_eq!(
        listed_contacts(sc, x),
        brute_pairs(sc, x, t, |target| target),
        "{when}: contacts"
    );
}

#[test]
fn skin_list_holds_exactly_the_brute_force_contacts_until_a_half_skin_move() {
    let (solver, mut x, t) = folded();
    let params = SelfCollisionParams::default();
    let mut sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
    sc.refresh(&mut x, &t, None);
    assert_eq!(sc.rebuilds(), 1);
    let contacts = listed_contacts(&sc, &x);
    assert!(contacts.len() > 200, "only {} contacts", contacts.len());
    // Whatever limit the list uses, moves up to it must keep every close pair listed.
    let limit = sc.limit(SPACING);
    assert!(limit > 0.0);
    assert_complete(&sc, &x, &t, "built");
    // Exactly the pairs within R at the build, no more.
    let list = listed(&sc);
    let radius = SPACING * (1.0 + params.search_margin);
    assert_eq!(list, brute_pairs(&sc, &x, &t, |_| radius * (1.0 + 1e-12)));

    // Adversarial moves within the skin: each particle heads for the nearest particle the
    // list does not pair it with; less their mean, scaled to just under half the skin.
    let x0 = x.clone();
    let mut moves: Vec<DVec3> = (0..x.len())
        .map(|a| {
            (0..x.len())
                .filter(|&b| b != a && sc.target(a as u32, b as u32, &t).is_some())
                .filter(|&b| {
                    list.binary_search(&(a.min(b) as u32, a.max(b) as u32))
                        .is_err()
                })
                .min_by(|&b, &c| x0[a].distance(x0[b]).total_cmp(&x0[a].distance(x0[c])))
                .map_or(DVec3::ZERO, |b| (x0[b] - x0[a]).normalize())
        })
        .collect();
    let mean = moves.iter().sum::<DVec3>() / moves.len() as f64;
    let longest = moves
        .iter()
        .map(|m| (*m - mean).length())
        .fold(0.0, f64::max);
    for m in &mut moves {
        *m = (*m - mean) * (0.999 * limit / longest);
    }
    for (xi, (x0i, m)) in x.iter_mut().zip(x0.iter().zip(&moves)) {
        *xi = *x0i + *m;
    }
    sc.refresh(&mut x, &t, None);
    assert_eq!(
        (sc.rebuilds(), sc.updates()),
        (1, 0),
        "list changed although nothing moved half the skin"
    );
    assert_complete(&sc, &x, &t, "after the moves");
    // The moves did bring unlisted pairs closer than R: the skin was needed.
    let closer = brute_pairs(&sc, &x, &t, |_| radius);
    assert!(closer.iter().any(|p| list.binary_search(p).is_err()));
    // A sweep reports one contact per touching pair.
    let touching = listed_contacts(&sc, &x).len();
    let mut p = solver.particles().clone();
    (p.positions, p.prev_positions) = (x.clone(), x);
    assert_eq!(sc.solve(&mut p).0, touching);
}

#[test]
fn movers_are_reanchored_the_whole_cloth_may_move_and_many_movers_rebuild() {
    let (solver, mut x, t) = folded();
    let params = SelfCollisionParams::default();
    let mut sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
    let limit = 0.5 * params.search_margin * SPACING;
    sc.refresh(&mut x, &t, None);
    // The whole cloth carried 10 half-skins away: its list still holds.
    for xi in &mut x {
        *xi += DVec3::new(10.0 * limit, -3.0 * limit, 0.0);
    }
    sc.refresh(&mut x, &t, None);
    assert_eq!((sc.rebuilds(), sc.updates()), (1, 0), "carried");
    x[100].x += 0.99 * limit;
    sc.refresh(&mut x, &t, None);
    assert_eq!(
        (sc.rebuilds(), sc.updates()),
        (1, 0),
        "moved within the skin"
    );
    // Particles 200 and 201 jump onto particle 300 (far away at rest): new contacts.
    x[200] = x[300] + DVec3::new(0.0, 0.2 * SPACING, 0.0);
    x[201] = x[300] + DVec3::new(0.2 * SPACING, 0.0, 0.0);
    assert!(listed(&sc).binary_search(&(200, 300)).is_err());
    sc.refresh(&mut x, &t, None);
    assert_eq!((sc.rebuilds(), sc.updates()), (1, 1), "two movers");
    assert!(listed(&sc).binary_search(&(200, 300)).is_ok());
    assert!(listed(&sc).binary_search(&(201, 300)).is_ok());
    assert_complete(&sc, &x, &t, "after re-anchoring");
    // 200 jumps again (re-anchored a second time) and 202 for the first time: the grid of
    // re-anchored members, updated in place, holds each once at its anchor.
    x[200] = x[300] + DVec3::new(0.0, -0.2 * SPACING, 0.0);
    x[202] = x[300] + DVec3::new(-0.2 * SPACING, 0.0, 0.0);
    sc.refresh(&mut x, &t, None);
    assert_eq!((sc.rebuilds(), sc.updates()), (1, 2), "re-anchored again");
    assert_eq!(sc.list.reanchored.len(), 3);
    let mut fresh = CellGrid::default();
    fresh.build(
        &sc.list.built_at,
        &sc.list.reanchored,
        sc.list.grid.spacing(),
    );
    assert_eq!(sc.moved.recent.entries(), fresh.entries());
    assert!(listed(&sc).binary_search(&(202, 300)).is_ok());
    assert_complete(&sc, &x, &t, "after re-anchoring again");
    // Everything shaken by half a skin: a full rebuild.
    let mut seed = 3;
    for xi in &mut x {
        *xi += DVec3::new(rand(&mut seed), rand(&mut seed), rand(&mut seed)) * (2.0 * limit);
    }
    sc.refresh(&mut x, &t, None);
    assert_eq!((sc.rebuilds(), sc.updates()), (2, 2), "shaken");
    assert_complete(&sc, &x, &t, "after the rebuild");
    // A thickness change drops the list.
    sc.invalidate();
    sc.refresh(&mut x, &t, None);
    assert_eq!(sc.rebuilds(), 3);
}

/// Self-collision alone, with the ground as a floor at one thickness.
struct Hook {
    sc: SelfCollision,
    thickness: Vec<f64>,
    fresh: bool,
}

impl SubstepHook for Hook {
    fn begin_substep(&mut self, _: &SubstepContext, _: &Particles) {
        self.fresh = true;
    }

    fn project(&mut self, _: &SubstepContext, p: &mut Particles) -> usize {
        let clamp = std::mem::take(&mut self.fresh).then_some(Clamp {
            prev: &p.prev_positions,
            w: &p.inv_masses,
        });
        self.sc.refresh(&mut p.positions, &self.thickness, clamp);
        let (contacts, _) = self.sc.solve(p);
        for (x, t) in p.positions.iter_mut().zip(&self.thickness) {
            x.y = x.y.max(*t);
        }
        contacts
    }
}

/// The self-fold scenario, 90 frames, with `params`: final positions, rebuilds, partial
/// updates and changes of skin.
fn fold_with(params: SelfCollisionParams) -> (Vec<DVec3>, u64, u64, u64) {
    let (mut solver, _) = self_fold(Method::Xpbd, 10, 30).expect("scenario");
    let sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
    let thickness = vec![solver.cloths()[0].thickness; solver.particles().len()];
    let mut hook = Hook {
        sc,
        thickness,
        fresh: true,
    };
    for _ in 0..90 {
        solver.step_with(&mut hook).expect("step");
    }
    (
        solver.particles().positions.clone(),
        hook.sc.rebuilds(),
        hook.sc.updates(),
        hook.sc.skin.changes(),
    )
}

#[test]
fn skin_list_folds_exactly_like_a_search_before_every_sweep() {
    // No skin: any motion at all rebuilds the list, i.e. a fresh search every sweep.
    let (every, sweeps, _, _) = fold_with(SelfCollisionParams {
        search_margin: 0.0,
        adaptive_margin: false,
        ..SelfCollisionParams::default()
    });
    assert_eq!(sweeps, 90 * 10, "a fresh search every sweep");
    // A fixed skin, and the adaptive one (the default), which must change along the way.
    let fixed = SelfCollisionParams {
        adaptive_margin: false,
        ..SelfCollisionParams::default()
    };
    for params in [fixed, SelfCollisionParams::default()] {
        let (skin, rebuilds, updates, changes) = fold_with(params);
        assert!(updates > 0, "no partial update was exercised");
        assert!(
            4 * rebuilds < 3 * sweeps,
            "{rebuilds} rebuilds in {sweeps} sweeps"
        );
        assert_eq!(
            changes > 0,
            params.adaptive_margin,
            "{changes} changes of skin"
        );
        let differ = every
            .iter()
            .zip(&skin)
            .filter(|(a, b)| a.to_array() != b.to_array())
            .count();
        assert_eq!(differ, 0, "{differ} particles differ");
    }
}

#[test]
fn a_thinner_skin_keeps_every_pair_whose_anchors_are_within_its_radius_once() {
    let (solver, mut x, t) = folded();
    let params = SelfCollisionParams {
        adaptive_margin: false,
        ..SelfCollisionParams::default()
    };
    let mut sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
    sc.refresh(&mut x, &t, None);
    let (r_old, r_new) = (sc.radius(SPACING), SPACING * (1.0 + STEPS[0]));
    // A pair the build listed between the two radii; its first particle moves past the
    // limit to within one thickness of the second, so it is re-anchored there: the thinner
    // skin must keep that pair, now from `extra`.
    let list = listed(&sc);
    let &(a, b) = list
        .iter()
        .find(|&&(a, b)| {
            let d = x[a as usize].distance(x[b as usize]);
            d > 1.1 * r_new && d <= r_old
        })
        .expect("a pair between the radii");
    let to_b = x[b as usize] - x[a as usize];
    x[a as usize] += to_b * (1.0 - 0.9 * SPACING / to_b.length());
    sc.refresh(&mut x, &t, None);
    assert_eq!((sc.rebuilds(), sc.updates()), (1, 1));
    let in_pairs = |sc: &SelfCollision| {
        sc.list
            .pairs
            .iter()
            .any(|l| (0..l.len()).any(|k| (l.a[k], l.b[k]) == (a, b)))
    };
    assert!(in_pairs(&sc));
    sc.skin = Skin::new(STEPS[0], false);
    sc.shrink();
    assert!(
        !in_pairs(&sc),
        "the build's test at the thinner radius drops it"
    );
    assert!(
        (0..sc.list.extra.len()).any(|k| (sc.list.extra.a[k], sc.list.extra.b[k]) == (a, b)),
        "its anchors keep it listed"
    );
    // Exactly the non-exempt pairs whose anchors are within the new radius, or whose
    // positions at the build were (`whole` asserts none is listed twice).
    let listed = listed(&sc);
    let anchors: Vec<DVec3> = (0..x.len())
        .map(|i| sc.list.built_at[sc.slot_of[i] as usize])
        .collect();
    let built: Vec<DVec3> = (0..x.len())
        .map(|i| sc.list.built_pos[sc.slot_of[i] as usize])
        .collect();
    let mut expected = brute_pairs(&sc, &anchors, &t, |_| r_new * (1.0 + 1e-12));
    expected.extend(brute_pairs(&sc, &built, &t, |_| r_new * (1.0 + 1e-12)));
    expected.sort_unstable();
    expected.dedup();
    assert_eq!(listed, expected);
    assert_complete(&sc, &x, &t, "after shrinking");
}

#[test]
fn exempt_pairs_are_those_of_one_cloth_within_a_fold_length_at_rest() {
    // Two cloths with the same rest positions. Cells of 1 × 0.6 spacing: pairs one column
    // and two rows apart, 1.562 spacings, lie just within the fold length (1.571).
    let n = 12;
    let side = SPACING * (n - 1) as f64;
    let solver = sheets(2, n, (side, 0.6 * side));
    let rest = solver.particles().positions.clone();
    let count = rest.len();
    let t = vec![SPACING; count];
    // A skin of 1.1 thickness: R = 2.1 t reaches same-cloth pairs beyond the fold length
    // (2 t apart) and leaves none on its border.
    let params = SelfCollisionParams {
        search_margin: 1.1,
        adaptive_margin: false,
        ..SelfCollisionParams::default()
    };
    let mut sc = SelfCollision::new(&solver, &[0, 1], params).expect("self-collision");
    let cloth = |i: usize| i / (n * n);
    let mut shares_triangle = vec![false; count * count];
    for info in solver.cloths() {
        for tri in &info.triangles {
            for k in 0..3 {
                let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
                shares_triangle[a * count + b] = true;
                shares_triangle[b * count + a] = true;
            }
        }
    }
    let fold = std::f64::consts::FRAC_PI_2 * SPACING;
    let (mut exempt, mut kept_same) = (0, 0);
    for a in 0..count {
        for b in a + 1..count {
            let target = sc.target(a as u32, b as u32, &t);
            let rest_distance = rest[a].distance(rest[b]);
            if cloth(a) != cloth(b) {
                assert_eq!(target, Some(SPACING), "two cloths' pair ({a}, {b})");
            } else if shares_triangle[a * count + b] || rest_distance < 0.999 * fold {
                assert_eq!(target, None, "({a}, {b}), {rest_distance} m apart at rest");
                exempt += 1;
            } else if rest_distance > 1.001 * fold {
                assert_eq!(target, Some(SPACING), "({a}, {b})");
                kept_same += 1;
            }
        }
    }
    assert!(
        exempt > 500 && kept_same > 10_000,
        "{exempt} exempt, {kept_same} kept"
    );
    // The list built with the cloths at their rest places: every pair of the two cloths
    // within R (the rest places coincide), and none of one cloth within the fold length.
    let mut x = rest.clone();
    sc.refresh(&mut x, &t, None);
    let radius = 2.1 * SPACING;
    let list = listed(&sc);
    assert_eq!(list, brute_pairs(&sc, &x, &t, |_| radius * (1.0 + 1e-12)));
    assert!(
        list.iter()
            .any(|&(a, b)| cloth(a as usize) == cloth(b as usize))
    );
    assert!(list.iter().any(|&(a, b)| a as usize + n * n == b as usize));
    assert!(
        list.iter()
            .all(|&(a, b)| cloth(a as usize) != cloth(b as usize)
                || rest[a as usize].distance(rest[b as usize]) > fold)
    );
}

#[test]
fn a_raised_stop_cuts_a_list_build_short_and_leaves_no_list() {
    // Two coincident sheets 10 m thick: every pair of the two cloths is a candidate.
    let n = 16;
    let solver = sheets(2, n, (0.3, 0.3));
    let count = solver.particles().len();
    let t = vec![10.0; count];
    let params = SelfCollisionParams {
        adaptive_margin: false,
        ..SelfCollisionParams::default()
    };
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let mut sc = SelfCollision::new(&solver, &[0, 1], params).expect("self-collision");
    sc.set_stop(std::sync::Arc::clone(&flag));
    let mut x = solver.particles().positions.clone();
    sc.refresh(&mut x, &t, None);
    assert_eq!((sc.pair_count(), sc.list.built_for), (0, None));
    flag.store(false, std::sync::atomic::Ordering::Relaxed);
    sc.refresh(&mut x, &t, None);
    assert_eq!(
        sc.pair_count(),
        (n * n) * (n * n),
        "every pair of the two cloths"
    );
}
