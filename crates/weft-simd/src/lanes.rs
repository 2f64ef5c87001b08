//! The vector operations Weft's explicit-SIMD kernels share, over any [`pulp::Simd`]: `L`
//! f64 lanes at once (eight on AVX-512, four on AVX2, two portable, one scalar), each lane
//! running the same IEEE operations in the same order (no fused multiply-adds), so a kernel
//! gives the same bits at every width.

use pulp::{Scalar128b, Simd, WithSimd};

use crate::path::SimdPath;

/// A 3-vector of lanes, one vector per axis.
pub type V3<S> = [<S as Simd>::f64s; 3];

/// A kernel written over `L` f64 lanes of any [`Simd`] (`L` = `S`'s f64 lanes).
pub trait LaneKernel {
    /// What the kernel returns.
    type Output;

    /// Runs the kernel on the vectors of `s`.
    fn run<S: Simd, const L: usize>(self, s: S) -> Self::Output;
}

/// Runs `kernel` on kernel path `path`: eight lanes on the AVX-512 path (`pulp`'s `V4`), four
/// on AVX2 (`V3`; also the AVX-512 path's fallback on a CPU without it), each entered through
/// `vectorize` so that the kernel compiles with those features; elsewhere two lanes of
/// portable code. Every width gives the same bits.
#[inline(always)]
pub fn on_path<K: LaneKernel>(path: SimdPath, kernel: K) -> K::Output {
    match path {
        #[cfg(target_arch = "x86_64")]
        SimdPath::Avx512 => match (pulp::x86::V4::try_new(), pulp::x86::V3::try_new()) {
            (Some(v4), _) => Simd::vectorize(v4, Lanes::<K, 8>(kernel)),
            (None, Some(v3)) => Simd::vectorize(v3, Lanes::<K, 4>(kernel)),
            (None, None) => kernel.run::<_, 2>(Scalar128b),
        },
        #[cfg(target_arch = "x86_64")]
        SimdPath::Avx2 => match pulp::x86::V3::try_new() {
            Some(v3) => Simd::vectorize(v3, Lanes::<K, 4>(kernel)),
            None => kernel.run::<_, 2>(Scalar128b),
        },
        _ => kernel.run::<_, 2>(Scalar128b),
    }
}

/// A [`LaneKernel`] at `L` lanes, as `pulp`'s `vectorize` takes it.
struct Lanes<K, const L: usize>(K);

impl<K: LaneKernel, const L: usize> WithSimd for Lanes<K, L> {
    type Output = K::Output;

    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> K::Output {
        self.0.run::<S, L>(s)
    }
}

/// The lanes of `a` as one vector of `S` (`L` = `S`'s f64 lanes).
#[inline(always)]
pub fn load<S: Simd, const L: usize>(a: [f64; L]) -> S::f64s {
    bytemuck::cast(a)
}

/// The lanes of `v` as an array.
#[inline(always)]
pub fn store<S: Simd, const L: usize>(v: S::f64s) -> [f64; L] {
    bytemuck::cast(v)
}

/// Lanes per axis as one vector per axis.
#[inline(always)]
pub fn load3<S: Simd, const L: usize>(v: &[[f64; L]; 3]) -> V3<S> {
    [load::<S, L>(v[0]), load::<S, L>(v[1]), load::<S, L>(v[2])]
}

/// One vector per axis as lanes per axis.
#[inline(always)]
pub fn store3<S: Simd, const L: usize>(v: &V3<S>) -> [[f64; L]; 3] {
    [
        store::<S, L>(v[0]),
        store::<S, L>(v[1]),
        store::<S, L>(v[2]),
    ]
}

/// Values `s .. s + L` of `v` as one vector (NaN in every lane where they run past its end).
#[inline(always)]
pub fn load_at<S: Simd, const L: usize>(v: &[f64], s: usize) -> S::f64s {
    match v.get(s..s + L).and_then(|c| c.first_chunk::<L>()) {
        Some(c) => load::<S, L>(*c),
        None => load::<S, L>([f64::NAN; L]),
    }
}

/// The operations on `S`, as functions rather than closures: a closure is a function of its
/// own without the target features, into which the intrinsics do not inline (measured:
/// `_mm256_mul_pd` as a call, the dihedral kernel twice as slow as scalar code).
#[derive(Clone, Copy)]
pub struct Ops<S>(pub S);

