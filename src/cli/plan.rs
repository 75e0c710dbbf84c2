//! `robocal plan`: a measurement plan (`core::plan`): N poses chosen for
//! identifiability within the joint limits, a workspace box and the tracker's
//! line of sight, written as a joint CSV or a program that waits at each pose,
//! with the parameter standard deviations it predicts for the tracker noise.
//! `robocal plan join`: a tracker export joined back to the plan's joints into
//! a measurement CSV.
//!
//! ```text
//! robocal plan --model ur5 --poses 50 --box "-800,-800,0,800,800,1000" \
//!     --tracker "2500,0,500" --max-angle-deg 60 --noise-mm 0.01 --format krl --out plan.src \
//!     --csv plan.csv
//! robocal plan join --plan plan.csv --tracker-export export.csv --out measurements.csv
//! robocal plan --model cal.json --track drawing.json --tracker "0,0,0" --csv plan.csv --out plan.src \
//!     --format krl
//! ```
//!
//! Box and tracker position: base frame, mm (with `--track`, the tracker's
//! position is in the cell frame and each pose carries the track's value,
//! `core::plan::track`); the reflector axis: tool frame.

use crate::plan::{
    join, make_plan, make_positioner_plan, make_track_plan, make_turntable_plan, plan_csv,
    points_program, program_columns, read_plan_csv, JoinBy, JoinOptions, MeasurementPlan,
    PlanPoint, PlanSettings, PositionerPlan, PositionerPlanSettings, TrackPlan, TrackPlanSettings,
    TrackerSight, TurntablePlan, TurntablePlanSettings, Units, WorkspaceBox,
};
use crate::program::Language;
use anyhow::{bail, Context};
use clap::{Args, Subcommand, ValueEnum};
use robocal_core::calibrate::external::readings::PositionerColumns;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::TiltRotate;
use robocal_core::model::RobotModel;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `robocal plan`: a subcommand, or the plan's own arguments.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct PlanArgs {
    /// The subcommand (`join`); absent: make a plan.
    #[command(subcommand)]
    pub command: Option<PlanCommand>,
    /// The arguments of a plan (without a subcommand).
    #[command(flatten)]
    pub make: MakeArgs,
}

/// The subcommands of `robocal plan`.
#[derive(Debug, Subcommand)]
pub enum PlanCommand {
    /// Join a tracker export to the plan's joints into a measurement CSV.
    Join(JoinArgs),
}

/// Output format of `robocal plan`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PlanFormat {
    /// The joint CSV (what `robocal plan join` reads).
    Csv,
    /// A KUKA KRL program (`.src`).
    Krl,
    /// An ABB RAPID module.
    Rapid,
    /// A Fanuc TP program (ASCII `.ls`).
    Fanuc,
    /// A Universal Robots URScript program.
    Urscript,
}

