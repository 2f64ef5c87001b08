//! Tests of the four-particle sweep: every part and straddler, softness, group coefficients,
//! multipliers and frame constants.

use glam::DVec3;

use super::*;
use crate::constraints::quad_lanes::*;
use crate::constraints::{BlockBuilder, Dihedral, Isometric};
use crate::test_rand::rng;
use crate::topology::Topology;

/// A `n × n` grid of spacing 0.02 m, flat at rest, crumpled by up to ±`bump` in z.
fn crumpled(n: u32, bump: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut rnd = rng(0x6a09_e667_f3bc_c909);
    let x = (0..n * n)
        .map(|i| DVec3::new(0.02 * (i % n) as f64, 0.02 * (i / n) as f64, bump * rnd()))
        .collect();
    let mut tris = Vec::new();
    for r in 0..n - 1 {
        for c in 0..n - 1 {
            let i = r * n + c;
            tris.push([i, i + 1, i + n]);
            tris.push([i + 1, i + n + 1, i + n]);
        }
    }
    (x, tris)
}

/// A dihedral family at compliance 0, undamped.
fn rigid() -> FamilyParams {
    FamilyParams {
        enabled: true,
        compliance: 0.0,
        damping: 0.0,
        pbd_stiffness: 1.0,
        spring_stiffness: 0.0,
        spring_damping: 0.0,
    }
}

/// `sweeps` symmetric XPBD sweeps (h = 1 ms) of `block` on the widest path, each from
/// cleared multipliers, with `prev` and inverse masses 1.
fn sweep<Q: QuadLanes>(
    block: &mut Block<4, Q>,
    x: &mut [DVec3],
    prev: &[DVec3],
    params: &[FamilyParams],
    sweeps: usize,
) {
    let w = vec![1.0; x.len()];
    for _ in 0..sweeps {
        block.reset_multipliers();
        block.project_symmetric_lanes(
            x,
            prev,
            &w,
            params,
            Rule::Xpbd { h: 1e-3 },
            SimdPath::widest(),
            false,
            &FrameConstants::default(),
        );
    }
}

#[test]
fn sweeps_flatten_a_crumpled_sheet_through_every_part_and_straddler() {
    let n = 48;
    let (mut x, tris) = crumpled(n, 0.004);
    let mut b = BlockBuilder::<4, Dihedral>::default();
    for wing in Topology::new(&tris).wings {
        b.push(
            [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]],
            0,
            Dihedral { rest: 0.0 },
        );
    }
    let free = vec![true; x.len()];
    let mut block = b.finish(&free);
    let parts = block.part_bounds.len() - 1;
    let straddlers: usize = (block.segments.iter())
        .map(|s| s[parts + 1] - s[parts])
        .sum();
    assert!(
        parts >= 2 && straddlers > 0,
        "{parts} parts, {straddlers} straddlers"
    );
    let prev = x.clone();
    let worst = |x: &[DVec3], block: &Block<4, Dihedral>| {
        (block.residuals(x)).fold(0.0f64, |m, c| m.max(c.abs()))
    };
    let start = worst(&x, &block);
    sweep(&mut block, &mut x, &prev, &[rigid()], 1000);
    let end = worst(&x, &block);
    // 6e-4 rad after 1,000 sweeps (bending alone converges slowly on long waves); with
    // the straddlers left out their row of hinges keeps a crease of 0.02 rad.
    assert!(
        start > 0.2 && end < 3e-3,
        "largest |θ − θ₀|: {start} → {end}"
    );
}

