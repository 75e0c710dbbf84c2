//! A linear track identified from tracker readings of the robot it carries,
//! with the robot's calibrated model held.
//!
//! Steps (frames and terms of `model::external::track`):
//! 1. per station (one track value), the base's pose in the cell frame by
//!    rigid registration of the model's reflector positions onto the
//!    readings, with its σ and the points' spread ([`super::station`]);
//!    refused when a station has fewer than 3 readings or they lie within
//!    [`MIN_ACROSS_MM`] of a line;
//! 2. the rail: a line through the stations' origins, least squares over
//!    the values (`t = a + b·v`), its direction `d = b/|b|`; then the
//!    stations' deviations across it along the rail frame's y and z as
//!    Legendre series of the normalised value with their order
//!    cross-validated ([`super::series`]); each series' mean and slope go
//!    back into the line, until the line moves by less than 1e-12 m;
//! 3. scale, zero and the positioning map: the stations' travel along `d`
//!    as a cross-validated series, its mean and slope giving zero and scale;
//! 4. the mount and the angles: the stations' rotations seen from the rail
//!    frame, `M_k = R_railᵀ·R_k`, their chordal mean as the mount, the
//!    remainder's fixed-axis angles (roll, pitch, yaw) as cross-validated
//!    series whose means go back into the mount (three passes);
//! 5. every reading predicted through the fitted track and the held robot;
//!    the fit judged on those residuals as the positioner's is
//!    (`judge::FitLimits`: RMS ≤ 3·√3·σ, each ≤ 5·√3·σ), and each station's
//!    rigid fit against the same RMS bound.
//!
//! Units: m and rad inside; reports in mm and arcsec.

use super::outcome::{
    MapReport, OrderScore, StationReport, TrackFit, TrackFitRequest, TrackRefusalReason as Why,
    TrackRefused, Unseen, UnseenTerm,
};
use super::series::{choose_order, SeriesFit};
use super::station::{fit_station, StationError, StationPose};
use crate::calibrate::external::judge::{rms_max, within, RMS_FACTOR};
use crate::calibrate::external::outcome::FitLimits;
use crate::measure::external::{ExternalAxis, MeasurementSet};
use crate::model::calibrated::CompensatedModel;
use crate::model::external::rotary::{closest_to_origin, Line};
use crate::model::external::track::{rail_rotation, CarriageTerm, LinearTrack};
use crate::model::external::travel_map::{Travel, TravelMap, MAX_MAP_ORDER};
use crate::model::kinematics::{deflected_joints, fk};
use crate::model::orientation::fixed_xyz_angles;
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
use nalgebra::{Matrix3, Vector3};

/// Fewest stations: the line takes two, and cross-validation needs more.
pub const MIN_STATIONS: usize = 5;
/// Fewest readings per station: three points not on a line fix a pose.
pub const MIN_POSES: usize = 3;
/// Smallest RMS spread of a station's points across their main line [mm].
pub const MIN_ACROSS_MM: f64 = 10.0;
/// Highest map order tried unless the request asks for less.
pub const DEFAULT_MAX_ORDER: usize = 6;

const ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// Where the held robot puts the reflector in its base frame [m] for
/// model-convention joints `q` [rad] and a payload [kg].
type Place<'a> = dyn Fn(&[f64], f64) -> Result<Vector3<f64>, String> + 'a;

/// Fits the track (module docs), the robot's readings placed by its
/// calibrated geometry and compliance (`q + c∘τ(q)` and its joint maps).
pub fn fit_track(req: &TrackFitRequest) -> Result<TrackFit, TrackRefused> {
    let robot = req.robot;
    fit_placed(req, &|q, kg| {
        deflected_joints(robot, q, kg)
            .and_then(|qd| fk(robot, &qd))
            .map(|p| p.p)
            .map_err(|e| e.to_string())
    })
}

/// Fits the track with the readings placed by the compensated model
/// (`CompensatedModel::predict_detailed_at`: geometry, compliance, joint
/// maps and the compensator's residual), the evaluation every prediction
/// and solve through the track uses (`solve::external::track`), so that
/// the track holds what the compensated model does not. The payload of
/// rows that give none is the model's.
pub fn fit_track_compensated(
    model: &CompensatedModel,
    set: &MeasurementSet,
    column: ExternalAxis,
    tracker_sigma_mm: f64,
    max_order: usize,
) -> Result<TrackFit, TrackRefused> {
    let req = TrackFitRequest {
        robot: &model.calibrated,
        payload_kg: model.payload_kg,
        set,
        column,
        tracker_sigma_mm,
        max_order,
    };
    fit_placed(&req, &|q, kg| {
        model
            .predict_detailed_at(q, kg)
            .map(|p| p.pose.p)
            .map_err(|e| e.to_string())
    })
}

