//! Honest model choice for compensators: k-fold cross-validation on the
//! training pool and the `auto` rule.
//!
//! Cross-validation: the samples are shuffled by the injected generator and
//! dealt into `k` folds; for each fold a compensator is trained on the other
//! folds and predicts the fold. Every sample is predicted exactly once out of
//! fold; the statistics are those of the position-error norm [mm] after
//! compensation, next to the base's (the residual itself, since the
//! model-based part is the same in every fold).
//!
//! `auto` ([`choose`]) keeps the base unless a compensator's cross-validated
//! mean is lower than the base's by at least `min_gain` (relative) **and** its
//! cross-validated max is not higher: a compensator worse on either never wins.

use super::{Compensator, Sample};
use crate::stats::ErrorStats;
use rand::seq::SliceRandom;
use rand::Rng;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Cross-validated errors of a base and its compensator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CvStats {
    pub folds: usize,
    /// The base alone (no compensator) [mm].
    pub base: ErrorStats,
    /// Out-of-fold errors after compensation [mm].
    pub compensated: ErrorStats,
}

/// Fold index of each of `n` samples: shuffled, sizes differing by at most one.
pub fn fold_assignment(n: usize, k: usize, rng: &mut impl Rng) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    order.shuffle(rng);
    let mut fold = vec![0; n];
    for (pos, &i) in order.iter().enumerate() {
        fold[i] = pos % k.max(1);
    }
    fold
}

/// k-fold cross-validation of a compensator trainer (module docs). `fit`
/// trains on the given samples; its error aborts the run.
pub fn cross_validate<E, F>(
    samples: &[Sample],
    k: usize,
    rng: &mut impl Rng,
    mut fit: F,
) -> Result<CvStats, E>
where
    F: FnMut(&[Sample]) -> Result<Arc<dyn Compensator>, E>,
{
    let k = k.clamp(2, samples.len().max(2));
    let fold = fold_assignment(samples.len(), k, rng);
    let mut after = vec![0.0; samples.len()];
    for f in 0..k {
        let train: Vec<Sample> = samples
            .iter()
            .zip(&fold)
            .filter(|(_, &g)| g != f)
            .map(|(s, _)| s.clone())
            .collect();
        let c = fit(&train)?;
        for (i, s) in samples.iter().enumerate() {
            if fold[i] == f {
                after[i] = (s.residual - c.residual_at(&s.q, &s.tau, s.payload_kg)).norm() * 1e3;
            }
        }
    }
    let before: Vec<f64> = samples.iter().map(|s| s.residual.norm() * 1e3).collect();
    Ok(CvStats {
        folds: k,
        base: ErrorStats::from_errors_mm(&before),
        compensated: ErrorStats::from_errors_mm(&after),
    })
}

/// The outcome of `auto` for one base.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Choice {
    /// Name of the chosen compensator; `None` keeps the base alone.
    pub chosen: Option<String>,
    pub reason: String,
}

