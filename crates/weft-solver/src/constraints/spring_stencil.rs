//! Explicit distance springs as a stencil: on a mesh whose particle numbering repeats (a grid),
//! every spring joins a particle i to i + o for one of a few offsets o. Each offset and
//! parameter group is a slot; a particle's force is the sum over the slots of its spring
//! there, so `W` consecutive particles load their neighbours with unit stride and need no
//! scatter. Each spring is evaluated once, from its lower end (the slots of positive offset),
//! in f32 lanes on a [`Mirror`] of the state; its force is kept in a [`Ring`] for the upper
//! end, o particles later, which adds it negated. Seen from the upper end the spring would give
//! exactly that force negated (every operation is symmetric or negated exactly), so momentum is
//! kept to the bit, and the sum order is fixed by the slots alone: the same bits on every
//! thread count and kernel path.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use std::collections::BTreeSet;

use glam::DVec3;
use rayon::prelude::*;

use super::{Block, Distance};
use crate::chunk::CHUNK;
use crate::params::FamilyParams;

/// Slots a stencil holds at most: a grid's stretch and shear springs take 8 (warp, weft and
/// bias each in their own parameter group), bend-distance springs up to 12 more; beyond,
/// the slots would be mostly empty lanes.
const MOST_SLOTS: usize = 24;

/// Below this length (m) a spring has no direction and gives no force (as
/// [`super::distance_evaluate`]'s limit).
const MIN_LEN: f32 = 1e-9;

/// The widest lane group the stencil serves: the multiple its stride and margins are rounded
/// to, and a [`Ring`]'s shadow length.
pub(crate) const WIDEST: usize = 16;

/// Where a slot's force on a particle comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    /// The spring of positive slot `p` (index into the positive slots), evaluated here.
    Own(usize),
    /// The spring of positive slot `p` evaluated at its lower end, o particles before: negated.
    Twin(usize),
}

/// The distance springs by slot (see the module documentation).
#[derive(Clone, Debug)]
pub(crate) struct SpringStencil {
    /// `n` rounded up to [`WIDEST`]: the stride of `rest`.
    stride: usize,
    /// Padding before and after the particles in a [`Mirror`]: the largest offset plus a
    /// vector, so that every lane's neighbour load stays inside.
    margin: usize,
    /// Each slot's offset o (the spring joins i and i + o); slots ascend by offset, then group.
    offsets: Vec<isize>,
    /// Each slot's parameter group.
    groups: Vec<u32>,
    /// The slots of positive offset, in slot order: the springs evaluated.
    positive: Vec<usize>,
    /// Each slot's source, in slot order: the sum order of a particle's force.
    sources: Vec<Source>,
    /// The largest |o|.
    widest: usize,
    /// Rest length of slot s's spring at particle i, `rest[s * stride + i]`; negative where
    /// particle i has none.
    rest: Vec<f32>,
}

/// The forces of the positive slots' springs on their lower ends for the last particles
/// before the group at work, per slot and axis, indexed by particle modulo a power of two
/// (at least the widest offset plus [`WIDEST`]) and followed by a shadow of its first
/// [`WIDEST`] entries, so that every read of `W` lanes is contiguous.
#[derive(Clone, Debug, Default)]
pub(crate) struct Ring {
    /// The ring's length (a power of two).
    len: usize,
    /// `(p * 3 + axis) * (len + WIDEST) + (i mod len)`, the shadow after each run.
    data: Vec<f32>,
}

impl Ring {
    /// The start of positive slot `p`'s axis `a`.
    #[inline(always)]
    fn base(&self, p: usize, a: usize) -> usize {
        (p * 3 + a) * (self.len + WIDEST)
    }
}

/// The positions (relative to `origin`) and velocities in f32, per axis, padded by the
/// stencil's margin on both sides: what the force lanes read.
#[derive(Clone, Debug, Default)]
pub(crate) struct Mirror {
    /// x − origin per axis (m).
    pub x: [Vec<f32>; 3],
    /// v per axis (m/s).
    pub v: [Vec<f32>; 3],
    /// The origin of `x`: the first particle's position when the mirror was loaded.
    pub origin: DVec3,
}

