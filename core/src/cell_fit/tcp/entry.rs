//! What a judged fit stores, for the command line (a cell file) and the
//! service (the robot's cell) alike: the entry, where a tool's orientation
//! comes from, and what it replaces.
//!
//! - A fit [`super::judge`] finds not plausible is not stored; forcing it
//!   stores it with the verdict kept in the answer (`fitted: false`,
//!   `forced: true`). Readings that determine nothing cannot be forced.
//! - The orientation ([`OrientationSource`]): the one the readings determined
//!   (an axis, a 6-D probe); else the one the user gives; else the stored
//!   tool's, kept; else unknown — a tool whose orientation is unknown is not
//!   stored (nothing writes zeros for it), and only an answer that stores
//!   nothing reports it so.
//! - A refit keeps the stored item's load and, unless a number is given, its
//!   number; the answer lists what changed ([`Replaced`]).
//!
//! Units: mm and fixed-axis degrees `[rx, ry, rz]` (`R = Rz·Ry·Rx`).

use super::{FitError, JudgedFit, NotFittedReason, ToolFit};
use crate::cell_fit::work_object::WorkObjectFit;
use crate::model::load::LoadDescription;
use crate::model::orientation::rotation_angle_between;
use crate::model::pose::rpy_matrix;
use crate::solve::cell::file::{PoseMmDeg, ToolDescription, WorkObjectDescription};
use crate::solve::cell::WorkObjectFrame;
use serde::Serialize;

/// Where a stored tool's orientation comes from (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OrientationSource {
    /// Determined by the readings (an axis, a 6-D probe).
    Fitted,
    /// Given by the user.
    Given,
    /// The stored tool's, kept.
    Kept,
    /// Not determined, not given, none stored (nothing is stored then).
    Unknown,
}

impl OrientationSource {
    /// Every source, in declaration order.
    pub const ALL: [OrientationSource; 4] = [
        OrientationSource::Fitted,
        OrientationSource::Given,
        OrientationSource::Kept,
        OrientationSource::Unknown,
    ];

    /// The source's name in answers and reports, as serialized (snake_case).
    pub fn as_str(self) -> &'static str {
        match self {
            OrientationSource::Fitted => "fitted",
            OrientationSource::Given => "given",
            OrientationSource::Kept => "kept",
            OrientationSource::Unknown => "unknown",
        }
    }
}

/// A tool or work object as stored (mm, degrees; a work object in the
/// robot base frame).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StoredEntry {
    /// The controller's tool or work-object number (`None`: none given or stored).
    pub number: Option<u32>,
    /// A work object's frame (tools: `None`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frame: Option<WorkObjectFrame>,
    /// Position: a tool's TCP in the flange frame, a work object's origin in
    /// `frame` [mm].
    pub xyz_mm: [f64; 3],
    /// Orientation, fixed-axis `[rx, ry, rz]` with `R = Rz·Ry·Rx` [deg].
    pub rpy_deg: [f64; 3],
    /// A tool's load (mass and centre of mass), kept from the stored tool (work
    /// objects: `None`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub load: Option<LoadDescription>,
}

impl StoredEntry {
    /// A cell file's tool.
    pub fn of_tool(t: &ToolDescription) -> Self {
        StoredEntry {
            number: t.number,
            frame: None,
            xyz_mm: t.tcp.xyz_mm,
            rpy_deg: t.tcp.rpy_deg,
            load: t.load.clone(),
        }
    }

    /// A cell file's work object.
    pub fn of_work_object(w: &WorkObjectDescription) -> Self {
        StoredEntry {
            number: w.number,
            frame: Some(w.frame),
            xyz_mm: w.pose.xyz_mm,
            rpy_deg: w.pose.rpy_deg,
            load: None,
        }
    }

    fn pose(&self) -> PoseMmDeg {
        PoseMmDeg {
            xyz_mm: self.xyz_mm,
            rpy_deg: self.rpy_deg,
        }
    }

    /// The entry as a cell file's tool `name`.
    pub fn tool_description(&self, name: &str) -> ToolDescription {
        ToolDescription {
            name: name.to_string(),
            number: self.number,
            tcp: self.pose(),
            load: self.load.clone(),
        }
    }