#[test]
fn a_block_is_soft_per_substep_exactly_when_every_hinge_is() {
    // One isometric hinge per group; Σ w k² against α/h² decides, hinge by hinge.
    let rest = [
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, -1.0, 0.0),
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
    ];
    let shape = Isometric::at_rest(&rest).expect("a hinge");
    let w = [2.0, 1.0, 0.5, 0.0];
    let s: f64 = (0..4)
        .map(|i| w[i] * shape.weights[i] * shape.weights[i])
        .sum();
    let h = 1e-3;
    let mut b = BlockBuilder::<4, Isometric>::default();
    b.push([0, 1, 2, 3], 0, shape);
    b.push([0, 1, 2, 3], 1, shape);
    let block = b.finish(&[true, true, true, false]);
    let at = |alpha: f64| FamilyParams {
        compliance: alpha * h * h,
        ..rigid()
    };
    let xpbd = Rule::Xpbd { h };
    assert!(block.soft_per_substep(&w, &[at(1.001 * s), at(2.0 * s)], xpbd));
    assert!(!block.soft_per_substep(&w, &[at(2.0 * s), at(0.9 * s)], xpbd));
    // A disabled family does not count; PBD and the dihedral never sweep forward only.
    let off = FamilyParams {
        enabled: false,
        ..at(0.0)
    };
    assert!(block.soft_per_substep(&w, &[at(1.001 * s), off], xpbd));
    assert!(!block.soft_per_substep(&w, &[at(s), at(s)], Rule::Pbd));
    let mut d = BlockBuilder::<4, Dihedral>::default();
    d.push([0, 1, 2, 3], 0, Dihedral { rest: 0.0 });
    let d = d.finish(&[true, true, true, false]);
    assert!(!d.soft_per_substep(&w, &[at(1e9)], xpbd));
}

#[test]
fn each_constraint_takes_its_own_group_coefficients() {
    // Two crumpled sheets in one block (so with more than one group, the lanes look their
    // coefficients up): group 0 rigid, group 1 disabled. The first sheet flattens, the
    // second does not move a bit.
    let n = 16;
    let (sheet, tris) = crumpled(n, 0.004);
    let count = sheet.len() as u32;
    let mut x: Vec<DVec3> = sheet.iter().chain(&sheet).copied().collect();
    let mut b = BlockBuilder::<4, Dihedral>::default();
    for wing in Topology::new(&tris).wings {
        let q = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
        b.push(q, 0, Dihedral { rest: 0.0 });
        b.push(q.map(|i| i + count), 1, Dihedral { rest: 0.0 });
    }
    let mut block = b.finish(&vec![true; x.len()]);
    let params = [
        rigid(),
        FamilyParams {
            enabled: false,
            ..rigid()
        },
    ];
    let prev = x.clone();
    let second = x[sheet.len()..].to_vec();
    let worst = |x: &[DVec3]| {
        let mut one = BlockBuilder::<4, Dihedral>::default();
        for wing in Topology::new(&tris).wings {
            let q = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
            one.push(q, 0, Dihedral { rest: 0.0 });
        }
        let one = one.finish(&vec![true; x.len()]);
        one.residuals(x).fold(0.0f64, |m, c| m.max(c.abs()))
    };
    let start = worst(&x[..sheet.len()]);
    sweep(&mut block, &mut x, &prev, &params, 200);
    let end = worst(&x[..sheet.len()]);
    assert!(start > 0.1 && end < 0.2 * start, "{start} → {end}");
    assert_eq!(x[sheet.len()..], second[..], "the disabled group moved");
}

#[test]
fn the_parted_isometric_sweep_carries_each_constraints_three_multipliers() {
    // Compliant isometric hinges on a crumpled sheet cut into parts and straddlers: one
    // sweep through the parts in parallel, symmetric or forward only, equals the same
    // sweep written out one constraint at a time in the block's order, each constraint's
    // multipliers carried from the forward half into the backward one.
    let n = 48;
    let (rest, tris) = crumpled(n, 0.0);
    let (mut x, _) = crumpled(n, 0.004);
    let mut b = BlockBuilder::<4, Isometric>::default();
    for wing in Topology::new(&tris).wings {
        let q = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
        let shape = Isometric::at_rest(&q.map(|i| rest[i as usize])).expect("hinge");
        b.push(q, 0, shape);
    }
    let mut block = b.finish(&vec![true; x.len()]);
    let parts = block.part_bounds.len() - 1;
    assert!(parts >= 2, "{parts} parts");
    let h = 1e-3;
    // α/h² = 2500 against Σ w kᵢ² of the order of 10⁴: the multipliers matter between the
    // halves.
    let params = [FamilyParams {
        compliance: 2500.0 * h * h,
        ..rigid()
    }];
    let w = vec![1.0; x.len()];
    let colours = block.colors.len();
    let mut order: Vec<usize> = Vec::new();
    // Every part's colours (parts are disjoint: their order is free), then the straddlers'.
    for p in 0..=parts {
        for c in 0..colours {
            order.extend(block.segments[c][p]..block.segments[c][p + 1]);
        }
    }
    let start = x.clone();
    // Forward and backward, and (as a soft block sweeps) forward only.
    for forward_only in [false, true] {
        let mut want = start.clone();
        let mut lambda = vec![DVec3::ZERO; block.len()];
        let mut one = |k: usize, x: &mut [DVec3]| {
            let (q, kw) = (block.particles[k], block.shapes[k].weights);
            let p = q.map(|i| x[i as usize]);
            let s: f64 = kw.iter().map(|k| k * k).sum();
            let v = block.shapes[k].curvature(&p);
            let alpha = 2500.0;
            let dl = (-v - lambda[k] * alpha) * (1.0 / (s + alpha));
            lambda[k] += dl;
            for j in 0..4 {
                x[q[j] as usize] += dl * kw[j];
            }
        };
        let backward = if forward_only { &[][..] } else { &order[..] };
        for &k in order.iter().chain(backward.iter().rev()) {
            one(k, &mut want);
        }
        x.copy_from_slice(&start);
        let prev = x.clone();
        block.reset_multipliers();
        block.project_symmetric_lanes(
            &mut x,
            &prev,
            &w,
            &params,
            Rule::Xpbd { h },
            SimdPath::widest(),
            forward_only,
            &FrameConstants::default(),
        );
        let worst = x
            .iter()
            .zip(&want)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-12,
            "forward only {forward_only}: largest difference {worst} m"
        );
    }
}

