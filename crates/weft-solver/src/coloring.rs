//! Greedy graph colouring: constraints of one colour share no free particle.

/// Colours constraints so that no two of one colour share a free particle.
///
/// Pinned particles (`free[i] == false`) never move, so sharing them is harmless and they do
/// not count. Constraints are visited in order and take the smallest colour their particles do
/// not use yet; the result is deterministic.
pub(crate) fn color<const N: usize>(constraints: &[[u32; N]], free: &[bool]) -> Vec<u32> {
    let mut used: Vec<Vec<u32>> = vec![Vec::new(); free.len()];
    let mut taken = Vec::new();
    constraints
        .iter()
        .map(|c| {
            taken.clear();
            for &p in c.iter().filter(|&&p| free[p as usize]) {
                taken.extend_from_slice(&used[p as usize]);
            }
            taken.sort_unstable();
            taken.dedup();
            let colour = taken
                .iter()
                .enumerate()
                .find(|&(k, &c)| k as u32 != c)
                .map_or(taken.len() as u32, |(k, _)| k as u32);
            for &p in c.iter().filter(|&&p| free[p as usize]) {
                used[p as usize].push(colour);
            }
            colour
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chain_needs_two_colours_and_no_colour_shares_a_free_particle() {
        let chain: Vec<[u32; 2]> = (0..10).map(|i| [i, i + 1]).collect();
        let colours = color(&chain, &[true; 11]);
        assert_eq!(*colours.iter().max().expect("non-empty"), 1);
        for (a, ca) in chain.iter().zip(&colours) {
            for (b, cb) in chain.iter().zip(&colours) {
                if a != b && ca == cb {
                    assert!(
                        a.iter().all(|p| !b.contains(p)),
                        "{a:?} and {b:?} share colour {ca}"
                    );
                }
            }
        }
    }

    #[test]
    fn pinned_particles_do_not_separate_colours() {
        // A star around pinned particle 0: every spoke may share one colour.
        let star: Vec<[u32; 2]> = (1..6).map(|i| [0, i]).collect();
        let mut free = [true; 6];
        assert_eq!(color(&star, &free), vec![0, 1, 2, 3, 4]);
        free[0] = false;
        assert_eq!(color(&star, &free), vec![0; 5]);
    }
}