    /// The entry as a cell file's work object `name`.
    pub fn work_object_description(&self, name: &str) -> WorkObjectDescription {
        WorkObjectDescription {
            name: name.to_string(),
            number: self.number,
            frame: self.frame.unwrap_or_default(),
            pose: self.pose(),
        }
    }
}

/// A part of an entry (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EntryField {
    /// The controller's number.
    Number,
    /// A work object's frame (base or measurement).
    Frame,
    /// The position `xyz_mm`.
    Position,
    /// The orientation `rpy_deg`.
    Orientation,
    /// A tool's load.
    Load,
}

impl EntryField {
    /// Every part, in declaration order.
    pub const ALL: [EntryField; 5] = [
        EntryField::Number,
        EntryField::Frame,
        EntryField::Position,
        EntryField::Orientation,
        EntryField::Load,
    ];

    /// The part's name in answers and reports, as serialized (snake_case).
    pub fn as_str(self) -> &'static str {
        match self {
            EntryField::Number => "number",
            EntryField::Frame => "frame",
            EntryField::Position => "position",
            EntryField::Orientation => "orientation",
            EntryField::Load => "load",
        }
    }
}

/// A stored entry replaced by a fit: old and new, how far the position
/// moved and the orientation turned (`None` when the old was given in
/// another frame), and which parts changed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Replaced {
    /// The entry stored before the fit.
    pub old: StoredEntry,
    /// The entry the fit stores in its place.
    pub new: StoredEntry,
    /// Distance between the old and the new position [mm] (`None` when the
    /// frames differ).
    pub moved_mm: Option<f64>,
    /// Angle of the rotation from the old to the new orientation [deg] (`None`
    /// when the frames differ).
    pub turned_deg: Option<f64>,
    /// The parts that differ between old and new, in the order of [`EntryField::ALL`].
    pub changed: Vec<EntryField>,
}

fn rad(v: [f64; 3]) -> nalgebra::Matrix3<f64> {
    let [x, y, z] = v.map(f64::to_radians);
    rpy_matrix(x, y, z)
}

fn fmt3(v: &[f64; 3]) -> String {
    format!("[{:.4}, {:.4}, {:.4}]", v[0], v[1], v[2])
}

impl Replaced {
    /// Compares `old` with `new`: distance moved and angle turned when both are
    /// in the same frame, and the parts that changed.
    pub fn between(old: StoredEntry, new: StoredEntry) -> Self {
        let same_frame = old.frame == new.frame;
        let moved_mm = same_frame.then(|| {
            nalgebra::Vector3::from(old.xyz_mm)
                .metric_distance(&nalgebra::Vector3::from(new.xyz_mm))
        });
        let turned_deg = same_frame
            .then(|| rotation_angle_between(&rad(old.rpy_deg), &rad(new.rpy_deg)).to_degrees());
        let mut changed = Vec::new();
        if old.number != new.number {
            changed.push(EntryField::Number);
        }
        if !same_frame {
            changed.push(EntryField::Frame);
        }
        if old.xyz_mm != new.xyz_mm {
            changed.push(EntryField::Position);
        }
        if old.rpy_deg != new.rpy_deg {
            changed.push(EntryField::Orientation);
        }
        if old.load != new.load {
            changed.push(EntryField::Load);
        }
        Replaced {
            old,
            new,
            moved_mm,
            turned_deg,
            changed,
        }
    }

