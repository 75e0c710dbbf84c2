//! A linear track identified from simulated tracker readings of the robot it
//! carries: a 4 m rail from its physics (`robocal_core::sim::track`: scale
//! off by 0.2 mm/m, rails bent by sums of sines within ±0.1 mm, a carriage
//! on two bearing blocks yawing by up to about 30″, pitch and roll), the
//! YS100 with ~1 mm / 0.1° geometric errors calibrated on a fixed base by
//! the project's own calibration, then measured at 11 track positions and
//! predicted at 6 held-out positions (values never fitted) through the
//! fitted track and the calibrated robot. The readings go through a
//! measurement CSV with an `e1` column.
//!
//! Predictions and solves through the fitted track are checked against the
//! same truth (`predictions_and_solves_through_the_track_land_on_the_truth`).
//!
//! Figures: `cargo test -p robocal-core --test track -- --nocapture`.

mod common;

use common::track::{
    calibrated_on_fixed_base, measure_on_track, prediction_errors, read_stations, true_pose,
    ys100_truth, STATIONS, TRACKER_SIGMA_MM,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::track::{
    fit_track, fit_track_compensated, TrackFit, TrackFitRequest, TrackRefusalReason, TrackRefused,
    UnseenTerm, DEFAULT_MAX_ORDER,
};
use robocal_core::measure::csv;
use robocal_core::measure::external::{ExternalAxis, MeasurementSet};
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::external::CarriageTerm;
use robocal_core::model::kinematics::fk;
use robocal_core::model::{Pose, RobotModel};
use robocal_core::plan::{
    join, make_track_plan, plan_csv, read_plan_csv, JoinOptions, PlanSettings, TrackPlan,
    TrackPlanSettings, TrackerSight,
};
use robocal_core::sim::track::TrueTrack;
use robocal_core::sim::{random_configurations, TrueRobot};
use robocal_core::solve::external::{carried, TrackPoseError, TrackSolver};
use robocal_core::solve::ik::{Goal, IkSettings, SolveOptions};

/// Held-out track values [mm], between the fitted ones.
const HELD_OUT: [f64; 6] = [200.0, 1000.0, 1400.0, 2600.0, 3000.0, 3800.0];
const POSES_PER_STATION: usize = 15;
fn request<'a>(
    robot: &'a RobotModel,
    set: &'a MeasurementSet,
    max_order: usize,
) -> TrackFitRequest<'a> {
    TrackFitRequest {
        robot,
        payload_kg: robot.payload.mass,
        set,
        column: ExternalAxis::E1,
        tracker_sigma_mm: TRACKER_SIGMA_MM,
        max_order,
    }
}

/// [`POSES_PER_STATION`] random poses at each [`HELD_OUT`] value, read on
/// the truth.
fn held_out(
    truth: &TrueRobot,
    nominal: &RobotModel,
    track: &TrueTrack,
    rng: &mut ChaCha8Rng,
) -> MeasurementSet {
    measure_on_track(truth, nominal, track, &HELD_OUT, POSES_PER_STATION, rng)
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}