impl Mirror {
    /// Writes particle `i`'s position and velocity (`m` the stencil's margin).
    #[inline(always)]
    pub fn set(&mut self, m: usize, i: usize, x: DVec3, v: DVec3) {
        let x = x - self.origin;
        for a in 0..3 {
            self.x[a][m + i] = x[a] as f32;
            self.v[a][m + i] = v[a] as f32;
        }
    }
}

impl SpringStencil {
    /// The stencil of `block`'s springs over `n` particles, or `None` when they do not form
    /// one: more than [`MOST_SLOTS`] (offset, group) slots, or two springs of one group between
    /// the same two particles.
    pub fn build(block: &Block<2, Distance>, n: usize) -> Option<Self> {
        let slots = slots_of(block)?;
        let stride = n.next_multiple_of(WIDEST);
        let mut rest = vec![-1.0f32; slots.len() * stride];
        for ((&[p, q], &group), shape) in
            block.particles.iter().zip(&block.group).zip(&block.shapes)
        {
            let o = q as isize - p as isize;
            for (i, o) in [(p as usize, o), (q as usize, -o)] {
                let s = slots.binary_search(&(o, group)).ok()?;
                let r = &mut rest[s * stride + i];
                if *r >= 0.0 {
                    return None;
                }
                *r = shape.rest as f32;
            }
        }
        let positive: Vec<usize> = (0..slots.len()).filter(|&s| slots[s].0 > 0).collect();
        let sources = slots
            .iter()
            .map(|&(o, g)| {
                let own = |o: isize| positive.iter().position(|&p| slots[p] == (o, g));
                match o > 0 {
                    true => own(o).map(Source::Own),
                    false => own(-o).map(Source::Twin),
                }
            })
            .collect::<Option<Vec<Source>>>()?;
        let (offsets, groups): (Vec<isize>, Vec<u32>) = slots.into_iter().unzip();
        let widest = offsets.iter().map(|o| o.unsigned_abs()).max().unwrap_or(0);
        Some(Self {
            stride,
            margin: (widest + WIDEST).next_multiple_of(WIDEST),
            offsets,
            groups,
            positive,
            sources,
            widest,
            rest,
        })
    }

    /// The padding of a [`Mirror`] on each side.
    pub fn margin(&self) -> usize {
        self.margin
    }

    /// Each slot's stiffness k (N/m) and damping c (N·s/m) in f32; zero for a disabled family.
    pub fn coefficients(&self, params: &[FamilyParams]) -> Vec<[f32; 2]> {
        self.groups
            .iter()
            .map(|&g| {
                let p = &params[g as usize];
                match p.enabled {
                    true => [p.spring_stiffness as f32, p.spring_damping as f32],
                    false => [0.0; 2],
                }
            })
            .collect()
    }

    /// Loads `x` and `v` into `mirror` (allocating it on first use), relative to `x[0]`.
    pub fn load(&self, mirror: &mut Mirror, x: &[DVec3], v: &[DVec3]) {
        let len = self.stride + 2 * self.margin;
        for a in 0..3 {
            mirror.x[a].resize(len, 0.0);
            mirror.v[a].resize(len, 0.0);
        }
        let origin = x.first().copied().unwrap_or(DVec3::ZERO);
        mirror.origin = origin;
        let n = x.len().min(v.len());
        let (m, c) = (self.margin, CHUNK);
        let [x0, x1, x2] = mirror.x.each_mut().map(|s| s[m..m + n].par_chunks_mut(c));
        let [v0, v1, v2] = mirror.v.each_mut().map(|s| s[m..m + n].par_chunks_mut(c));
        let (x, v) = (x[..n].par_chunks(c), v[..n].par_chunks(c));
        (x0, x1, x2, v0, v1, v2, x, v).into_par_iter().for_each(
            |(x0, x1, x2, v0, v1, v2, x, v)| {
                for (i, (&x, &v)) in x.iter().zip(v).enumerate() {
                    let x = x - origin;
                    (x0[i], x1[i], x2[i]) = (x.x as f32, x.y as f32, x.z as f32);
                    (v0[i], v1[i], v2[i]) = (v.x as f32, v.y as f32, v.z as f32);
                }
            },
        );
    }

