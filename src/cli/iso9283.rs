//! `robocal iso9283 plan`: the ISO 9283 test cube (`core::iso9283`) in a box
//! of the workspace, solved to joint commands (nominal or filtered), as the
//! plan CSV or a program cycling P1 → P5 n times. `robocal iso9283`: AP, RP,
//! APa/b/c, RPa/b/c, AD and RD from the measured cycles.
//!
//! ```text
//! robocal iso9283 plan --model cal.json --box "1000,-400,300,1800,400,1100" \
//!     --commands filtered --format krl --cycles 30 --out iso.src --csv iso_plan.csv
//! robocal iso9283 join --plan iso_plan.csv --tracker-export export.csv --out cycles.csv
//! robocal iso9283 --plan iso_plan.csv --measured cycles.csv [--json] \
//!     [--report iso.html --robot R --model cal.json --load-kg 10 --speed-percent 100]
//! ```
//!
//! Box and orientation (`--rpy`, fixed-axis `R = Rz·Ry·Rx`, deg): base frame.
//! The plan CSV's commanded poses: the model's measurement frame (see
//! `core::iso9283::csv` for both file formats).

use crate::model::orientation::fixed_xyz_matrix;
use crate::plan::WorkspaceBox;
use crate::plan::{JoinBy, Units};
use crate::program::Language;
use crate::report::iso9283::{
    cycles_of, is_date, render_iso9283_html, today_utc, Iso9283Conditions, MeasuredSet,
};
use anyhow::{bail, Context};
use clap::{Args, Subcommand, ValueEnum};
use robocal_core::check::iso9283::csv::{plan_csv, pose_data, read_cycles_csv, read_plan_csv};
use robocal_core::check::iso9283::join::{cycles_csv, join_cycles};
use robocal_core::check::iso9283::program::cycle_program;
use robocal_core::check::iso9283::{
    assess, evaluate, plan_cube, Commands, CubePlan, CubeSettings, Iso9283Figures,
};
use robocal_core::model::calibrated::CompensatedModel;
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `robocal iso9283`: a subcommand, or the figures' own arguments.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Iso9283Args {
    /// The subcommand (`plan`, `join`); absent: the figures of the measured cycles.
    #[command(subcommand)]
    pub command: Option<Iso9283Command>,
    /// The arguments of the figures (without a subcommand).
    #[command(flatten)]
    pub figures: FiguresArgs,
}

/// The subcommands of `robocal iso9283`.
#[derive(Debug, Subcommand)]
pub enum Iso9283Command {
    /// Lay out the test cube and write its joint commands (CSV or a program).
    Plan(CubeArgs),
    /// Join the tracker's export of a run to the plan into a cycles CSV.
    Join(JoinArgs),
}

/// Arguments of `robocal iso9283 join`.
#[derive(Debug, Args)]
pub struct JoinArgs {
    /// The plan CSV (`robocal iso9283 plan --csv`).
    #[arg(long)]
    pub plan: PathBuf,
    /// The tracker export: point name (`P<i> cycle <k>`, optional), x, y, z.
    #[arg(long)]
    pub tracker_export: PathBuf,
    /// Units of the export's positions: mm, m or detect.
    #[arg(long, default_value = "detect")]
    pub units: String,
    /// Join by name, order (P1 … P5 of cycle 1, then of cycle 2, …) or detect.
    #[arg(long, default_value = "detect")]
    pub by: String,
    /// Output cycles CSV (what `robocal iso9283 --measured` reads).
    #[arg(long)]
    pub out: PathBuf,
}

/// Which joint commands a plan drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CommandsArg {
    /// Solved on the nominal model: what the robot does without calibration.
    Nominal,
    /// Solved on the calibrated model (the false targets' joints).
    Filtered,
}

impl From<CommandsArg> for Commands {
    fn from(c: CommandsArg) -> Commands {
        match c {
            CommandsArg::Nominal => Commands::Nominal,
            CommandsArg::Filtered => Commands::Filtered,
        }
    }
}

/// Output format of `robocal iso9283 plan`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CubeFormat {
    /// The plan CSV (what `robocal iso9283 --plan` reads).
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

