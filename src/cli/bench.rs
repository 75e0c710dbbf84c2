//! `robocal bench`: in-process timings of robocal's side of the peer
//! benchmark (`scripts/peer_bench.py`), printed as JSON.
//!
//! - `bench km`: KM (thesis §2.2, eqs. 2.3–2.4) on an identification CSV, the
//!   validation error of the fitted model, and the wall time of the whole
//!   `identify::calibrate` call (registration, identifiability, KM), repeated.
//! - `bench ik`: inverse kinematics of target poses (CSV `x,y,z` in mm and
//!   `qw,qx,qy,qz`, in the robot's base frame) on a model (preset, model JSON
//!   or calibrated model file), each solve timed alone; the accuracy of each
//!   solution is measured independently by forward kinematics of the returned
//!   joints (position error in mm, rotation angle in rad).
//!
//! - `bench methods`: every calibration method alone on a simulated YS100 with
//!   effects no model has (`compensate::unmodelled_truth`): 100
//!   identification poses, N training poses, 200 validation poses; per method
//!   and N the wall time of its whole run (base fit, cross-validation with the
//!   blocked folds, training) and its validation mean and max. With
//!   `--phases`, a line on standard error at each step (phase, candidate,
//!   fit or cross-validation) with the wall and processor seconds since the
//!   run started: a step whose processor time grows slower than its wall
//!   time times the threads leaves cores idle.
//!
//! Times are wall-clock on the calling thread (pin with `taskset -c 0`).

use crate::calibrate::compensate::select::Parallelism;
use crate::calibrate::identify::{calibrate, CalibrationSettings, Method};
use crate::measure::{self, csv};
use crate::solve::ik::{Goal, IkSettings, IkSolver, SolveOptions, TargetFrame};
use anyhow::{bail, Context};
use clap::{Args, Subcommand};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use robocal_core::csv_write::{push_row, Cell};
use robocal_core::model::calibrated::{CalibratedModelFile, CompensatedModel};
use serde_json::json;
use std::time::Instant;

/// Arguments of `robocal bench`: which timing to run.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// The timing to run.
    #[command(subcommand)]
    pub what: BenchCommand,
}

/// The timings of `robocal bench`.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// KM calibration: validation accuracy and time per calibration.
    Km(KmArgs),
    /// Inverse kinematics: solve rate, accuracy and time per target.
    Ik(IkArgs),
    /// Every calibration method's run time on simulated training pools.
    Methods(MethodsArgs),
}

/// Arguments of `robocal bench methods`.
#[derive(Debug, Args)]
pub struct MethodsArgs {
    /// Training pool sizes, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1500,10000")]
    pub poses: Vec<usize>,
    /// Methods (default: every one but `auto`).
    #[arg(long, value_delimiter = ',')]
    pub method: Vec<String>,
    /// Seed of the truth, the poses and the training.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Threads a cross-validation's trainings run on (0: the cores available).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// The candidates `auto` weighs (default: every joint-map and
    /// compensator method).
    #[arg(long, value_delimiter = ',')]
    pub auto_candidates: Vec<String>,
    /// Print a line on standard error at each step of the run (method,
    /// candidate, fit or cross-validation) with the wall and processor
    /// seconds since the method started, so the steps that leave cores
    /// idle show (processor / wall below the thread count).
    #[arg(long)]
    pub phases: bool,
}

/// Arguments of `robocal bench km`.
#[derive(Debug, Args)]
pub struct KmArgs {
    /// Preset name or model JSON file.
    #[arg(long)]
    pub model: String,
    /// Identification measurement CSV.
    #[arg(long)]
    pub identify: String,
    /// Validation measurement CSV.
    #[arg(long)]
    pub validate: String,
    /// Sign of `*_dif` columns (real-data layout): plus or minus.
    #[arg(long, default_value = "plus")]
    pub dif_sign: String,
    /// Calibrations to time.
    #[arg(long, default_value_t = 10)]
    pub repeat: usize,
}

