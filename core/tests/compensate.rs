//! Learned compensators (issue 9) against simulated ground truth with effects
//! the model-based calibration does not have, and against the real
//! laser-tracker data (data/ur5-wam-laser-tracker).
//!
//! The simulated truth is `compensate::unmodelled_truth` on the YS100: ~1 mm /
//! 0.1° geometric errors, the joint stiffness of the thesis's Table 7.2, link
//! masses 25 % above the model's and centres of mass moved by 60 mm, a gear
//! transmission error of 4e-5 rad (first harmonic) and 2e-5 rad backlash on
//! every joint, 0.01 mm tracker noise, and a tracker frame 3.4 m from the base,
//! turned by 30°. The calibration knows the preset's masses and none of the
//! other effects.
//!
//! Everything runs through the identification pipeline
//! (`identify::calibrate_with_training`) with the three data roles: 100
//! identification poses fit the base, the training pool trains the
//! compensator, 200 validation poses judge; each figure is recomputed through
//! `CompensatedModel::predict` from the model the report delivers.

mod common;

use common::{measure_truth, real, shipped_model};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::compensate::select::Parallelism;
use robocal_core::calibrate::compensate::CompensatorSpec;
use robocal_core::calibrate::identify::joint_maps::JointMapSettings;
use robocal_core::calibrate::identify::progress::ETA_FROM_FRACTION;
use robocal_core::calibrate::identify::{
    calibrate, calibrate_with_training, CalibrationOptions, CalibrationReport, CompensatorOptions,
    Method, Phase, Progress,
};
use robocal_core::measure::{self, Measurement};
use robocal_core::model::calibrated::{CompensatedModel, StoredCompensator};
use robocal_core::model::{preset, RobotModel};
use robocal_core::sim::random_configurations;
use robocal_core::sim::unmodelled_truth;
use robocal_core::solve::ik::{Goal, IkSettings, IkSolver, SolveOptions};
use robocal_core::stats::ErrorStats;
use std::sync::OnceLock;

/// The base model of a calibrated method, in the measurement frame.
fn base(nominal: &RobotModel, r: &CalibrationReport, method: &str) -> CompensatedModel {
    CompensatedModel {
        calibrated: r.methods[method].calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: r.tracker_to_base.inverse(),
        payload_kg: nominal.payload.mass,
        compensator: None,
    }
}

/// Position-error statistics of a model on measured poses [mm].
fn errors(m: &CompensatedModel, data: &[Measurement]) -> ErrorStats {
    let e: Vec<f64> = data
        .iter()
        .map(|d| {
            let p = m.predict_detailed_at(&d.q, d.payload_mass).unwrap().pose.p;
            (m.cell_from_base.transform_point(&p) - d.position).norm() * 1e3
        })
        .collect();
    ErrorStats::from_errors_mm(&e)
}

/// (method name, base, compensator spec) of the thesis's hybrid methods.
fn hybrids() -> Vec<(&'static str, &'static str, CompensatorSpec)> {
    vec![
        ("km-rbf", "km", CompensatorSpec::km_rbf()),
        ("skcm-nn", "skcm", CompensatorSpec::skcm_nn()),
        ("skcm-iwonn", "skcm", CompensatorSpec::skcm_iwonn()),
        ("skcm-tlbonn", "skcm", CompensatorSpec::skcm_tlbonn()),
        ("km-gp", "km", CompensatorSpec::Gp(Default::default())),
        ("skcm-gp", "skcm", CompensatorSpec::Gp(Default::default())),
    ]
}

const BASES_AND_COMPENSATORS: [Method; 10] = [
    Method::Km,
    Method::Skcm,
    Method::KmRbf,
    Method::SkcmNn,
    Method::SkcmIwonn,
    Method::SkcmTlbonn,
    Method::KmGp,
    Method::SkcmGp,
    Method::SkcmMaps,
    Method::SkcmMapsGp,
];