/// Picks among `candidates` (name, cross-validation) by cross-validated mean,
/// never one whose mean is not at least `min_gain` (relative) below the base's
/// or whose max is above the base's (module docs).
pub fn choose(candidates: &[(String, CvStats)], min_gain: f64) -> Choice {
    let mut best: Option<&(String, CvStats)> = None;
    let mut rejected = Vec::new();
    for c in candidates {
        let (b, a) = (&c.1.base, &c.1.compensated);
        if a.max_mm > b.max_mm {
            rejected.push(format!(
                "{}: cross-validated max {:.4} mm > base {:.4} mm",
                c.0, a.max_mm, b.max_mm
            ));
        } else if a.mean_mm > b.mean_mm * (1.0 - min_gain) {
            rejected.push(format!(
                "{}: cross-validated mean {:.4} mm is not {:.0}% below the base's {:.4} mm",
                c.0,
                a.mean_mm,
                min_gain * 100.0,
                b.mean_mm
            ));
        } else if best.is_none_or(|x| a.mean_mm < x.1.compensated.mean_mm) {
            best = Some(c);
        }
    }
    match best {
        Some((name, cv)) => Choice {
            chosen: Some(name.clone()),
            reason: format!(
                "{name}: cross-validated ({} folds) mean {:.4} mm, max {:.4} mm against the base's {:.4} / {:.4} mm",
                cv.folds,
                cv.compensated.mean_mm,
                cv.compensated.max_mm,
                cv.base.mean_mm,
                cv.base.max_mm
            ),
        },
        None => Choice {
            chosen: None,
            reason: if rejected.is_empty() {
                "no compensator was tried; the base stays".into()
            } else {
                format!("the base stays: {}", rejected.join("; "))
            },
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    struct Fixed(Vector3<f64>);
    impl Compensator for Fixed {
        fn residual(&self, _: &[f64], _: &[f64]) -> Vector3<f64> {
            self.0
        }
        fn name(&self) -> &str {
            "fixed"
        }
    }

    #[test]
    fn cv_of_a_mean_offset_predicts_every_sample_out_of_fold() {
        // Residual = constant c plus ±d alternating: the mean of the other folds
        // is exactly c when folds are balanced in sign... instead check against
        // a direct leave-fold-out computation.
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let samples: Vec<Sample> = (0..20)
            .map(|i| Sample {
                q: vec![i as f64],
                tau: vec![0.0],
                payload_kg: 0.0,
                residual: Vector3::new(1e-4 + 1e-5 * i as f64, 0.0, 0.0),
            })
            .collect();
        let mut fits = 0;
        let cv = cross_validate(&samples, 4, &mut rng, |train| {
            fits += 1;
            assert_eq!(train.len(), 15);
            let m = train.iter().map(|s| s.residual).sum::<Vector3<f64>>() / train.len() as f64;
            Ok::<_, ()>(Arc::new(Fixed(m)) as Arc<dyn Compensator>)
        })
        .unwrap();
        assert_eq!(fits, 4);
        assert_eq!(cv.compensated.n, 20);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let fold = fold_assignment(20, 4, &mut rng);
        let mut expect = Vec::new();
        for (i, s) in samples.iter().enumerate() {
            let others: Vec<f64> = samples
                .iter()
                .zip(&fold)
                .filter(|(_, &g)| g != fold[i])
                .map(|(t, _)| t.residual.x)
                .collect();
            let m = others.iter().sum::<f64>() / others.len() as f64;
            expect.push((s.residual.x - m).abs() * 1e3);
        }
        let e = ErrorStats::from_errors_mm(&expect);
        assert!((e.mean_mm - cv.compensated.mean_mm).abs() < 1e-12);
        assert!((cv.base.mean_mm - 0.195).abs() < 1e-12);
    }

    fn stats(mean: f64, max: f64) -> ErrorStats {
        ErrorStats {
            n: 10,
            mean_mm: mean,
            max_mm: max,
            std_mm: 0.0,
            rms_mm: mean,
            p95_mm: max,
        }
    }

    #[test]
    fn auto_never_takes_a_compensator_worse_on_mean_or_max() {
        let cv = |m, x| CvStats {
            folds: 5,
            base: stats(0.10, 0.30),
            compensated: stats(m, x),
        };
        let c = choose(
            &[
                ("worse-max".into(), cv(0.05, 0.31)),
                ("too-small-gain".into(), cv(0.099, 0.2)),
                ("good".into(), cv(0.07, 0.25)),
                ("better".into(), cv(0.06, 0.3)),
            ],
            0.02,
        );
        assert_eq!(c.chosen.as_deref(), Some("better"));
        let c = choose(&[("worse-max".into(), cv(0.05, 0.31))], 0.02);
        assert_eq!(c.chosen, None);
        assert!(c.reason.contains("max"), "{}", c.reason);
    }
}