/// Arguments of `robocal plan` without a subcommand: the plan to make.
#[derive(Debug, Args)]
#[command(group = clap::ArgGroup::new("one_axis").args(["track", "turntable"]))]
#[command(group = clap::ArgGroup::new("face_plate").args(["positioner", "turntable"]))]
pub struct MakeArgs {
    /// Robot model: a preset (ys100, hh800, ur5, ur10) or a model JSON file.
    #[arg(long)]
    pub model: Option<String>,
    /// Number of poses (default 50); with `--track`, per station (default 4).
    #[arg(long)]
    pub poses: Option<usize>,
    /// Random candidate configurations drawn within the joint limits.
    #[arg(long, default_value_t = 1000)]
    pub candidates: usize,
    /// Workspace box of the TCP, base frame: "xmin,ymin,zmin,xmax,ymax,zmax" [mm].
    #[arg(long = "box", allow_hyphen_values = true)]
    pub workspace: Option<String>,
    /// Tracker position in the base frame (with `--track`, the cell frame): "x,y,z" [mm].
    #[arg(long, allow_hyphen_values = true)]
    pub tracker: Option<String>,
    /// The robot's linear track (JSON, nominal or calibrated): plan poses at
    /// stations spread over its travel, each pose with the track's value.
    #[arg(long)]
    pub track: Option<String>,
    /// Stations along the track, at least 5 (default: one every 400 mm).
    #[arg(long, requires = "track")]
    pub stations: Option<usize>,
    /// The track's or the turntable's column in the plan and the
    /// measurements, e1 … e6.
    #[arg(long, requires = "one_axis", default_value = "e1", value_parser = super::track::parse_axis)]
    pub column: ExternalAxis,
    /// The stations' lowest and highest value: "lo,hi" [mm] (default: the
    /// track's travel); with `--turntable` its sweep [deg] (default
    /// -165,165).
    #[arg(long, requires = "one_axis", allow_hyphen_values = true)]
    pub travel: Option<String>,
    /// A tilt-rotate positioner (JSON, its nominal model): plan its two
    /// axes' sweeps for `positioner calibrate` instead of robot poses.
    #[arg(long, conflicts_with_all = ["track", "model"])]
    pub positioner: Option<String>,
    /// A one-axis turntable (JSON, its nominal model): plan its sweep for
    /// `turntable calibrate` instead of robot poses.
    #[arg(long, conflicts_with_all = ["track", "model", "positioner"])]
    pub turntable: Option<String>,
    /// Values of the turntable's sweep, evenly over `--travel`.
    #[arg(long, requires = "turntable", default_value_t = 12)]
    pub values: usize,
    /// A reflector's design position on the face plate, "x,y,z" [mm]; repeat
    /// for each (the first is the reference).
    #[arg(long, requires = "face_plate", allow_hyphen_values = true)]
    pub reflector: Vec<String>,
    /// Axis 1's (tilt) sweep: "lo,hi" [deg] (default -90,90).
    #[arg(long, requires = "positioner", allow_hyphen_values = true)]
    pub tilt: Option<String>,
    /// Values of axis 1's sweep, evenly over it.
    #[arg(long, requires = "positioner", default_value_t = 13)]
    pub tilt_values: usize,
    /// Axis 2's (rotate) sweep: "lo,hi" [deg] (default -165,165).
    #[arg(long, requires = "positioner", allow_hyphen_values = true)]
    pub rotate: Option<String>,
    /// Values of axis 2's sweep, evenly over it.
    #[arg(long, requires = "positioner", default_value_t = 12)]
    pub rotate_values: usize,
    /// Axis 1's (tilt) column, e1 … e6.
    #[arg(long, requires = "positioner", default_value = "e1", value_parser = super::track::parse_axis)]
    pub tilt_column: ExternalAxis,
    /// Axis 2's (rotate) column, e1 … e6.
    #[arg(long, requires = "positioner", default_value = "e2", value_parser = super::track::parse_axis)]
    pub rotate_column: ExternalAxis,
    /// Reflector axis in the tool frame: "x,y,z" (default: the tool's z axis).
    #[arg(long, allow_hyphen_values = true)]
    pub reflector_axis: Option<String>,
    /// Maximum angle between the reflector axis and the line to the tracker [deg].
    #[arg(long, default_value_t = 60.0)]
    pub max_angle_deg: f64,
    /// Tracker noise, standard deviation per axis [mm].
    #[arg(long, default_value_t = 0.01)]
    pub noise_mm: f64,
    /// Payload mass [kg] (default: the model's).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// Seed of the candidates.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output: the joint CSV or a program.
    #[arg(long, value_enum, default_value_t = PlanFormat::Csv)]
    pub format: PlanFormat,
    /// Program name.
    #[arg(long, default_value = "plan")]
    pub name: String,
    /// Wait at each pose [s].
    #[arg(long, default_value_t = 2.0)]
    pub wait_s: f64,
    /// Output file (`-`: standard output, the σ table then goes to standard error).
    #[arg(long)]
    pub out: Option<String>,
    /// Also write the joint CSV here (what `plan join` reads).
    #[arg(long)]
    pub csv: Option<PathBuf>,
}

/// Arguments of `robocal plan join`.
#[derive(Debug, Args)]
pub struct JoinArgs {
    /// The plan's joint CSV (`robocal plan --format csv`, or `--csv`).
    #[arg(long)]
    pub plan: PathBuf,
    /// The tracker export: point name or index (optional), x, y, z.
    #[arg(long)]
    pub tracker_export: PathBuf,
    /// Units of the export's positions: mm, m or detect.
    #[arg(long, default_value = "detect")]
    pub units: String,
    /// Join by name, order or detect (name when the export has a name column).
    #[arg(long, default_value = "detect")]
    pub by: String,
    /// Output measurement CSV.
    #[arg(long)]
    pub out: PathBuf,
}