/// A calibration through the pipeline with the three data roles: 100
/// identification poses (Q1), `n_train` training poses (Q2), 200 validation
/// poses (Q3), all of the same simulated truth.
struct Study {
    nominal: RobotModel,
    train: Vec<Measurement>,
    valid: Vec<Measurement>,
    report: CalibrationReport,
}

/// The threads a calibration's cross-validations run on: the cores
/// available, or `ROBOCAL_TEST_THREADS` when set (`scripts/idle_core.sh`
/// runs this file with 1, every fold after the other, to measure what the
/// second core saves; the results are the same on any number).
fn parallelism() -> Parallelism {
    match std::env::var("ROBOCAL_TEST_THREADS") {
        Ok(v) => Parallelism {
            threads: v
                .parse()
                .expect("ROBOCAL_TEST_THREADS: a number of threads"),
        },
        Err(_) => Parallelism::default(),
    }
}

fn options(methods: &[Method], seed: u64, cv_folds: usize) -> CalibrationOptions {
    let parallel = parallelism();
    let d = CalibrationOptions::default();
    CalibrationOptions {
        methods: methods.to_vec(),
        compensator: CompensatorOptions {
            seed,
            cv_folds,
            parallel,
            ..Default::default()
        },
        joint_maps: JointMapSettings {
            parallel,
            ..d.joint_maps
        },
        ..d
    }
}

fn study(n_train: usize, effects: bool, seed: u64, methods: &[Method], cv_folds: usize) -> Study {
    let nominal = preset("ys100").unwrap();
    let t = unmodelled_truth(&nominal, effects, seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed + 100);
    let ident = measure_truth(&t, &nominal, 100, &mut rng);
    let train = measure_truth(&t, &nominal, n_train, &mut rng);
    let valid = measure_truth(&t, &nominal, 200, &mut rng);
    let opts = options(methods, seed, cv_folds);
    let report =
        calibrate_with_training(&nominal, &ident, &train, &valid, &opts, &|_| true).unwrap();
    Study {
        nominal,
        train,
        valid,
        report,
    }
}

impl Study {
    /// The model a method delivers, rebuilt from the report as its model file
    /// would be (measurement frame, compensator included).
    fn model(&self, method: &str) -> CompensatedModel {
        let m = &self.report.methods[method];
        CompensatedModel {
            compensator: m.compensator_arc(),
            ..base(&self.nominal, &self.report, method)
        }
    }

    /// Validation errors of a method recomputed through
    /// `CompensatedModel::predict` (not the pipeline's own statistics), after
    /// checking that the two agree.
    fn validation(&self, method: &str) -> ErrorStats {
        let e = errors(&self.model(method), &self.valid);
        let r = &self.report.methods[method]
            .validation
            .as_ref()
            .unwrap()
            .stats;
        assert!(
            (e.mean_mm - r.mean_mm).abs() < 1e-6 && (e.max_mm - r.max_mm).abs() < 1e-6,
            "{method}: report {r:?} vs recomputed {e:?}"
        );
        e
    }

    fn compensator(&self, method: &str) -> &StoredCompensator {
        self.report.methods[method]
            .stored_compensator
            .as_ref()
            .unwrap_or_else(|| panic!("{method} has no compensator"))
    }
}

static THOUSAND: OnceLock<Study> = OnceLock::new();

fn thousand() -> &'static Study {
    THOUSAND.get_or_init(|| study(1000, true, 1, &BASES_AND_COMPENSATORS, 0))
}

