//! ISO 9283 figures with a typed outcome each: for every pose AP (with
//! APx/y/z and the barycentre), RP (l̄, S_l), APa/b/c and ±RPa/b/c, and for
//! every pair of poses AD and ±RD — each either computed (the formulas of
//! the module header, [`super`], through [`pose_figures`] and
//! [`distance_figures`]) or not, with a [`NotComputedReason`] and a message.
//! Data that leaves a figure undetermined (a pose not measured or not
//! commanded, too few cycles, no orientation) is an outcome, not an error;
//! only values beyond [`XYZ_MAX_MM`] / [`ABC_MAX_DEG`], more than
//! [`CYCLES_MAX`] cycles, or a name or cycle number given twice are refused.
//!
//! Frames and units as in [`super`]: millimetres in the frame the attained
//! positions are measured in, degrees, `R = Rz(c)·Ry(b)·Rx(a)`.

use super::figures::{distance_figures, pose_figures, PoseCycles};
use super::Iso9283Error;
use serde::{Deserialize, Serialize};

/// Largest coordinate magnitude of a commanded or attained position [mm].
pub const XYZ_MAX_MM: f64 = 100_000.0;
/// Largest magnitude of a commanded or attained angle [deg].
pub const ABC_MAX_DEG: f64 = 360.0;
/// Most cycles of one pose.
pub const CYCLES_MAX: usize = 1000;
/// Fewest cycles the standard's statistics need (n − 1 in S).
pub const CYCLES_MIN: usize = 2;

/// Why a figure was not computed (a closed set: the API's `reason` enum
/// derives from it). When several apply, the first in this order is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NotComputedReason {
    /// The plan commands the pose but no cycle of it was sent.
    PoseNotMeasured,
    /// The pose was measured but the plan does not command it (figures
    /// against the command: AP, APa/b/c, AD).
    PoseNotInPlan,
    /// Fewer than 2 cycles measured at the pose.
    TooFewCycles,
    /// Fewer than 2 cycles measured at both poses of a distance.
    TooFewSharedCycles,
    /// No cycle of the pose carries an orientation.
    NoOrientationMeasured,
    /// Some cycles of the pose carry an orientation, others do not.
    OrientationIncomplete,
    /// The plan gives the pose's position but not its orientation (APa/b/c).
    NoCommandedOrientation,
}

impl NotComputedReason {
    /// Every reason, in the order of precedence.
    pub const ALL: [NotComputedReason; 7] = [
        NotComputedReason::PoseNotMeasured,
        NotComputedReason::PoseNotInPlan,
        NotComputedReason::TooFewCycles,
        NotComputedReason::TooFewSharedCycles,
        NotComputedReason::NoOrientationMeasured,
        NotComputedReason::OrientationIncomplete,
        NotComputedReason::NoCommandedOrientation,
    ];

    /// The code the API and the JSON output use.
    pub fn code(self) -> &'static str {
        match self {
            NotComputedReason::PoseNotMeasured => "pose_not_measured",
            NotComputedReason::PoseNotInPlan => "pose_not_in_plan",
            NotComputedReason::TooFewCycles => "too_few_cycles",
            NotComputedReason::TooFewSharedCycles => "too_few_shared_cycles",
            NotComputedReason::NoOrientationMeasured => "no_orientation_measured",
            NotComputedReason::OrientationIncomplete => "orientation_incomplete",
            NotComputedReason::NoCommandedOrientation => "no_commanded_orientation",
        }
    }
}

/// A figure, computed or not (`"outcome": "computed"` with its values, or
/// `"outcome": "not_computed"` with `reason` and `message`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "outcome", rename_all = "snake_case")]
pub enum Outcome<T> {
    /// The figure, computed.
    Computed(T),
    /// The figure is undetermined by the data.
    NotComputed {
        /// Why it was not computed.
        reason: NotComputedReason,
        /// What is missing, for the user.
        message: String,
    },
}

impl<T> Outcome<T> {
    /// The computed figure, or `None`.
    pub fn computed(&self) -> Option<&T> {
        match self {
            Outcome::Computed(v) => Some(v),
            Outcome::NotComputed { .. } => None,
        }
    }