/// Arguments of `robocal iso9283 plan`.
#[derive(Debug, Args)]
pub struct CubeArgs {
    /// A calibrated model file (`calibrate --save`), a model JSON file or a preset.
    #[arg(long)]
    pub model: String,
    /// The box the cube must fit in, base frame: "xmin,ymin,zmin,xmax,ymax,zmax" [mm].
    #[arg(long = "box", allow_hyphen_values = true)]
    pub workspace: String,
    /// Tool orientation at every pose, base frame: "rx,ry,rz" [deg], R = Rz·Ry·Rx.
    #[arg(long, default_value = "180,0,0", allow_hyphen_values = true)]
    pub rpy: String,
    /// Joint commands: solved on the nominal model or on the calibrated one (filtered).
    #[arg(long, value_enum, default_value_t = CommandsArg::Filtered)]
    pub commands: CommandsArg,
    /// Output: the plan CSV or a program cycling through P1 … P5.
    #[arg(long, value_enum, default_value_t = CubeFormat::Csv)]
    pub format: CubeFormat,
    /// Cycles of the program (the standard's n).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub cycles: u32,
    /// Wait at each pose [s].
    #[arg(long, default_value_t = 2.0)]
    pub wait_s: f64,
    /// Program name.
    #[arg(long, default_value = "iso9283")]
    pub name: String,
    /// Output file (`-` or absent: standard output; the summary goes to standard error).
    #[arg(long)]
    pub out: Option<String>,
    /// Also write the plan CSV here (what `robocal iso9283 --plan` reads).
    #[arg(long)]
    pub csv: Option<PathBuf>,
}