/// The acceptance: held-out track positions within 1.5× the robot's own
/// validation error on a fixed base; a fit without maps refused; the terms
/// the readings cannot see named.
#[test]
fn held_out_track_positions_are_predicted_within_the_robots_own_error() {
    let track = TrueTrack::rail_4m();
    for seed in [1u64, 2, 3] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (nominal, truth) = ys100_truth(&mut rng);
        let (calibrated, robot_val_rms) =
            calibrated_on_fixed_base(&nominal, &truth, &track, &mut rng);
        let measured = measure_on_track(
            &truth,
            &nominal,
            &track,
            &STATIONS,
            POSES_PER_STATION,
            &mut rng,
        );
        // Through the CSV: written with its e1 column, read back.
        let text = csv::write_set(&measured);
        assert!(text.starts_with("q1,q2,q3,q4,q5,q6,e1,x,y,z,payload_kg\n"));
        let set = csv::parse_set(&text).unwrap();
        assert_eq!(set, measured);
        let fit = fit_track(&request(&calibrated, &set, DEFAULT_MAX_ORDER)).unwrap_or_else(|e| {
            panic!(
                "seed {seed}: {e} {:?}",
                e.fit.as_ref().map(|f| (&f.maps, &f.stations))
            )
        });
        let held = held_out(&truth, &nominal, &track, &mut rng);
        let errors = prediction_errors(&fit, &calibrated, &held);
        let (held_rms, held_max) = (rms(&errors), max(&errors));
        // Without maps (a straight rail: line, scale, zero, mount).
        let straight = match fit_track(&request(&calibrated, &set, 0)) {
            Err(TrackRefused {
                reason: TrackRefusalReason::ResidualsTooLarge,
                fit: Some(f),
                ..
            }) => *f,
            other => panic!("seed {seed}: a straight rail should be refused, got {other:?}"),
        };
        let straight_errors = prediction_errors(&straight, &calibrated, &held);
        let scale_error_mm_per_m = (fit.model.scale - 1.0) * 1e3;
        let rail_x = track.cell_from_rail.r.column(0).into_owned();
        let direction_arcsec = fit
            .model
            .rail
            .direction
            .cross(&rail_x)
            .norm()
            .asin()
            .to_degrees()
            * 3600.0;
        println!(
            "seed {seed}: robot on a fixed base, validation rms {robot_val_rms:.4} mm; \
             held-out track positions rms {held_rms:.4} mm (max {held_max:.4}), ratio {:.2}; \
             without maps rms {:.4} mm (max {:.4}); fit residuals rms {:.4} (max {:.4}) mm; \
             scale error {scale_error_mm_per_m:.4} mm/m (truth 0.2); direction off the true rail {direction_arcsec:.1}″",
            held_rms / robot_val_rms,
            rms(&straight_errors),
            max(&straight_errors),
            fit.rms_mm,
            fit.max_mm,
        );
        for m in &fit.maps {
            println!(
                "  {:?}: order {} (cv rms {}), amplitude {:.4} {}, station σ {:.4}",
                m.term,
                m.order,
                m.candidates
                    .iter()
                    .map(|c| format!("{}:{:.4}", c.order, c.cv_rms))
                    .collect::<Vec<_>>()
                    .join(" "),
                m.amplitude,
                m.unit,
                m.station_sigma
            );
        }
        if seed == 1 {
            println!("{}", fit.model.to_json());
            for u in &fit.unseen {
                println!("  unseen {:?}: {}", u.term, u.note);
            }
        }
        assert!(
            held_rms <= 1.5 * robot_val_rms,
            "seed {seed}: held-out rms {held_rms} vs robot {robot_val_rms}"
        );
        assert!(rms(&straight_errors) > 3.0 * held_rms);
        assert!(
            (scale_error_mm_per_m - 0.2).abs() < 0.03,
            "{scale_error_mm_per_m}"
        );
        assert!(direction_arcsec < 20.0, "{direction_arcsec}");
        let terms: Vec<UnseenTerm> = fit.unseen.iter().map(|u| u.term).collect();
        assert_eq!(terms, UnseenTerm::ALL.to_vec());
        // The yaw the truth has is found: its map reaches ≥ 15″.
        let yaw = fit
            .maps
            .iter()
            .find(|m| m.term == CarriageTerm::Yaw)
            .unwrap();
        assert!(yaw.amplitude > 15.0, "yaw {}", yaw.amplitude);
        // Stored and read back, the same track.
        let back =
            robocal_core::model::external::LinearTrack::from_json(&fit.model.to_json()).unwrap();
        for v in HELD_OUT {
            let (a, b) = (
                back.cell_from_base(v).unwrap(),
                fit.model.cell_from_base(v).unwrap(),
            );
            assert!((a.p - b.p).norm() < 1e-9);
        }
        // Beyond the travel measured the track refuses.
        assert!(fit.model.cell_from_base(4000.5).is_err());
    }
}