/// 1000 training poses: KM-RBF, SKCM-NN, SKCM-TLBONN and the Gaussian
/// processes lower the validation mean by ≥ 15 % against their bases, the
/// best compensator by ≥ 50 % (to ≤ 0.5× its base).
#[test]
fn thousand_poses_every_compensator_beats_its_base() {
    let s = thousand();
    let mut best_gain: f64 = 0.0;
    for (method, b, _) in hybrids() {
        let c = s.report.methods[method].compensator.as_ref().unwrap();
        assert_eq!(c.trained_on, "training");
        assert_eq!(c.training_poses, 1000);
        assert_eq!(c.base.name(), b);
        let base = s.validation(b);
        let comp = s.validation(method);
        let gain = 1.0 - comp.mean_mm / base.mean_mm;
        eprintln!(
            "{method}: validation mean {:.4} -> {:.4} mm ({:.1} %), max {:.4} -> {:.4} mm",
            base.mean_mm,
            comp.mean_mm,
            gain * 100.0,
            base.max_mm,
            comp.max_mm
        );
        // IWO with the thesis's loss (eq. 5.7, mean + 0.7·max over 850 fitting
        // poses) does not reach the 15 % here (docs/guide/compensators.md);
        // it is reported, not held to it.
        if !method.ends_with("iwonn") {
            assert!(gain >= 0.15, "{method}: only {:.1} % better", gain * 100.0);
        }
        best_gain = best_gain.max(gain);
    }
    assert!(best_gain >= 0.5, "best gain {:.1} %", best_gain * 100.0);
}

/// Same seed, same weights, bit for bit: the pipeline run again on the same
/// data (IWO evaluates its offspring in parallel; the unit tests repeat every
/// trainer on a smaller set).
#[test]
fn training_is_deterministic() {
    let s = thousand();
    let nominal = &s.nominal;
    let t = unmodelled_truth(nominal, true, 1);
    let mut rng = ChaCha8Rng::seed_from_u64(101);
    let ident = measure_truth(&t, nominal, 100, &mut rng);
    let opts = options(&[Method::KmRbf, Method::SkcmIwonn], 1, 0);
    let again =
        calibrate_with_training(nominal, &ident, &s.train, &s.valid, &opts, &|_| true).unwrap();
    for method in ["km-rbf", "skcm-iwonn"] {
        assert_eq!(
            again.methods[method].stored_compensator.as_ref(),
            Some(s.compensator(method)),
            "{method}"
        );
    }
}

/// The compensated models' IK (its Jacobian includes the derivative of the
/// network, of the Gaussian process and of the joint maps)
/// solves 10,000 targets as the uncompensated one does, each checked through
/// the compensated prediction.
#[test]
fn compensated_ik_solves_10000_targets() {
    let s = thousand();
    let plain = s.model("skcm");
    let comp = s.model("skcm-nn");
    let gp = s.model("skcm-gp");
    let maps = s.model("skcm-maps");
    let maps_gp = s.model("skcm-maps-gp");
    assert!(maps.calibrated.joint_maps.is_some() && maps_gp.compensator.is_some());
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let qs = random_configurations(&s.nominal, 10_000, &mut rng);
    let (mut rates, mut evaluations) = (Vec::new(), Vec::new());
    for m in [&plain, &comp, &gp, &maps, &maps_gp] {
        let solver = IkSolver::new(m.clone(), IkSettings::default());
        let goals: Vec<Goal> = qs
            .iter()
            .map(|q| Goal::from(&m.predict(q).unwrap()))
            .collect();
        let sols = solver.solve_batch(&goals, &SolveOptions::default());
        let mut ok = 0;
        for (g, sol) in goals.iter().zip(&sols) {
            if sol.converged {
                let p = m.predict(&sol.q).unwrap();
                assert!(
                    (p.p - g.position).norm() < 1e-6,
                    "{:e} m",
                    (p.p - g.position).norm()
                );
                ok += 1;
            } else {
                assert!(sol.reason.is_some());
            }
        }
        rates.push(ok as f64 / goals.len() as f64);
        evaluations.push(sols.iter().map(|s| s.iterations).sum::<usize>());
    }
    eprintln!(
        "IK success: SKCM / SKCM-NN / SKCM-GP / SKCM+maps / SKCM+maps-GP {rates:?}; evaluations {evaluations:?}"
    );
    for r in &rates[1..] {
        assert!(*r >= 0.999 && *r >= rates[0] - 0.0005, "{rates:?}");
    }
}

