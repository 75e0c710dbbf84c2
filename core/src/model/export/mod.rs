//! Exports of a (calibrated) model for other tools, as text: URDF, standard-DH
//! and modified-DH tables, and robocal's own JSON. Writing files is the
//! caller's business.
//!
//! Only the *geometric* model is exported: calibrated link geometry, registered
//! base frame and tool. Joint compliance (thesis eq. 2.8), joint angle error
//! maps and learned compensators cannot be written in these formats, and every
//! text says so.
//!
//! Conventions (robocal's chain, `model::robot`): link k (0-based) is
//! `Rx(α)·Tx(a)·[Ry(β)]·Tz(d)·Rz(θ)` with `θ = q + θ_offset`, the controller
//! reading `q_ctrl = sign·(q − zero)`. URDF in metres and radians, root link
//! `cell` (the measurement frame), joint values the controller's readings;
//! `mdh-csv` rows `a_mm, alpha_deg, d_mm, theta_offset_deg, beta_deg`;
//! `dh-csv` the exact regrouping `Rz(θ)·Tz(d)·Tx(a)·Rx(α)` (only without
//! Hayati twists after the base); transform rows `x_mm, y_mm, z_mm, rx_deg,
//! ry_deg, rz_deg` as `Tr·Rz·Ry·Rx`. Closed-loop models (HH800) have no URDF
//! or DH form here. More: docs/design.md "Exports".

use crate::csv_write::{comment_line, push_header, push_row, Cell};
use crate::model::calibrated::{CalibratedModelFile, CompensatedModel};
use crate::model::kinematics::chain::{base_constant, tool_pose};
use crate::model::orientation::fixed_xyz_angles;
use crate::model::{Pose, RobotModel};
use std::fmt::Write as _;
use std::str::FromStr;

/// An export format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ExportFormat {
    /// URDF (XML), metres and radians, root link `cell`.
    #[serde(rename = "urdf")]
    Urdf,
    /// Standard (distal) DH table, CSV.
    #[serde(rename = "dh-csv")]
    DhCsv,
    /// Modified DH table (robocal's own rows), CSV.
    #[serde(rename = "mdh-csv")]
    MdhCsv,
    /// robocal's own model JSON.
    #[serde(rename = "json")]
    Json,
}

impl ExportFormat {
    /// Every format, in declaration order.
    pub const ALL: [ExportFormat; 4] = [
        ExportFormat::Urdf,
        ExportFormat::DhCsv,
        ExportFormat::MdhCsv,
        ExportFormat::Json,
    ];

    /// The format's name on the command line and in the API (`urdf`, `dh-csv`,
    /// `mdh-csv`, `json`).
    pub fn name(self) -> &'static str {
        match self {
            ExportFormat::Urdf => "urdf",
            ExportFormat::DhCsv => "dh-csv",
            ExportFormat::MdhCsv => "mdh-csv",
            ExportFormat::Json => "json",
        }
    }

    /// The media type of the text.
    pub fn content_type(self) -> &'static str {
        match self {
            ExportFormat::Urdf => "application/xml",
            ExportFormat::DhCsv | ExportFormat::MdhCsv => "text/csv",
            ExportFormat::Json => "application/json",
        }
    }

    /// A file name extension.
    pub fn extension(self) -> &'static str {
        match self {
            ExportFormat::Urdf => "urdf",
            ExportFormat::DhCsv | ExportFormat::MdhCsv => "csv",
            ExportFormat::Json => "json",
        }
    }
}

impl FromStr for ExportFormat {
    type Err = ExportError;
    fn from_str(s: &str) -> Result<Self, ExportError> {
        ExportFormat::ALL
            .into_iter()
            .find(|f| f.name() == s.trim())
            .ok_or_else(|| ExportError::UnknownFormat(s.to_string()))
    }
}

/// Why a model cannot be exported.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// No format has this name; the name given.
    #[error("unknown export format `{0}`; use urdf, dh-csv, mdh-csv or json")]
    UnknownFormat(String),
    /// The model has what the format cannot hold (a closed loop, Hayati twists
    /// in DH); the message says what.
    #[error("{0}")]
    NotRepresentable(String),
}

/// What the text says about its origin.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportSource<'a> {
    /// Robot name.
    pub robot: &'a str,
    /// Calibration method (`nominal` for an uncalibrated model).
    pub method: &'a str,
}