/// With exact readings, the truth robot held and a straight rail whose only
/// error is its scale, the fit gives the truth back to rounding.
#[test]
fn a_straight_rail_comes_back_exactly() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (nominal, mut truth) = ys100_truth(&mut rng);
    truth.noise_mm = 0.0;
    let mut track = TrueTrack::rail_4m();
    track.lateral.clear();
    track.vertical.clear();
    track.yaw_extra.clear();
    track.pitch_extra.clear();
    track.roll.clear();
    let set = measure_on_track(
        &truth,
        &nominal,
        &track,
        &STATIONS[..6],
        POSES_PER_STATION,
        &mut rng,
    );
    let fit = fit_track(&request(&truth.model, &set, DEFAULT_MAX_ORDER)).unwrap();
    assert!(
        (fit.model.scale - (1.0 + 2e-4)).abs() < 1e-10,
        "{}",
        fit.model.scale
    );
    assert!(fit.max_mm < 1e-7, "{}", fit.max_mm);
    for v in [0.0, 777.0, 2000.0] {
        let (a, b) = (
            fit.model.cell_from_base(v).unwrap(),
            track.cell_from_base(v),
        );
        assert!(
            (a.p - b.p).norm() < 1e-10 && (a.r - b.r).norm() < 1e-10,
            "{v}"
        );
    }
}

/// Readings the track fit cannot carry are refused, naming the station or
/// the reading.
#[test]
fn fits_the_readings_cannot_carry_are_refused() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (nominal, truth) = ys100_truth(&mut rng);
    let track = TrueTrack::rail_4m();
    let model = &truth.model;
    let why =
        |set: &MeasurementSet| fit_track(&request(model, set, DEFAULT_MAX_ORDER)).unwrap_err();

    let few = measure_on_track(
        &truth,
        &nominal,
        &track,
        &STATIONS[..4],
        POSES_PER_STATION,
        &mut rng,
    );
    assert_eq!(why(&few).reason, TrackRefusalReason::TooFewStations);

    let good = measure_on_track(
        &truth,
        &nominal,
        &track,
        &STATIONS[..7],
        POSES_PER_STATION,
        &mut rng,
    );
    assert!(fit_track(&request(model, &good, DEFAULT_MAX_ORDER)).is_ok());

    // Station 1200 mm keeps two readings.
    let mut thin = good.clone();
    let keep: Vec<usize> = (0..thin.poses.len())
        .filter(|&i| {
            thin.external[i].get(ExternalAxis::E1) != Some(1200.0) || i % POSES_PER_STATION < 2
        })
        .collect();
    thin.poses = keep.iter().map(|&i| good.poses[i].clone()).collect();
    thin.external = keep.iter().map(|&i| good.external[i]).collect();
    let e = why(&thin);
    assert_eq!(
        (e.reason, e.station_mm),
        (TrackRefusalReason::TooFewPoses, Some(1200.0))
    );

    // Station 800 mm: the robot held two poses only, read again and again.
    let mut line = good.clone();
    let rows: Vec<usize> = (0..good.poses.len())
        .filter(|&i| good.external[i].get(ExternalAxis::E1) == Some(800.0))
        .collect();
    let stations = vec![(
        800.0,
        (0..POSES_PER_STATION)
            .map(|k| {
                let q = &good.poses[rows[k % 2]].q_deg;
                nominal
                    .joints_from_controller(&q.iter().map(|d| d.to_radians()).collect::<Vec<_>>())
            })
            .collect::<Vec<_>>(),
    )];
    let again = read_stations(&truth, &nominal, &track, &stations, &mut rng);
    for (k, &i) in rows.iter().enumerate() {
        line.poses[i] = again.poses[k].clone();
    }
    let e = why(&line);
    assert_eq!(
        (e.reason, e.station_mm),
        (TrackRefusalReason::Collinear, Some(800.0))
    );

    // One reading off by 0.15 mm: named.
    let mut off = good.clone();
    let i = rows[3];
    off.poses[i].xyz_mm[2] += 0.15;
    let e = why(&off);
    assert_eq!(
        (e.reason, e.row),
        (TrackRefusalReason::ResidualOutlier, Some(i + 1))
    );
    assert!(e.fit.is_some());

    // The robot's model wrong by 2 mm in a link: stations do not fit it.
    let mut wrong = truth.model.clone();
    wrong.links[2].a += 0.002;
    let e = fit_track(&request(&wrong, &good, DEFAULT_MAX_ORDER)).unwrap_err();
    assert_eq!(e.reason, TrackRefusalReason::StationResiduals);

    // No column, or the wrong one.
    let bare = MeasurementSet::without_axes(good.poses.clone());
    assert_eq!(why(&bare).reason, TrackRefusalReason::MissingColumn);
    let mut e2 = request(model, &good, DEFAULT_MAX_ORDER);
    e2.column = ExternalAxis::E2;
    assert_eq!(
        fit_track(&e2).unwrap_err().reason,
        TrackRefusalReason::MissingColumn
    );
    let mut sigma = request(model, &good, DEFAULT_MAX_ORDER);
    sigma.tracker_sigma_mm = 0.0;
    assert_eq!(
        fit_track(&sigma).unwrap_err().reason,
        TrackRefusalReason::NotFinite
    );
}

