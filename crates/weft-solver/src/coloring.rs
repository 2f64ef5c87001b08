//! Greedy graph colouring: constraints of one colour share no free particle.

/// Colours constraints so that no two of one colour share a free particle.
///
/// Pinned particles (`free[i] == false`) never move, so sharing them is harmless and they do
/// not count. Constraints are visited in order and take the smallest colour their particles do
/// not use yet; the result is deterministic. Each particle's colours below 64 are one bit each
/// of a word (a 1024² cloth's build made a million small lists before); the rare higher ones
/// are listed per particle.
pub(crate) fn color<const N: usize>(constraints: &[[u32; N]], free: &[bool]) -> Vec<u32> {
    let mut low = vec![0u64; free.len()];
    let mut high: std::collections::HashMap<u32, Vec<u32>> = Default::default();
    let mut taken = Vec::new();
    constraints
        .iter()
        .map(|c| {
            let free_of = || c.iter().copied().filter(|&p| free[p as usize]);
            let mask = free_of().fold(0u64, |m, p| m | low[p as usize]);
            let colour = if mask != u64::MAX {
                (!mask).trailing_zeros()
            } else {
                taken.clear();
                for p in free_of() {
                    taken.extend(high.get(&p).into_iter().flatten());
                }
                taken.sort_unstable();
                taken.dedup();
                // The smallest colour from 64 on that none of them uses.
                (64..)
                    .zip(&taken)
                    .find(|&(k, &c)| k != c)
                    .map_or(64 + taken.len() as u32, |(k, _)| k)
            };
            for p in free_of() {
                if colour < 64 {
                    low[p as usize] |= 1 << colour;
                } else {
                    high.entry(p).or_default().push(colour);
                }
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

    /// The list-per-particle colouring this replaces.
    fn by_lists<const N: usize>(constraints: &[[u32; N]], free: &[bool]) -> Vec<u32> {
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
                let colour = (taken.iter().enumerate())
                    .find(|&(k, &c)| k as u32 != c)
                    .map_or(taken.len() as u32, |(k, _)| k as u32);
                for &p in c.iter().filter(|&&p| free[p as usize]) {
                    used[p as usize].push(colour);
                }
                colour
            })
            .collect()
    }

    #[test]
    fn bit_words_colour_as_lists_did_past_64_colours() {
        // Pseudo-random pairs over 300 particles, a hub in 150 of them (colours past 64), and
        // every tenth particle pinned.
        let mut seed = 12345u64;
        let mut next = |n: u64| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) % n) as u32
        };
        let mut pairs: Vec<[u32; 2]> = (0..2000).map(|_| [next(300), next(300)]).collect();
        pairs.retain(|[a, b]| a != b);
        pairs.extend((1..151).map(|i| [0, i]));
        let free: Vec<bool> = (0..300).map(|i| i % 10 != 5).collect();
        let colours = color(&pairs, &free);
        assert_eq!(colours, by_lists(&pairs, &free));
        assert!(*colours.iter().max().expect("colours") >= 150);
    }
}
