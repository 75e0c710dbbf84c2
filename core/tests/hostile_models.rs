//! Models a careless or hostile user can send (issue 35): every numeric field
//! of a description extreme, finite or not (1e-300 … 1e300, ±∞, NaN). The
//! description either refuses the model naming the field, or the model it
//! accepts goes through forward kinematics, a small calibration, a solve and
//! every export, a program filter (a small KRL program) and a measurement
//! plan without a panic and in bounded time. Models built in SI
//! without the description (as the core's callers may) with a huge tool or
//! compliance end a calibration with a reason instead of hanging or panicking.

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{
    calibrate, CalibrationError, CalibrationOptions, LmSettings, Method,
};
use robocal_core::measure::{self, Measurement};
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::export::{export, ExportFormat, ExportSource};
use robocal_core::model::kinematics::chain::tool_pose;
use robocal_core::model::kinematics::fk;
use robocal_core::model::orientation::{rotation_to, OrientationConvention};
use robocal_core::model::presets::preset_description;
use robocal_core::model::{preset, ModelDescription, RobotModel};
use robocal_core::plan::{make_plan, PlanSettings};
use robocal_core::program::{filter, Language, ProgramFile};
use robocal_core::sim::{try_random_configurations, PoseFilter, TrueRobot};
use robocal_core::solve::cell::{Cell, Tool};
use robocal_core::solve::ik::{IkSettings, IkSolver, SolveOptions};
use std::time::{Duration, Instant};

/// What only a hang takes: the work these tests time takes well under a
/// second on any machine that builds the project, so only a loop that never
/// ends reaches this, however slow or loaded the machine.
const HANG: Duration = Duration::from_secs(120);

/// `n` random configurations of `model`, without the floor check: an
/// accepted model may hang its whole arm below its base plane (`d1 = −100 m`),
/// which is odd but not hostile. `None` when no configuration closes.
fn configurations(model: &RobotModel, n: usize, rng: &mut ChaCha8Rng) -> Option<Vec<Vec<f64>>> {
    let anywhere = PoseFilter {
        min_z_m: None,
        ..PoseFilter::default()
    };
    try_random_configurations(model, n, &anywhere, rng, |_| true).ok()
}

/// Simulated measurements of `model` itself (no errors): `None` when the
/// simulation refuses the model.
fn measured(model: &RobotModel, n: usize, seed: u64) -> Option<Vec<Measurement>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let qs = configurations(model, n, &mut rng)?;
    let rows = TrueRobot::new(model.clone())
        .measure(&qs, Some(model.payload.mass), None, &mut rng)
        .ok()?;
    Some(measure::to_measurements(model, &rows, model.payload.mass))
}

/// A KRL program of `model`'s own flange poses at `qs` (mm, KUKA A B C,
/// no status or turn: the filter takes the nearest branch) with tool 1 of
/// [`cell_of`], then a target a kilometre away that nothing reaches.
fn krl_program(model: &RobotModel, qs: &[Vec<f64>]) -> Vec<ProgramFile> {
    let mut src = String::from("DEF hostile()\r\n$TOOL = TOOL_DATA[1]\r\n");
    for q in qs {
        let Ok(p) = fk(model, q) else { continue };
        let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
        src.push_str(&format!(
            "LIN {{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4}}}\r\n",
            p.p.x * 1e3,
            p.p.y * 1e3,
            p.p.z * 1e3,
            abc[0],
            abc[1],
            abc[2]
        ));
    }
    src.push_str("LIN {X 1000000.0,Y 0.0,Z 0.0,A 0.0,B 90.0,C 0.0}\r\nEND\r\n");
    vec![ProgramFile {
        name: "hostile.src".into(),
        text: src,
    }]
}

/// A cell whose tool 1 is `model`'s own tool (what its poses are of).
fn cell_of(model: &RobotModel) -> Cell {
    let mut cell = Cell::default();
    cell.tools.push(Tool {
        name: "tool".into(),
        number: Some(1),
        tcp: tool_pose(model),
        load: None,
    });
    cell
}