/// The robot's compensated model as a calibration gives it: the calibrated
/// geometry, the controller's nominal model, no compensator.
fn compensated(calibrated: RobotModel, nominal: &RobotModel) -> CompensatedModel {
    CompensatedModel {
        calibrated,
        nominal: nominal.clone(),
        cell_from_base: Pose::identity(),
        payload_kg: nominal.payload.mass,
        compensator: None,
    }
}

/// The truth's tool pose in the cell frame: the true robot (no noise) on the
/// true track at `value_mm`.
/// Predict and solve through the fitted track, checked against the
/// simulated truth (its physics, not the model's code): the reflector
/// predicted at held-out track values for new joints, and targets the true
/// robot reached at held-out values solved back into joints that the true
/// robot on the true track takes to within the same bound as the fit's
/// held-out test (1.5 × the robot's own validation error on a fixed base);
/// the same through a straight rail (no maps) for comparison; values
/// beyond the travel refused.
#[test]
fn predictions_and_solves_through_the_track_land_on_the_truth() {
    let track = TrueTrack::rail_4m();
    for seed in [1u64, 2, 3] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (nominal, truth) = ys100_truth(&mut rng);
        let (calibrated, robot_val_rms) =
            calibrated_on_fixed_base(&nominal, &truth, &track, &mut rng);
        let set = measure_on_track(
            &truth,
            &nominal,
            &track,
            &STATIONS,
            POSES_PER_STATION,
            &mut rng,
        );
        let model = compensated(calibrated.clone(), &nominal);
        let fit = fit_track_compensated(
            &model,
            &set,
            ExternalAxis::E1,
            TRACKER_SIGMA_MM,
            DEFAULT_MAX_ORDER,
        )
        .unwrap();
        // Without a compensator the compensated model places the readings
        // as the calibrated geometry does: the same track.
        let plain = fit_track(&request(&calibrated, &set, DEFAULT_MAX_ORDER)).unwrap();
        for v in HELD_OUT {
            let (a, b) = (
                fit.model.cell_from_base(v).unwrap(),
                plain.model.cell_from_base(v).unwrap(),
            );
            assert!((a.p - b.p).norm() < 1e-12 && (a.r - b.r).norm() < 1e-12);
        }
        let straight =
            match fit_track_compensated(&model, &set, ExternalAxis::E1, TRACKER_SIGMA_MM, 0) {
                Err(TrackRefused { fit: Some(f), .. }) => f.model,
                other => panic!("seed {seed}: a straight rail should be refused, got {other:?}"),
            };
        let on_track = TrackSolver::new(&model, None, fit.model.clone(), IkSettings::default());
        let on_straight = TrackSolver::new(&model, None, straight, IkSettings::default());

        // Predict: new joints at held-out values.
        let mut predicted = Vec::new();
        for v in HELD_OUT {
            for q in random_configurations(&nominal, POSES_PER_STATION, &mut rng) {
                let p = on_track.predict(&q, v).unwrap();
                let want = true_pose(&truth, &track, &q, v).p;
                predicted.push((p.p - want).norm() * 1e3);
                // The carried model predicts the same pose in its cell frame.
                let c = carried(&model, &fit.model, v).unwrap().predict(&q).unwrap();
                assert!((c.p - p.p).norm() < 1e-12 && (c.r - p.r).norm() < 1e-12);
            }
        }

        // Solve: points the true robot reached, solved back at their values
        // (position only: a reflector's readings do not fix the tool's
        // orientation; the true orientation guides the seed).
        let position_only = SolveOptions {
            position_only: true,
            ..SolveOptions::default()
        };
        let (mut solved, mut straight_solved, mut round_trip) = (Vec::new(), Vec::new(), 0.0f64);
        for v in HELD_OUT {
            for q in random_configurations(&nominal, POSES_PER_STATION, &mut rng) {
                let target = true_pose(&truth, &track, &q, v);
                let goal = Goal::from(&target);
                let s = on_track.solve(&goal, v, &position_only).unwrap();
                assert!(s.converged, "seed {seed} at {v} mm: {:?}", s.reason);
                round_trip =
                    round_trip.max((on_track.predict(&s.q, v).unwrap().p - target.p).norm());
                solved.push((true_pose(&truth, &track, &s.q, v).p - target.p).norm() * 1e3);
                let s = on_straight.solve(&goal, v, &position_only).unwrap();
                assert!(s.converged, "seed {seed} at {v} mm: {:?}", s.reason);
                straight_solved
                    .push((true_pose(&truth, &track, &s.q, v).p - target.p).norm() * 1e3);
            }
        }
        println!(
            "seed {seed}: robot on a fixed base, validation rms {robot_val_rms:.4} mm; \
             predicted at held-out track values: rms {:.4} mm (max {:.4}); \
             solved there, the true robot off its target: rms {:.4} mm (max {:.4}), \
             through a straight rail rms {:.4} mm (max {:.4}); round trip within {:.1e} mm",
            rms(&predicted),
            max(&predicted),
            rms(&solved),
            max(&solved),
            rms(&straight_solved),
            max(&straight_solved),
            round_trip * 1e3,
        );
        assert!(rms(&predicted) <= 1.5 * robot_val_rms, "seed {seed}");
        assert!(rms(&solved) <= 1.5 * robot_val_rms, "seed {seed}");
        assert!(rms(&straight_solved) > 3.0 * rms(&solved), "seed {seed}");
        assert!(round_trip < 1e-6, "{round_trip} m");

        // Beyond the travel measured: refused, naming the value and the travel.
        let q = &random_configurations(&nominal, 1, &mut rng)[0];
        match on_track.predict(q, 4000.5) {
            Err(TrackPoseError::OutsideTravel(o)) => {
                assert_eq!((o.value_mm, o.lo_mm, o.hi_mm), (4000.5, 0.0, 4000.0))
            }
            other => panic!("{other:?}"),
        }
        let goal = Goal::from(&true_pose(&truth, &track, q, 0.0));
        assert!(on_track
            .solve(&goal, -1.0, &SolveOptions::default())
            .is_err());
        assert!(on_track
            .solve(&goal, f64::NAN, &SolveOptions::default())
            .is_err());
        assert!(carried(&model, &fit.model, 4001.0).is_err());
    }
}