/// Arguments of `robocal bench ik`.
#[derive(Debug, Args)]
pub struct IkArgs {
    /// Preset name or model JSON file (the nominal model).
    #[arg(long)]
    pub model: String,
    /// A calibrated model file (`robocal calibrate --save`) to solve on instead.
    #[arg(long)]
    pub calibrated: Option<String>,
    /// Targets CSV: x,y,z (mm), qw,qx,qy,qz, in the base frame.
    #[arg(long)]
    pub targets: String,
    /// Position tolerance (mm).
    #[arg(long, default_value_t = 1e-4)]
    pub position_tolerance_mm: f64,
    /// Orientation tolerance (rad).
    #[arg(long, default_value_t = 1e-7)]
    pub orientation_tolerance_rad: f64,
    /// Passes over the targets.
    #[arg(long, default_value_t = 5)]
    pub repeat: usize,
    /// Write the solutions here (CSV: converged, q1..qN in model radians), for
    /// checking them with another implementation's forward kinematics.
    #[arg(long)]
    pub joints_out: Option<String>,
}

/// Runs the timing and prints its figures as pretty JSON on standard output.
pub fn run(a: BenchArgs) -> anyhow::Result<()> {
    let out = match a.what {
        BenchCommand::Km(k) => km(&k)?,
        BenchCommand::Ik(i) => ik(&i)?,
        BenchCommand::Methods(m) => methods(&m)?,
    };
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}

fn methods(a: &MethodsArgs) -> anyhow::Result<serde_json::Value> {
    use crate::calibrate::identify::calibrate_with_training;
    use crate::sim::random_configurations;
    use crate::sim::unmodelled_truth;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    let methods: Vec<Method> = if a.method.is_empty() {
        Method::ALL
            .into_iter()
            .filter(|m| *m != Method::Auto)
            .collect()
    } else {
        a.method
            .iter()
            .map(|m| Method::parse(m).with_context(|| format!("unknown method {m}")))
            .collect::<anyhow::Result<_>>()?
    };
    let nominal = crate::model::preset("ys100")?;
    let truth = unmodelled_truth(&nominal, true, a.seed);
    let mut rng = ChaCha8Rng::seed_from_u64(a.seed + 100);
    let mut measure = |n: usize| -> anyhow::Result<Vec<measure::Measurement>> {
        let qs = random_configurations(&nominal, n, &mut rng);
        let rows = truth.measure(&qs, Some(nominal.payload.mass), None, &mut rng)?;
        Ok(measure::to_measurements(
            &nominal,
            &rows,
            nominal.payload.mass,
        ))
    };
    let auto_candidates: Vec<Method> = a
        .auto_candidates
        .iter()
        .map(|m| Method::parse(m).with_context(|| format!("unknown method {m}")))
        .collect::<anyhow::Result<_>>()?;
    let ident = measure(100)?;
    let valid = measure(200)?;
    let mut rows = Vec::new();
    for &n in &a.poses {
        let train = measure(n)?;
        for m in &methods {
            let d = CalibrationSettings::default();
            let settings = CalibrationSettings {
                methods: vec![*m],
                seed: a.seed,
                auto_candidates: if auto_candidates.is_empty() {
                    d.auto_candidates.clone()
                } else {
                    auto_candidates.clone()
                },
                ..d
            };
            let opts = settings.options(Parallelism { threads: a.threads });
            let t = Instant::now();
            let steps = StepLog::new(a.phases);
            let r = calibrate_with_training(&nominal, &ident, &train, &valid, &opts, &|p| {
                steps.see(p);
                true
            })?;
            let seconds = t.elapsed().as_secs_f64();
            steps.end();
            let v = r
                .methods
                .get(m)
                .and_then(|x| x.validation.as_ref())
                .map(|v| v.stats.clone());
            let row = json!({
                "method": m.name(),
                "threads": opts.compensator.parallel.threads(),
                "chosen": r.methods.get(m).and_then(|x| x.auto.as_ref()).map(|x| x.chosen.name()),
                "training_poses": n,
                "seconds": seconds,
                "validation_mean_mm": v.as_ref().map(|v| v.mean_mm),
                "validation_max_mm": v.as_ref().map(|v| v.max_mm),
                "failed": r.failed.iter().find(|f| f.method == *m).map(|f| f.reason.clone()),
            });
            eprintln!("{row}");
            rows.push(row);
        }
    }
    Ok(
        json!({"bench": "methods", "robot": "ys100", "identification_poses": ident.len(), "validation_poses": valid.len(), "runs": rows}),
    )
}

