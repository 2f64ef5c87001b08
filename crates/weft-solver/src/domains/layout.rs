//! How the eight constraints of a chunk reach their particles: unit-stride windows where the
//! particles are consecutive, gathers elsewhere.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use crate::constraints::lanes::LANES;

/// How the eight constraints of a chunk reach their particles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Layout {
    /// p = p₀ + l and q = q₀ + l: two unit-stride loads per axis.
    Contiguous,
    /// p = p₀ + 2l and q = p + 1: one unit-stride load of 16 particles, de-interleaved.
    Paired,
    /// p = p₀ + (0, 1, 4, 5, 8, 9, 12, 13) and q = p + 2 (every other pair of a row's
    /// two-apart bending pairs): one unit-stride load of 16 particles, permuted.
    Quad,
    /// p = p₀ + 4l and q = p + 2 (two-apart bending pairs at every other vertex): one
    /// unit-stride load of 31 particles, permuted.
    Spaced,
    /// p = p₀ + 2l and q = q₀ + 2l with the two 15-particle windows apart: two unit-stride
    /// loads, even slots taken (a diagonal family on alternating-diagonal grids).
    Strided,
    /// Anything else: one load per lane.
    Gathered,
}

/// A full chunk of [`LANES`] constraints.
#[derive(Clone, Copy, Debug)]
pub(super) struct Chunk {
    /// First constraint of the chunk.
    pub start: usize,
    /// How its lanes reach their particles.
    pub layout: Layout,
    /// All lanes share one parameter group.
    pub uniform: bool,
    /// All lanes share one rest length, [`Chunk::rest`].
    pub same_rest: bool,
    /// The first lane's particles (all a structured layout needs: the others follow from it).
    pub p0: u32,
    /// The first lane's second particle.
    pub q0: u32,
    /// The first lane's parameter group.
    pub group: u32,
    /// The first lane's rest length (m, f32 like the sweep's arithmetic).
    pub rest: f32,
    /// Bit l set when lane l is a constraint. A dead lane fills a structured window's hole
    /// (a grid row's end): it loads and stores its two particles like any lane, but its
    /// correction factor is forced to zero, so it writes back what it read.
    pub live: u8,
}

/// [`Chunk::live`] of a chunk with no hole.
pub(super) const ALL_LIVE: u8 = u8::MAX;

/// Loads one end of lanes `off..off + W` of a chunk: `idx` gives each lane's particle.
#[inline(always)]
fn gather<T: Copy + Default, const W: usize>(src: &[T], idx: &[u32], off: usize) -> [T; W] {
    // A plain loop: `array::from_fn` here stayed an out-of-line call per gather.
    let mut out = [T::default(); W];
    for l in 0..W {
        out[l] = src[idx[off + l] as usize];
    }
    out
}

#[inline(always)]
fn scatter<T: Copy, const W: usize>(dst: &mut [T], idx: &[u32], off: usize, val: &[T; W]) {
    for l in 0..W {
        dst[idx[off + l] as usize] = val[l];
    }
}

