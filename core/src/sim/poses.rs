//! Random measurement configurations (the thesis's §7.4 "30 robot joint readings
//! … cover its entire workspace"): joint values uniform within the joint limits
//! (model convention, rad), filtered by TCP height and loop closure.

use super::SimError;
use crate::model::kinematics::fk;
use crate::model::RobotModel;
use rand::Rng;

/// Which random configurations are admissible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseFilter {
    /// Minimum TCP height above the base plane [m], measured against gravity
    /// (`h = −p·ĝ`; for a floor robot `h = z`, for a ceiling robot `h = −z`; with
    /// zero gravity `h = z`). `None` disables the check. Default `Some(0.0)`.
    pub min_z_m: Option<f64>,
    /// Margin kept from both joint limits [rad]. Default 2°.
    pub margin_rad: f64,
}

impl Default for PoseFilter {
    fn default() -> Self {
        PoseFilter {
            min_z_m: Some(0.0),
            margin_rad: 2f64.to_radians(),
        }
    }
}

/// Height of a base-frame point above the base plane, against gravity.
fn height(model: &RobotModel, p: &nalgebra::Vector3<f64>) -> f64 {
    let g = model.gravity.norm();
    if g > 0.0 {
        -p.dot(&model.gravity) / g
    } else {
        p.z
    }
}

/// `n` random configurations with the default [`PoseFilter`].
///
/// # Panics
/// If the filter rejects (almost) everything; see [`try_random_configurations`].
pub fn random_configurations(model: &RobotModel, n: usize, rng: &mut impl Rng) -> Vec<Vec<f64>> {
    random_configurations_with(model, n, &PoseFilter::default(), rng)
}

/// `n` random configurations admitted by `filter`.
///
/// # Panics
/// If the filter rejects (almost) everything; see [`try_random_configurations`].
pub fn random_configurations_with(
    model: &RobotModel,
    n: usize,
    filter: &PoseFilter,
    rng: &mut impl Rng,
) -> Vec<Vec<f64>> {
    try_random_configurations(model, n, filter, rng, |_| true).unwrap_or_else(|e| panic!("{e}"))
}

/// `n` random configurations (model convention, rad): each joint uniform in
/// `[lower + margin, upper − margin]` (the midpoint when the margin swallows the
/// range), rejecting configurations whose forward kinematics fails (a closed loop
/// that cannot close), whose TCP is below `filter.min_z_m`, or that `accept`
/// refuses (e.g. "the nominal model's loop closes too"). Draws are deterministic
/// for a seeded `rng`. Gives up after `10_000 + 1_000·n` draws.
pub fn try_random_configurations(
    model: &RobotModel,
    n: usize,
    filter: &PoseFilter,
    rng: &mut impl Rng,
    mut accept: impl FnMut(&[f64]) -> bool,
) -> Result<Vec<Vec<f64>>, SimError> {
    let ranges: Vec<(f64, f64)> = model
        .links
        .iter()
        .map(|l| {
            let (lo, hi) = (
                l.limits[0] + filter.margin_rad,
                l.limits[1] - filter.margin_rad,
            );
            if lo <= hi {
                (lo, hi)
            } else {
                let mid = 0.5 * (l.limits[0] + l.limits[1]);
                (mid, mid)
            }
        })
        .collect();
    let max_attempts = 10_000 + 1_000 * n;
    let mut out = Vec::with_capacity(n);
    let mut attempts = 0;
    while out.len() < n {
        if attempts >= max_attempts {
            return Err(SimError::TooFewConfigurations {
                wanted: n,
                found: out.len(),
                attempts,
            });
        }
        attempts += 1;
        let q: Vec<f64> = ranges
            .iter()
            .map(|&(lo, hi)| lo + (hi - lo) * rng.gen::<f64>())
            .collect();
        let Ok(tcp) = fk(model, &q) else { continue };
        if let Some(min) = filter.min_z_m {
            if height(model, &tcp.p) < min {
                continue;
            }
        }
        if !accept(&q) {
            continue;
        }
        out.push(q);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::preset;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn configurations_respect_limits_height_and_loop() {
        for name in ["ys100", "hh800", "ur5"] {
            let m = preset(name).unwrap();
            let f = PoseFilter::default();
            let qs = random_configurations(&m, 200, &mut ChaCha8Rng::seed_from_u64(3));
            assert_eq!(qs.len(), 200);
            for q in &qs {
                assert!(m.within_limits(q, 0.0));
                for (x, l) in q.iter().zip(&m.links) {
                    assert!(*x >= l.limits[0] + f.margin_rad - 1e-12);
                    assert!(*x <= l.limits[1] - f.margin_rad + 1e-12);
                }
                let p = fk(&m, q).unwrap();
                assert!(p.p.z >= 0.0, "{name}");
            }
            let again = random_configurations(&m, 200, &mut ChaCha8Rng::seed_from_u64(3));
            assert_eq!(qs, again);
        }
    }

    #[test]
    fn impossible_filter_is_an_error() {
        let m = preset("ys100").unwrap();
        let f = PoseFilter {
            min_z_m: Some(100.0),
            margin_rad: 0.0,
        };
        let e = try_random_configurations(&m, 3, &f, &mut ChaCha8Rng::seed_from_u64(1), |_| true)
            .unwrap_err();
        assert!(matches!(e, SimError::TooFewConfigurations { found: 0, .. }));
    }
}
