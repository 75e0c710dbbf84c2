//! The configuration of a target that names none: one rule for every entry
//! point — `robocal solve`, `robocal filter`, the HTTP solve and filter
//! routes (docs/design.md "Inverse kinematics", "Configuration of an
//! unflagged target").
//!
//! Candidates: the closed-form solutions of the nominal model carrying the
//! tool (the controller's own inverse kinematics), each joint on its 2π
//! representative within the limits nearest the reference. The reference
//! `r` (model convention, rad):
//! 1. the previous target's joints along a path — a program's motions in the
//!    order they run (a joint move before a target sets them);
//! 2. else a stated joint seed (`--seed-deg`, `seed_deg`);
//! 3. else the middle of each joint range (0 for a range of 2π or more).
//!
//! The chosen candidate is the one nearest `r` in `Σ_k (q_k − r_k)²` [rad²]
//! (candidates within the limits before those beyond them, on the target
//! before those clamped to the reach boundary); the calibrated solve starts
//! from it. A stated branch (`--branch`, `branch`, a program's configuration
//! flags, path mode's kept branch) restricts the candidates to it.
//!
//! When the calibrated model does not reach the target from the nearest
//! candidate, a solve (`IkSolver::solve_goal` without a branch) goes on to the
//! next ones, nearest first, and reports the configuration it found. The
//! program filter does not: a controller given no flags takes the nearest
//! configuration itself, so the target fails, naming the configurations that
//! do reach it.

use std::f64::consts::TAU;

/// The middle of each joint range, 0 for a range of 2π or more (clamped
/// into it) [rad].
pub fn middle_of_ranges(limits: &[[f64; 2]]) -> Vec<f64> {
    limits
        .iter()
        .map(|&[lo, hi]| {
            if hi - lo >= TAU {
                0.0f64.clamp(lo, hi)
            } else {
                0.5 * (lo + hi)
            }
        })
        .collect()
}

/// The rule's reference joints: `along` (the previous target's joints, or a
/// stated seed) when it has one value per joint, all finite; else the middle
/// of the ranges.
pub fn reference(limits: &[[f64; 2]], along: Option<&[f64]>) -> Vec<f64> {
    match along {
        Some(q) if q.len() == limits.len() && q.iter().all(|v| v.is_finite()) => q.to_vec(),
        _ => middle_of_ranges(limits),
    }
}

/// The rule's distance of joints `q` from the reference `r`: `Σ (q_k − r_k)²` [rad²].
pub fn distance(q: &[f64], r: &[f64]) -> f64 {
    q.iter().zip(r).map(|(a, b)| (a - b).powi(2)).sum()
}

/// The index of the candidate nearest `r` (the first of equals); `None`
/// without candidates.
pub fn nearest<Q: AsRef<[f64]>>(candidates: &[Q], r: &[f64]) -> Option<usize> {
    candidates
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| distance(a.as_ref(), r).total_cmp(&distance(b.as_ref(), r)))
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn the_reference_is_the_path_or_the_middle_of_the_ranges() {
        let limits = [[-PI, PI], [-1.0, 2.0], [-2.0 * PI, 2.0 * PI], [0.5, 7.0]];
        assert_eq!(middle_of_ranges(&limits), vec![0.0, 0.5, 0.0, 0.5]);
        let q = [0.1, 0.2, 0.3, 0.4];
        assert_eq!(reference(&limits, Some(&q)), q.to_vec());
        // A seed of the wrong length or with a NaN is no reference.
        assert_eq!(reference(&limits, Some(&q[..3])), middle_of_ranges(&limits));
        assert_eq!(
            reference(&limits, Some(&[0.0, f64::NAN, 0.0, 0.0])),
            middle_of_ranges(&limits)
        );
    }

    #[test]
    fn the_nearest_candidate_is_by_the_sum_of_squares() {
        // By the sum of absolute differences the second would be nearer (1.2 < 1.3);
        // by the sum of squares the first is (0.845 < 1.44).
        let cands = [vec![0.65, 0.65], vec![1.2, 0.0]];
        assert_eq!(nearest(&cands, &[0.0, 0.0]), Some(0));
        assert_eq!(distance(&cands[1], &[0.0, 0.0]), 1.44);
        let empty: [Vec<f64>; 0] = [];
        assert_eq!(nearest(&empty, &[0.0]), None);
        // Equals: the first.
        assert_eq!(nearest(&[[1.0], [-1.0]], &[0.0]), Some(0));
    }
}