/// Both ends of lanes `off..off + W` of a chunk from one array (positions, previous positions
/// or inverse masses). `W` divides [`LANES`] and `off` is a multiple of `W`: a kernel path
/// projects a chunk in parts as wide as its vector registers, read straight from the layout.
#[inline(always)]
pub(super) fn load_ends<const LAYOUT: u8, const W: usize, T: Copy + Default>(
    src: &[T],
    p: &[u32],
    q: &[u32],
    off: usize,
) -> ([T; W], [T; W]) {
    match layout_of(LAYOUT) {
        Layout::Contiguous => {
            let (p0, q0) = (p[0] as usize + off, q[0] as usize + off);
            let mut a = [T::default(); W];
            let mut b = [T::default(); W];
            a.copy_from_slice(&src[p0..p0 + W]);
            b.copy_from_slice(&src[q0..q0 + W]);
            (a, b)
        }
        Layout::Paired => {
            let p0 = p[0] as usize + 2 * off;
            let s = &src[p0..p0 + 2 * W];
            (
                std::array::from_fn(|l| s[2 * l]),
                std::array::from_fn(|l| s[2 * l + 1]),
            )
        }
        Layout::Quad => {
            // QUAD[off + l] = 2 off + QUAD[l] for the offsets used (multiples of 2).
            let p0 = p[0] as usize + 2 * off;
            let s = &src[p0..p0 + 2 * W];
            (
                std::array::from_fn(|l| s[QUAD[l]]),
                std::array::from_fn(|l| s[QUAD[l] + 2]),
            )
        }
        Layout::Spaced => {
            let p0 = p[0] as usize + 4 * off;
            let s = &src[p0..p0 + 4 * W - 1];
            (
                std::array::from_fn(|l| s[4 * l]),
                std::array::from_fn(|l| s[4 * l + 2]),
            )
        }
        Layout::Strided => {
            let (p0, q0) = (p[0] as usize + 2 * off, q[0] as usize + 2 * off);
            let (sp, sq) = (&src[p0..p0 + 2 * W - 1], &src[q0..q0 + 2 * W - 1]);
            (
                std::array::from_fn(|l| sp[2 * l]),
                std::array::from_fn(|l| sq[2 * l]),
            )
        }
        Layout::Gathered => (gather(src, p, off), gather(src, q, off)),
    }
}

/// Whether every particle lanes `off..off + W` of a chunk reach lies below `n`, in the same
/// terms as [`load_ends`] and [`store_ends`] index: checked once per part, it lets the
/// compiler drop the per-array bounds checks of arrays `n` long.
#[inline(always)]
pub(super) fn window_fits<const LAYOUT: u8, const W: usize>(
    p: &[u32],
    q: &[u32],
    off: usize,
    n: usize,
) -> bool {
    match layout_of(LAYOUT) {
        Layout::Contiguous => {
            let (p0, q0) = (p[0] as usize + off, q[0] as usize + off);
            p0 + W <= n && q0 + W <= n
        }
        Layout::Paired | Layout::Quad => p[0] as usize + 2 * off + 2 * W <= n,
        Layout::Spaced => p[0] as usize + 4 * off + 4 * W - 1 <= n,
        Layout::Strided => {
            let (p0, q0) = (p[0] as usize + 2 * off, q[0] as usize + 2 * off);
            p0 + 2 * W - 1 <= n && q0 + 2 * W - 1 <= n
        }
        Layout::Gathered => (0..W).all(|l| (p[off + l] as usize) < n && (q[off + l] as usize) < n),
    }
}

/// Offsets of the first ends in a [`Layout::Quad`] chunk.
pub(super) const QUAD: [usize; LANES] = [0, 1, 4, 5, 8, 9, 12, 13];

/// Window of a [`Layout::Spaced`] chunk: first ends at 0, 4, …, 28, second ends 2 further.
pub(super) const SPACED: usize = 4 * LANES - 1;

/// Window of a [`Layout::Strided`] end: lanes at even offsets 0..=14.
pub(super) const STRIDED: usize = 2 * LANES - 1;