/// Arguments of `robocal iso9283` without a subcommand: the figures of the measured cycles.
#[derive(Debug, Args)]
pub struct FiguresArgs {
    /// Plan CSV(s) with the commanded poses; one per `--measured`, in order.
    #[arg(long)]
    pub plan: Vec<PathBuf>,
    /// Measured cycles CSV(s): pose, cycle, x_mm, y_mm, z_mm [, rx_deg, ry_deg, rz_deg].
    #[arg(long)]
    pub measured: Vec<PathBuf>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write the ISO 9283 report as HTML here: the test conditions, then
    /// one table of every test's figures side by side with the change.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// The report's robot (name, serial number).
    #[arg(long)]
    pub robot: Option<String>,
    /// The model file the commands were solved with: the report gives its
    /// SHA-256 (a version's `model.json` hashes as the service's report does).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// The model's version (default: the `--model` file's name).
    #[arg(long)]
    pub model_version: Option<String>,
    /// Test date, YYYY-MM-DD (default: today, UTC).
    #[arg(long)]
    pub date: Option<String>,
    /// Load carried during the test [kg].
    #[arg(long)]
    pub load_kg: Option<f64>,
    /// Speed between the poses [% of the rated speed].
    #[arg(long)]
    pub speed_percent: Option<f64>,
    /// What measured the cycles (tracker, reflector, session).
    #[arg(long)]
    pub measurement: Option<String>,
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

/// The cube plan of `a` on `model`.
pub fn cube_plan(model: &CompensatedModel, a: &CubeArgs) -> anyhow::Result<CubePlan> {
    let b = numbers::<6>("--box", &a.workspace)?;
    let r = numbers::<3>("--rpy", &a.rpy)?.map(f64::to_radians);
    let workspace = WorkspaceBox {
        min_mm: [b[0], b[1], b[2]],
        max_mm: [b[3], b[4], b[5]],
    };
    let settings = CubeSettings::new(
        workspace,
        fixed_xyz_matrix(r[0], r[1], r[2]),
        a.commands.into(),
    );
    Ok(plan_cube(model, &settings)?)
}

/// The program text cycling `cycles` times through the plan's poses, each
/// motion commented `P<i> cycle <k>` (`core::iso9283::program`).
pub fn cube_program(
    plan: &CubePlan,
    language: Language,
    name: &str,
    cycles: u32,
    wait_s: f64,
) -> anyhow::Result<String> {
    Ok(cycle_program(plan, language, name, cycles, wait_s)?
        .into_iter()
        .map(|f| f.text)
        .collect())
}

/// A one-paragraph summary of the plan.
pub fn plan_summary(plan: &CubePlan) -> String {
    let c = &plan.cube;
    let mut s = format!(
        "# ISO 9283 cube, {} commands: edge {:.1} mm (largest in the box {:.1} mm), centre {:.1?} mm (base frame)\n",
        plan.commands.name(),
        c.edge_mm,
        plan.largest_edge_mm,
        c.centre_mm
    );
    for p in &plan.poses {
        let _ = writeln!(
            s,
            "# {}: commanded {:.3?} mm (measurement frame), joints {:.4?} deg",
            p.name, p.commanded_mm, p.joints_deg
        );
    }
    s
}

/// Lays out and writes the plan; returns its summary.
pub fn make(a: &CubeArgs) -> anyhow::Result<String> {
    let model = super::model_files::load_compensated(&a.model)?;
    let plan = cube_plan(&model, a)?;
    let language = match a.format {
        CubeFormat::Csv => None,
        CubeFormat::Krl => Some(Language::Krl),
        CubeFormat::Rapid => Some(Language::Rapid),
        CubeFormat::Fanuc => Some(Language::Fanuc),
        CubeFormat::Urscript => Some(Language::UrScript),
    };
    let text = match language {
        None => plan_csv(&plan),
        Some(l) => cube_program(&plan, l, &a.name, a.cycles, a.wait_s)?,
    };
    match a.out.as_deref() {
        None | Some("-") => print!("{text}"),
        Some(path) => std::fs::write(path, text).with_context(|| format!("cannot write {path}"))?,
    }
    if let Some(path) = &a.csv {
        std::fs::write(path, plan_csv(&plan))
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(plan_summary(&plan))
}

/// The figures as a text table.
pub fn figures_table(label: &str, f: &Iso9283Figures) -> String {
    let mut s = format!("ISO 9283 pose characteristics: {label}\n");
    s.push_str("pose   n      AP[mm]   APx[mm]   APy[mm]   APz[mm]    RP[mm]   APa/b/c[deg]            ±RPa/b/c[deg]\n");
    for p in &f.poses {
        let abc = |v: Option<[f64; 3]>| {
            v.map_or("-".to_string(), |v| {
                format!("{:.4},{:.4},{:.4}", v[0], v[1], v[2])
            })
        };
        let _ = writeln!(
            s,
            "{:<5}{:>3}{:>12.4}{:>10.4}{:>10.4}{:>10.4}{:>10.4}   {:<24}{}",
            p.pose,
            p.cycles,
            p.ap_mm,
            p.ap_xyz_mm[0],
            p.ap_xyz_mm[1],
            p.ap_xyz_mm[2],
            p.rp_mm,
            abc(p.ap_abc_deg),
            abc(p.rp_abc_deg)
        );
    }
    s.push_str("distance   n    D_c[mm]     AD[mm]    ±RD[mm]\n");
    for d in &f.distances {
        let _ = writeln!(
            s,
            "{:<9}{:>3}{:>11.3}{:>11.4}{:>11.4}",
            format!("{}-{}", d.from, d.to),
            d.cycles,
            d.commanded_mm,
            d.ad_mm,
            d.rd_mm
        );
    }
    s
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The report's conditions from the flags; `sets` the tests' measured sets.
pub fn conditions(a: &FiguresArgs, sets: Vec<MeasuredSet>) -> anyhow::Result<Iso9283Conditions> {
    let date = match &a.date {
        Some(d) if is_date(d) => d.clone(),
        Some(d) => bail!("--date: expected a date YYYY-MM-DD, got {d:?}"),
        None => today_utc(),
    };
    for (flag, v) in [
        ("--load-kg", a.load_kg),
        ("--speed-percent", a.speed_percent),
    ] {
        if v.is_some_and(|v| !(v.is_finite() && v >= 0.0)) {
            bail!("{flag}: expected a finite number ≥ 0");
        }
    }
    let model_sha256 = match &a.model {
        Some(p) => Some(hex(&Sha256::digest(
            std::fs::read(p).with_context(|| format!("cannot read {}", p.display()))?,
        ))),
        None => None,
    };
    let model_version = a.model_version.clone().or_else(|| {
        a.model
            .as_ref()
            .and_then(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned())
    });
    Ok(Iso9283Conditions {
        robot: a.robot.clone(),
        model_version,
        model_sha256,
        date,
        load_kg: a.load_kg,
        speed_percent: a.speed_percent,
        measurement: a.measurement.clone(),
        sets,
        robocal_version: env!("CARGO_PKG_VERSION"),
    })
}

/// The conditions a report should state and `a` leaves out (flag names).
pub fn unstated(a: &FiguresArgs) -> Vec<&'static str> {
    [
        ("--robot", a.robot.is_none()),
        ("--model", a.model.is_none() && a.model_version.is_none()),
        ("--load-kg", a.load_kg.is_none()),
        ("--speed-percent", a.speed_percent.is_none()),
    ]
    .into_iter()
    .filter(|(_, missing)| *missing)
    .map(|(f, _)| f)
    .collect()
}

/// The figures of each plan and its measured cycles, as text or JSON.
pub fn figures(a: &FiguresArgs) -> anyhow::Result<String> {
    if a.plan.is_empty() || a.plan.len() != a.measured.len() {
        bail!(
            "give one --plan and one --measured per test (got {} and {}), or use `robocal iso9283 plan`",
            a.plan.len(),
            a.measured.len()
        );
    }
    let read = |p: &PathBuf| {
        std::fs::read_to_string(p).with_context(|| format!("cannot read {}", p.display()))
    };
    let mut out = String::new();
    let mut all = Vec::new();
    let mut assessed = Vec::new();
    let mut sets = Vec::new();
    for (plan, measured) in a.plan.iter().zip(&a.measured) {
        let commanded = read_plan_csv(&read(plan)?).with_context(|| plan.display().to_string())?;
        let text = read(measured)?;
        let cycles =
            read_cycles_csv(&text, &commanded).with_context(|| measured.display().to_string())?;
        let f = evaluate(&cycles).with_context(|| measured.display().to_string())?;
        let label = measured.display().to_string();
        out.push_str(&figures_table(&label, &f));
        all.push(serde_json::json!({ "measured": label, "figures": f }));
        let assessment = assess(&pose_data(&commanded, cycles))
            .with_context(|| measured.display().to_string())?;
        sets.push(MeasuredSet {
            label: label.clone(),
            cycles: cycles_of(&assessment),
            sha256: Some(hex(&Sha256::digest(text.as_bytes()))),
        });
        assessed.push((label, assessment));
    }
    if let Some(path) = &a.report {
        let c = conditions(a, sets)?;
        std::fs::write(path, render_iso9283_html(&c, &assessed))
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if a.json {
        return Ok(serde_json::to_string_pretty(&all)? + "\n");
    }
    Ok(out)
}

/// Joins the tracker export; returns a summary (the poses and cycles it
/// lacks among them).
pub fn join_files(a: &JoinArgs) -> anyhow::Result<String> {
    let read = |p: &PathBuf| {
        std::fs::read_to_string(p).with_context(|| format!("cannot read {}", p.display()))
    };
    let plan = read_plan_csv(&read(&a.plan)?).with_context(|| a.plan.display().to_string())?;
    let options = super::plan::join_options(&a.units, &a.by)?;
    let joined = join_cycles(&plan, &read(&a.tracker_export)?, &options)
        .with_context(|| a.tracker_export.display().to_string())?;
    std::fs::write(&a.out, cycles_csv(&joined.rows))
        .with_context(|| format!("cannot write {}", a.out.display()))?;
    let mut s = format!(
        "{} positions of {} poses over {} cycles joined by {} (read in {}) into {}\n",
        joined.rows.len(),
        plan.len(),
        joined.cycles,
        if joined.by == JoinBy::Order {
            "order"
        } else {
            "name"
        },
        if joined.units == Units::M { "m" } else { "mm" },
        a.out.display()
    );
    if !joined.missing.is_empty() {
        let _ = writeln!(
            s,
            "not in the export ({}): {}",
            joined.missing.len(),
            joined.missing.join(", ")
        );
    }
    Ok(s)
}

/// Runs the subcommand, or prints the figures (a table, or JSON with `--json`) and writes the
/// report when asked; a plan's summary goes to standard error when the plan goes to standard
/// output.
pub fn run(a: Iso9283Args) -> anyhow::Result<()> {
    match &a.command {
        Some(Iso9283Command::Plan(c)) => {
            let summary = make(c)?;
            if matches!(c.out.as_deref(), None | Some("-")) {
                eprint!("{summary}");
            } else {
                print!("{summary}");
            }
        }
        Some(Iso9283Command::Join(j)) => print!("{}", join_files(j)?),
        None => {
            if a.figures.report.is_some() {
                let missing = unstated(&a.figures);
                if !missing.is_empty() {
                    eprintln!(
                        "the report states no {} (give {})",
                        missing
                            .iter()
                            .map(|f| f.trim_start_matches("--").replace('-', " "))
                            .collect::<Vec<_>>()
                            .join(", "),
                        missing.join(", ")
                    );
                }
            }
            print!("{}", figures(&a.figures)?)
        }
    }
    Ok(())
}