    /// Why the figure was not computed, or `None` when it was.
    pub fn reason(&self) -> Option<NotComputedReason> {
        match self {
            Outcome::Computed(_) => None,
            Outcome::NotComputed { reason, .. } => Some(*reason),
        }
    }
}

fn not<T>(reason: NotComputedReason, message: String) -> Outcome<T> {
    Outcome::NotComputed { reason, message }
}

/// AP: the barycentre's distance from the command.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PositionAccuracy {
    /// Barycentre of the attained positions (x̄, ȳ, z̄) [mm].
    pub barycentre_mm: [f64; 3],
    /// AP, the barycentre's distance from the commanded position [mm].
    pub ap_mm: f64,
    /// APx, APy, APz = x̄ − x_c, … [mm].
    pub ap_xyz_mm: [f64; 3],
}

/// RP = l̄ + 3·S_l.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PositionRepeatability {
    /// l̄, the mean distance of the attained positions from their barycentre [mm].
    pub l_mean_mm: f64,
    /// S_l, the standard deviation of those distances (n − 1) [mm].
    pub s_l_mm: f64,
    /// RP = l̄ + 3·S_l [mm].
    pub rp_mm: f64,
}

/// APa, APb, APc.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationAccuracy {
    /// APa, APb, APc = ā − a_c, … [deg].
    pub ap_abc_deg: [f64; 3],
}

/// ±RPa, ±RPb, ±RPc = ±3·S.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationRepeatability {
    /// RPa, RPb, RPc = 3·S_a, … [deg] (read as ±).
    pub rp_abc_deg: [f64; 3],
}

/// AD = D̄ − D_c.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DistanceAccuracy {
    /// D_c, the commanded distance [mm].
    pub commanded_mm: f64,
    /// D̄, the mean attained distance [mm].
    pub mean_mm: f64,
    /// AD = D̄ − D_c [mm].
    pub ad_mm: f64,
}

/// RD = ±3·S_D.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DistanceRepeatability {
    /// D̄, the mean attained distance [mm].
    pub mean_mm: f64,
    /// S_D, the standard deviation of the attained distances (n − 1) [mm].
    pub s_d_mm: f64,
    /// RD = 3·S_D [mm] (read as ±).
    pub rd_mm: f64,
}

/// One pose's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PoseOutcomes {
    /// The pose's name.
    pub pose: String,
    /// Whether the plan commands the pose.
    pub commanded: bool,
    /// Cycles measured at the pose (`n`).
    pub cycles: usize,
    /// Pose accuracy AP.
    pub ap: Outcome<PositionAccuracy>,
    /// Pose repeatability RP.
    pub rp: Outcome<PositionRepeatability>,
    /// Orientation accuracy APa, APb, APc.
    pub ap_abc: Outcome<OrientationAccuracy>,
    /// Orientation repeatability RPa, RPb, RPc.
    pub rp_abc: Outcome<OrientationRepeatability>,
}

/// One pair of poses' figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DistanceOutcomes {
    /// Name of the distance's first pose.
    pub from: String,
    /// Name of the distance's second pose.
    pub to: String,
    /// Cycles measured at both poses.
    pub cycles: usize,
    /// Distance accuracy AD.
    pub ad: Outcome<DistanceAccuracy>,
    /// Distance repeatability RD.
    pub rd: Outcome<DistanceRepeatability>,
}

/// Every pose's figures, and every pair's, in the order of the poses given.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Assessment {
    /// Each pose's figures, in the order given.
    pub poses: Vec<PoseOutcomes>,
    /// Each pair of poses' figures.
    pub distances: Vec<DistanceOutcomes>,
}

/// A commanded pose [mm, deg].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandedPose {
    /// Commanded position [mm].
    pub xyz_mm: [f64; 3],
    /// Commanded `a, b, c` [deg], when the plan gives them.
    pub abc_deg: Option<[f64; 3]>,
}