fn numbers<const N: usize>(flag: &str, s: &str) -> anyhow::Result<[f64; N]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{flag}: expected {N} comma-separated numbers, got {s:?}"))?;
    match <[f64; N]>::try_from(v) {
        Ok(a) if a.iter().all(|x| x.is_finite()) => Ok(a),
        _ => bail!("{flag}: expected {N} finite comma-separated numbers, got {s:?}"),
    }
}

fn settings(a: &MakeArgs) -> anyhow::Result<PlanSettings> {
    let workspace = match &a.workspace {
        Some(s) => {
            let v = numbers::<6>("--box", s)?;
            Some(WorkspaceBox {
                min_mm: [v[0], v[1], v[2]],
                max_mm: [v[3], v[4], v[5]],
            })
        }
        None => None,
    };
    let tracker = match &a.tracker {
        Some(s) => Some(TrackerSight {
            position_mm: numbers::<3>("--tracker", s)?,
            axis: match &a.reflector_axis {
                Some(r) => numbers::<3>("--reflector-axis", r)?,
                None => [0.0, 0.0, 1.0],
            },
            max_angle_deg: a.max_angle_deg,
        }),
        None => None,
    };
    Ok(PlanSettings {
        poses: a.poses.unwrap_or(if a.track.is_some() { 4 } else { 50 }),
        candidates: a.candidates,
        workspace,
        tracker,
        noise_mm: a.noise_mm,
        payload_kg: a.payload_kg,
        seed: a.seed,
        ..PlanSettings::default()
    })
}

/// The predicted standard deviations as a text table.
pub fn sigma_table(plan: &MeasurementPlan) -> String {
    let c = plan.counts;
    let mut s = format!(
        "# {} poses of {}: {} candidates drawn, {} reachable, {} inside the box, {} in the tracker's sight\n\
         # predicted standard deviations for a tracker noise of {} mm per axis\n",
        plan.q.len(),
        plan.robot,
        c.drawn,
        c.reachable,
        c.in_box,
        c.in_sight,
        plan.noise_mm
    );
    for m in &plan.predicted {
        let _ = writeln!(s, "{}:", m.method);
        for p in &m.params {
            let _ = writeln!(s, "  {:<10} {:>12.4e} {}", p.name, p.std, p.unit);
        }
        if !m.not_identified.is_empty() {
            let _ = writeln!(s, "  not identified: {}", m.not_identified.join(", "));
        }
    }
    s
}

/// The σ table of a track plan: per station its value, poses, the
/// candidates in sight and the predicted σ of the base's pose.
pub fn track_table(plan: &TrackPlan) -> String {
    let c = plan.counts;
    let mut s = format!(
        "# {} poses of {} at {} stations of {}: {} candidates drawn, {} reachable, {} inside the box\n\
         # predicted standard deviations of the base's pose at each station for a tracker noise of {} mm per axis\n\
         # {:>12} {:>6} {:>10} {:>12} {:>12} {:>12} {:>12}\n",
        plan.points.len(),
        plan.robot,
        plan.stations.len(),
        plan.axis,
        c.drawn,
        c.reachable,
        c.in_box,
        plan.noise_mm,
        "value_mm",
        "poses",
        "in_sight",
        "position_mm",
        "rx_arcsec",
        "ry_arcsec",
        "rz_arcsec"
    );
    for st in &plan.stations {
        let [x, y, z] = st.angle_sigma_arcsec;
        let _ = writeln!(
            s,
            "  {:>12.3} {:>6} {:>10} {:>12.4e} {:>12.4} {:>12.4} {:>12.4}",
            st.value_mm,
            st.points.len(),
            st.in_sight,
            st.position_sigma_mm,
            x,
            y,
            z
        );
    }
    s
}