/// The model in `format`.
pub fn export(
    model: &CompensatedModel,
    source: &ExportSource,
    format: ExportFormat,
) -> Result<String, ExportError> {
    match format {
        ExportFormat::Json => {
            Ok(
                CalibratedModelFile::from_compensated(model, source.robot, source.method).to_json()
                    + "\n",
            )
        }
        ExportFormat::Urdf => urdf(model, source),
        ExportFormat::DhCsv => dh_csv(model, source, false),
        ExportFormat::MdhCsv => dh_csv(model, source, true),
    }
}

const NOT_REPRESENTABLE: &str =
    "joint compliance (deflection under load) and learned compensators \
are not representable in this format: this is the geometric model only";

/// What the format drops from `m` beyond [`NOT_REPRESENTABLE`]: its joint
/// angle error maps, when it has them.
fn dropped_maps(m: &RobotModel) -> &'static str {
    if m.joint_maps.is_some() {
        "; its joint angle error maps (km-maps / skcm-maps) are not carried either: \
positions computed from this file miss them (export json keeps them)"
    } else {
        ""
    }
}

fn open_chain(m: &RobotModel, what: &str) -> Result<(), ExportError> {
    if m.closed_loop.is_some() {
        return Err(ExportError::NotRepresentable(format!(
            "{} has a closed loop (a passive joint driven through a parallelogram), which {what} \
             cannot describe; export json instead",
            m.name
        )));
    }
    Ok(())
}

/// The constant part of link `k` with `θ_offset + zero` folded in: the URDF
/// joint origin (the joint rotates about its z axis after it).
fn joint_origin(m: &RobotModel, k: usize) -> Pose {
    let l = &m.links[k];
    let mut p = Pose::identity();
    if k == 0 {
        p = base_constant(l);
    } else {
        p.rot_x(l.alpha);
        p.tr_x(l.a);
        if l.parallel {
            p.rot_y(l.beta);
        }
        p.tr_z(l.d);
    }
    p.rot_z(l.theta + l.zero);
    p
}

fn xyz_rpy(p: &Pose) -> String {
    let [r, pi, y] = fixed_xyz_angles(&p.r);
    format!(
        "xyz=\"{} {} {}\" rpy=\"{} {} {}\"",
        p.p.x, p.p.y, p.p.z, r, pi, y
    )
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace("--", "- -")
}

fn urdf(model: &CompensatedModel, source: &ExportSource) -> Result<String, ExportError> {
    let m = &model.calibrated;
    open_chain(m, "URDF")?;
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<!-- robocal export: {} model of {} ({} joints). Metres, radians.\n     \
         Root link `cell` is the measurement frame; `base` the registered robot base; `tcp` the tool centre point.\n     \
         Joint values are controller readings (q_ctrl, radians); origins include the calibrated joint offsets.\n     \
         Note: {NOT_REPRESENTABLE}{}. -->",
        xml_escape(source.method),
        xml_escape(source.robot),
        m.dof(),
        dropped_maps(m)
    );
    let _ = writeln!(s, "<robot name=\"{}\">", xml_escape(source.robot));
    let _ = writeln!(s, "  <link name=\"cell\"/>");
    let _ = writeln!(
        s,
        "  <joint name=\"base_joint\" type=\"fixed\">\n    <parent link=\"cell\"/>\n    <child link=\"base\"/>\n    <origin {}/>\n  </joint>",
        xyz_rpy(&model.cell_from_base)
    );
    let _ = writeln!(s, "  <link name=\"base\"/>");
    let mut parent = "base".to_string();
    for (k, l) in m.links.iter().enumerate() {
        let child = format!("link_{}", k + 1);
        // Limits in the controller convention.
        let a = (l.limits[0] - l.zero) * l.sign;
        let b = (l.limits[1] - l.zero) * l.sign;
        let _ = writeln!(
            s,
            "  <joint name=\"joint_{}\" type=\"revolute\">\n    <parent link=\"{parent}\"/>\n    <child link=\"{child}\"/>\n    <origin {}/>\n    <axis xyz=\"0 0 {}\"/>\n    <limit lower=\"{}\" upper=\"{}\" effort=\"0\" velocity=\"0\"/>\n  </joint>",
            k + 1,
            xyz_rpy(&joint_origin(m, k)),
            l.sign,
            a.min(b),
            a.max(b)
        );
        let _ = writeln!(s, "  <link name=\"{child}\"/>");
        parent = child;
    }
    let _ = writeln!(
        s,
        "  <joint name=\"tcp_joint\" type=\"fixed\">\n    <parent link=\"{parent}\"/>\n    <child link=\"tcp\"/>\n    <origin {}/>\n  </joint>",
        xyz_rpy(&tool_pose(m))
    );
    let _ = writeln!(s, "  <link name=\"tcp\"/>");
    let _ = writeln!(s, "</robot>");
    Ok(s)
}

