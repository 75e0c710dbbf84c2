//! Learned compensation outside the region it learned from: a simulated YS100
//! with effects no model here has (`unmodelled_truth`) is identified and
//! trained on poses with joint 1 in [−60°, 0°], and validated inside that
//! region and outside it (joint 1 in [20°, 80°], beyond the 5° fade). Outside,
//! every compensator must fall back to its base (mean within 5 %, max within
//! 10 %) and the joint maps be no worse than theirs, and `solve`'s coverage
//! must flag the outside solutions and not the inside ones.

mod common;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{calibrate_with_training, CalibrationOptions, Method};
use robocal_core::measure::{self, Measurement};
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::{preset, Coverage, RobotModel};
use robocal_core::sim::unmodelled_truth;
use robocal_core::sim::{random_configurations, TrueRobot};

/// `n` measurements with joint 1 drawn uniformly in `[lo, hi]` degrees.
fn region(
    truth: &TrueRobot,
    nominal: &RobotModel,
    n: usize,
    [lo, hi]: [f64; 2],
    rng: &mut ChaCha8Rng,
) -> Vec<Measurement> {
    let mut qs = random_configurations(nominal, n, rng);
    for q in &mut qs {
        q[0] = rng.gen_range(lo.to_radians()..hi.to_radians());
    }
    let rows = truth
        .measure(&qs, Some(nominal.payload.mass), None, rng)
        .unwrap();
    measure::to_measurements(nominal, &rows, nominal.payload.mass)
}

const INSIDE: [f64; 2] = [-60.0, 0.0];
const OUTSIDE: [f64; 2] = [20.0, 80.0];
/// Every compensator method and the joint maps.
fn methods() -> Vec<Method> {
    Method::COMPENSATED
        .iter()
        .chain(&Method::JOINT_MAPS)
        .copied()
        .collect()
}

#[test]
fn compensators_fall_back_to_their_base_outside_and_solve_flags_it() {
    let nominal = preset("ys100").unwrap();
    let truth = unmodelled_truth(&nominal, true, 3);
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let ident = region(&truth, &nominal, 100, INSIDE, &mut rng);
    let train = region(&truth, &nominal, 400, INSIDE, &mut rng);
    let inside = region(&truth, &nominal, 150, INSIDE, &mut rng);
    let outside = region(&truth, &nominal, 150, OUTSIDE, &mut rng);
    let mut opts = CalibrationOptions {
        methods: [Method::Km, Method::Skcm]
            .into_iter()
            .chain(methods())
            .collect(),
        ..Default::default()
    };
    opts.compensator.cv_folds = 0;
    let run = |valid: &[Measurement]| {
        calibrate_with_training(&nominal, &ident, &train, valid, &opts, &|_| true).unwrap()
    };
    let (r_in, r_out) = (run(&inside), run(&outside));
    for m in methods() {
        let base = match (m.base(), m) {
            (Some(b), _) => b.name(),
            (None, Method::KmMaps) => "km",
            (None, _) => "skcm",
        };
        let stats = |r: &robocal_core::calibrate::identify::CalibrationReport, name: &str| {
            r.methods[name].validation.as_ref().unwrap().stats.clone()
        };
        let (b_in, c_in) = (stats(&r_in, base), stats(&r_in, m.name()));
        let (b_out, c_out) = (stats(&r_out, base), stats(&r_out, m.name()));
        eprintln!(
            "{m}: inside {:.4} / {:.4} mm (base {:.4} / {:.4}); outside {:.4} / {:.4} mm (base {:.4} / {:.4})",
            c_in.mean_mm, c_in.max_mm, b_in.mean_mm, b_in.max_mm,
            c_out.mean_mm, c_out.max_mm, b_out.mean_mm, b_out.max_mm
        );
        // A compensator falls back to its base; the joint maps of the joints
        // still inside their ranges keep applying (joint 1's fades), so they
        // must only be no worse.
        let (lo_mean, lo_max) = if m.compensated().is_some() {
            (0.95 * b_out.mean_mm, 0.90 * b_out.max_mm)
        } else {
            (0.0, 0.0)
        };
        assert!(
            c_out.mean_mm <= 1.05 * b_out.mean_mm && c_out.mean_mm >= lo_mean,
            "{m} outside mean {} vs base {}",
            c_out.mean_mm,
            b_out.mean_mm
        );
        assert!(
            c_out.max_mm <= 1.10 * b_out.max_mm && c_out.max_mm >= lo_max,
            "{m} outside max {} vs base {}",
            c_out.max_mm,
            b_out.max_mm
        );
        // The flags solve reports, at the measured joints.
        let rep = &r_in.methods[m.name()];
        let mut cm = CompensatedModel::from_nominal(nominal.clone());
        cm.calibrated = rep.calibrated.clone();
        cm.compensator = rep.compensator_arc();
        let flagged = |set: &[Measurement]| {
            set.iter()
                .filter(|p| {
                    let c = cm.compensation_at(&p.q).expect("maps or a support");
                    c.level != Coverage::Inside || c.far_from_training
                })
                .count() as f64
                / set.len() as f64
        };
        let (f_in, f_out) = (flagged(&inside), flagged(&outside));
        eprintln!(
            "{m}: flagged {:.1} % inside, {:.1} % outside",
            f_in * 100.0,
            f_out * 100.0
        );
        assert!(f_out >= 0.9, "{m}: {f_out}");
        assert!(f_in <= 0.05, "{m}: {f_in}");
    }
}
