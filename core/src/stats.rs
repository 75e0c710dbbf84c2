//! Error statistics of a pose set (docs/design.md "Data roles"): mean, maximum, standard
//! deviation, RMS and 95th percentile of the position-error norm, in millimetres, and
//! ([`OrientationStats`]) the same of the orientation error, the angle of
//! `R_measured·R_predictedᵀ`, in degrees, over the poses that measured an orientation.

use serde::{Deserialize, Serialize};

/// Statistics of the position-error norm over a set of poses [mm].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Number of poses.
    pub n: usize,
    /// Mean of the error norms.
    pub mean_mm: f64,
    /// Largest error norm.
    pub max_mm: f64,
    /// Sample standard deviation (n − 1), as MATLAB's `std`.
    pub std_mm: f64,
    /// Root mean square of the error norms.
    pub rms_mm: f64,
    /// 95th percentile, linear interpolation between closest ranks.
    pub p95_mm: f64,
}

impl ErrorStats {
    /// Statistics of error norms given in millimetres.
    pub fn from_errors_mm(e: &[f64]) -> ErrorStats {
        let n = e.len();
        if n == 0 {
            return ErrorStats {
                n,
                mean_mm: 0.0,
                max_mm: 0.0,
                std_mm: 0.0,
                rms_mm: 0.0,
                p95_mm: 0.0,
            };
        }
        let nf = n as f64;
        let mean = e.iter().sum::<f64>() / nf;
        let max = e.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let var = if n > 1 {
            e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (nf - 1.0)
        } else {
            0.0
        };
        let rms = (e.iter().map(|x| x * x).sum::<f64>() / nf).sqrt();
        let mut s = e.to_vec();
        s.sort_by(|a, b| a.total_cmp(b));
        let pos = 0.95 * (nf - 1.0);
        let lo = pos.floor() as usize;
        let hi = (lo + 1).min(n - 1);
        let p95 = s[lo] + (s[hi] - s[lo]) * (pos - lo as f64);
        ErrorStats {
            n,
            mean_mm: mean,
            max_mm: max,
            std_mm: var.sqrt(),
            rms_mm: rms,
            p95_mm: p95,
        }
    }
}

/// Orientation-error statistics of a set [deg]: the angle of
/// `R_measured·R_predictedᵀ` (both in the registered frame) over the poses
/// with a measured orientation. Serialised with an `orientation_` prefix
/// beside [`ErrorStats`] (`orientation_mean_deg`, …); a set without any
/// orientation measurement has none (never zeros).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrientationStats {
    /// Poses with a measured orientation.
    #[serde(rename = "orientation_n")]
    pub n: usize,
    /// Mean of the orientation errors.
    #[serde(rename = "orientation_mean_deg")]
    pub mean_deg: f64,
    /// Largest orientation error.
    #[serde(rename = "orientation_max_deg")]
    pub max_deg: f64,
    /// Sample standard deviation (n − 1).
    #[serde(rename = "orientation_std_deg")]
    pub std_deg: f64,
    /// Root mean square of the orientation errors.
    #[serde(rename = "orientation_rms_deg")]
    pub rms_deg: f64,
    /// 95th percentile, as [`ErrorStats::p95_mm`].
    #[serde(rename = "orientation_p95_deg")]
    pub p95_deg: f64,
}

impl OrientationStats {
    /// Statistics of the angles [deg] of the poses that have one (`None`
    /// entries: no orientation measured); `None` when no pose has one.
    pub fn from_angles_deg(angles: &[Option<f64>]) -> Option<OrientationStats> {
        let a: Vec<f64> = angles.iter().flatten().copied().collect();
        if a.is_empty() {
            return None;
        }
        let s = ErrorStats::from_errors_mm(&a);
        Some(OrientationStats {
            n: s.n,
            mean_deg: s.mean_mm,
            max_deg: s.max_mm,
            std_deg: s.std_mm,
            rms_deg: s.rms_mm,
            p95_deg: s.p95_mm,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_values() {
        let s = ErrorStats::from_errors_mm(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.n, 4);
        assert!((s.mean_mm - 2.5).abs() < 1e-15);
        assert_eq!(s.max_mm, 4.0);
        assert!((s.std_mm - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert!((s.rms_mm - 7.5f64.sqrt()).abs() < 1e-15);
        // 0.95·3 = 2.85 → 3 + 0.85·1
        assert!((s.p95_mm - 3.85).abs() < 1e-12);
    }

    /// Poses without an orientation are left out; none at all gives none.
    #[test]
    fn orientation_stats_skip_poses_without_one() {
        assert_eq!(OrientationStats::from_angles_deg(&[None, None]), None);
        let s = OrientationStats::from_angles_deg(&[Some(0.1), None, Some(0.3)]).unwrap();
        assert_eq!(s.n, 2);
        assert!((s.mean_deg - 0.2).abs() < 1e-15);
        assert_eq!(s.max_deg, 0.3);
        assert!((s.rms_deg - 0.05f64.sqrt()).abs() < 1e-15);
        let v = serde_json::to_value(&s).unwrap();
        assert_eq!(v["orientation_max_deg"], 0.3);
        assert_eq!(v["orientation_n"], 2);
    }
}