/// The steps of one bench run (`--phases`): a line per change of phase,
/// candidate or stage (fit or cross-validation) with the wall and processor
/// seconds since the run started.
struct StepLog {
    on: bool,
    start: Instant,
    cpu0: f64,
    last: std::sync::Mutex<Option<String>>,
}

impl StepLog {
    fn new(on: bool) -> Self {
        StepLog {
            on,
            start: Instant::now(),
            cpu0: process_cpu_s(),
            last: std::sync::Mutex::new(None),
        }
    }

    fn see(&self, p: &crate::calibrate::identify::Progress) {
        if !self.on {
            return;
        }
        let step = format!(
            "{} {} {}",
            p.phase.label(),
            p.candidate.map_or("-", |c| c.name()),
            if p.fold.is_some() { "cv" } else { "fit" }
        );
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if last.as_deref() != Some(step.as_str()) {
            self.line(&step);
            *last = Some(step);
        }
    }

    fn end(&self) {
        if self.on {
            self.line("end");
        }
    }

    fn line(&self, step: &str) {
        eprintln!(
            "step {:>9.3} s wall {:>9.3} s cpu  {step}",
            self.start.elapsed().as_secs_f64(),
            process_cpu_s() - self.cpu0
        );
    }
}

/// Processor seconds (user and system) the process used so far.
fn process_cpu_s() -> f64 {
    // SAFETY: getrusage writes the struct it is given and nothing else.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return f64::NAN;
    }
    let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    s(u.ru_utime) + s(u.ru_stime)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn km(a: &KmArgs) -> anyhow::Result<serde_json::Value> {
    let model = super::model_files::load_model(&a.model)?;
    let dif = match a.dif_sign.as_str() {
        "plus" => csv::DifSign::Plus,
        "minus" => csv::DifSign::Minus,
        other => bail!("--dif-sign must be plus or minus, got {other}"),
    };
    let read = |p: &str| -> anyhow::Result<_> {
        let text = std::fs::read_to_string(p).with_context(|| format!("cannot read {p}"))?;
        csv::parse_with(&text, dif).with_context(|| p.to_string())
    };
    let payload = model.payload.mass;
    let ident = measure::to_measurements(&model, &read(&a.identify)?, payload);
    let valid = measure::to_measurements(&model, &read(&a.validate)?, payload);
    let settings = CalibrationSettings {
        methods: vec![Method::Km],
        ..CalibrationSettings::default()
    };
    let opts = settings.options(Parallelism::default());
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..a.repeat.max(1) {
        let t = Instant::now();
        let r = calibrate(&model, &ident, &valid, &opts, &|_| true)?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
        last = Some(r);
    }
    let r = last.expect("at least one run");
    let m = r.methods.get(&Method::Km).context("KM did not run")?;
    let v = m.validation.as_ref().context("no validation")?;
    Ok(json!({
        "bench": "km",
        "model": a.model,
        "identification_poses": ident.len(),
        "validation_poses": valid.len(),
        "nominal_validation_mean_mm": r.nominal.validation.as_ref().map(|v| v.stats.mean_mm),
        "validation_mean_mm": v.stats.mean_mm,
        "validation_max_mm": v.stats.max_mm,
        "identification_mean_mm": m.identification.stats.mean_mm,
        "parameters": m.parameters.len(),
        "converged": m.solver.converged,
        "iterations": m.solver.iterations,
        "repeats": times.len(),
        "time_ms_median": median(times.clone()),
        "time_ms_min": times.iter().copied().fold(f64::INFINITY, f64::min),
    }))
}

