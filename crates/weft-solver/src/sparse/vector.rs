//! Per-particle vector passes in parallel chunks, with sums taken in chunk order (the same
//! bits on any thread count).

use glam::DVec3;
use rayon::prelude::*;

use crate::chunk::CHUNK;

#[cfg(test)]
/// Σ a·b over chunks of [`CHUNK`] particles, the chunks' partial sums added in order.
pub(crate) fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    let partials: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .map(|(a, b)| a.iter().zip(b).map(|(a, b)| a.dot(*b)).sum::<f64>())
        .collect();
    partials.iter().sum()
}

/// `p ← z + β p` in parallel.
pub(crate) fn xpby(z: &[DVec3], beta: f64, p: &mut [DVec3]) {
    p.par_chunks_mut(CHUNK)
        .zip(z.par_chunks(CHUNK))
        .for_each(|(p, z)| {
            for (p, z) in p.iter_mut().zip(z) {
                *p = *z + *p * beta;
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_and_update_agree_with_serial_loops() {
        let n = 3 * CHUNK + 17;
        let a: Vec<DVec3> = (0..n).map(|i| DVec3::splat(i as f64 * 0.5)).collect();
        let b: Vec<DVec3> = (0..n).map(|i| DVec3::new(1.0, -2.0, i as f64)).collect();
        let serial: f64 = a
            .chunks(CHUNK)
            .zip(b.chunks(CHUNK))
            .map(|(a, b)| a.iter().zip(b).map(|(a, b)| a.dot(*b)).sum::<f64>())
            .sum();
        assert_eq!(dot(&a, &b), serial);
        let mut p = b.clone();
        xpby(&a, 2.0, &mut p);
        for i in 0..n {
            assert_eq!(p[i], a[i] + b[i] * 2.0);
        }
    }
}