fn fit_placed(req: &TrackFitRequest, place: &Place) -> Result<TrackFit, TrackRefused> {
    let sigma = req.tracker_sigma_mm;
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(TrackRefused::new(
            Why::NotFinite,
            format!("the tracker's σ must be a positive number of mm, got {sigma}"),
        ));
    }
    let limits = FitLimits::of(sigma);
    let points = model_points(req, place)?;
    let stations = stations(&points)?;
    for s in &stations {
        if s.rms_m * 1e3 > limits.rms_mm {
            return Err(TrackRefused::new(
                Why::StationResiduals,
                format!(
                    "the {} readings at track value {} mm do not fit one rigid pose of the robot: rms {:.4} mm, beyond {:.4} mm ({}·√3 σ); check the robot's model, the reflector and that the track stood still",
                    s.rows.len(),
                    s.value_mm,
                    s.rms_m * 1e3,
                    limits.rms_mm,
                    RMS_FACTOR
                ),
            )
            .figures(s.rms_m * 1e3, limits.rms_mm)
            .at_station(s.value_mm));
        }
    }
    let max_order = req.max_order.min(MAX_MAP_ORDER);
    let travel = Travel {
        lo_mm: stations[0].value_mm,
        hi_mm: stations[stations.len() - 1].value_mm,
    };
    let x: Vec<f64> = stations
        .iter()
        .map(|s| {
            travel
                .normalized(s.value_mm)
                .expect("stations span the travel")
        })
        .collect();
    let v: Vec<f64> = stations.iter().map(|s| s.value_mm).collect();
    let t: Vec<Vector3<f64>> = stations.iter().map(|s| s.cell_from_base.p).collect();

    let rail = fit_rail(&x, &v, &t, &travel, max_order);
    let d = rail.direction;
    let c = closest_to_origin(&d, &rail.a);
    let along: Vec<f64> = t.iter().map(|p| (p - c).dot(&d)).collect();
    let along_fit = choose_order(&x, &along, 1, max_order).expect("MIN_STATIONS carry the line");
    let (mid, half) = (0.5 * (travel.lo_mm + travel.hi_mm), 0.5 * travel.span_mm());
    let (c0, c1) = (along_fit.0.coefficients[0], along_fit.0.coefficients[1]);
    let (zero, per_mm) = (c0 - c1 * mid / half, c1 / half);
    let r_rail = rail_rotation(&d);
    let turns: Vec<Matrix3<f64>> = stations
        .iter()
        .map(|s| r_rail.transpose() * s.cell_from_base.r)
        .collect();
    let (mount, angle_fits) = fit_angles(&x, &turns, max_order);

    let mut fits: Vec<(SeriesFit, Vec<SeriesFit>)> = vec![along_fit];
    fits.extend(rail.lateral.to_vec());
    fits.extend(angle_fits);
    let mut maps: [TravelMap; 6] = Default::default();
    for (term, (best, _)) in CarriageTerm::ALL.into_iter().zip(&fits) {
        let gauge = if term.is_angle() { 1 } else { 2 };
        let mut coefficients = best.coefficients.clone();
        for c in coefficients.iter_mut().take(gauge) {
            *c = 0.0;
        }
        maps[term.index()] = TravelMap { coefficients };
    }
    let track = LinearTrack {
        rail: Line {
            direction: d,
            point: c,
        },
        scale: per_mm * 1e3,
        zero,
        mount,
        travel,
        maps,
    };
    let station_reports = station_reports(&track, &stations, sigma);
    let map_reports = map_reports(&track, &x, &fits, &station_reports);
    let residual_mm: Vec<f64> = points
        .iter()
        .map(|p| {
            let base = track
                .cell_from_base(p.value_mm)
                .expect("every reading's value is a station's, within the travel");
            (base.transform_point(&p.in_base) - p.in_cell).norm() * 1e3
        })
        .collect();
    let (rms_mm, max_mm) = rms_max(&residual_mm);
    let spacing = v.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    let fit = TrackFit {
        description: track.describe(),
        model: track,
        stations: station_reports,
        maps: map_reports,
        residual_mm,
        rms_mm,
        max_mm,
        unseen: unseen(spacing),
        limits,
    };
    judge(fit)
}