fn small_options(methods: Vec<Method>) -> CalibrationOptions {
    CalibrationOptions {
        methods,
        lm: LmSettings {
            max_iterations: 20,
            ..LmSettings::default()
        },
        ..CalibrationOptions::default()
    }
}

/// A tool 1e308 m away (`tool.xyz_mm = [1e308, 0, 0]` once converted):
/// the calibration ends with a reason at once instead of iterating for ever
/// in the identifiability SVD.
#[test]
fn a_huge_tool_ends_the_calibration_with_a_reason() {
    let good = preset("ys100").unwrap();
    let ident = measured(&good, 30, 3).unwrap();
    let mut model = good.clone();
    model.tool.p.x = 1e308;
    let t0 = Instant::now();
    let r = calibrate(
        &model,
        &ident,
        &[],
        &small_options(vec![Method::Km]),
        &|_| true,
    );
    // It returns, with a reason: only a hang (the SVD iterating for ever)
    // takes a minute.
    assert!(t0.elapsed() < HANG, "{:?}", t0.elapsed());
    let e = r.expect_err("a 1e308 m tool cannot calibrate");
    assert!(
        !matches!(e, CalibrationError::Cancelled),
        "ended as a cancel: {e}"
    );
    assert!(e.to_string().contains("not finite"), "{e}");
}

/// Compliance 1e308 rad/(N·m) on every joint: KM and SKCM end with a reason,
/// no panic (it was `expect("checked")` in the registration).
#[test]
fn a_huge_compliance_fails_without_a_panic() {
    let good = preset("ys100").unwrap();
    let ident = measured(&good, 30, 4).unwrap();
    let mut model = good.clone();
    for l in model.links.iter_mut() {
        l.compliance = 1e308;
    }
    let opts = small_options(vec![Method::Km, Method::Skcm]);
    let t0 = Instant::now();
    let r = calibrate(&model, &ident, &[], &opts, &|_| true);
    assert!(t0.elapsed() < HANG, "{:?}", t0.elapsed());
    let e = r.expect_err("a 1e308 compliance cannot calibrate");
    assert!(e.to_string().contains("not finite"), "{e}");
}

/// A change to a description.
type Edit = Box<dyn Fn(&mut ModelDescription)>;

/// The description refuses the issue's values naming field, value and bound.
#[test]
fn the_issue_values_are_refused_by_name() {
    let base = preset_description("ys100").unwrap();
    let cases: Vec<(&str, Edit)> = vec![
        ("tool.xyz_mm[0]", Box::new(|d| d.tool.xyz_mm[0] = 1e308)),
        ("joints[1].d_mm", Box::new(|d| d.joints[1].d_mm = 1e308)),
        ("joints[1].a_mm", Box::new(|d| d.joints[1].a_mm = 1e15)),
        (
            "joints[2].mass_kg",
            Box::new(|d| d.joints[2].mass_kg = 1e308),
        ),
        (
            "joints[0].limits_deg[0]",
            Box::new(|d| d.joints[0].limits_deg = [-1e308, 1e308]),
        ),
        (
            "joints[3].zero_deg",
            Box::new(|d| d.joints[3].zero_deg = 1e308),
        ),
        (
            "joints[1].compliance_rad_per_nm",
            Box::new(|d| d.joints[1].compliance_rad_per_nm = 1e308),
        ),
        (
            "payload.com_mm[2]",
            Box::new(|d| d.payload.com_mm[2] = -1e300),
        ),
        (
            "joints[4].alpha_deg",
            Box::new(|d| d.joints[4].alpha_deg = f64::NAN),
        ),
    ];
    for (field, set) in cases {
        let mut d = base.clone();
        set(&mut d);
        let e = d.to_model().expect_err(field).to_string();
        assert!(e.contains(&format!("`{field}`")), "{field}: {e}");
        assert!(e.contains("outside the bound ["), "{field}: {e}");
    }
}