/// A transform's cells: `x_mm, y_mm, z_mm, rx_deg, ry_deg, rz_deg`.
fn transform_cells(p: &Pose) -> [Cell; 6] {
    let [rx, ry, rz] = fixed_xyz_angles(&p.r).map(f64::to_degrees);
    [p.p.x * 1e3, p.p.y * 1e3, p.p.z * 1e3, rx, ry, rz].map(Cell::num)
}

/// A transform row of a DH table: its name, the joint columns empty.
fn transform_row(s: &mut String, name: &str, joint_columns: usize, p: &Pose) {
    let mut row = vec![Cell::text(name)];
    row.extend((0..joint_columns).map(|_| Cell::empty()));
    row.extend(transform_cells(p));
    push_row(s, &row);
}

fn dh_csv(
    model: &CompensatedModel,
    source: &ExportSource,
    modified: bool,
) -> Result<String, ExportError> {
    let m = &model.calibrated;
    open_chain(m, "a DH table")?;
    let n = m.dof();
    if !modified {
        let hayati: Vec<String> = m
            .links
            .iter()
            .enumerate()
            .skip(1)
            .filter(|(_, l)| l.parallel && l.beta != 0.0)
            .map(|(k, _)| format!("j{}", k + 1))
            .collect();
        if !hayati.is_empty() {
            return Err(ExportError::NotRepresentable(format!(
                "the model has Hayati twists β on {} (parallel axes), which standard DH cannot \
                 describe; export mdh-csv (with a beta_deg column) or urdf instead",
                hayati.join(", ")
            )));
        }
    }
    let mut s = String::new();
    let (kind, link) = if modified {
        (
            "modified DH (Craig) with Hayati beta",
            "Rx(alpha)*Tx(a)*Ry(beta)*Tz(d)*Rz(theta)",
        )
    } else {
        ("standard DH", "Rz(theta)*Tz(d)*Tx(a)*Rx(alpha)")
    };
    s.push_str(&comment_line(&format!(
        "robocal export: {} model of {}, {kind}; mm and degrees",
        source.method, source.robot
    )));
    s.push_str(&comment_line(&format!(
        "T = cell_from_base * base * T_1 * ... * T_{n} * tool; T_i = {link}; theta = q + theta_offset_deg; q_ctrl = sign * (q - zero_deg)"
    )));
    s.push_str(&comment_line(&format!(
        "transform rows: Tr(x,y,z)*Rz(rz)*Ry(ry)*Rx(rx). Note: {NOT_REPRESENTABLE}{}",
        dropped_maps(m)
    )));
    let mut header = vec!["name", "a_mm", "alpha_deg", "d_mm", "theta_offset_deg"];
    if modified {
        header.push("beta_deg");
    }
    header.extend([
        "sign",
        "zero_deg",
        "lower_deg",
        "upper_deg",
        "x_mm",
        "y_mm",
        "z_mm",
        "rx_deg",
        "ry_deg",
        "rz_deg",
    ]);
    push_header(&mut s, &header);
    let joint_columns = if modified { 9 } else { 8 };
    transform_row(
        &mut s,
        "cell_from_base",
        joint_columns,
        &model.cell_from_base,
    );
    // The base link's constant part is the base transform; joint 1 keeps θ0.
    transform_row(&mut s, "base", joint_columns, &base_constant(&m.links[0]));
    for k in 0..n {
        let l = &m.links[k];
        // Modified: link k's own a, α, β, d (0 for the base link's, moved
        // into `base`). Standard: d and θ of link k, a and α of link k+1.
        let (a, alpha, beta, d) = if modified {
            if k == 0 {
                (0.0, 0.0, 0.0, 0.0)
            } else {
                (l.a, l.alpha, if l.parallel { l.beta } else { 0.0 }, l.d)
            }
        } else {
            let next = m.links.get(k + 1);
            (
                next.map_or(0.0, |x| x.a),
                next.map_or(0.0, |x| x.alpha),
                0.0,
                if k == 0 { 0.0 } else { l.d },
            )
        };
        let mut row = vec![Cell::text(format!("j{}", k + 1))];
        row.extend([a * 1e3, alpha.to_degrees(), d * 1e3, l.theta.to_degrees()].map(Cell::num));
        if modified {
            row.push(Cell::num(beta.to_degrees()));
        }
        row.extend(
            [
                l.sign,
                l.zero.to_degrees(),
                l.limits[0].to_degrees(),
                l.limits[1].to_degrees(),
            ]
            .map(Cell::num),
        );
        row.extend((0..6).map(|_| Cell::empty()));
        push_row(&mut s, &row);
    }
    transform_row(&mut s, "tool", joint_columns, &tool_pose(m));
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::kinematics::fk;
    use crate::model::orientation::fixed_xyz_matrix;
    use crate::model::preset;
    use crate::sim::{synthetic_calibration, SyntheticErrors};
    use nalgebra::Vector3;

    /// Reads the DH CSV back and chains it as its header says (independent of
    /// the model code: elementary transforms from nalgebra).
    fn chain_from_csv(text: &str, modified: bool, q: &[f64]) -> Pose {
        let rows: Vec<Vec<&str>> = text
            .lines()
            .filter(|l| !l.starts_with('#'))
            .skip(1)
            .map(|l| l.split(',').collect())
            .collect();
        let num = |c: &str| c.parse::<f64>().unwrap();
        let transform = |r: &Vec<&str>| {
            let v: Vec<f64> = r[r.len() - 6..].iter().map(|c| num(c)).collect();
            Pose::new(
                fixed_xyz_matrix(v[3].to_radians(), v[4].to_radians(), v[5].to_radians()),
                Vector3::new(v[0], v[1], v[2]) * 1e-3,
            )
        };
        let rot = |axis: &nalgebra::Unit<Vector3<f64>>, a: f64| {
            Pose::new(
                nalgebra::Rotation3::from_axis_angle(axis, a).into_inner(),
                Vector3::zeros(),
            )
        };
        let tr = |v: Vector3<f64>| Pose::from_translation(v);
        let mut t = transform(&rows[0]).compose(&transform(&rows[1]));
        for (k, r) in rows[2..rows.len() - 1].iter().enumerate() {
            let a = num(r[1]) * 1e-3;
            let alpha = num(r[2]).to_radians();
            let d = num(r[3]) * 1e-3;
            let theta = q[k] + num(r[4]).to_radians();
            let link = if modified {
                let beta = num(r[5]).to_radians();
                rot(&Vector3::x_axis(), alpha)
                    .compose(&tr(Vector3::new(a, 0.0, 0.0)))
                    .compose(&rot(&Vector3::y_axis(), beta))
                    .compose(&tr(Vector3::new(0.0, 0.0, d)))
                    .compose(&rot(&Vector3::z_axis(), theta))
            } else {
                rot(&Vector3::z_axis(), theta)
                    .compose(&tr(Vector3::new(0.0, 0.0, d)))
                    .compose(&tr(Vector3::new(a, 0.0, 0.0)))
                    .compose(&rot(&Vector3::x_axis(), alpha))
            };
            t = t.compose(&link);
        }
        t.compose(&transform(&rows[rows.len() - 1]))
    }

    #[test]
    fn dh_tables_chain_back_to_the_model() {
        let src = ExportSource {
            robot: "r",
            method: "km",
        };
        let mut e = SyntheticErrors::typical(1e-6);
        e.payload_kg = Some(5.0);
        for name in ["ur10", "ys100"] {
            let cm = synthetic_calibration(&preset(name).unwrap(), &e, 4);
            let q = [0.3, -1.1, 0.8, -0.4, 1.2, 0.5];
            let want = cm.cell_from_base.compose(&fk(&cm.calibrated, &q).unwrap());
            let mdh = export(&cm, &src, ExportFormat::MdhCsv).unwrap();
            let got = chain_from_csv(&mdh, true, &q);
            assert!((got.p - want.p).norm() < 1e-12, "{name} mdh");
            assert!((got.r - want.r).norm() < 1e-12);
            // Standard DH needs a model without Hayati twists (the nominal one).
            assert!(
                matches!(
                    export(&cm, &src, ExportFormat::DhCsv),
                    Err(ExportError::NotRepresentable(_))
                ) || cm
                    .calibrated
                    .links
                    .iter()
                    .all(|l| !l.parallel || l.beta == 0.0)
            );
            let nominal = CompensatedModel::from_nominal(cm.nominal.clone());
            let want = fk(&nominal.calibrated, &q).unwrap();
            let dh = export(&nominal, &src, ExportFormat::DhCsv).unwrap();
            let got = chain_from_csv(&dh, false, &q);
            assert!((got.p - want.p).norm() < 1e-12, "{name} dh");
            assert!((got.r - want.r).norm() < 1e-12);
        }
    }

    #[test]
    fn closed_loops_and_unknown_formats_are_refused() {
        let cm = CompensatedModel::from_nominal(preset("hh800").unwrap());
        let src = ExportSource {
            robot: "hh800",
            method: "nominal",
        };
        let e = export(&cm, &src, ExportFormat::Urdf).unwrap_err();
        assert!(e.to_string().contains("closed loop"), "{e}");
        assert!(export(&cm, &src, ExportFormat::Json).is_ok());
        assert!("sdf".parse::<ExportFormat>().is_err());
        for f in ExportFormat::ALL {
            assert_eq!(f.name().parse::<ExportFormat>().unwrap(), f);
        }
    }

    /// A robot or method name with a line break stays inside its comment
    /// line: the CSV has the same rows as with a plain name.
    #[test]
    fn a_name_cannot_break_out_of_the_comment_line() {
        let cm = CompensatedModel::from_nominal(preset("ur5").unwrap());
        for f in [ExportFormat::DhCsv, ExportFormat::MdhCsv] {
            let plain = export(
                &cm,
                &ExportSource {
                    robot: "arm",
                    method: "km",
                },
                f,
            )
            .unwrap();
            let src = ExportSource {
                robot: "arm\nname,a_mm,evil\r\n=1+1",
                method: "km\n@x",
            };
            let text = export(&cm, &src, f).unwrap();
            assert_eq!(text.lines().count(), plain.lines().count(), "{text}");
            let rows = |t: &str| {
                t.lines()
                    .filter(|l| !l.starts_with('#'))
                    .map(str::to_string)
                    .collect::<Vec<_>>()
            };
            assert_eq!(rows(&text), rows(&plain));
        }
    }

    /// The issue's robot name: a spreadsheet splits the comment line at its
    /// comma (or `;`, or a tab, by locale); no cell of any line is then a
    /// formula, and every data cell is a number or a name.
    #[test]
    fn a_formula_in_a_name_is_no_live_cell_of_any_line() {
        let cm = CompensatedModel::from_nominal(preset("ur5").unwrap());
        let src = ExportSource {
            robot: "cell,=cmd|' /C calc'!A0",
            method: "km",
        };
        for f in [ExportFormat::DhCsv, ExportFormat::MdhCsv] {
            let text = export(&cm, &src, f).unwrap();
            let first = text.lines().next().unwrap();
            assert_eq!(
                first,
                "# robocal export: km model of cell,'=cmd|' /C calc'!A0, standard DH; mm and degrees"
                    .replace(
                        "standard DH",
                        if f == ExportFormat::DhCsv {
                            "standard DH"
                        } else {
                            "modified DH (Craig) with Hayati beta"
                        }
                    )
            );
            for line in text.lines() {
                for sep in [',', ';', '\t'] {
                    for cell in line.split(sep) {
                        let c = cell.trim_start_matches([' ', '"']);
                        let formula = c.starts_with(['=', '+', '@'])
                            || (c.starts_with('-') && c.parse::<f64>().is_err());
                        assert!(!formula, "{f:?}: `{cell}` in {line}");
                    }
                }
            }
            for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
                for cell in line.split(',').skip(1).filter(|c| !c.is_empty()) {
                    assert!(cell.parse::<f64>().is_ok(), "{cell} in {line}");
                }
            }
        }
    }
}