/// One reading: its track value, the held robot's reflector in the base
/// frame and the reading in the cell frame [m].
struct Point {
    value_mm: f64,
    in_base: Vector3<f64>,
    in_cell: Vector3<f64>,
}

fn model_points(req: &TrackFitRequest, place: &Place) -> Result<Vec<Point>, TrackRefused> {
    if !req.set.has(req.column) {
        return Err(TrackRefused::new(
            Why::MissingColumn,
            format!(
                "the set has no column `{}`, which the track's values are read from",
                req.column
            ),
        ));
    }
    let robot = req.robot;
    let dof = robot.dof();
    let mut out = Vec::with_capacity(req.set.poses.len());
    for (i, r) in req.set.readings().enumerate() {
        let row = i + 1;
        let value_mm = r.external.get(req.column).ok_or_else(|| {
            TrackRefused::new(
                Why::MissingColumn,
                format!("reading {row} has no value of `{}`", req.column),
            )
            .at_row(row)
        })?;
        if r.pose.q_deg.len() != dof {
            return Err(TrackRefused::new(
                Why::JointCount,
                format!(
                    "reading {row} has {} joint values, the robot has {dof} joints",
                    r.pose.q_deg.len()
                ),
            )
            .at_row(row));
        }
        let q_ctrl: Vec<f64> = r.pose.q_deg.iter().map(|d| d.to_radians()).collect();
        let q = robot.joints_from_controller(&q_ctrl);
        let payload = r.pose.payload_kg.unwrap_or(req.payload_kg);
        let in_base = place(&q, payload);
        let in_cell = Vector3::from(r.pose.xyz_mm) * 1e-3;
        match in_base {
            Ok(p)
                if p.iter().chain(in_cell.iter()).all(|x| x.is_finite())
                    && value_mm.is_finite() =>
            {
                out.push(Point {
                    value_mm,
                    in_base: p,
                    in_cell,
                })
            }
            other => {
                let why = match other {
                    Err(e) => e,
                    Ok(_) => "a value is not finite".into(),
                };
                return Err(TrackRefused::new(
                    Why::NotFinite,
                    format!("reading {row}: the robot's model cannot place it: {why}"),
                )
                .at_row(row));
            }
        }
    }
    Ok(out)
}

/// The stations in increasing value, each fitted and checked.
fn stations(points: &[Point]) -> Result<Vec<StationPose>, TrackRefused> {
    let mut values: Vec<f64> = points.iter().map(|p| p.value_mm).collect();
    values.sort_by(f64::total_cmp);
    values.dedup();
    if values.len() < MIN_STATIONS {
        return Err(TrackRefused::new(
            Why::TooFewStations,
            format!(
                "the readings are at {} track values; the track's line and maps need at least {MIN_STATIONS} (measure at more positions along the travel)",
                values.len()
            ),
        )
        .figures(values.len() as f64, MIN_STATIONS as f64));
    }
    values
        .into_iter()
        .map(|value| {
            let rows: Vec<usize> = (0..points.len())
                .filter(|&i| points[i].value_mm == value)
                .collect();
            let a: Vec<Vector3<f64>> = rows.iter().map(|&i| points[i].in_base).collect();
            let b: Vec<Vector3<f64>> = rows.iter().map(|&i| points[i].in_cell).collect();
            let collinear = |across_mm: f64| {
                TrackRefused::new(
                    Why::Collinear,
                    format!(
                        "the readings at track value {value} mm lie within {across_mm:.2} mm of a line: the base's turn about it is not seen (spread the robot's poses by at least {MIN_ACROSS_MM} mm across)"
                    ),
                )
                .figures(across_mm, MIN_ACROSS_MM)
                .at_station(value)
            };
            let s = fit_station(value, rows, &a, &b).map_err(|e| match e {
                StationError::TooFewPoses(n) => TrackRefused::new(
                    Why::TooFewPoses,
                    format!(
                        "{n} readings at track value {value} mm: the base's pose needs at least {MIN_POSES} robot poses not on a line"
                    ),
                )
                .figures(n as f64, MIN_POSES as f64)
                .at_station(value),
                StationError::Collinear(spread) => collinear(spread.across_m() * 1e3),
                StationError::NotFinite => TrackRefused::new(
                    Why::NotFinite,
                    format!("the readings at track value {value} mm are not finite"),
                )
                .at_station(value),
            })?;
            if s.spread.across_m() * 1e3 < MIN_ACROSS_MM {
                return Err(collinear(s.spread.across_m() * 1e3));
            }
            Ok(s)
        })
        .collect()
}

