//! The four-particle shapes' lane kernels as one interface: [`QuadLanes`] projects `L`
//! dihedral ([`super::dihedral_lanes`]) or isometric ([`super::isometric_lanes`]) bending
//! constraints at once in the vectors of a [`Simd`], or one at a time from constants prepared
//! once a frame ([`FrameConstants`]); the sweep in [`super::quad_sweep`] runs either.

use pulp::Simd;

use super::lanes::{Coef, Coefs, Quads};
use super::{Dihedral, Isometric, Shape, dihedral_lanes, isometric_lanes};

/// A four-particle shape with a kernel projecting `L` independent constraints at once in the
/// vectors of a [`Simd`], every lane with the same IEEE operations (the same bits on every
/// path and width).
pub(crate) trait QuadLanes: Shape<4> {
    /// Projects the constraints `shapes` (one per lane) on `x` in place, with their
    /// multipliers `lambda` (constraint `l`'s at `l * MULTIPLIERS ..`); `prev` is read only
    /// when `DAMPED`.
    #[allow(clippy::too_many_arguments)]
    fn project_lanes<S: Simd, const L: usize, const DAMPED: bool>(
        s: S,
        x: &mut Quads<L>,
        prev: &Quads<L>,
        w: &[[f64; L]; 4],
        shapes: &[Self; L],
        coef: &Coefs<L>,
        lambda: &mut [f64],
    );

    /// Σᵢ wᵢ |∇ᵢC|² of the constraint on particles of inverse masses `w` where it does not
    /// depend on the positions (per axis, for a vector constraint), else `None`.
    fn constant_stiffness(&self, _w: [f64; 4]) -> Option<f64> {
        None
    }

    /// Whether the kernel pays for its lanes: when its arithmetic outweighs moving twelve
    /// coordinates per constraint between the particles and the lanes and back. Where it does
    /// not, every kernel path projects one constraint at a time (the one-lane kernel, the
    /// same bits).
    const WIDE: bool = true;

    /// What a constraint's projection computes from the inverse masses and coefficients
    /// alone, kept over a frame ([`FrameConstants`]).
    type Prepared: Copy + Send + Sync;

    /// The constants of this constraint on particles of inverse masses `w` with `coef`, or
    /// `None` for a shape that keeps none.
    fn prepare(&self, _w: [f64; 4], _coef: &Coefs<1>) -> Option<Self::Prepared> {
        None
    }

    /// [`QuadLanes::project_lanes`] of this one constraint with its constants `prep` from
    /// [`QuadLanes::prepare`]: the same bits.
    fn project_prepared<const DAMPED: bool>(
        &self,
        prep: &Self::Prepared,
        x: &mut Quads<1>,
        prev: &Quads<1>,
        coef: &Coefs<1>,
        lambda: &mut [f64],
    );
}

/// A shape that keeps no constants: no value exists, so its
/// [`QuadLanes::project_prepared`] cannot be called.
#[derive(Clone, Copy, Debug)]
pub(crate) enum NoConstants {}

/// A block's per-constraint constants for a frame ([`QuadLanes::prepare`]) and the inverse
/// masses and coefficients they hold for: recomputed only when those change (a grab, a
/// pin, an edited parameter, a new time step).
#[derive(Clone, Debug)]
pub(crate) struct FrameConstants<P> {
    /// One per constraint, in block order; empty when the shape keeps none.
    pub(super) values: Vec<P>,
    /// The inverse masses they were prepared for, in block order.
    pub(super) w: Vec<f64>,
    /// The group coefficients they were prepared for.
    pub(super) coef: Vec<Coef>,
}

impl<P> Default for FrameConstants<P> {
    fn default() -> Self {
        Self {
            values: Vec::new(),
            w: Vec::new(),
            coef: Vec::new(),
        }
    }
}

impl<P> FrameConstants<P> {
    /// The constants, one per constraint (empty: none kept).
    #[cfg(test)]
    pub fn values(&self) -> &[P] {
        &self.values
    }
}

impl QuadLanes for Dihedral {
    type Prepared = NoConstants;

    fn project_prepared<const DAMPED: bool>(
        &self,
        prep: &NoConstants,
        _x: &mut Quads<1>,
        _prev: &Quads<1>,
        _coef: &Coefs<1>,
        _lambda: &mut [f64],
    ) {
        match *prep {}
    }

    #[inline(always)]
    fn project_lanes<S: Simd, const L: usize, const DAMPED: bool>(
        s: S,
        x: &mut Quads<L>,
        prev: &Quads<L>,
        w: &[[f64; L]; 4],
        shapes: &[Self; L],
        coef: &Coefs<L>,
        lambda: &mut [f64],
    ) {
        let rest: [f64; L] = std::array::from_fn(|l| shapes[l].rest);
        let lambda: &mut [f64; L] = match lambda.try_into() {
            Ok(a) => a,
            Err(_) => return,
        };
        dihedral_lanes::project::<S, L, DAMPED>(s, x, prev, w, &rest, coef, lambda);
    }
}

impl QuadLanes for Isometric {
    /// A dozen flops per axis against twelve gathered and twelve scattered coordinates: one
    /// lane at a time is the quicker (T-shirt, solve only, 1 thread, AVX-512: 8.0 ms per
    /// frame with eight lanes, 8.1–8.5 with four, 8.8 with two, 7.2 with one).
    const WIDE: bool = false;

    /// ∇ᵢCₐ = kᵢ on axis a for every configuration: [`Isometric::stiffness`].
    fn constant_stiffness(&self, w: [f64; 4]) -> Option<f64> {
        Some(self.stiffness(w))
    }

    /// The steps wᵢkᵢ and the inverse denominator: the weights are constant, so all of the
    /// projection but the positions' part (T-shirt, 1 thread: the isometric sweep 4.4 → 3.1 ms
    /// per frame).
    type Prepared = isometric_lanes::Prepared;

    fn prepare(&self, w: [f64; 4], coef: &Coefs<1>) -> Option<isometric_lanes::Prepared> {
        Some(isometric_lanes::Prepared::new(w, self.weights, coef))
    }

    #[inline(always)]
    fn project_prepared<const DAMPED: bool>(
        &self,
        prep: &isometric_lanes::Prepared,
        x: &mut Quads<1>,
        prev: &Quads<1>,
        coef: &Coefs<1>,
        lambda: &mut [f64],
    ) {
        let Ok(lambda) = <&mut [f64; 3]>::try_from(lambda) else {
            return;
        };
        let mut lam = lambda.map(|v| [v]);
        prep.project::<DAMPED>(x, prev, self.weights, coef, &mut lam);
        *lambda = lam.map(|v| v[0]);
    }

    #[inline(always)]
    fn project_lanes<S: Simd, const L: usize, const DAMPED: bool>(
        s: S,
        x: &mut Quads<L>,
        prev: &Quads<L>,
        w: &[[f64; L]; 4],
        shapes: &[Self; L],
        coef: &Coefs<L>,
        lambda: &mut [f64],
    ) {
        let k: [[f64; L]; 4] =
            std::array::from_fn(|v| std::array::from_fn(|l| shapes[l].weights[v]));
        if lambda.len() != 3 * L {
            return;
        }
        let mut lam: [[f64; L]; 3] =
            std::array::from_fn(|a| std::array::from_fn(|l| lambda[3 * l + a]));
        isometric_lanes::project::<S, L, DAMPED>(s, x, prev, w, &k, coef, &mut lam);
        for l in 0..L {
            for a in 0..3 {
                lambda[3 * l + a] = lam[a][l];
            }
        }
    }
}