/// The σ table of a positioner's plan: the sweeps and the predicted σ of
/// each axis's parameters and each reflector's position.
pub fn positioner_table(plan: &PositionerPlan, s: &PositionerPlanSettings) -> String {
    let mut out = format!(
        "# {} values of the positioner's two axes, each of the {} reflectors read at every one: \
         axis 2 at {} values over {}..{} deg with axis 1 at {} deg, axis 1 at {} values over {}..{} deg with axis 2 at {} deg\n\
         # predicted standard deviations for a tracker noise of {} mm per axis (condition number {:.1e})\n",
        plan.values_deg.len(),
        s.reflectors_mm.len(),
        s.rotate_values,
        s.rotate_deg[0],
        s.rotate_deg[1],
        plan.tilt_held_deg,
        s.tilt_values,
        s.tilt_deg[0],
        s.tilt_deg[1],
        plan.rotate_held_deg,
        plan.noise_mm,
        plan.condition
    );
    for (name, a) in ["axis 1 (tilt)", "axis 2 (rotate)"].iter().zip(&plan.sigma) {
        let _ = writeln!(
            out,
            "{name}: direction {:.3e} deg, line {:.3e} mm, zero offset {:.3e} deg, scale {:.3e}",
            a.direction_deg, a.point_mm, a.zero_offset_deg, a.scale
        );
    }
    for (k, r) in plan.reflector_sigma_mm.iter().enumerate() {
        let _ = writeln!(out, "reflector {}: {r:.3e} mm", k + 1);
    }
    out
}

/// The σ table of a turntable's plan: the sweep and the predicted σ of the
/// axis's parameters and each reflector's position.
pub fn turntable_table(plan: &TurntablePlan, s: &TurntablePlanSettings) -> String {
    let a = &plan.sigma;
    let mut out = format!(
        "# {} values of the turntable's axis over {}..{} deg, each of the {} reflectors read at every one\n\
         # predicted standard deviations for a tracker noise of {} mm per axis (condition number {:.1e})\n\
         axis: direction {:.3e} deg, line {:.3e} mm, zero offset {:.3e} deg, scale {:.3e}\n",
        plan.values_deg.len(),
        s.travel_deg[0],
        s.travel_deg[1],
        s.reflectors_mm.len(),
        plan.noise_mm,
        plan.condition,
        a.direction_deg,
        a.point_mm,
        a.zero_offset_deg,
        a.scale
    );
    for (k, r) in plan.reflector_sigma_mm.iter().enumerate() {
        let _ = writeln!(out, "reflector {}: {r:.3e} mm", k + 1);
    }
    out
}

/// The turntable's plan of `a` (`--turntable`).
fn turntable_plan(a: &MakeArgs, path: &str) -> anyhow::Result<(Vec<PlanPoint>, String)> {
    let nominal = super::turntable::read_turntable(path)?;
    let settings = TurntablePlanSettings {
        reflectors_mm: reflectors(a)?,
        travel_deg: match &a.travel {
            Some(t) => numbers::<2>("--travel", t)?,
            None => TurntablePlanSettings::default().travel_deg,
        },
        values: a.values,
        column: a.column,
        noise_mm: a.noise_mm,
    };
    let plan = make_turntable_plan(&nominal, &settings)?;
    Ok((plan.points.clone(), turntable_table(&plan, &settings)))
}

/// The `--reflector` positions [mm].
fn reflectors(a: &MakeArgs) -> anyhow::Result<Vec<[f64; 3]>> {
    a.reflector
        .iter()
        .map(|r| numbers::<3>("--reflector", r))
        .collect()
}

/// The positioner's plan of `a` (`--positioner`).
fn positioner_plan(a: &MakeArgs, path: &str) -> anyhow::Result<(Vec<PlanPoint>, String)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {path}"))?;
    let nominal =
        TiltRotate::from_json(&text).with_context(|| format!("positioner file {path}"))?;
    let d = PositionerPlanSettings::default();
    let range = |flag: &str, given: &Option<String>, default: [f64; 2]| match given {
        Some(t) => numbers::<2>(flag, t),
        None => Ok(default),
    };
    let settings = PositionerPlanSettings {
        reflectors_mm: reflectors(a)?,
        tilt_deg: range("--tilt", &a.tilt, d.tilt_deg)?,
        tilt_values: a.tilt_values,
        rotate_deg: range("--rotate", &a.rotate, d.rotate_deg)?,
        rotate_values: a.rotate_values,
        columns: PositionerColumns {
            tilt: a.tilt_column,
            rotate: a.rotate_column,
        },
        noise_mm: a.noise_mm,
    };
    if let Some(l) = language(a.format) {
        program_columns(&settings.columns, l)?;
    }
    let plan = make_positioner_plan(&nominal, &settings)?;
    Ok((plan.points.clone(), positioner_table(&plan, &settings)))
}

fn language(format: PlanFormat) -> Option<Language> {
    match format {
        PlanFormat::Csv => None,
        PlanFormat::Krl => Some(Language::Krl),
        PlanFormat::Rapid => Some(Language::Rapid),
        PlanFormat::Fanuc => Some(Language::Fanuc),
        PlanFormat::Urscript => Some(Language::UrScript),
    }
}