    /// The stride of the per-slot arrays: the particle count rounded up to [`WIDEST`]; state
    /// kept beside the stencil is padded to it, so that every group of lanes is whole.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// A ring for this stencil's springs (see [`Ring`]).
    pub fn ring(&self) -> Ring {
        let len = (self.widest + WIDEST).next_power_of_two();
        Ring {
            len,
            data: vec![0.0; self.positive.len() * 3 * (len + WIDEST)],
        }
    }

    /// Makes `ring` ready for groups of `W` from `start` on (a multiple of `W`): the springs
    /// of the particles before `start` that reach it, zero before the first particle.
    #[inline(always)]
    pub fn warm_ring<const W: usize, const DAMPED: bool>(
        &self,
        coef: &[[f32; 2]],
        from: &Mirror,
        ring: &mut Ring,
        start: usize,
    ) {
        if start < self.widest {
            ring.data.fill(0.0);
        }
        let first = start.saturating_sub(self.widest) / W * W;
        for i in (first..start).step_by(W) {
            self.evaluate::<W, DAMPED>(coef, from, ring, i);
        }
    }

    /// The spring forces (N) on the `W` particles from `i` (a multiple of `W`, below the
    /// stride) from the state in `from`, per axis, with `ring` warmed for `i` (by
    /// [`SpringStencil::warm_ring`] or the group before): the sum over the slots in their
    /// order of each spring's force, evaluated here for positive offsets and read back
    /// negated from the ring for negative ones. Each lane's arithmetic is the same IEEE
    /// operations on every width, so the width changes no bit.
    #[inline(always)]
    pub fn group_forces<const W: usize, const DAMPED: bool>(
        &self,
        coef: &[[f32; 2]],
        from: &Mirror,
        ring: &mut Ring,
        i: usize,
    ) -> [[f32; W]; 3] {
        self.evaluate::<W, DAMPED>(coef, from, ring, i);
        let mask = ring.len - 1;
        let mut f = [[0.0f32; W]; 3];
        for (&source, &o) in self.sources.iter().zip(&self.offsets) {
            // A twin's spring sits in the ring at its lower end, i + o (o < 0).
            let (p, at, own) = match source {
                Source::Own(p) => (p, i & mask, true),
                Source::Twin(p) => (p, i.wrapping_add_signed(o) & mask, false),
            };
            for a in 0..3 {
                let b = ring.base(p, a) + at;
                let r = &ring.data[b..b + W];
                if own {
                    for l in 0..W {
                        f[a][l] += r[l];
                    }
                } else {
                    for l in 0..W {
                        f[a][l] -= r[l];
                    }
                }
            }
        }
        f
    }

    /// Evaluates the positive slots' springs at the `W` particles from `i` on (velocities
    /// read only where `DAMPED`), each as the force on its lower end, f = (k C + c Ċ) n with
    /// C = |d| − rest, n = d/|d|, Ċ = n·(v_j − v_i) and d = x_j − x_i (Müller et al. 2007,
    /// eq. 9, as forces −(k C + c Ċ)∇C), into `ring` at `i`.
    #[inline(always)]
    fn evaluate<const W: usize, const DAMPED: bool>(
        &self,
        coef: &[[f32; 2]],
        from: &Mirror,
        ring: &mut Ring,
        i: usize,
    ) {
        const { assert!(W <= WIDEST) };
        let m = self.margin;
        let vel = |at: usize| match DAMPED {
            true => axes::<W>(&from.v, at),
            false => [[0.0; W]; 3],
        };
        let (xi, vi) = (axes::<W>(&from.x, m + i), vel(m + i));
        let at = i & (ring.len - 1);
        for (p, &s) in self.positive.iter().enumerate() {
            let j = (m + i).wrapping_add_signed(self.offsets[s]);
            let (xj, vj) = (axes::<W>(&from.x, j), vel(j));
            let rest = lanes::<W>(&self.rest, s * self.stride + i);
            let f = spring::<W, DAMPED>(coef[s], rest, &xi, &vi, &xj, &vj);
            for a in 0..3 {
                let b = ring.base(p, a);
                ring.data[b + at..b + at + W].copy_from_slice(&f[a]);
                if at == 0 {
                    ring.data[b + ring.len..b + ring.len + W].copy_from_slice(&f[a]);
                }
            }
        }
    }
}