/// 50 training poses: `auto` is never worse than its base method by more than
/// 2 % on the validation mean or max, although a plain network may well be.
#[test]
fn fifty_poses_auto_falls_back_to_the_base() {
    let mut methods = BASES_AND_COMPENSATORS.to_vec();
    methods.push(Method::Auto);
    let s = study(50, true, 2, &methods, 5);
    for (method, b, _) in hybrids() {
        let e = s.validation(method);
        let base = s.validation(b);
        eprintln!(
            "{method} on 50 poses: validation mean {:.4} vs base {:.4} mm, max {:.4} vs {:.4} mm",
            e.mean_mm, base.mean_mm, e.max_mm, base.max_mm
        );
    }
    let auto = &s.report.methods["auto"];
    let a = auto.auto.as_ref().unwrap();
    eprintln!("auto: {}", a.reason);
    let base = a.chosen.base().unwrap_or(a.chosen).name();
    let got = s.validation("auto");
    let want = s.validation(base);
    assert!(
        got.mean_mm <= 1.02 * want.mean_mm && got.max_mm <= 1.02 * want.max_mm,
        "auto ({}) {got:?} vs its base {base} {want:?}",
        a.chosen.name()
    );
    // Every compensator candidate was cross-validated on the 50 training
    // poses; the joint maps by their own cross-validation.
    let (nets, maps): (Vec<_>, Vec<_>) = a
        .candidates
        .iter()
        .partition(|c| c.method.compensated().is_some());
    // The compensators on the joint maps are tried only on kept maps (none here).
    let on_bases = Method::COMPENSATED
        .iter()
        .filter(|m| matches!(m.base(), Some(Method::Km | Method::Skcm)))
        .count();
    assert_eq!(nets.len(), on_bases, "{:?}", a.candidates);
    for c in &nets {
        assert_eq!(c.cross_validation.as_ref().unwrap().compensated.n, 50);
    }
    let maps: Vec<Method> = maps.iter().map(|c| c.method).collect();
    assert_eq!(maps, Method::JOINT_MAPS, "{:?}", a.candidates);
}

/// Without unmodelled effects there is nothing to learn but noise: no
/// compensator makes the validation mean or max worse by more than 5 %.
#[test]
fn effects_off_no_compensator_hurts() {
    let s = study(300, false, 3, &BASES_AND_COMPENSATORS, 0);
    for (method, b, _) in hybrids() {
        let base = s.validation(b);
        let comp = s.validation(method);
        eprintln!(
            "{method}, effects off: mean {:.4} -> {:.4}, max {:.4} -> {:.4} mm",
            base.mean_mm, comp.mean_mm, base.max_mm, comp.max_mm
        );
        assert!(
            comp.mean_mm <= 1.05 * base.mean_mm && comp.max_mm <= 1.05 * base.max_mm,
            "{method}: {comp:?} vs base {base:?}"
        );
    }
}