/// One attained pose: its cycle number (distances pair equal cycles) [mm, deg].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleReading {
    /// Cycle number, 1 to [`CYCLES_MAX`].
    pub cycle: u32,
    /// Attained position [mm].
    pub xyz_mm: [f64; 3],
    /// Attained `a, b, c` [deg], when measured.
    pub abc_deg: Option<[f64; 3]>,
}

/// A pose of the test: its command, if the plan has it, and its cycles, if
/// measured.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseData {
    /// The pose's name (`P1` … `P5`).
    pub name: String,
    /// Its command (`None`: the plan does not have the pose).
    pub commanded: Option<CommandedPose>,
    /// Its cycles (`None`: the pose was not measured).
    pub measured: Option<Vec<CycleReading>>,
}

fn check_values(what: &str, v: &[f64; 3], max: f64, unit: &str) -> Result<(), Iso9283Error> {
    match v.iter().find(|x| !(x.is_finite() && x.abs() <= max)) {
        None => Ok(()),
        Some(x) => Err(Iso9283Error::InvalidInput(format!(
            "{what}: {x} is not a finite number within ±{max} {unit}"
        ))),
    }
}

/// Names and cycle numbers once each; values finite and within bounds.
fn validate(poses: &[PoseData]) -> Result<(), Iso9283Error> {
    for (i, p) in poses.iter().enumerate() {
        if poses[..i].iter().any(|q| q.name == p.name) {
            return Err(Iso9283Error::InvalidInput(format!(
                "pose {} is given twice",
                p.name
            )));
        }
        if let Some(c) = &p.commanded {
            let what = format!("pose {}, commanded", p.name);
            check_values(&what, &c.xyz_mm, XYZ_MAX_MM, "mm")?;
            if let Some(abc) = &c.abc_deg {
                check_values(&what, abc, ABC_MAX_DEG, "deg")?;
            }
        }
        let readings = p.measured.as_deref().unwrap_or_default();
        if readings.len() > CYCLES_MAX {
            return Err(Iso9283Error::InvalidInput(format!(
                "pose {}: {} cycles; at most {CYCLES_MAX}",
                p.name,
                readings.len()
            )));
        }
        for (k, r) in readings.iter().enumerate() {
            if readings[..k].iter().any(|o| o.cycle == r.cycle) {
                return Err(Iso9283Error::InvalidInput(format!(
                    "pose {} has cycle {} twice",
                    p.name, r.cycle
                )));
            }
            let what = format!("pose {}, cycle {}", p.name, r.cycle);
            check_values(&what, &r.xyz_mm, XYZ_MAX_MM, "mm")?;
            if let Some(abc) = &r.abc_deg {
                check_values(&what, abc, ABC_MAX_DEG, "deg")?;
            }
        }
    }
    Ok(())
}

/// How many of a pose's cycles carry an orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Orientation {
    None,
    Some,
    All,
}

/// The measured cycles in the figures' form; orientations only when every
/// cycle carries one.
fn pose_cycles(p: &PoseData, readings: &[CycleReading]) -> (PoseCycles, Orientation) {
    let with = readings.iter().filter(|r| r.abc_deg.is_some()).count();
    let orientation = match with {
        0 => Orientation::None,
        n if n == readings.len() => Orientation::All,
        _ => Orientation::Some,
    };
    let pc = PoseCycles {
        name: p.name.clone(),
        commanded_mm: p.commanded.map_or([0.0; 3], |c| c.xyz_mm),
        commanded_abc_deg: p.commanded.and_then(|c| c.abc_deg),
        cycles: readings.iter().map(|r| r.cycle).collect(),
        attained_mm: readings.iter().map(|r| r.xyz_mm).collect(),
        attained_abc_deg: (orientation == Orientation::All)
            .then(|| readings.iter().filter_map(|r| r.abc_deg).collect()),
    };
    (pc, orientation)
}

fn too_few(name: &str, n: usize) -> String {
    format!(
        "pose {name}: {n} cycle(s) measured; the standard's statistics need at least {CYCLES_MIN} (30 recommended)"
    )
}