    /// The lines a text report prints: old → new of each part.
    pub fn describe(&self) -> String {
        let num = |n: Option<u32>| n.map_or("none".to_string(), |n| n.to_string());
        let load = |l: &Option<LoadDescription>| {
            l.as_ref().map_or("none".to_string(), |l| {
                format!("{} kg at {} mm ({:?})", l.mass_kg, fmt3(&l.com_mm), l.frame)
            })
        };
        let mark = |f: EntryField| {
            if self.changed.contains(&f) {
                "changed"
            } else {
                "unchanged"
            }
        };
        let by = |v: Option<f64>, unit: &str, what: &str| match v {
            Some(v) => format!("{what} {v:.4}{unit}"),
            None => "in another frame before".to_string(),
        };
        let mut s = format!(
            "  position [mm]: {} → {} ({}, {})\n  orientation [deg]: {} → {} ({}, {})\n",
            fmt3(&self.old.xyz_mm),
            fmt3(&self.new.xyz_mm),
            by(self.moved_mm, " mm", "moved"),
            mark(EntryField::Position),
            fmt3(&self.old.rpy_deg),
            fmt3(&self.new.rpy_deg),
            by(self.turned_deg, "°", "turned"),
            mark(EntryField::Orientation),
        );
        if let (Some(a), Some(b)) = (self.old.frame, self.new.frame) {
            let f = |w: WorkObjectFrame| format!("{w:?}").to_lowercase();
            s += &format!(
                "  frame: {} → {} ({})\n",
                f(a),
                f(b),
                mark(EntryField::Frame)
            );
        }
        if self.old.frame.is_none() {
            s += &format!(
                "  load: {} → {} ({})\n",
                load(&self.old.load),
                load(&self.new.load),
                mark(EntryField::Load)
            );
        }
        s += &format!(
            "  number: {} → {} ({})\n",
            num(self.old.number),
            num(self.new.number),
            mark(EntryField::Number)
        );
        s
    }
}

/// What storing asks beyond the readings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StoreRequest {
    /// The stored item of that name, if any.
    pub existing: Option<StoredEntry>,
    /// The controller's number given (`None`: keep the stored one).
    pub number: Option<u32>,
    /// A tool's orientation given by the user [deg].
    pub rpy_deg: Option<[f64; 3]>,
    /// Whether the entry is to be stored (a command without a cell file
    /// only reports).
    pub store: bool,
    /// Store a fit judged not plausible.
    pub force: bool,
}

/// A fit to store (or report): the entry, the orientation's source (tools),
/// what it replaces, and the verdict it overruled when forced.
#[derive(Debug, Clone, PartialEq)]
pub struct Fitted<F> {
    /// The fit itself (a [`ToolFit`] or a [`WorkObjectFit`]).
    pub fit: F,
    /// `None` only for a report of a tool whose orientation is unknown.
    pub entry: Option<StoredEntry>,
    /// Where a tool's orientation comes from (`None` for a work object, whose
    /// orientation is always fitted).
    pub orientation: Option<OrientationSource>,
    /// The stored entry this one replaces, with what changed (`None`: nothing
    /// of that name was stored).
    pub replaced: Option<Replaced>,
    /// The verdict of [`super::judge`] the user forced past.
    pub overruled: Option<FitError>,
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// The part of a stored (or reported) fit's answer the command line and
/// the service share: `fitted` (false when forced past the verdict, whose
/// reason, message and figures follow), the fit, the orientation's source
/// and what it replaced.
#[derive(Debug, Serialize)]
pub struct Answer<'a, F: Serialize> {
    /// Whether the fit passed [`super::judge`] (false when it was forced past
    /// the verdict).
    pub fitted: bool,
    /// Whether the user forced a fit judged not plausible to be stored.
    #[serde(skip_serializing_if = "is_false")]
    pub forced: bool,
    /// The verdict forced past (reason, message and figures, flattened into the answer).
    #[serde(flatten)]
    pub overruled: Option<&'a FitError>,
    /// The fit itself.
    pub fit: &'a F,
    /// Where a tool's orientation comes from (`None` for a work object).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation: Option<OrientationSource>,
    /// The stored entry replaced and what changed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub replaced: Option<&'a Replaced>,
}

impl<F: Serialize> Fitted<F> {
    /// The shared part of the answer.
    pub fn answer(&self) -> Answer<'_, F> {
        Answer {
            fitted: self.overruled.is_none(),
            forced: self.overruled.is_some(),
            overruled: self.overruled.as_ref(),
            fit: &self.fit,
            orientation: self.orientation,
            replaced: self.replaced.as_ref(),
        }
    }
}

/// A fit's outcome.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome<F> {
    /// The fit is stored (or reported), judged plausible or forced past its verdict.
    Fitted(Box<Fitted<F>>),
    /// Nothing is stored: the readings determine nothing, the verdict was not
    /// forced, or a tool's orientation is unknown.
    NotFitted(FitError),
}

