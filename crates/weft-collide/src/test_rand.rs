//! A deterministic pseudo-random source for the crate's tests.

/// A pseudo-random number in [−1, 1), advancing `state` (64-bit LCG, Knuth's MMIX constants).
pub(crate) fn rand(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}
