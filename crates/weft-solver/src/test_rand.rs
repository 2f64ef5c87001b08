//! A seeded random source for unit tests (xorshift64, Marsaglia 2003): reproducible inputs
//! without a dependency.

/// Uniform numbers in [−0.5, 0.5) from `seed` (which must not be 0).
pub(crate) fn rng(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}