/// The figures of one pose.
fn pose_outcomes(p: &PoseData, pc: Option<&(PoseCycles, Orientation)>) -> PoseOutcomes {
    use NotComputedReason as R;
    let name = &p.name;
    let n = pc.map_or(0, |(c, _)| c.attained_mm.len());
    let figures = |ap: Outcome<PositionAccuracy>,
                   rp: Outcome<PositionRepeatability>,
                   ap_abc: Outcome<OrientationAccuracy>,
                   rp_abc: Outcome<OrientationRepeatability>| PoseOutcomes {
        pose: name.clone(),
        commanded: p.commanded.is_some(),
        cycles: n,
        ap,
        rp,
        ap_abc,
        rp_abc,
    };
    let Some((pc, orientation)) = pc else {
        let m = format!("pose {name} is in the plan but no cycle of it was measured");
        return figures(
            not(R::PoseNotMeasured, m.clone()),
            not(R::PoseNotMeasured, m.clone()),
            not(R::PoseNotMeasured, m.clone()),
            not(R::PoseNotMeasured, m),
        );
    };
    let not_in_plan = || {
        (
            R::PoseNotInPlan,
            format!("pose {name} was measured but the plan does not command it"),
        )
    };
    if n < CYCLES_MIN {
        let m = too_few(name, n);
        let against_command = || match p.commanded {
            None => not_in_plan(),
            Some(_) => (R::TooFewCycles, m.clone()),
        };
        let (ap_r, ap_m) = against_command();
        let (abc_r, abc_m) = against_command();
        return figures(
            not(ap_r, ap_m),
            not(R::TooFewCycles, m.clone()),
            not(abc_r, abc_m),
            not(R::TooFewCycles, m.clone()),
        );
    }
    // At least 2 finite cycles (validated): the figures exist.
    let f = pose_figures(pc).expect("validated cycles");
    let ap = match p.commanded {
        None => {
            let (r, m) = not_in_plan();
            not(r, m)
        }
        Some(_) => Outcome::Computed(PositionAccuracy {
            barycentre_mm: f.barycentre_mm,
            ap_mm: f.ap_mm,
            ap_xyz_mm: f.ap_xyz_mm,
        }),
    };
    let rp = Outcome::Computed(PositionRepeatability {
        l_mean_mm: f.l_mean_mm,
        s_l_mm: f.s_l_mm,
        rp_mm: f.rp_mm,
    });
    let orientation_missing = match orientation {
        Orientation::None => Some((
            R::NoOrientationMeasured,
            format!("pose {name}: no cycle carries an orientation (abc_deg)"),
        )),
        Orientation::Some => Some((
            R::OrientationIncomplete,
            format!("pose {name}: some cycles carry an orientation (abc_deg), others do not"),
        )),
        Orientation::All => None,
    };
    let rp_abc = match (&orientation_missing, f.rp_abc_deg) {
        (Some((r, m)), _) => not(*r, m.clone()),
        (None, Some(rp)) => Outcome::Computed(OrientationRepeatability { rp_abc_deg: rp }),
        (None, None) => unreachable!("every cycle carries an orientation"),
    };
    let ap_abc = match (p.commanded, orientation_missing, f.ap_abc_deg) {
        (None, _, _) => {
            let (r, m) = not_in_plan();
            not(r, m)
        }
        (Some(_), Some((r, m)), _) => not(r, m),
        (Some(_), None, Some(ap)) => Outcome::Computed(OrientationAccuracy { ap_abc_deg: ap }),
        (Some(_), None, None) => not(
            R::NoCommandedOrientation,
            format!("pose {name}: the plan gives its position but not its orientation"),
        ),
    };
    figures(ap, rp, ap_abc, rp_abc)
}

