//! How the joint maps' cross-validation deals its folds: by the poses
//! themselves, not by a seed (`calibrate::pose_key`). A pose's key reads the
//! bits of its joint values [rad], its measured position [m] and its
//! session; the poses in key order are dealt to the folds in turn. So the
//! folds are the same whatever the seed and whatever the order of the rows,
//! and each holds ⌊n/F⌋ or ⌈n/F⌉ poses.

use crate::calibrate::pose_key::{key_order, words_key};
use crate::measure::Measurement;

/// The key of one pose (module docs).
fn pose_key(m: &Measurement) -> u64 {
    words_key(
        m.q.iter()
            .chain(m.position.iter())
            .map(|v| v.to_bits())
            .chain(std::iter::once(m.session as u64)),
    )
}

/// The poses of `data` (indices) in each of `folds` folds (module docs).
pub(super) fn folds_by_pose(data: &[Measurement], folds: usize) -> Vec<Vec<usize>> {
    let keys: Vec<u64> = data.iter().map(pose_key).collect();
    let order = key_order(&keys);
    (0..folds)
        .map(|f| order.iter().copied().skip(f).step_by(folds).collect())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn pose(i: usize) -> Measurement {
        let x = i as f64;
        Measurement {
            q: vec![0.01 * x, -0.02 * x, 0.5],
            position: Vector3::new(0.1 + 1e-3 * x, 0.2, 0.3 - 1e-4 * x),
            orientation: None,
            payload_mass: 0.0,
            session: 0,
            std: None,
        }
    }

    /// Every pose in one fold, the folds balanced, and the same poses
    /// together however the rows are ordered.
    #[test]
    fn the_folds_follow_the_poses_not_their_order() {
        let data: Vec<Measurement> = (0..103).map(pose).collect();
        let folds = folds_by_pose(&data, 5);
        let mut all: Vec<usize> = folds.concat();
        all.sort_unstable();
        assert_eq!(all, (0..103).collect::<Vec<_>>());
        assert!(folds.iter().all(|f| f.len() == 20 || f.len() == 21));
        // Reversed rows: row i is pose 102 − i; the same poses share folds.
        let reversed: Vec<Measurement> = (0..103).rev().map(pose).collect();
        let as_poses = |folds: Vec<Vec<usize>>, of: &dyn Fn(usize) -> usize| {
            let mut f: Vec<Vec<usize>> = folds
                .into_iter()
                .map(|f| {
                    let mut p: Vec<usize> = f.into_iter().map(of).collect();
                    p.sort_unstable();
                    p
                })
                .collect();
            f.sort();
            f
        };
        assert_eq!(
            as_poses(folds, &|i| i),
            as_poses(folds_by_pose(&reversed, 5), &|i| 102 - i)
        );
    }

    /// Neighbouring poses are spread: no fold holds a run of consecutive
    /// poses as dealing them in order would (of 100 poses in 5 folds, the
    /// first 20 land in at least 4 folds).
    #[test]
    fn neighbouring_poses_are_spread_over_the_folds() {
        let data: Vec<Measurement> = (0..100).map(pose).collect();
        let folds = folds_by_pose(&data, 5);
        let fold_of = |p: usize| folds.iter().position(|f| f.contains(&p)).unwrap();
        let mut first: Vec<usize> = (0..20).map(fold_of).collect();
        first.sort_unstable();
        first.dedup();
        assert!(first.len() >= 4, "{first:?}");
    }
}