/// Stores both ends of lanes `off..off + W` of a chunk (see [`load_ends`]).
#[inline(always)]
pub(super) fn store_ends<const LAYOUT: u8, const W: usize, T: Copy + Default>(
    dst: &mut [T],
    p: &[u32],
    q: &[u32],
    off: usize,
    a: &[T; W],
    b: &[T; W],
) {
    match layout_of(LAYOUT) {
        Layout::Contiguous => {
            let (p0, q0) = (p[0] as usize + off, q[0] as usize + off);
            dst[p0..p0 + W].copy_from_slice(a);
            dst[q0..q0 + W].copy_from_slice(b);
        }
        Layout::Paired => {
            let p0 = p[0] as usize + 2 * off;
            let s = &mut dst[p0..p0 + 2 * W];
            for l in 0..W {
                s[2 * l] = a[l];
                s[2 * l + 1] = b[l];
            }
        }
        Layout::Quad => {
            let p0 = p[0] as usize + 2 * off;
            let s = &mut dst[p0..p0 + 2 * W];
            for l in 0..W {
                s[QUAD[l]] = a[l];
                s[QUAD[l] + 2] = b[l];
            }
        }
        Layout::Spaced => {
            // Read, replace the part's slots, write back: the other slots (odd offsets) are
            // particles no lane of this chunk touches, so they keep their values.
            let p0 = p[0] as usize + 4 * off;
            let mut win = [T::default(); SPACED];
            let win = &mut win[..4 * W - 1];
            win.copy_from_slice(&dst[p0..p0 + 4 * W - 1]);
            for l in 0..W {
                win[4 * l] = a[l];
                win[4 * l + 2] = b[l];
            }
            dst[p0..p0 + 4 * W - 1].copy_from_slice(win);
        }
        Layout::Strided => {
            let (p0, q0) = (p[0] as usize + 2 * off, q[0] as usize + 2 * off);
            for (start, v) in [(p0, a), (q0, b)] {
                // Read, replace the even slots, write the window back: the odd slots are
                // particles no other lane of this chunk touches, so they keep their values.
                let mut win = [T::default(); STRIDED];
                let win = &mut win[..2 * W - 1];
                win.copy_from_slice(&dst[start..start + 2 * W - 1]);
                for l in 0..W {
                    win[2 * l] = v[l];
                }
                dst[start..start + 2 * W - 1].copy_from_slice(win);
            }
        }
        Layout::Gathered => {
            scatter(dst, p, off, a);
            scatter(dst, q, off, b);
        }
    }
}

/// The layout a `const` layout number stands for (const generics take no enums on stable).
#[inline(always)]
pub(super) const fn layout_of(n: u8) -> Layout {
    match n {
        0 => Layout::Contiguous,
        1 => Layout::Paired,
        2 => Layout::Quad,
        3 => Layout::Strided,
        4 => Layout::Spaced,
        _ => Layout::Gathered,
    }
}

/// The unit-stride layout eight independent constraints fit, if any.
pub(super) fn structured_layout(p: &[u32], q: &[u32]) -> Option<Layout> {
    let all = |f: &dyn Fn(usize) -> bool| (0..LANES).all(f);
    if all(&|l| p[l] == p[0] + l as u32 && q[l] == q[0] + l as u32) {
        Some(Layout::Contiguous)
    } else if all(&|l| p[l] == p[0] + 2 * l as u32 && q[l] == p[l] + 1) {
        Some(Layout::Paired)
    } else if all(&|l| p[l] == p[0] + QUAD[l] as u32 && q[l] == p[l] + 2) {
        Some(Layout::Quad)
    } else if all(&|l| p[l] == p[0] + 4 * l as u32 && q[l] == p[l] + 2) {
        Some(Layout::Spaced)
    } else if all(&|l| p[l] == p[0] + 2 * l as u32 && q[l] == q[0] + 2 * l as u32)
        && p[0].abs_diff(q[0]) as usize >= STRIDED
    {
        Some(Layout::Strided)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_window_fits_exactly_when_its_last_particle_does() {
        // Contiguous ends 0..8 and 8..16 need 16 particles.
        assert!(window_fits::<0, 8>(&[0], &[8], 0, 16));
        assert!(!window_fits::<0, 8>(&[0], &[8], 0, 15));
        // Paired lanes 4..8 read particles 8..16.
        assert!(window_fits::<1, 4>(&[0], &[1], 4, 16));
        assert!(!window_fits::<1, 4>(&[0], &[1], 4, 15));
        // Spaced: the last second end is p₀ + 4·7 + 2 = 30.
        assert!(window_fits::<4, 8>(&[0], &[2], 0, 31));
        assert!(!window_fits::<4, 8>(&[0], &[2], 0, 30));
        // Strided: the second end's window is q₀..q₀ + 15.
        assert!(window_fits::<3, 8>(&[0], &[20], 0, 35));
        assert!(!window_fits::<3, 8>(&[0], &[20], 0, 34));
        // Gathered: every lane's own particles.
        let (p, q) = ([0, 2, 4, 6], [1, 3, 5, 9]);
        assert!(window_fits::<5, 4>(&p, &q, 0, 10));
        assert!(!window_fits::<5, 4>(&p, &q, 0, 9));
    }
}