/// `y ≈ a + b·x` by least squares: `(a, b)`.
fn linear(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(x, y)| (x - mx) * (y - my)).sum();
    let b = sxy / sxx;
    (my - b * mx, b)
}

/// The rail line `a + b·v` [m, m/mm], its unit direction and the lateral
/// and vertical series (step 2 of the module docs).
struct Rail {
    a: Vector3<f64>,
    direction: Vector3<f64>,
    lateral: [(SeriesFit, Vec<SeriesFit>); 2],
}

fn fit_rail(x: &[f64], v: &[f64], t: &[Vector3<f64>], travel: &Travel, max_order: usize) -> Rail {
    let mut a = Vector3::zeros();
    let mut b = Vector3::zeros();
    for k in 0..3 {
        let y: Vec<f64> = t.iter().map(|p| p[k]).collect();
        let (ak, bk) = linear(v, &y);
        a[k] = ak;
        b[k] = bk;
    }
    let mid = 0.5 * (travel.lo_mm + travel.hi_mm);
    let half = 0.5 * travel.span_mm();
    let mut last = None;
    for _ in 0..20 {
        let r = rail_rotation(&b);
        let mut moved = 0.0f64;
        let mut fits = Vec::with_capacity(2);
        for col in [1, 2] {
            let dir: Vector3<f64> = r.column(col).into_owned();
            let y: Vec<f64> = t
                .iter()
                .zip(v)
                .map(|(p, v)| (p - a - b * *v).dot(&dir))
                .collect();
            let fit = choose_order(x, &y, 1, max_order).expect("MIN_STATIONS carry the line");
            let (c0, c1) = (fit.0.coefficients[0], fit.0.coefficients[1]);
            a += dir * (c0 - c1 * mid / half);
            b += dir * (c1 / half);
            moved = moved.max(c0.abs() + c1.abs());
            fits.push(fit);
        }
        let done = moved < 1e-12;
        last = Some(fits);
        if done {
            break;
        }
    }
    let mut fits = last.expect("one pass at least");
    let vertical = fits.pop().expect("two series");
    let lateral = fits.pop().expect("two series");
    Rail {
        a,
        direction: b.normalize(),
        lateral: [lateral, vertical],
    }
}

/// The mount and the roll, pitch and yaw series (step 4 of the module docs).
fn fit_angles(
    x: &[f64],
    turns: &[Matrix3<f64>],
    max_order: usize,
) -> (Matrix3<f64>, Vec<(SeriesFit, Vec<SeriesFit>)>) {
    let sum: Matrix3<f64> = turns.iter().sum();
    let svd = sum.svd(true, true);
    let (u, vt) = (svd.u.expect("u"), svd.v_t.expect("v_t"));
    let det = (u * vt).determinant().signum();
    let mut mount = u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, det)) * vt;
    let mut fits = Vec::new();
    for _ in 0..3 {
        let angles: Vec<[f64; 3]> = turns
            .iter()
            .map(|m| fixed_xyz_angles(&(m * mount.transpose())))
            .collect();
        fits = (0..3)
            .map(|j| {
                let y: Vec<f64> = angles.iter().map(|a| a[j]).collect();
                choose_order(x, &y, 0, max_order).expect("MIN_STATIONS carry a constant")
            })
            .collect();
        let c0: Vec<f64> = fits.iter().map(|f| f.0.coefficients[0]).collect();
        mount = rpy_matrix(c0[0], c0[1], c0[2]) * mount;
    }
    (mount, fits)
}

/// Per station: its σ in the rail frame and the track's misfit.
fn station_reports(
    track: &LinearTrack,
    stations: &[StationPose],
    sigma_mm: f64,
) -> Vec<StationReport> {
    let r_rail = track.rail_rotation();
    stations
        .iter()
        .map(|s| {
            let n = s.rows.len() as f64;
            let sigma_angles_arcsec = match &s.turn_information_inv {
                Some(inv) => {
                    let cov = r_rail.transpose() * inv * r_rail;
                    [0, 1, 2].map(|k| (cov[(k, k)].max(0.0)).sqrt() * sigma_mm * 1e-3 / ARCSEC)
                }
                None => [f64::INFINITY; 3],
            };
            let model: Pose = track
                .cell_from_base(s.value_mm)
                .expect("a station's value is within the travel");
            let dp = r_rail.transpose() * (model.p - s.cell_from_base.p) * 1e3;
            let turn = r_rail.transpose() * model.r * s.cell_from_base.r.transpose() * r_rail;
            let da = fixed_xyz_angles(&turn).map(|a| a / ARCSEC);
            StationReport {
                value_mm: s.value_mm,
                poses: s.rows.len(),
                spread_mm: s.spread.rms_m.map(|r| r * 1e3),
                sigma_position_mm: sigma_mm / n.sqrt(),
                sigma_angles_arcsec,
                rms_mm: s.rms_m * 1e3,
                misfit: [dp.x, dp.y, dp.z, da[0], da[1], da[2]],
            }
        })
        .collect()
}

