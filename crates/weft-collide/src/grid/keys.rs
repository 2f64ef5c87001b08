//! Cell keys: a point's grid cell packed into one integer whose order is the cells'
//! lexicographic order, the key offsets of neighbour columns, and the radix sort of compact
//! keys that orders a build.

use glam::DVec3;

/// Bits of a digit of the radix sort.
pub(super) const DIGIT: u32 = 11;

/// Sorts `v` stably by its high 32 bits, of which only the low `bits` may be set: a
/// least-significant-digit radix sort, one counting pass and one scatter per [`DIGIT`] bits
/// (Knuth, TAOCP vol. 3, §5.2.5). `copy` is scratch.
pub(super) fn radix_sort(v: &mut Vec<u64>, copy: &mut Vec<u64>, bits: u32) {
    copy.resize(v.len(), 0);
    let mut shift = 32;
    while shift < 32 + bits {
        let digit = |x: u64| ((x >> shift) & ((1 << DIGIT) - 1)) as usize;
        let mut start = [0usize; 1 << DIGIT];
        for &x in v.iter() {
            start[digit(x)] += 1;
        }
        let mut sum = 0;
        for s in &mut start {
            (*s, sum) = (sum, sum + *s);
        }
        for &x in v.iter() {
            let d = digit(x);
            copy[start[d]] = x;
            start[d] += 1;
        }
        std::mem::swap(v, copy);
        shift += DIGIT;
    }
}

/// Keys made compact to the box of the cells in use: a cell's offsets from the box's lowest
/// cell, packed x, y, z with just the bits each needs, so that they sort as the keys do.
#[derive(Clone, Copy, Debug)]
pub(super) struct Compact {
    lo: [u64; 3],
    /// Shifts of x and y in the compact key (z is not shifted).
    shift: [u32; 2],
    /// Bits of the compact key.
    pub(super) bits: u32,
}

impl Compact {
    /// The packing for `keys`, or `None` when it needs more than 32 bits.
    pub(super) fn of(keys: impl Iterator<Item = u64>) -> Option<Self> {
        let (mut lo, mut hi) = ([u64::MAX; 3], [0u64; 3]);
        for key in keys {
            for (axis, v) in Self::fields(key).into_iter().enumerate() {
                lo[axis] = lo[axis].min(v);
                hi[axis] = hi[axis].max(v);
            }
        }
        let width = |a: usize| {
            (hi[a].saturating_sub(lo[a]))
                .checked_ilog2()
                .map_or(0, |b| b + 1)
        };
        let (wx, wy, wz) = (width(0), width(1), width(2));
        let bits = wx + wy + wz;
        (bits <= 32).then_some(Self {
            lo,
            shift: [wy + wz, wz],
            bits,
        })
    }

    /// A key's x, y and z cell coordinates.
    fn fields(key: u64) -> [u64; 3] {
        let mask = (1 << BITS) - 1;
        [key >> (2 * BITS), (key >> BITS) & mask, key & mask]
    }

    /// The compact form of `key` (a key of the cells the packing was made for).
    pub(super) fn apply(&self, key: u64) -> u64 {
        let [x, y, z] = Self::fields(key);
        ((x - self.lo[0]) << self.shift[0]) | ((y - self.lo[1]) << self.shift[1]) | (z - self.lo[2])
    }
}

/// Bits per cell coordinate in a cell key.
pub(super) const BITS: u32 = 21;
/// Key steps of one cell along y and along x (z is 1).
pub(super) const Y: u64 = 1 << BITS;
pub(super) const X: u64 = 1 << (2 * BITS);

/// The key of the cell holding `p`: its coordinates, offset to be positive and clamped to
/// 1..2²¹ − 2, packed x, y, z from the high bits, so that key order is lexicographic cell
/// order and a neighbour's key is the key ± 1, ± Y, ± X. Clamping is 1-Lipschitz: cells that
/// are neighbours stay neighbours (or merge), so no close pair is lost; only points more than
/// 2²⁰ cells from the origin share border cells.
///
/// The floor is taken without `f64::floor`, a call into libm on the baseline x86-64 target,
/// and without converting an integer back to a float (whose false dependency on the target
/// register chained every key): the coordinate is clamped to ±2²¹ cells (beyond which every
/// key component is clamped anyway), rounded to an integer by adding and subtracting
/// 1.5 · 2⁵² (exact there: the unit in the last place is 1; Rust never reassociates the two),
/// and stepped down where that rounded up. A NaN coordinate converts to 0: such points
/// gather in one cell.
#[inline]
pub(super) fn cell_key(p: DVec3, inv_spacing: f64) -> u64 {
    const LIMIT: f64 = (1u64 << (BITS)) as f64;
    const ROUND: f64 = 1.5 * (1u64 << 52) as f64;
    let half = 1i64 << (BITS - 1);
    let max = (1i64 << BITS) - 2;
    let k = |v: f64| {
        let v = (v * inv_spacing).clamp(-LIMIT, LIMIT);
        let r = (v + ROUND) - ROUND;
        let floor = if r > v { r - 1.0 } else { r };
        (floor as i64 + half).clamp(1, max) as u64
    };
    (k(p.x) << (2 * BITS)) | (k(p.y) << BITS) | k(p.z)
}

/// Neighbour columns (dx, dy) after a cell's own in key order, each visited over
/// dz ∈ −1..=1: with the cell itself and the cell above it (0, 0, +1) they are the 13
/// lexicographically positive neighbours, so each pair of neighbouring cells is visited once.
/// As key offsets from (x, y, z) to (x + dx, y + dy, z − 1).
pub(super) const COLUMNS: [u64; 4] = [Y - 1, X - Y - 1, X - 1, X + Y - 1];

/// All nine neighbour columns (dx, dy ∈ −1..=1) in key order, as key offsets from
/// (x − 1, y − 1, z − 1) to (x + dx, y + dy, z − 1).
pub(super) const NEAR_COLUMNS: [u64; 9] = [
    0,
    Y,
    2 * Y,
    X,
    X + Y,
    X + 2 * Y,
    2 * X,
    2 * X + Y,
    2 * X + 2 * Y,
];