/// The poses of `plan` grouped by station: `(value_mm, configurations)`.
fn planned_stations(plan: &TrackPlan) -> Vec<(f64, Vec<Vec<f64>>)> {
    plan.stations
        .iter()
        .map(|s| {
            (
                s.value_mm,
                s.points.iter().map(|&k| plan.q[k].clone()).collect(),
            )
        })
        .collect()
}

/// `√(Σ σ²)` of the base's three turns [arcsec] from reflector positions
/// `p` [m]: `σ²·trace((Σ|a'|²·I − a'·a'ᵀ)⁻¹)`, `a'` about the centroid.
fn turn_sigma_arcsec(p: &[nalgebra::Vector3<f64>]) -> f64 {
    let c = p.iter().sum::<nalgebra::Vector3<f64>>() / p.len() as f64;
    let inertia = p.iter().fold(nalgebra::Matrix3::zeros(), |m, x| {
        let a = x - c;
        m + nalgebra::Matrix3::identity() * a.norm_squared() - a * a.transpose()
    });
    let trace = inertia.try_inverse().map_or(f64::INFINITY, |m| m.trace());
    TRACKER_SIGMA_MM * 1e-3 * trace.sqrt() * 180.0 * 3600.0 / std::f64::consts::PI
}

/// Per station of `plan`, the median turn σ of 25 draws of 4 random poses
/// over the plan's predicted one; asserting on the way that the plan's σ
/// is the fit's station σ and the one computed here from the points.
fn turn_sigma_ratios(
    plan: &TrackPlan,
    fit: &TrackFit,
    calibrated: &RobotModel,
    rng: &mut ChaCha8Rng,
) -> Vec<f64> {
    let stations = planned_stations(plan);
    let mut ratios = Vec::new();
    for (planned, (value, qs)) in plan.stations.iter().zip(&stations) {
        let fitted = fit.stations.iter().find(|s| s.value_mm == *value).unwrap();
        let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let (p, f) = (
            norm(planned.angle_sigma_arcsec),
            norm(fitted.sigma_angles_arcsec),
        );
        assert!(
            (p - f).abs() < 1e-6 * f,
            "{value} mm: planned {p} vs fitted {f}"
        );
        let at = |qs: &[Vec<f64>]| {
            qs.iter()
                .map(|q| fk(calibrated, q).unwrap().p)
                .collect::<Vec<_>>()
        };
        assert!((turn_sigma_arcsec(&at(qs)) - p).abs() < 1e-6 * p);
        let mut random: Vec<f64> = (0..25)
            .map(|_| turn_sigma_arcsec(&at(&random_configurations(calibrated, 4, rng))))
            .collect();
        random.sort_by(f64::total_cmp);
        ratios.push(random[12] / p);
    }
    ratios
}