/// A compensator method whose base fails fails on its own (with the reason),
/// the others are delivered; without a training pool the compensator trains
/// on the identification poses; cancelling during training cancels the
/// calibration.
#[test]
fn base_failure_pool_choice_and_cancellation() {
    let mut nominal = preset("ys100").unwrap();
    let t = unmodelled_truth(&nominal, true, 4);
    let mut rng = ChaCha8Rng::seed_from_u64(104);
    let ident = measure_truth(&t, &nominal, 60, &mut rng);
    // A model without masses: SKCM (and so SKCM-NN) and the torque RBF cannot run.
    for l in nominal.links.iter_mut() {
        l.mass = 0.0;
    }
    nominal.payload.mass = 0.0;
    let ident: Vec<Measurement> = ident
        .into_iter()
        .map(|m| Measurement {
            payload_mass: 0.0,
            ..m
        })
        .collect();
    let opts = options(&[Method::Km, Method::SkcmNn, Method::KmRbf], 1, 0);
    let r = calibrate(&nominal, &ident, &[], &opts, &|_| true).unwrap();
    assert!(r.methods.contains_key("km"));
    let failed: Vec<&str> = r.failed.iter().map(|f| f.method.name()).collect();
    assert_eq!(failed, ["skcm-nn", "km-rbf"], "{:?}", r.failed);
    assert!(r.failed.iter().all(|f| f.reason.contains("torque")));
    // Compensator on KM, trained on the identification pool (no Q2) by auto.
    let opts = options(&[Method::Auto], 1, 3);
    let r = calibrate(&nominal, &ident, &[], &opts, &|_| true).unwrap();
    let a = r.methods["auto"].auto.as_ref().unwrap();
    assert_eq!(a.chosen, Method::Km, "{}", a.reason);
    assert!(
        a.reason.contains("skcm and km-rbf not tried"),
        "{}",
        a.reason
    );
    // Only what needs no torques is tried: the compensators on KM with
    // joint inputs (the Gaussian process), then the joint maps on KM.
    let tried: Vec<Method> = a.candidates.iter().map(|c| c.method).collect();
    assert_eq!(tried, [Method::KmGp, Method::KmMaps], "{:?}", a.candidates);
    // Its model file names the method it delivers.
    assert_eq!(r.methods["auto"].model_file_method(), "auto: km");
    assert_eq!(r.methods["auto"].method.name(), "auto");
    // Cancelled from the progress callback during SKCM-NN's training: with
    // no cross-validation its plan (methods/plan.rs) is SKCM's fit, SKCM's
    // weight, and one training, the weights' difference over the 10
    // trainings the weight is set for; the training starts after the fit.
    let nominal = preset("ys100").unwrap();
    let ident = measure_truth(&t, &nominal, 60, &mut rng);
    let opts = options(&[Method::SkcmNn], 1, 0);
    let (fit, nn) = (Method::Skcm.row().weight, Method::SkcmNn.row().weight);
    let training_from = 10.0 + 90.0 * fit / (fit + (nn - fit) / 10.0);
    let seen = std::sync::atomic::AtomicUsize::new(0);
    let r = calibrate(&nominal, &ident, &[], &opts, &|p| {
        if p.phase == "skcm-nn" && p.percent > training_from + 1e-9 {
            seen.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            return false;
        }
        true
    });
    assert!(matches!(
        r,
        Err(robocal_core::calibrate::identify::CalibrationError::Cancelled)
    ));
    assert_eq!(seen.load(std::sync::atomic::Ordering::SeqCst), 1);
    // Without Q2 the compensator says it trained on the identification poses.
    let r = calibrate(&nominal, &ident, &[], &opts, &|_| true).unwrap();
    let c = r.methods["skcm-nn"].compensator.as_ref().unwrap();
    assert_eq!(
        (c.trained_on.as_str(), c.training_poses),
        ("identification", 60)
    );
}

/// Real data through the pipeline with the shipped model files (link masses
/// and centres of mass, so SKCM and the torque-based RBF can run): the grid
/// identifies the base and, with no training pool, trains the compensators
/// (judged by 5-fold cross-validation inside it); the 20 random poses
/// validate. `auto` is never worse than KM on mean or max; on the UR5 the
/// joint-map methods and `auto` reach 0.068 mm mean and 0.13 mm max. Every
/// method's figures are printed beside the published hybrid
/// (MDH + graph neural network) on the same 20 poses: UR5 0.155 mm, WAM 2.92 mm.
///
/// One test per robot, so that the two calibrations run side by side.
#[test]
fn real_data_auto_never_worse_than_km_ur5() {
    real_data_auto_never_worse_than_km(
        "UR5",
        shipped_model("ur5"),
        "UR5/3D_UR5_uncalibrated_grid_cleaned.csv",
        "UR5/3D_UR5_uncalibrated_random_cleaned.csv",
        0.155,
    );
}

/// The WAM half of the test above.
#[test]
fn real_data_auto_never_worse_than_km_wam() {
    real_data_auto_never_worse_than_km(
        "WAM",
        shipped_model("wam"),
        "WAM/3D_WAM_uncalibrated_grid_cleaned.csv",
        "WAM/3D_WAM_uncalibrated_random_cleaned.csv",
        2.92,
    );
}

/// What a calibration's every progress report showed: the percentage never
/// going back; the time left, when given, a finite number of seconds, never
/// negative, and given from 1 % of the methods' work on (they start at 10 %,
/// progress::ETA_FROM_FRACTION).
#[derive(Default)]
struct ProgressWatch {
    last: f64,
    reports: usize,
    with_eta: usize,
    problems: Vec<String>,
}