/// Target poses of a CSV with columns x,y,z,qw,qx,qy,qz (any order).
fn read_pose_targets(path: &str) -> anyhow::Result<Vec<Goal>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {path}"))?;
    let mut lines = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
    let header: Vec<String> = lines
        .next()
        .context("empty targets file")?
        .split(',')
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    let col = |n: &str| {
        header
            .iter()
            .position(|c| c == n)
            .with_context(|| format!("{path}: no column {n}"))
    };
    let idx = [
        col("x")?,
        col("y")?,
        col("z")?,
        col("qw")?,
        col("qx")?,
        col("qy")?,
        col("qz")?,
    ];
    lines
        .enumerate()
        .map(|(i, l)| {
            let f: Vec<f64> = l
                .split(',')
                .map(|v| v.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("{path}: line {}", i + 2))?;
            let g = |k: usize| f.get(idx[k]).copied().context("short line");
            let q = UnitQuaternion::from_quaternion(Quaternion::new(g(3)?, g(4)?, g(5)?, g(6)?));
            Ok(Goal {
                position: Vector3::new(g(0)?, g(1)?, g(2)?) * 1e-3,
                rotation: Some(*q.to_rotation_matrix().matrix()),
            })
        })
        .collect()
}

fn ik(a: &IkArgs) -> anyhow::Result<serde_json::Value> {
    let nominal = super::model_files::load_model(&a.model)?;
    let model = match &a.calibrated {
        None => CompensatedModel::from_nominal(nominal),
        Some(p) => {
            let text = std::fs::read_to_string(p).with_context(|| format!("cannot read {p}"))?;
            CalibratedModelFile::from_json(&text)
                .and_then(|f| f.to_compensated())
                .map_err(|e| anyhow::anyhow!("{p}: {e}"))?
        }
    };
    let settings = IkSettings {
        position_tolerance_m: a.position_tolerance_mm * 1e-3,
        orientation_tolerance_rad: a.orientation_tolerance_rad,
        ..IkSettings::default()
    };
    let solver = IkSolver::new(model, settings);
    let goals = read_pose_targets(&a.targets)?;
    let options = SolveOptions {
        frame: TargetFrame::Base,
        ..SolveOptions::default()
    };
    let mut times = Vec::with_capacity(goals.len() * a.repeat.max(1));
    let mut solutions = Vec::new();
    for pass in 0..a.repeat.max(1) {
        for g in &goals {
            let t = Instant::now();
            let s = solver.solve_goal(g, &options);
            times.push(t.elapsed().as_secs_f64() * 1e6);
            if pass == 0 {
                solutions.push(s);
            }
        }
    }
    if let Some(path) = &a.joints_out {
        let mut out = String::new();
        for s in &solutions {
            let mut row = vec![Cell::int(u8::from(s.converged))];
            row.extend(s.q.iter().map(|v| Cell::num(*v)));
            push_row(&mut out, &row);
        }
        std::fs::write(path, out).with_context(|| format!("cannot write {path}"))?;
    }
    // Accuracy by forward kinematics of the returned joints, not the solver's residual.
    let (mut solved, mut max_p, mut max_r, mut sum_p) = (0, 0.0f64, 0.0f64, 0.0);
    for (g, s) in goals.iter().zip(&solutions) {
        if !s.converged {
            continue;
        }
        solved += 1;
        let pose = solver.model().predict_base(&s.q)?;
        let dp = (pose.p - g.position).norm() * 1e3;
        let r = g.rotation.expect("pose targets");
        let dr = nalgebra::Rotation3::from_matrix_unchecked(pose.r.transpose() * r).angle();
        max_p = max_p.max(dp);
        max_r = max_r.max(dr);
        sum_p += dp;
    }
    Ok(json!({
        "bench": "ik",
        "model": a.calibrated.clone().unwrap_or_else(|| a.model.clone()),
        "targets": goals.len(),
        "solved": solved,
        "solve_rate": solved as f64 / goals.len().max(1) as f64,
        "position_tolerance_mm": a.position_tolerance_mm,
        "orientation_tolerance_rad": a.orientation_tolerance_rad,
        "mean_position_error_mm": sum_p / solved.max(1) as f64,
        "max_position_error_mm": max_p,
        "max_orientation_error_rad": max_r,
        "repeats": a.repeat.max(1),
        "time_us_median": median(times.clone()),
        "time_us_mean": times.iter().sum::<f64>() / times.len().max(1) as f64,
    }))
}
