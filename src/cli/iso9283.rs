//! `robocal iso9283 plan`: the ISO 9283 test cube (`core::iso9283`) in a box
//! of the workspace, solved to joint commands (nominal or filtered), as the
//! plan CSV or a program cycling P1 → P5 n times. `robocal iso9283`: AP, RP,
//! APa/b/c, RPa/b/c, AD and RD from the measured cycles.
//!
//! ```text
//! robocal iso9283 plan --model cal.json --box "1000,-400,300,1800,400,1100" \
//!     --commands filtered --format krl --cycles 30 --out iso.src --csv iso_plan.csv
//! robocal iso9283 --plan iso_plan.csv --measured cycles.csv [--json] [--report iso.html]
//! ```
//!
//! Box and orientation (`--rpy`, fixed-axis `R = Rz·Ry·Rx`, deg): base frame.
//! The plan CSV's commanded poses: the model's measurement frame (see
//! `core::iso9283::csv` for both file formats).

use crate::calibrate::compensate::CompensatedModel;
use crate::model::orientation::fixed_xyz_matrix;
use crate::plan::WorkspaceBox;
use crate::solve::program::{export::joint_program, Language};
use anyhow::{bail, Context};
use clap::{Args, Subcommand, ValueEnum};
use robocal_core::check::iso9283::csv::{plan_csv, read_cycles_csv, read_plan_csv};
use robocal_core::check::iso9283::{
    evaluate, plan_cube, Commands, CubePlan, CubeSettings, Iso9283Figures,
};
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Iso9283Args {
    #[command(subcommand)]
    pub command: Option<Iso9283Command>,
    #[command(flatten)]
    pub figures: FiguresArgs,
}

#[derive(Debug, Subcommand)]
pub enum Iso9283Command {
    /// Lay out the test cube and write its joint commands (CSV or a program).
    Plan(CubeArgs),
}

/// Which joint commands a plan drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CommandsArg {
    Nominal,
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
    Csv,
    Krl,
    Rapid,
    Fanuc,
    Urscript,
}

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
    /// Also write the figures as an HTML report (one section per test) here.
    #[arg(long)]
    pub report: Option<PathBuf>,
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

/// The program text cycling `cycles` times through the plan's poses.
pub fn cube_program(
    plan: &CubePlan,
    language: Language,
    name: &str,
    cycles: u32,
    wait_s: f64,
) -> anyhow::Result<String> {
    let mut joints = Vec::new();
    for p in &plan.poses {
        let q: [f64; 6] = p.joints_deg.as_slice().try_into().map_err(|_| {
            anyhow::anyhow!(
                "programs need 6 joints, the model has {}",
                p.joints_deg.len()
            )
        })?;
        joints.push(q);
    }
    let cycled: Vec<[f64; 6]> = (0..cycles).flat_map(|_| joints.iter().copied()).collect();
    Ok(joint_program(language, name, &cycled, wait_s)
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
    let mut tests = Vec::new();
    for (plan, measured) in a.plan.iter().zip(&a.measured) {
        let commanded = read_plan_csv(&read(plan)?).with_context(|| plan.display().to_string())?;
        let cycles = read_cycles_csv(&read(measured)?, &commanded)
            .with_context(|| measured.display().to_string())?;
        let f = evaluate(&cycles).with_context(|| measured.display().to_string())?;
        let label = measured.display().to_string();
        out.push_str(&figures_table(&label, &f));
        all.push(serde_json::json!({ "measured": label, "figures": f }));
        tests.push((label, f));
    }
    if let Some(path) = &a.report {
        std::fs::write(path, crate::report::iso9283::render_iso9283_html(&tests))
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if a.json {
        return Ok(serde_json::to_string_pretty(&all)? + "\n");
    }
    Ok(out)
}

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
        None => print!("{}", figures(&a.figures)?),
    }
    Ok(())
}