/// The figures of one pair of poses.
fn distance_outcomes(
    (p, pp): (&PoseData, Option<&(PoseCycles, Orientation)>),
    (q, qq): (&PoseData, Option<&(PoseCycles, Orientation)>),
) -> DistanceOutcomes {
    use NotComputedReason as R;
    let pair = |cycles, ad, rd| DistanceOutcomes {
        from: p.name.clone(),
        to: q.name.clone(),
        cycles,
        ad,
        rd,
    };
    let (Some((pc, _)), Some((qc, _))) = (pp, qq) else {
        let missing = if pp.is_none() { &p.name } else { &q.name };
        let m = format!("pose {missing} is in the plan but no cycle of it was measured");
        return pair(
            0,
            not(R::PoseNotMeasured, m.clone()),
            not(R::PoseNotMeasured, m),
        );
    };
    let shared = pc.cycles.iter().filter(|c| qc.cycles.contains(c)).count();
    let not_in_plan = [p, q].into_iter().find(|x| x.commanded.is_none()).map(|x| {
        not(
            R::PoseNotInPlan,
            format!(
                "pose {} was measured but the plan does not command it",
                x.name
            ),
        )
    });
    let Some(d) = distance_figures(pc, qc) else {
        let m = format!(
            "poses {} and {}: {} cycle(s) measured at both; the standard's statistics need at least {CYCLES_MIN}",
            p.name, q.name, shared
        );
        return pair(
            shared,
            not_in_plan.unwrap_or_else(|| not(R::TooFewSharedCycles, m.clone())),
            not(R::TooFewSharedCycles, m),
        );
    };
    pair(
        shared,
        not_in_plan.unwrap_or(Outcome::Computed(DistanceAccuracy {
            commanded_mm: d.commanded_mm,
            mean_mm: d.mean_mm,
            ad_mm: d.ad_mm,
        })),
        Outcome::Computed(DistanceRepeatability {
            mean_mm: d.mean_mm,
            s_d_mm: d.s_d_mm,
            rd_mm: d.rd_mm,
        }),
    )
}