/// `Ops` methods that forward two vectors to a `Simd` method of the same meaning.
macro_rules! binary {
    ($($(#[$doc:meta])* $name:ident => $method:ident -> $out:ident;)*) => {
        $(
            $(#[$doc])*
            #[inline(always)]
            pub fn $name(self, a: S::f64s, b: S::f64s) -> S::$out {
                self.0.$method(a, b)
            }
        )*
    };
}

impl<S: Simd> Ops<S> {
    binary! {
        /// a + b.
        add => add_f64s -> f64s;
        /// a − b.
        sub => sub_f64s -> f64s;
        /// a · b.
        mul => mul_f64s -> f64s;
        /// a / b.
        div => div_f64s -> f64s;
        /// a > b.
        gt => greater_than_f64s -> m64s;
        /// a ≥ b.
        ge => greater_than_or_equal_f64s -> m64s;
        /// a ≤ b.
        le => less_than_or_equal_f64s -> m64s;
        /// a < b.
        lt => less_than_f64s -> m64s;
        /// a = b.
        eq => equal_f64s -> m64s;
    }
    /// Every lane `v`.
    #[inline(always)]
    pub fn c(self, v: f64) -> S::f64s {
        self.0.splat_f64s(v)
    }
    /// −a.
    #[inline(always)]
    pub fn neg(self, a: S::f64s) -> S::f64s {
        self.0.neg_f64s(a)
    }
    /// √a.
    #[inline(always)]
    pub fn sqrt(self, a: S::f64s) -> S::f64s {
        self.0.sqrt_f64s(a)
    }
    /// `t` where `m`, else `f`.
    #[inline(always)]
    pub fn sel(self, m: S::m64s, t: S::f64s, f: S::f64s) -> S::f64s {
        self.0.select_f64s(m, t, f)
    }
    /// a ∧ b.
    #[inline(always)]
    pub fn and(self, a: S::m64s, b: S::m64s) -> S::m64s {
        self.0.and_m64s(a, b)
    }
    /// a ∨ b.
    #[inline(always)]
    pub fn or(self, a: S::m64s, b: S::m64s) -> S::m64s {
        self.0.or_m64s(a, b)
    }
    /// ¬a.
    #[inline(always)]
    pub fn not(self, a: S::m64s) -> S::m64s {
        self.0.not_m64s(a)
    }
    /// Whether any lane of `m` is set.
    #[inline(always)]
    pub fn any(self, m: S::m64s) -> bool {
        self.0.first_true_m64s(m) < S::F64_LANES
    }
    /// `m` per lane (`L` = `S`'s f64 lanes).
    #[inline(always)]
    pub fn bits<const L: usize>(self, m: S::m64s) -> [bool; L] {
        let ones = self.sel(m, self.c(1.0), self.c(0.0));
        store::<S, L>(ones).map(|v| v != 0.0)
    }
    /// max(a, b) as `f64::max` gives it where b is not NaN (b where a is).
    #[inline(always)]
    pub fn max(self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.sel(self.gt(a, b), a, b)
    }
    /// min(a, b) as `f64::min` gives it where b is not NaN (b where a is).
    #[inline(always)]
    pub fn min(self, a: S::f64s, b: S::f64s) -> S::f64s {
        self.sel(self.lt(a, b), a, b)
    }
    /// a − b per axis.
    #[inline(always)]
    pub fn dif(self, a: &V3<S>, b: &V3<S>) -> V3<S> {
        [
            self.sub(a[0], b[0]),
            self.sub(a[1], b[1]),
            self.sub(a[2], b[2]),
        ]
    }
    /// u × v.
    #[inline(always)]
    pub fn cross(self, u: &V3<S>, v: &V3<S>) -> V3<S> {
        [
            self.sub(self.mul(u[1], v[2]), self.mul(u[2], v[1])),
            self.sub(self.mul(u[2], v[0]), self.mul(u[0], v[2])),
            self.sub(self.mul(u[0], v[1]), self.mul(u[1], v[0])),
        ]
    }
    /// u · v, summed from x to z.
    #[inline(always)]
    pub fn dot(self, u: &V3<S>, v: &V3<S>) -> S::f64s {
        let xy = self.add(self.mul(u[0], v[0]), self.mul(u[1], v[1]));
        self.add(xy, self.mul(u[2], v[2]))
    }
}