/// The plan's points and σ table: over the track's stations with `--track`.
fn planned(a: &MakeArgs, model: &RobotModel) -> anyhow::Result<(Vec<PlanPoint>, String)> {
    let Some(path) = &a.track else {
        let plan = make_plan(model, &settings(a)?)?;
        return Ok((plan.points.clone(), sigma_table(&plan)));
    };
    let track = super::track::read_track(path)?;
    let travel_mm = match &a.travel {
        Some(t) => Some(numbers::<2>("--travel", t)?),
        None => None,
    };
    let plan = make_track_plan(
        model,
        &track,
        &TrackPlanSettings {
            stations: a.stations,
            axis: a.column,
            travel_mm,
            poses: settings(a)?,
        },
    )?;
    Ok((plan.points.clone(), track_table(&plan)))
}

/// Makes the plan and writes its exports; returns the σ table.
pub fn make(a: &MakeArgs) -> anyhow::Result<String> {
    let (points, table) = match (&a.positioner, &a.turntable, &a.model) {
        (Some(path), _, _) => positioner_plan(a, path)?,
        (None, Some(path), _) => turntable_plan(a, path)?,
        (None, None, Some(model)) => planned(a, &super::model_files::load_model(model)?)?,
        (None, None, None) => {
            bail!("--model is required (or --positioner, --turntable, or `robocal plan join`)")
        }
    };
    let text = match language(a.format) {
        None => plan_csv(&points),
        Some(l) => points_program(&points, l, &a.name, a.wait_s)?
            .into_iter()
            .map(|f| f.text)
            .collect(),
    };
    match a.out.as_deref() {
        None | Some("-") => print!("{text}"),
        Some(path) => std::fs::write(path, text).with_context(|| format!("cannot write {path}"))?,
    }
    if let Some(path) = &a.csv {
        std::fs::write(path, plan_csv(&points))
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(table)
}

/// Joins the tracker export; returns a one-line summary.
/// The `--units` and `--by` of a join (`plan join`, `iso9283 join`) as
/// `JoinOptions`; any other value is refused naming the flag.
pub(crate) fn join_options(units: &str, by: &str) -> anyhow::Result<JoinOptions> {
    let units = match units {
        "mm" => Units::Mm,
        "m" => Units::M,
        "detect" => Units::Detect,
        u => bail!("--units: mm, m or detect, got {u:?}"),
    };
    let by = match by {
        "name" => JoinBy::Name,
        "order" => JoinBy::Order,
        "detect" => JoinBy::Detect,
        b => bail!("--by: name, order or detect, got {b:?}"),
    };
    Ok(JoinOptions { units, by })
}

/// Joins the export to the plan, writes the measurement CSV to `--out`, and returns the line
/// that says how many rows were joined, by what and in which unit.
pub fn join_files(a: &JoinArgs) -> anyhow::Result<String> {
    let read = |p: &PathBuf| {
        std::fs::read_to_string(p).with_context(|| format!("cannot read {}", p.display()))
    };
    let plan = read_plan_csv(&read(&a.plan)?).with_context(|| a.plan.display().to_string())?;
    let options = join_options(&a.units, &a.by)?;
    let joined = join(&plan, &read(&a.tracker_export)?, &options)
        .with_context(|| a.tracker_export.display().to_string())?;
    std::fs::write(&a.out, crate::measure::csv::write_set(&joined.set()))
        .with_context(|| format!("cannot write {}", a.out.display()))?;
    Ok(format!(
        "{} measurements joined by {} (positions read in {}) into {}\n",
        joined.rows.len(),
        if joined.by == JoinBy::Order {
            "order"
        } else {
            "name"
        },
        if joined.units == Units::M { "m" } else { "mm" },
        a.out.display()
    ))
}

/// Runs `join`, or makes the plan and prints its σ table (to standard error when the plan
/// goes to standard output).
pub fn run(a: PlanArgs) -> anyhow::Result<()> {
    match &a.command {
        Some(PlanCommand::Join(j)) => print!("{}", join_files(j)?),
        None => {
            let table = make(&a.make)?;
            if matches!(a.make.out.as_deref(), None | Some("-")) {
                eprint!("{table}");
            } else {
                print!("{table}");
            }
        }
    }
    Ok(())
}
