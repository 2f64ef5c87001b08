//! Explicit distance springs as a stencil: on a mesh whose particle numbering repeats (a grid),
//! every spring joins a particle i to i + o for one of a few offsets o. Each offset and
//! parameter group is a slot; a particle's force is the sum over the slots of its spring
//! there, each taken from its own end, so `W` consecutive particles load their neighbours with
//! unit stride and need no scatter. The forces are taken in f32 lanes on a [`Mirror`] of the state; a spring seen
//! from its two ends gives exactly opposite forces (every operation is symmetric or negated
//! exactly), so momentum is kept to the bit, and the sum order is fixed by the slots alone:
//! the same bits on every thread count and kernel path.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use std::collections::BTreeSet;

use glam::DVec3;

use super::lanes::LANES;
use super::{Block, Distance};
use crate::params::FamilyParams;

/// Slots a stencil holds at most: a grid's stretch and shear springs take 8 (warp, weft and
/// bias each in their own parameter group), bend-distance springs up to 12 more; beyond,
/// the slots would be mostly empty lanes.
const MOST_SLOTS: usize = 24;

/// Below this length (m) a spring has no direction and gives no force (as
/// [`super::distance_evaluate`]'s limit).
const MIN_LEN: f32 = 1e-9;

/// The distance springs by slot (see the module documentation).
#[derive(Clone, Debug)]
pub(crate) struct SpringStencil {
    /// `n` rounded up to [`LANES`]: the stride of `rest`.
    stride: usize,
    /// Padding before and after the particles in a [`Mirror`]: the largest offset plus a
    /// vector, so that every lane's neighbour load stays inside.
    margin: usize,
    /// Each slot's offset o (the spring joins i and i + o); slots ascend by offset, then group.
    offsets: Vec<isize>,
    /// Each slot's parameter group.
    groups: Vec<u32>,
    /// Rest length of slot s's spring at particle i, `rest[s * stride + i]`; negative where
    /// particle i has none.
    rest: Vec<f32>,
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
        let slots: Vec<(isize, u32)> = slots.into_iter().collect();
        let stride = n.next_multiple_of(LANES);
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
        let (offsets, groups): (Vec<isize>, Vec<u32>) = slots.into_iter().unzip();
        let widest = offsets.iter().map(|o| o.unsigned_abs()).max().unwrap_or(0);
        Some(Self {
            stride,
            margin: (widest + LANES).next_multiple_of(LANES),
            offsets,
            groups,
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
        mirror.origin = x.first().copied().unwrap_or(DVec3::ZERO);
        for (i, (&x, &v)) in x.iter().zip(v).enumerate() {
            mirror.set(self.margin, i, x, v);
        }
    }

    /// The stride of the per-slot arrays: the particle count rounded up to [`LANES`]; state
    /// kept beside the stencil is padded to it, so that every group of lanes is whole.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// The spring forces (N) on the `W` particles from `i` (a multiple of `W`, below the
    /// stride) from the state in `from`, per axis: f = Σ_slots (k C + c Ċ) n with
    /// C = |d| − rest, n = d/|d|, Ċ = n·(v_j − v_i) and d = x_j − x_i (Müller et al. 2007,
    /// eq. 9, as forces −(k C + c Ċ)∇C). Each lane's arithmetic is the same IEEE operations on
    /// every width, so the width changes no bit.
    #[inline(always)]
    pub fn group_forces<const W: usize>(
        &self,
        coef: &[[f32; 2]],
        from: &Mirror,
        i: usize,
    ) -> [[f32; W]; 3] {
        let m = self.margin;
        // Every load is W values from `at`: the margins and the stride keep them inside.
        let ld = |src: &[f32], at: usize| -> [f32; W] {
            let mut o = [0.0f32; W];
            o.copy_from_slice(&src[at..at + W]);
            o
        };
        let xi = [0, 1, 2].map(|a| ld(&from.x[a], m + i));
        let vi = [0, 1, 2].map(|a| ld(&from.v[a], m + i));
        let (mut fx, mut fy, mut fz) = ([0.0f32; W], [0.0f32; W], [0.0f32; W]);
        for (s, &o) in self.offsets.iter().enumerate() {
            let at = (m + i).wrapping_add_signed(o);
            let xj = [0, 1, 2].map(|a| ld(&from.x[a], at));
            let vj = [0, 1, 2].map(|a| ld(&from.v[a], at));
            let rest = ld(&self.rest, s * self.stride + i);
            let [k, c] = coef[s];
            let mut d = [[0.0f32; W]; 3];
            let mut dv = [[0.0f32; W]; 3];
            for a in 0..3 {
                for l in 0..W {
                    d[a][l] = xj[a][l] - xi[a][l];
                    dv[a][l] = vj[a][l] - vi[a][l];
                }
            }
            let mut scale = [0.0f32; W];
            for l in 0..W {
                let len2 = d[0][l] * d[0][l] + d[1][l] * d[1][l] + d[2][l] * d[2][l];
                let rate = d[0][l] * dv[0][l] + d[1][l] * dv[1][l] + d[2][l] * dv[2][l];
                let len = len2.sqrt();
                let inv = 1.0 / len;
                // (k C + c Ċ)/|d|, with Ċ = d·(v_j − v_i)/|d|.
                let t = k * (len - rest[l]) * inv + c * rate * (inv * inv);
                scale[l] = if rest[l] >= 0.0 && len > MIN_LEN {
                    t
                } else {
                    0.0
                };
            }
            for l in 0..W {
                fx[l] += scale[l] * d[0][l];
                fy[l] += scale[l] * d[1][l];
                fz[l] += scale[l] * d[2][l];
            }
        }
        [fx, fy, fz]
    }
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
        /// Every particle's force, `W` lanes at a time.
        fn all<const W: usize>(
            st: &SpringStencil,
            coef: &[[f32; 2]],
            m: &Mirror,
            n: usize,
        ) -> Vec<[f32; 3]> {
            let mut out = Vec::new();
            for i in (0..st.stride()).step_by(W) {
                let f = st.group_forces::<W>(coef, m, i);
                out.extend((0..W).map(|l| [f[0][l], f[1][l], f[2][l]]));
            }
            out.truncate(n);
            out
        }
        let mut first: Option<Vec<[f32; 3]>> = None;
        let widths = [
            (4, all::<4>(&st, &coef, &mirror, x.len())),
            (8, all::<8>(&st, &coef, &mirror, x.len())),
            (16, all::<16>(&st, &coef, &mirror, x.len())),
        ];
        for (path, got) in widths {
            let largest = want.iter().map(|f| f.length()).fold(0.0, f64::max);
            assert!(largest > 1.0);
            for (g, f) in got.iter().zip(&want) {
                let g = DVec3::new(g[0].into(), g[1].into(), g[2].into());
                assert!(
                    (g - *f).length() < 1e-4 * largest,
                    "{path} lanes: {g} against {f}"
                );
            }
            // Momentum: the forces cancel to f32 rounding of their sum.
            let total: DVec3 = got
                .iter()
                .map(|g| DVec3::new(g[0].into(), g[1].into(), g[2].into()))
                .sum();
            assert!(total.length() < 1e-5 * largest, "{path} lanes: {total}");
            match &first {
                Some(f) => assert_eq!(
                    f.iter().flatten().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    got.iter()
                        .flatten()
                        .map(|v| v.to_bits())
                        .collect::<Vec<_>>(),
                    "{path} lanes"
                ),
                None => first = Some(got),
            }
        }
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