/// Every figure of `poses` with its outcome; distances for every pair, in
/// order, over the cycles both poses have. Errors only for values out of
/// bounds, more than [`CYCLES_MAX`] cycles, or a pose or a pose's cycle
/// number given twice.
pub fn assess(poses: &[PoseData]) -> Result<Assessment, Iso9283Error> {
    validate(poses)?;
    let cycles: Vec<Option<(PoseCycles, Orientation)>> = poses
        .iter()
        .map(|p| p.measured.as_deref().map(|r| pose_cycles(p, r)))
        .collect();
    let figures = poses
        .iter()
        .zip(&cycles)
        .map(|(p, c)| pose_outcomes(p, c.as_ref()))
        .collect();
    let mut distances = Vec::new();
    for i in 0..poses.len() {
        for j in i + 1..poses.len() {
            distances.push(distance_outcomes(
                (&poses[i], cycles[i].as_ref()),
                (&poses[j], cycles[j].as_ref()),
            ));
        }
    }
    Ok(Assessment {
        poses: figures,
        distances,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use NotComputedReason as R;

    fn reading(cycle: u32, xyz_mm: [f64; 3], abc_deg: Option<[f64; 3]>) -> CycleReading {
        CycleReading {
            cycle,
            xyz_mm,
            abc_deg,
        }
    }

    /// Attained (0,0,0), (2,0,0), (4,0,0) against commanded (1,1,0):
    /// barycentre (2,0,0), AP = √2, APx/y/z = (1, −1, 0); l = 2, 0, 2,
    /// l̄ = 4/3, S_l = √(4/3), RP = 4/3 + 3·√(4/3).
    fn p1(abc: bool) -> PoseData {
        let a = |v: [f64; 3]| abc.then_some(v);
        PoseData {
            name: "P1".into(),
            commanded: Some(CommandedPose {
                xyz_mm: [1.0, 1.0, 0.0],
                abc_deg: Some([11.0, 5.0, 180.0]),
            }),
            measured: Some(vec![
                reading(1, [0.0, 0.0, 0.0], a([10.0, 5.0, 179.0])),
                reading(2, [2.0, 0.0, 0.0], a([12.0, 5.0, -179.0])),
                reading(3, [4.0, 0.0, 0.0], a([14.0, 5.0, 180.0])),
            ]),
        }
    }

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }

    #[test]
    fn a_complete_pose_has_every_figure_by_hand() {
        let a = assess(&[p1(true)]).unwrap();
        let f = &a.poses[0];
        assert_eq!((f.cycles, f.commanded), (3, true));
        let ap = f.ap.computed().unwrap();
        assert_eq!(ap.barycentre_mm, [2.0, 0.0, 0.0]);
        close(ap.ap_mm, 2f64.sqrt());
        assert_eq!(ap.ap_xyz_mm, [1.0, -1.0, 0.0]);
        let rp = f.rp.computed().unwrap();
        close(rp.l_mean_mm, 4.0 / 3.0);
        close(rp.s_l_mm, (4.0f64 / 3.0).sqrt());
        close(rp.rp_mm, 4.0 / 3.0 + 3.0 * (4.0f64 / 3.0).sqrt());
        // a: 10, 12, 14 against 11: APa 1, S 2, RPa 6; b constant; c: 179,
        // −179, 180 against 180: deviations −1, 1, 0: APc 0, RPc 3.
        let ap_abc = f.ap_abc.computed().unwrap().ap_abc_deg;
        let rp_abc = f.rp_abc.computed().unwrap().rp_abc_deg;
        for (got, want) in ap_abc.iter().zip([1.0, 0.0, 0.0]) {
            close(*got, want);
        }
        for (got, want) in rp_abc.iter().zip([6.0, 0.0, 3.0]) {
            close(*got, want);
        }
        assert!(a.distances.is_empty());
    }

    /// P2 commanded at (3,4,0): D_c = 5 to P1's (0,0,0); attained distances
    /// 5, 6, 7 in cycles 1–3: AD = 1, S_D = 1, RD = 3. A fourth cycle of P2
    /// that P1 lacks is not paired.
    #[test]
    fn distances_pair_equal_cycles_by_hand() {
        let pose = |name: &str, c: [f64; 3], r: Vec<CycleReading>| PoseData {
            name: name.into(),
            commanded: Some(CommandedPose {
                xyz_mm: c,
                abc_deg: None,
            }),
            measured: Some(r),
        };
        let a = pose(
            "P1",
            [0.0; 3],
            (1..=3).map(|k| reading(k, [0.0; 3], None)).collect(),
        );
        let b = pose(
            "P2",
            [3.0, 4.0, 0.0],
            vec![
                reading(1, [3.0, 4.0, 0.0], None),
                reading(2, [3.6, 4.8, 0.0], None),
                reading(3, [4.2, 5.6, 0.0], None),
                reading(4, [99.0, 0.0, 0.0], None),
            ],
        );
        let out = assess(&[a, b]).unwrap();
        let d = &out.distances[0];
        assert_eq!((d.from.as_str(), d.to.as_str(), d.cycles), ("P1", "P2", 3));
        let ad = d.ad.computed().unwrap();
        close(ad.commanded_mm, 5.0);
        close(ad.mean_mm, 6.0);
        close(ad.ad_mm, 1.0);
        let rd = d.rd.computed().unwrap();
        close(rd.s_d_mm, 1.0);
        close(rd.rd_mm, 3.0);
        // Positions only: the orientation figures say why not.
        assert_eq!(out.poses[0].ap_abc.reason(), Some(R::NoOrientationMeasured));
        assert_eq!(out.poses[0].rp_abc.reason(), Some(R::NoOrientationMeasured));
    }

    #[test]
    fn each_reason_where_it_applies() {
        // Not measured: nothing of the pose, nor its distances.
        let mut gone = p1(true);
        gone.name = "P2".into();
        gone.measured = None;
        let out = assess(&[p1(true), gone]).unwrap();
        let f = &out.poses[1];
        assert_eq!(f.cycles, 0);
        for r in [
            f.ap.reason(),
            f.rp.reason(),
            f.ap_abc.reason(),
            f.rp_abc.reason(),
        ] {
            assert_eq!(r, Some(R::PoseNotMeasured));
        }
        assert_eq!(out.distances[0].ad.reason(), Some(R::PoseNotMeasured));
        assert_eq!(out.distances[0].rd.reason(), Some(R::PoseNotMeasured));

        // Not in the plan: RP and ±RPa/b/c as measured, AP, APa/b/c and AD not.
        let mut loose = p1(true);
        loose.name = "P3".into();
        loose.commanded = None;
        let out = assess(&[p1(true), loose]).unwrap();
        let f = &out.poses[1];
        assert!(!f.commanded);
        assert_eq!(f.ap.reason(), Some(R::PoseNotInPlan));
        assert_eq!(f.ap_abc.reason(), Some(R::PoseNotInPlan));
        close(
            f.rp.computed().unwrap().rp_mm,
            4.0 / 3.0 + 3.0 * (4.0f64 / 3.0).sqrt(),
        );
        // Without a command, a, b, c deviate from the first cycle's: the
        // spread is the same (RPa 6, RPc 3).
        let rp_abc = f.rp_abc.computed().unwrap().rp_abc_deg;
        close(rp_abc[0], 6.0);
        close(rp_abc[2], 3.0);
        assert_eq!(out.distances[0].ad.reason(), Some(R::PoseNotInPlan));
        // Same cycles, same motion: D_j = 0 in every cycle.
        close(out.distances[0].rd.computed().unwrap().rd_mm, 0.0);

        // One cycle: too few, at the pose and for its distances.
        let mut one = p1(true);
        one.name = "P4".into();
        one.measured.as_mut().unwrap().truncate(1);
        let out = assess(&[p1(true), one]).unwrap();
        let f = &out.poses[1];
        assert_eq!(f.cycles, 1);
        for r in [
            f.ap.reason(),
            f.rp.reason(),
            f.ap_abc.reason(),
            f.rp_abc.reason(),
        ] {
            assert_eq!(r, Some(R::TooFewCycles));
        }
        assert_eq!(out.distances[0].cycles, 1);
        assert_eq!(out.distances[0].ad.reason(), Some(R::TooFewSharedCycles));
        assert_eq!(out.distances[0].rd.reason(), Some(R::TooFewSharedCycles));

        // An orientation in some cycles only.
        let mut partial = p1(true);
        partial.measured.as_mut().unwrap()[1].abc_deg = None;
        let f = &assess(&[partial]).unwrap().poses[0];
        assert_eq!(f.ap_abc.reason(), Some(R::OrientationIncomplete));
        assert_eq!(f.rp_abc.reason(), Some(R::OrientationIncomplete));
        assert!(f.ap.computed().is_some());

        // A commanded position without an orientation: APa/b/c only.
        let mut plain = p1(true);
        plain.commanded.as_mut().unwrap().abc_deg = None;
        let f = &assess(&[plain]).unwrap().poses[0];
        assert_eq!(f.ap_abc.reason(), Some(R::NoCommandedOrientation));
        assert!(f.rp_abc.computed().is_some());
    }

    #[test]
    fn values_out_of_bounds_and_repeated_names_are_refused() {
        let mut far = p1(false);
        far.measured.as_mut().unwrap()[0].xyz_mm[0] = XYZ_MAX_MM * 1.5;
        assert!(assess(&[far]).unwrap_err().to_string().contains("cycle 1"));
        let mut nan = p1(true);
        nan.commanded.as_mut().unwrap().abc_deg = Some([f64::NAN, 0.0, 0.0]);
        assert!(assess(&[nan]).is_err());
        assert!(assess(&[p1(false), p1(false)]).is_err());
        let mut twice = p1(false);
        twice.measured.as_mut().unwrap()[1].cycle = 1;
        assert!(assess(&[twice])
            .unwrap_err()
            .to_string()
            .contains("cycle 1 twice"));
        let mut many = p1(false);
        many.measured = Some(
            (1..=CYCLES_MAX as u32 + 1)
                .map(|k| reading(k, [0.0; 3], None))
                .collect(),
        );
        assert!(assess(&[many]).is_err());
    }

    #[test]
    fn the_reason_codes_are_their_serde_names() {
        for r in NotComputedReason::ALL {
            assert_eq!(serde_json::to_value(r).unwrap(), r.code());
        }
        let o: Outcome<OrientationRepeatability> = not(R::TooFewCycles, "m".into());
        assert_eq!(
            serde_json::to_value(o).unwrap(),
            serde_json::json!({"outcome": "not_computed", "reason": "too_few_cycles", "message": "m"})
        );
    }
}