/// Values a field is set to: tiny, ordinary, huge, not finite.
fn extreme() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(1e-300),
        Just(-1e-300),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        (-300i32..=300).prop_map(|e| 10f64.powi(e)),
        (-300i32..=300).prop_map(|e| -(10f64.powi(e))),
        -400.0..400.0f64,
        // The edges of the accepted bounds (model::bounds), so that most
        // cases are accepted models at their most extreme.
        prop::sample::select(vec![
            100_000.0, -100_000.0, 360.0, -360.0, 3600.0, -3600.0, 10_000.0, 10.0, 100.0, -100.0,
        ]),
        prop::sample::select(vec![
            100_000.0, -100_000.0, 360.0, -360.0, 3600.0, -3600.0, 10_000.0, 10.0, 100.0, -100.0,
        ]),
    ]
}

/// How many random models the property test accepted and ran end to end.
static ACCEPTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
/// Of those, how many filtered at least one target of their program.
static FILTERED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
/// Of those, how many the measurement plan answered with poses.
static PLANNED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Sets numeric field `k` (of the fields every description has) to `v`.
fn set_field(d: &mut ModelDescription, k: usize, v: f64) {
    let n = d.joints.len();
    let j = (k / 16) % n;
    let joint = &mut d.joints[j];
    match k % 16 {
        0 => joint.alpha_deg = v,
        1 => joint.a_mm = v,
        2 => joint.d_mm = v,
        3 => joint.theta_offset_deg = v,
        4 => joint.limits_deg[(k / 7) % 2] = v,
        5 => joint.zero_deg = v,
        6 => joint.mass_kg = v,
        7 => joint.com_mm[k % 3] = v,
        8 => joint.compliance_rad_per_nm = v,
        9 => d.tool.xyz_mm[k % 3] = v,
        10 => d.tool.rpy_deg[k % 3] = v,
        11 => d.payload.mass_kg = v,
        12 => d.payload.com_mm[k % 3] = v,
        13 => d.gravity_mps2[k % 3] = v,
        14 => d.payload.mass_offset_kg = v,
        _ => joint.b_mm = if j == 0 { v } else { 0.0 },
    }
}