/// A plan over the track (`plan::make_track_plan`: by default a station
/// every 400 mm over the 4 m, 4 D-optimal poses each, the tracker at the cell frame's origin seeing
/// the reflector within 60° from each station through the drawing's track)
/// measured on the truth, joined back through the plan's CSV and a tracker
/// export into a measurement CSV with its `e1` column, and fitted: accepted,
/// held-out track positions within 1.5× the robot's own validation error on
/// a fixed base; the plan's predicted turn σ are the fit's station σ; random
/// poses at the same stations see the base's turns worse; a plan of 8
/// stations (one every 571 mm) predicts the same held-out readings worse,
/// or is refused.
#[test]
fn a_planned_track_measurement_fits_and_validates() {
    let track = TrueTrack::rail_4m();
    let drawing = TrueTrack::drawing_4m();
    for seed in [1u64, 2, 3] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (nominal, truth) = ys100_truth(&mut rng);
        let (calibrated, robot_val_rms) =
            calibrated_on_fixed_base(&nominal, &truth, &track, &mut rng);
        let settings = TrackPlanSettings {
            poses: PlanSettings {
                tracker: Some(TrackerSight {
                    position_mm: [0.0, 0.0, 0.0],
                    ..TrackerSight::default()
                }),
                seed,
                ..TrackPlanSettings::default().poses
            },
            ..TrackPlanSettings::default()
        };
        let plan = make_track_plan(&calibrated, &drawing, &settings).unwrap();
        assert_eq!(plan.stations.len(), 11);
        assert_eq!(plan.points.len(), 44);
        let stations = planned_stations(&plan);
        let measured = read_stations(&truth, &nominal, &track, &stations, &mut rng);
        // The tracker's export names each point; joined back to the plan's CSV.
        let export = common::tracker_export(
            plan.points
                .iter()
                .zip(&measured.poses)
                .rev()
                .map(|(p, m)| (p.name.as_str(), m.xyz_mm)),
        );
        let points = read_plan_csv(&plan_csv(&plan.points)).unwrap();
        assert_eq!(points, plan.points);
        let joined = join(&points, &export, &JoinOptions::default()).unwrap();
        let set = csv::parse_set(&csv::write_set(&joined.set())).unwrap();
        assert_eq!(set.axes, vec![ExternalAxis::E1]);
        for ((r, m), p) in set
            .readings()
            .zip(&measured.readings().collect::<Vec<_>>())
            .zip(&plan.points)
        {
            assert_eq!(r.external, m.external);
            assert_eq!(r.pose.xyz_mm, m.pose.xyz_mm);
            for (a, b) in r.pose.q_deg.iter().zip(&m.pose.q_deg) {
                assert!((a - b).abs() < 1e-9, "{}: {a} vs {b}", p.name);
            }
        }
        let fit = fit_track(&request(&calibrated, &set, DEFAULT_MAX_ORDER))
            .unwrap_or_else(|e| panic!("seed {seed}: the planned measurements refused: {e}"));
        let held = held_out(&truth, &nominal, &track, &mut rng);
        let errors = prediction_errors(&fit, &calibrated, &held);
        let (held_rms, held_max) = (rms(&errors), max(&errors));
        let ratios = turn_sigma_ratios(&plan, &fit, &calibrated, &mut rng);
        // The same robot planned with 8 stations (one every 571 mm), judged
        // on the same held-out readings.
        let sparse = TrackPlanSettings {
            stations: Some(8),
            ..settings.clone()
        };
        let sparse = make_track_plan(&calibrated, &drawing, &sparse).unwrap();
        let read = read_stations(
            &truth,
            &nominal,
            &track,
            &planned_stations(&sparse),
            &mut rng,
        );
        // A sparse plan may be refused (the rail bending faster than it samples).
        let sparse = match fit_track(&request(&calibrated, &read, DEFAULT_MAX_ORDER)) {
            Ok(f) => {
                let rms8 = rms(&prediction_errors(&f, &calibrated, &held));
                assert!(
                    held_rms < rms8,
                    "seed {seed}: {held_rms} at 400 mm vs {rms8} at 571 mm"
                );
                format!(
                    "held-out rms {rms8:.4} mm, ratio {:.2}",
                    rms8 / robot_val_rms
                )
            }
            Err(e) => format!("refused ({:?}: {})", e.reason, e.message),
        };
        println!(
            "seed {seed}: planned {} stations x 4 poses; robot on a fixed base validated at rms {robot_val_rms:.4} mm; \
             held-out track positions rms {held_rms:.4} mm (max {held_max:.4}), ratio {:.2}; \
             turn sigma planned {:.3}..{:.3} arcsec, random 4 poses' median / planned {:.2}..{:.2}; \
             8 stations: {sparse}",
            plan.stations.len(),
            held_rms / robot_val_rms,
            plan.stations.iter().map(|s| s.angle_sigma_arcsec.iter().map(|x| x * x).sum::<f64>().sqrt()).fold(f64::INFINITY, f64::min),
            plan.stations.iter().map(|s| s.angle_sigma_arcsec.iter().map(|x| x * x).sum::<f64>().sqrt()).fold(0.0, f64::max),
            ratios.iter().copied().fold(f64::INFINITY, f64::min),
            ratios.iter().copied().fold(0.0, f64::max),
        );
        assert!(
            held_rms <= 1.5 * robot_val_rms,
            "seed {seed}: held-out rms {held_rms} vs robot {robot_val_rms}"
        );
        assert!(ratios.iter().all(|r| *r > 1.0), "{ratios:?}");
    }
}