impl ProgressWatch {
    fn see(&mut self, p: &Progress) {
        self.reports += 1;
        if p.percent.is_nan() || p.percent < self.last {
            self.problems.push(format!(
                "{} % after {} % ({})",
                p.percent, self.last, p.phase
            ));
        }
        self.last = p.percent;
        let eta_from = 10.0 + 90.0 * ETA_FROM_FRACTION + 1e-9;
        match p.eta_s {
            Some(eta) if eta.is_finite() && eta >= 0.0 => self.with_eta += 1,
            Some(eta) => self
                .problems
                .push(format!("{eta} s left at {} %", p.percent)),
            None if matches!(p.phase, Phase::Method(_)) && p.percent >= eta_from => self
                .problems
                .push(format!("no time left at {} % ({})", p.percent, p.phase)),
            None => {}
        }
    }
}

fn real_data_auto_never_worse_than_km(
    name: &str,
    model: RobotModel,
    grid: &str,
    random: &str,
    published: f64,
) {
    {
        let ident = measure::to_measurements(&model, &real(grid), 0.0);
        let valid = measure::to_measurements(&model, &real(random), 0.0);
        let mut methods = BASES_AND_COMPENSATORS.to_vec();
        methods.extend([Method::KmMaps, Method::SkcmMaps, Method::Auto]);
        let opts = options(&methods, 1, 5);
        let watch = std::sync::Mutex::new(ProgressWatch::default());
        let r = calibrate(&model, &ident, &valid, &opts, &|p| {
            watch.lock().unwrap().see(p);
            true
        })
        .unwrap();
        let watch = watch.into_inner().unwrap();
        assert!(watch.problems.is_empty(), "{name}: {:?}", watch.problems);
        assert!(
            watch.with_eta > 0 && watch.last == 100.0,
            "{name}: {} reports, {} with a time left, last at {} %",
            watch.reports,
            watch.with_eta,
            watch.last
        );
        eprintln!(
            "{name}: {} progress reports, {} with a time left, the percentage never back",
            watch.reports, watch.with_eta
        );
        for (m, rep) in &r.methods {
            let v = &rep.validation.as_ref().unwrap().stats;
            eprintln!(
                "{name} {m}: random-20 mean {:.4} mm, max {:.4} mm (published hybrid {published} mm mean)",
                v.mean_mm, v.max_mm
            );
        }
        for f in &r.failed {
            eprintln!("{name} {} failed: {}", f.method.name(), f.reason);
        }
        let km = &r.methods["km"].validation.as_ref().unwrap().stats;
        let auto = &r.methods["auto"];
        let got = &auto.validation.as_ref().unwrap().stats;
        eprintln!("{name} auto: {}", auto.auto.as_ref().unwrap().reason);
        eprintln!(
            "{name} auto: {:.4} / {:.4} mm; KM {:.4} / {:.4} mm",
            got.mean_mm, got.max_mm, km.mean_mm, km.max_mm
        );
        // "Never worse" at the resolution of the reported figures (0.1 µm,
        // four decimals in mm): on the UR5 auto's and KM's max share their
        // worst pose and differ by nanometres.
        let resolution_mm = 1e-4;
        assert!(
            got.mean_mm <= km.mean_mm + resolution_mm && got.max_mm <= km.max_mm + resolution_mm,
            "{name}: auto {got:?} vs KM {km:?}"
        );
        if name == "UR5" {
            // Issue acceptance on the real UR5: the joint maps and auto at
            // most 0.068 mm mean and 0.13 mm max on the 20 random poses.
            for m in ["km-maps", "skcm-maps", "auto"] {
                let v = &r.methods[m].validation.as_ref().unwrap().stats;
                assert!(
                    v.mean_mm <= 0.068 && v.max_mm <= 0.13,
                    "UR5 {m}: {:.4} / {:.4} mm",
                    v.mean_mm,
                    v.max_mm
                );
            }
        }
    }
}