/// The (offset, group) slots of `block`'s springs, ascending, each spring's in both directions;
/// `None` beyond [`MOST_SLOTS`] or for a spring from a particle to itself.
pub(super) fn slots_of(block: &Block<2, Distance>) -> Option<Vec<(isize, u32)>> {
    let mut slots: BTreeSet<(isize, u32)> = BTreeSet::new();
    for (&[p, q], &group) in block.particles.iter().zip(&block.group) {
        let o = q as isize - p as isize;
        if o == 0 {
            return None;
        }
        slots.extend([(o, group), (-o, group)]);
        if slots.len() > MOST_SLOTS {
            return None;
        }
    }
    Some(slots.into_iter().collect())
}

/// `W` values of `src` from `at` (the margins and the stride keep every load inside).
#[inline(always)]
fn lanes<const W: usize>(src: &[f32], at: usize) -> [f32; W] {
    let mut o = [0.0f32; W];
    o.copy_from_slice(&src[at..at + W]);
    o
}

/// `W` values of each axis of `src` from `at` (written out: `array::map` stays a call).
#[inline(always)]
fn axes<const W: usize>(src: &[Vec<f32>; 3], at: usize) -> [[f32; W]; 3] {
    [
        lanes::<W>(&src[0], at),
        lanes::<W>(&src[1], at),
        lanes::<W>(&src[2], at),
    ]
}