proptest! {
    // A fixed seed: every run explores the same 48 models (the case that
    // once failed CI, ys100 with d1 = −100 m, is pinned in a test below).
    #![proptest_config(ProptestConfig {
        cases: 48,
        rng_seed: RngSeed::Fixed(0x5eed_0035),
        ..ProptestConfig::default()
    })]

    /// Random extreme fields: refused, or the model works end to end within
    /// a few seconds.
    #[test]
    fn extreme_models_are_refused_or_work(
        preset_name in prop::sample::select(vec!["ys100", "ur5", "hh800"]),
        edits in prop::collection::vec((0usize..96, extreme()), 1..4),
        seed in 0u64..1000,
    ) {
        let mut d = preset_description(preset_name).unwrap();
        for (k, v) in &edits {
            set_field(&mut d, *k, *v);
        }
        let Ok(model) = d.to_model() else {
            return Ok(());
        };
        ACCEPTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let t0 = Instant::now();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let qs = configurations(&model, 5, &mut rng).unwrap_or_default();
        let compensated = CompensatedModel::from_nominal(model.clone());
        let solver = IkSolver::new(compensated.clone(), IkSettings::default());
        for q in &qs {
            if let Ok(p) = fk(&model, q) {
                let _ = solver.solve(&p, &SolveOptions::default());
            }
        }
        let source = ExportSource { robot: &model.name, method: "nominal" };
        for f in ExportFormat::ALL {
            let _ = export(&compensated, &source, f);
        }
        // The filter: every target filtered or failed with a reason (the
        // unreachable one failed), or the program refused.
        let files = krl_program(&model, &qs[..qs.len().min(3)]);
        if let Ok(out) = filter(Language::Krl, &files, &cell_of(&model), &compensated, &IkSettings::default()) {
            let r = &out.report;
            prop_assert_eq!(r.filtered + r.failed + r.skipped, r.targets.len());
            prop_assert!(r.targets.last().is_some_and(|t| t.reason.is_some()), "{:?}", r.targets.last());
            if r.filtered > 0 {
                FILTERED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
        }
        let plan = make_plan(&model, &PlanSettings { poses: 15, candidates: 60, seed, ..PlanSettings::default() });
        if let Ok(plan) = plan {
            prop_assert_eq!(plan.q.len(), 15);
            PLANNED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        if let Some(ident) = measured(&model, 25, seed) {
            let _ = calibrate(&model, &ident, &[], &small_options(vec![Method::Km, Method::Skcm]), &|_| true);
        }
        prop_assert!(t0.elapsed() < HANG, "{edits:?}: {:?}", t0.elapsed());
    }
}

/// The property test above is not vacuous: a good share of its random
/// extreme models pass the bounds and run the whole pipeline.
#[test]
fn the_property_test_runs_accepted_models() {
    extreme_models_are_refused_or_work();
    let n = ACCEPTED.load(std::sync::atomic::Ordering::Relaxed);
    assert!(n >= 10, "only {n} of 48 random models were accepted");
    let filtered = FILTERED.load(std::sync::atomic::Ordering::Relaxed);
    let planned = PLANNED.load(std::sync::atomic::Ordering::Relaxed);
    println!("{n} accepted models: {filtered} filtered a target, {planned} planned");
    assert!(
        filtered >= n / 2,
        "only {filtered} of {n} accepted models filtered a target"
    );
    assert!(
        planned >= n / 2,
        "only {planned} of {n} accepted models planned"
    );
}

/// Limits wholly beyond ±180° (here [-3600°, -360°] on a wrist joint) once
/// made the identifiability's random poses sample an empty range.
#[test]
fn multi_turn_limits_beyond_a_half_turn_calibrate() {
    let mut d = preset_description("ur5").unwrap();
    d.joints[4].limits_deg = [-3600.0, -360.0];
    let model = d.to_model().unwrap();
    let ident = measured(&model, 25, 0).expect("measurable");
    let r = calibrate(
        &model,
        &ident,
        &[],
        &small_options(vec![Method::Km]),
        &|_| true,
    );
    assert!(r.is_ok(), "{:?}", r.err());
}

/// A model accepted at the door whose arm hangs wholly below its base plane
/// (ys100 with `d1 = −100 m`) still solves, exports and calibrates: nothing in
/// the pipeline assumes a pose above the floor.
#[test]
fn an_arm_below_its_base_plane_runs_end_to_end() {
    let mut d = preset_description("ys100").unwrap();
    d.joints[0].d_mm = -100_000.0;
    let model = d.to_model().expect("within the bounds");
    let ident = measured(&model, 25, 0).expect("configurations close");
    let r = calibrate(
        &model,
        &ident,
        &[],
        &small_options(vec![Method::Km]),
        &|_| true,
    );
    assert!(r.is_ok(), "{:?}", r.err());
}

/// The program and plan of the property test work on an ordinary model: its
/// own poses filter, the far target fails with a reason, the plan has its
/// poses.
#[test]
fn an_ordinary_model_filters_its_program_and_plans() {
    let model = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let qs = configurations(&model, 3, &mut rng).unwrap();
    let files = krl_program(&model, &qs);
    let compensated = CompensatedModel::from_nominal(model.clone());
    let out = filter(
        Language::Krl,
        &files,
        &cell_of(&model),
        &compensated,
        &IkSettings::default(),
    )
    .unwrap_or_else(|e| panic!("{e}\n{}", files[0].text));
    let r = &out.report;
    assert_eq!((r.filtered, r.failed), (3, 1), "{:?}", r.targets);
    let plan = make_plan(
        &model,
        &PlanSettings {
            poses: 15,
            candidates: 60,
            ..PlanSettings::default()
        },
    )
    .unwrap();
    assert_eq!(plan.q.len(), 15);
}