/// The fit, or with `force` the one a forcible verdict judged (the verdict
/// kept without its copy of the fit).
fn accept<F>(
    fitted: Result<F, FitError>,
    force: bool,
    take: fn(JudgedFit) -> Option<F>,
) -> Result<(F, Option<FitError>), FitError> {
    match fitted {
        Ok(f) => Ok((f, None)),
        Err(mut e) if force && e.reason.forcible() && e.fit.is_some() => {
            match e.fit.take().and_then(|j| take(*j)) {
                Some(f) => Ok((f, Some(e))),
                None => Err(e),
            }
        }
        Err(e) => Err(e),
    }
}

/// A tool fit's outcome for `req`.
pub fn tool(fitted: Result<ToolFit, FitError>, req: &StoreRequest) -> Outcome<ToolFit> {
    let take = |j| match j {
        JudgedFit::Tool(f) => Some(f),
        JudgedFit::WorkObject(_) => None,
    };
    let (fit, overruled) = match accept(fitted, req.force, take) {
        Ok(a) => a,
        Err(e) => return Outcome::NotFitted(e),
    };
    let existing = req.existing.as_ref();
    let (rpy, source) = match (fit.rpy_deg, req.rpy_deg, existing) {
        (Some(r), _, _) => (Some(r), OrientationSource::Fitted),
        (None, Some(r), _) => (Some(r), OrientationSource::Given),
        (None, None, Some(e)) => (Some(e.rpy_deg), OrientationSource::Kept),
        (None, None, None) => (None, OrientationSource::Unknown),
    };
    let Some(rpy_deg) = rpy else {
        if req.store {
            let [x, y, z] = fit.xyz_mm;
            return Outcome::NotFitted(
                FitError::new(
                    NotFittedReason::OrientationUnknown,
                    format!(
                        "the {} method fits the TCP's position only ([{x:.4}, {y:.4}, {z:.4}] mm) and no stored tool of this name has an orientation to keep: give it (`rpy_deg`, `--rpy-deg`; [0, 0, 0] is a tool frame parallel to the flange's), fit the tool's axis (`axis_point` or `plane`), or measure a 6-D probe (`tracker_frame`)",
                        fit.method.as_str()
                    ),
                )
                .with_fit(JudgedFit::Tool(fit)),
            );
        }
        return Outcome::Fitted(Box::new(Fitted {
            fit,
            entry: None,
            orientation: Some(source),
            replaced: None,
            overruled,
        }));
    };
    let entry = StoredEntry {
        number: req.number.or(existing.and_then(|e| e.number)),
        frame: None,
        xyz_mm: fit.xyz_mm,
        rpy_deg,
        load: existing.and_then(|e| e.load.clone()),
    };
    Outcome::Fitted(Box::new(Fitted {
        replaced: existing.map(|e| Replaced::between(e.clone(), entry.clone())),
        fit,
        entry: Some(entry),
        orientation: Some(source),
        overruled,
    }))
}

/// A work-object fit's outcome for `req` (its orientation is always fitted).
pub fn work_object(
    fitted: Result<WorkObjectFit, FitError>,
    req: &StoreRequest,
) -> Outcome<WorkObjectFit> {
    let take = |j| match j {
        JudgedFit::WorkObject(f) => Some(f),
        JudgedFit::Tool(_) => None,
    };
    let (fit, overruled) = match accept(fitted, req.force, take) {
        Ok(a) => a,
        Err(e) => return Outcome::NotFitted(e),
    };
    let existing = req.existing.as_ref();
    let entry = StoredEntry {
        number: req.number.or(existing.and_then(|e| e.number)),
        frame: Some(WorkObjectFrame::Base),
        xyz_mm: fit.xyz_mm,
        rpy_deg: fit.rpy_deg,
        load: None,
    };
    Outcome::Fitted(Box::new(Fitted {
        replaced: existing.map(|e| Replaced::between(e.clone(), entry.clone())),
        fit,
        entry: Some(entry),
        orientation: None,
        overruled,
    }))
}