/// One slot's spring forces on the `W` particles at `xi` from those at `xj` (see
/// [`SpringStencil::evaluate`]); zero where `rest` is negative (no spring) or the particles
/// meet.
#[inline(always)]
fn spring<const W: usize, const DAMPED: bool>(
    [k, c]: [f32; 2],
    rest: [f32; W],
    xi: &[[f32; W]; 3],
    vi: &[[f32; W]; 3],
    xj: &[[f32; W]; 3],
    vj: &[[f32; W]; 3],
) -> [[f32; W]; 3] {
    let mut d = [[0.0f32; W]; 3];
    let mut dv = [[0.0f32; W]; 3];
    for a in 0..3 {
        for l in 0..W {
            d[a][l] = xj[a][l] - xi[a][l];
            if DAMPED {
                dv[a][l] = vj[a][l] - vi[a][l];
            }
        }
    }
    let mut f = [[0.0f32; W]; 3];
    for l in 0..W {
        let len2 = d[0][l] * d[0][l] + d[1][l] * d[1][l] + d[2][l] * d[2][l];
        let len = len2.sqrt();
        let inv = 1.0 / len;
        // (k C + c Ċ)/|d|, with Ċ = d·(v_j − v_i)/|d|.
        let mut t = k * (len - rest[l]) * inv;
        if DAMPED {
            let rate = d[0][l] * dv[0][l] + d[1][l] * dv[1][l] + d[2][l] * dv[2][l];
            t += c * rate * (inv * inv);
        }
        let scale = if rest[l] >= 0.0 && len > MIN_LEN {
            t
        } else {
            0.0
        };
        for a in 0..3 {
            f[a][l] = scale * d[a][l];
        }
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::BlockBuilder;
    use crate::params::Family;

    /// A `w` × `h` grid's stretch and shear springs (both diagonals), rest lengths from `x`.
    fn grid(w: usize, h: usize, x: &[DVec3]) -> Block<2, Distance> {
        let mut b = BlockBuilder::default();
        let at = |r: usize, c: usize| (r * w + c) as u32;
        let mut add = |p: u32, q: u32, group: u32| {
            let rest = (x[p as usize] - x[q as usize]).length();
            b.push([p, q], group, Distance { rest });
        };
        for r in 0..h {
            for c in 0..w {
                if c + 1 < w {
                    add(at(r, c), at(r, c + 1), Family::Stretch as u32);
                }
                if r + 1 < h {
                    add(at(r, c), at(r + 1, c), Family::Stretch as u32);
                }
                if r + 1 < h && c + 1 < w {
                    add(at(r, c), at(r + 1, c + 1), Family::Shear as u32);
                    add(at(r, c + 1), at(r + 1, c), Family::Shear as u32);
                }
            }
        }
        b.unordered()
    }

    #[test]
    fn stencil_forces_match_the_f64_springs_and_keep_momentum() {
        let (w, h) = (13, 7);
        let rest: Vec<DVec3> = (0..w * h)
            .map(|i| DVec3::new((i % w) as f64 * 0.02, 0.0, (i / w) as f64 * 0.02))
            .collect();
        let block = grid(w, h, &rest);
        let st = SpringStencil::build(&block, w * h).expect("a grid is a stencil");
        assert_eq!(st.offsets, [-14, -13, -12, -1, 1, 12, 13, 14]);
        // Stretched and moving: every spring carries a force and a damping term.
        let x: Vec<DVec3> = rest
            .iter()
            .enumerate()
            .map(|(i, p)| *p * 1.1 + DVec3::new(0.0, 0.003 * ((i * 7) % 5) as f64, 0.0))
            .collect();
        let v: Vec<DVec3> = (0..x.len())
            .map(|i| DVec3::new(0.1 * ((i * 3) % 4) as f64, -0.2, 0.05))
            .collect();
        let mut params = vec![FamilyParams::default_for(Family::Stretch); Family::COUNT];
        for p in &mut params {
            p.enabled = true;
            p.spring_stiffness = 800.0;
            p.spring_damping = 0.3;
        }
        params[Family::Shear as usize].spring_stiffness = 200.0;
        let cs = crate::constraints::ConstraintSet {
            distance: block,
            ..Default::default()
        };
        let mut want = vec![DVec3::ZERO; x.len()];
        cs.spring_forces(&x, &v, &params, &mut want);
        let mut mirror = Mirror::default();
        st.load(&mut mirror, &x, &v);
        let coef = st.coefficients(&params);
        /// Every particle's force, `W` lanes at a time, in runs of `part` particles taken
        /// last run first through one ring (NaN at the start: whatever a run reads it has
        /// warmed itself).
        fn all<const W: usize, const D: bool>(
            st: &SpringStencil,
            coef: &[[f32; 2]],
            m: &Mirror,
            n: usize,
            part: usize,
        ) -> Vec<[f32; 3]> {
            let mut ring = st.ring();
            ring.data.fill(f32::NAN);
            let mut out = vec![[0.0; 3]; st.stride()];
            for start in (0..st.stride()).step_by(part).rev() {
                st.warm_ring::<W, D>(coef, m, &mut ring, start);
                for i in (start..(start + part).min(st.stride())).step_by(W) {
                    let f = st.group_forces::<W, D>(coef, m, &mut ring, i);
                    for l in 0..W {
                        out[i + l] = [f[0][l], f[1][l], f[2][l]];
                    }
                }
            }
            out.truncate(n);
            out
        }
        /// Every particle's force with each spring evaluated from both ends.
        fn both_ends(st: &SpringStencil, coef: &[[f32; 2]], m: &Mirror, n: usize) -> Vec<[f32; 3]> {
            let mg = st.margin;
            let at = |src: &[f32], k: usize| lanes::<1>(src, k);
            (0..n)
                .map(|i| {
                    let xi = [0, 1, 2].map(|a| at(&m.x[a], mg + i));
                    let vi = [0, 1, 2].map(|a| at(&m.v[a], mg + i));
                    let mut f = [0.0f32; 3];
                    for (s, &o) in st.offsets.iter().enumerate() {
                        let j = (mg + i).wrapping_add_signed(o);
                        let xj = [0, 1, 2].map(|a| at(&m.x[a], j));
                        let vj = [0, 1, 2].map(|a| at(&m.v[a], j));
                        let rest = at(&st.rest, s * st.stride + i);
                        let g = spring::<1, true>(coef[s], rest, &xi, &vi, &xj, &vj);
                        for a in 0..3 {
                            f[a] += g[a][0];
                        }
                    }
                    f
                })
                .collect()
        }
        let bits = |f: &[[f32; 3]]| f.iter().flatten().map(|v| v.to_bits()).collect::<Vec<_>>();
        let reference = both_ends(&st, &coef, &mirror, x.len());
        let mut first: Option<Vec<[f32; 3]>> = None;
        let widths = [
            (
                "4 lanes, one run",
                all::<4, true>(&st, &coef, &mirror, x.len(), 96),
            ),
            (
                "8 lanes, runs of 8",
                all::<8, true>(&st, &coef, &mirror, x.len(), 8),
            ),
            (
                "8 lanes, runs of 32",
                all::<8, true>(&st, &coef, &mirror, x.len(), 32),
            ),
            (
                "16 lanes, runs of 16",
                all::<16, true>(&st, &coef, &mirror, x.len(), 16),
            ),
            (
                "16 lanes, runs of 48",
                all::<16, true>(&st, &coef, &mirror, x.len(), 48),
            ),
        ];
        for (path, got) in widths {
            let largest = want.iter().map(|f| f.length()).fold(0.0, f64::max);
            assert!(largest > 1.0);
            for (g, f) in got.iter().zip(&want) {
                let g = DVec3::new(g[0].into(), g[1].into(), g[2].into());
                assert!(
                    (g - *f).length() < 1e-4 * largest,
                    "{path}: {g} against {f}"
                );
            }
            // Momentum: the forces cancel to f32 rounding of their sum.
            let total: DVec3 = got
                .iter()
                .map(|g| DVec3::new(g[0].into(), g[1].into(), g[2].into()))
                .sum();
            assert!(total.length() < 1e-5 * largest, "{path}: {total}");
            // Each spring once gives the bits of each spring from both ends.
            assert_eq!(bits(&got), bits(&reference), "{path}");
            match &first {
                Some(f) => assert_eq!(bits(f), bits(&got), "{path}"),
                None => first = Some(got),
            }
        }

        // Undamped springs skip the velocities: the same bits as damped ones of no damping,
        // and other bits than the damped springs'.
        let n = x.len();
        let still: Vec<[f32; 2]> = coef.iter().map(|&[k, _]| [k, 0.0]).collect();
        let undamped = all::<8, false>(&st, &still, &mirror, n, 32);
        assert_eq!(
            bits(&undamped),
            bits(&all::<8, true>(&st, &still, &mirror, n, 32))
        );
        assert_ne!(bits(&undamped), bits(&reference));
    }

    #[test]
    fn meshes_that_are_no_stencil_are_refused() {
        let x: Vec<DVec3> = (0..40).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        let chain = |pairs: &[[u32; 2]], groups: &[u32]| {
            let mut b = BlockBuilder::default();
            for (&pq, &g) in pairs.iter().zip(groups) {
                b.push(pq, g, Distance { rest: 1.0 });
            }
            SpringStencil::build(&b.unordered(), x.len())
        };
        assert!(chain(&[[0, 1], [1, 2]], &[0, 0]).is_some());
        // One offset in two groups: two slots; two springs of two groups on one pair too.
        assert!(chain(&[[0, 1], [1, 2]], &[0, 1]).is_some());
        assert!(chain(&[[0, 1], [0, 1]], &[0, 1]).is_some());
        // Two springs of one group between the same particles.
        assert!(chain(&[[0, 1], [0, 1]], &[0, 0]).is_none());
        assert!(chain(&[[0, 1], [1, 0]], &[0, 0]).is_none());
        // Thirteen offsets (26 slots with their opposites).
        let many: Vec<[u32; 2]> = (1..14).map(|o| [0, o]).collect();
        assert!(chain(&many, &[0; 13]).is_none());
        assert!(chain(&many[..12], &[0; 12]).is_some());
    }
}
