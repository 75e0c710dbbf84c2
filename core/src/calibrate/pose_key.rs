//! Deals poses by the poses themselves, not by a seed: each pose gets a 64-bit
//! key mixed from the bits of its numbers (splitmix64's finaliser, Steele, Lea
//! and Flood 2014, applied after each word), and whatever a cross-validation
//! would draw at random (its folds, its regions' first centre, a holdout) is
//! drawn in the order of the keys (then of the indices, for identical rows).
//! So the draw is the same whatever the calibration's seed and whatever the
//! order of the rows, and the keys' mixing spreads neighbouring poses as a
//! shuffle would. Units do not matter: a key reads the numbers' bits.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// splitmix64's finaliser: a bijection of `u64` whose every output bit
/// depends on every input bit.
pub fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The key of a pose given as the numbers that make it (module docs).
pub fn key_of(numbers: impl IntoIterator<Item = f64>) -> u64 {
    words_key(numbers.into_iter().map(f64::to_bits))
}

/// The key of a pose given as 64-bit words (module docs).
pub fn words_key(words: impl IntoIterator<Item = u64>) -> u64 {
    words.into_iter().fold(0x9E37_79B9_7F4A_7C15, |h, w| {
        mix(h.wrapping_add(w).wrapping_add(0x9E37_79B9_7F4A_7C15))
    })
}

/// The indices of `keys` in the order of the keys, then of the indices.
pub fn key_order(keys: &[u64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..keys.len()).collect();
    order.sort_by_key(|i| (keys[*i], *i));
    order
}

/// The fold of each pose: the poses in key order dealt to `folds` folds in
/// turn, so each holds ⌊n/F⌋ or ⌈n/F⌉ poses.
pub fn deal(keys: &[u64], folds: usize) -> Vec<usize> {
    let mut fold = vec![0; keys.len()];
    for (pos, i) in key_order(keys).into_iter().enumerate() {
        fold[i] = pos % folds.max(1);
    }
    fold
}

/// A generator seeded by the set of keys (their wrapping sum, so the rows'
/// order does not matter), for a draw that must be random-like yet the same
/// for the same poses.
pub fn generator_of(keys: &[u64]) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(mix(keys.iter().fold(0u64, |s, k| s.wrapping_add(*k))))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Balanced folds, every pose in one, and the same poses together
    /// however the rows are ordered.
    #[test]
    fn dealt_folds_follow_the_poses_not_their_order() {
        let keys: Vec<u64> = (0..103).map(|i| key_of([0.01 * i as f64, -0.5])).collect();
        let fold = deal(&keys, 5);
        let mut sizes = [0; 5];
        for f in &fold {
            sizes[*f] += 1;
        }
        assert!(sizes.iter().all(|s| *s == 20 || *s == 21), "{sizes:?}");
        let reversed: Vec<u64> = keys.iter().rev().copied().collect();
        let again = deal(&reversed, 5);
        for i in 0..103 {
            assert_eq!(fold[i], again[102 - i]);
        }
        // Neighbouring poses are spread: not every run of five in one fold.
        assert!(fold.windows(5).any(|w| w.iter().any(|f| *f != w[0])));
    }

    /// The generator depends on the set of poses only.
    #[test]
    fn the_generator_ignores_the_rows_order() {
        use rand::Rng;
        let keys: Vec<u64> = (0..10).map(|i| key_of([i as f64])).collect();
        let mut rev = keys.clone();
        rev.reverse();
        let a: u64 = generator_of(&keys).gen();
        let b: u64 = generator_of(&rev).gen();
        let c: u64 = generator_of(&keys[1..]).gen();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}