#[test]
fn frame_constants_give_the_kernels_bits_and_follow_the_inverse_masses() {
    // Damped, compliant isometric hinges on a crumpled sheet, some particles pinned: a
    // symmetric sweep with the frame constants equals one computing them in the kernel, to
    // the bit, positions and multipliers; constants kept for other inverse masses are
    // refused (the sweep then computes its own), and preparing again renews them.
    let n = 32;
    let (rest, tris) = crumpled(n, 0.0);
    let (start, _) = crumpled(n, 0.004);
    let mut b = BlockBuilder::<4, Isometric>::default();
    for wing in Topology::new(&tris).wings {
        let q = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
        let shape = Isometric::at_rest(&q.map(|i| rest[i as usize])).expect("hinge");
        b.push(q, 0, shape);
    }
    let mut plain = b.finish(&vec![true; start.len()]);
    let mut kept = plain.clone();
    let h = 1e-3;
    let params = [FamilyParams {
        compliance: 300.0 * h * h,
        damping: 0.02,
        ..rigid()
    }];
    let rule = Rule::Xpbd { h };
    let mut w: Vec<f64> = (0..start.len()).map(|i| 1.0 + (i % 3) as f64).collect();
    w[0] = 0.0;
    w[n as usize - 1] = 0.0;
    let prev: Vec<DVec3> = start
        .iter()
        .map(|p| *p - DVec3::new(0.0, 0.0, 1e-3))
        .collect();
    let mut constants = FrameConstants::default();
    kept.prepare_constants(&mut constants, &w, &params, rule);
    assert_eq!(constants.values().len(), kept.len());
    let none = FrameConstants::default();
    let run = |block: &mut Block<4, Isometric>, w: &[f64], c: &FrameConstants<_>| {
        let mut x = start.clone();
        block.reset_multipliers();
        for _ in 0..3 {
            block.project_symmetric_lanes(
                &mut x,
                &prev,
                w,
                &params,
                rule,
                SimdPath::widest(),
                false,
                c,
            );
        }
        let bits: Vec<[u64; 3]> = x.iter().map(|p| p.to_array().map(f64::to_bits)).collect();
        let lambda: Vec<u64> = block.lambda.iter().map(|l| l.to_bits()).collect();
        (bits, lambda)
    };
    let want = run(&mut plain, &w, &none);
    assert_eq!(run(&mut kept, &w, &constants), want);
    assert_ne!(
        run(&mut kept, &w, &none).0,
        run(&mut kept, &[1.0; 1024][..], &none).0
    );
    // Another particle pinned: the kept constants no longer hold.
    let mut pinned = w.clone();
    pinned[n as usize * 5 + 7] = 0.0;
    let want = run(&mut plain, &pinned, &none);
    assert_eq!(run(&mut kept, &pinned, &constants), want);
    let before = constants.values().to_vec();
    kept.prepare_constants(&mut constants, &pinned, &params, rule);
    assert_ne!(constants.values(), &before[..]);
    assert_eq!(run(&mut kept, &pinned, &constants), want);
}