fn map_reports(
    track: &LinearTrack,
    x: &[f64],
    fits: &[(SeriesFit, Vec<SeriesFit>)],
    stations: &[StationReport],
) -> Vec<MapReport> {
    CarriageTerm::ALL
        .into_iter()
        .zip(fits)
        .map(|(term, (best, tried))| {
            let unit = term.per_si();
            let amplitude = x
                .iter()
                .map(|x| track.maps[term.index()].at(*x).abs() * unit)
                .fold(0.0, f64::max);
            let mut sig: Vec<f64> = stations
                .iter()
                .map(|s| match term {
                    CarriageTerm::Along | CarriageTerm::Lateral | CarriageTerm::Vertical => {
                        s.sigma_position_mm
                    }
                    CarriageTerm::Roll => s.sigma_angles_arcsec[0],
                    CarriageTerm::Pitch => s.sigma_angles_arcsec[1],
                    CarriageTerm::Yaw => s.sigma_angles_arcsec[2],
                })
                .collect();
            sig.sort_by(f64::total_cmp);
            MapReport {
                term,
                unit: term.unit(),
                order: best.order,
                candidates: tried
                    .iter()
                    .map(|f| OrderScore {
                        order: f.order,
                        cv_rms: f.cv_rms * unit,
                    })
                    .collect(),
                amplitude,
                rms: best.rms * unit,
                station_sigma: sig[sig.len() / 2],
            }
        })
        .collect()
}

/// The terms the readings cannot see, with their figures.
fn unseen(spacing_mm: f64) -> Vec<Unseen> {
    UnseenTerm::ALL
        .into_iter()
        .map(|term| Unseen {
            term,
            note: match term {
                UnseenTerm::StraightnessMeanAndSlope => "a straightness's mean and slope over the travel are the rail line's position and direction, and the positioning map's are zero and scale; the maps hold what bends about that line".into(),
                UnseenTerm::AngleMeans => "the mean roll, pitch and yaw are the robot base's mount on the carriage; the maps hold what turns about it".into(),
                UnseenTerm::ShortBends => format!("bends and turns shorter than two station spacings ({:.0} mm) are not sampled: measure more stations to see them", 2.0 * spacing_mm),
                UnseenTerm::CarriagePivot => "where the carriage pivots: an angle about a point other than the robot base moves the base along, across or up, which the positioning and straightness maps hold; a bent rail or a rack's error and the carriage's arm are not told apart".into(),
            },
        })
        .collect()
}

/// The fit, or the refusal its residuals call for.
fn judge(fit: TrackFit) -> Result<TrackFit, TrackRefused> {
    let limits = fit.limits;
    if !within(fit.rms_mm, limits.rms_mm) {
        let (rms, bound) = (fit.rms_mm, limits.rms_mm);
        return Err(TrackRefused::new(
            Why::ResidualsTooLarge,
            format!(
                "the readings do not follow the fitted track: residuals rms {rms:.4} mm (max {:.4} mm), beyond {bound:.4} mm (3·√3 σ of {:.4} mm per axis); the rail may bend faster than the stations sample, the robot's model may be off, or the track moved",
                fit.max_mm, limits.sigma_mm
            ),
        )
        .figures(rms, bound)
        .with_fit(fit));
    }
    if let Some((i, r)) = fit
        .residual_mm
        .iter()
        .enumerate()
        .find(|(_, r)| !within(**r, limits.max_mm))
    {
        let (r, bound) = (*r, limits.max_mm);
        return Err(TrackRefused::new(
            Why::ResidualOutlier,
            format!(
                "reading {} is {r:.4} mm from where the fitted track puts it, beyond {bound:.4} mm (5·√3 σ): a wrong reading (remove or re-measure it)",
                i + 1
            ),
        )
        .figures(r, bound)
        .at_row(i + 1)
        .with_fit(fit));
    }
    Ok(fit)
}
