//! The ISO 9283 test cube (corners and poses in the module header,
//! [`super`]) and its poses solved to joint commands on a model.
//!
//! Frames and units: the box, the cube and the tool orientation are given in
//! the robot's (registered) base frame, mm; the commanded poses of the plan
//! are expressed in the model's measurement (cell) frame, where the tracker
//! measures the attained ones (the base frame for an unregistered model).
//! Joint commands: model convention [rad] in `q`, controller convention
//! [deg] in `joints_deg`.

use super::Iso9283Error;
use crate::model::calibrated::CompensatedModel;
use crate::model::orientation::fixed_xyz_angles;
use crate::model::Pose;
use crate::plan::WorkspaceBox;
use crate::solve::ik::{IkSettings, IkSolver, SolveOptions, TargetFrame};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// An axis-aligned cube, base frame [mm].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TestCube {
    /// Centre of the cube, base frame [mm].
    pub centre_mm: [f64; 3],
    /// Length of an edge [mm].
    pub edge_mm: f64,
}

/// Corner signs of C1 … C8.
const CORNERS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Distance of P2 … P5 from their corners, as a fraction of the diagonal.
pub const CORNER_FRACTION: f64 = 0.1;

impl TestCube {
    /// The largest cube in `b`: edge the box's smallest extent, centred in it.
    pub fn largest_in(b: &WorkspaceBox) -> Result<TestCube, Iso9283Error> {
        let ext: Vec<f64> = (0..3).map(|k| b.max_mm[k] - b.min_mm[k]).collect();
        if b.min_mm.iter().chain(&b.max_mm).any(|v| !v.is_finite()) || ext.iter().any(|e| *e <= 0.0)
        {
            return Err(Iso9283Error::InvalidInput(format!(
                "the box needs min < max on every axis, got min {:?} max {:?} mm",
                b.min_mm, b.max_mm
            )));
        }
        Ok(TestCube {
            centre_mm: [0, 1, 2].map(|k| 0.5 * (b.min_mm[k] + b.max_mm[k])),
            edge_mm: ext.iter().cloned().fold(f64::INFINITY, f64::min),
        })
    }

    /// Corner `C{i}`, `i` in 1..=8.
    pub fn corner(&self, i: usize) -> [f64; 3] {
        let s = CORNERS[i - 1];
        [0, 1, 2].map(|k| self.centre_mm[k] + 0.5 * self.edge_mm * s[k])
    }

    /// P1 … P5: the centre, then 10 % of the diagonal from C1, C2, C7, C8
    /// along the diagonals C1–C7 and C2–C8 of the plane C1–C2–C7–C8.
    pub fn poses(&self) -> [[f64; 3]; 5] {
        let toward = |from: usize, to: usize| {
            let (a, b) = (self.corner(from), self.corner(to));
            [0, 1, 2].map(|k| a[k] + CORNER_FRACTION * (b[k] - a[k]))
        };
        [
            self.centre_mm,
            toward(1, 7),
            toward(2, 8),
            toward(7, 1),
            toward(8, 2),
        ]
    }

    fn scaled(&self, f: f64) -> TestCube {
        TestCube {
            centre_mm: self.centre_mm,
            edge_mm: self.edge_mm * f,
        }
    }
}

/// Which joint commands drive the robot to the cube's poses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Commands {
    /// Solved on the controller's nominal model (with the same registration):
    /// what the robot does without calibration.
    Nominal,
    /// Solved on the calibrated, compensated model (the false targets'
    /// joints): what a filtered program does.
    Filtered,
}

impl Commands {
    /// Both kinds of commands, in declaration order.
    pub const ALL: [Commands; 2] = [Commands::Nominal, Commands::Filtered];

    /// The name on the command line and in the API (`nominal`, `filtered`).
    pub fn name(self) -> &'static str {
        match self {
            Commands::Nominal => "nominal",
            Commands::Filtered => "filtered",
        }
    }
}

impl std::str::FromStr for Commands {
    type Err = Iso9283Error;
    fn from_str(s: &str) -> Result<Self, Iso9283Error> {
        Commands::ALL
            .into_iter()
            .find(|c| c.name() == s.trim().to_ascii_lowercase())
            .ok_or_else(|| {
                Iso9283Error::InvalidInput(format!("commands `{s}`: use nominal or filtered"))
            })
    }
}

/// How to lay out and solve the cube.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeSettings {
    /// The box the cube must fit in, base frame [mm].
    pub workspace: WorkspaceBox,
    /// The tool orientation at every pose, base frame (maps tool vectors).
    pub orientation: Matrix3<f64>,
    /// Which model the poses are solved on.
    pub commands: Commands,
    /// When a pose cannot be solved the edge shrinks by this factor …
    pub shrink: f64,
    /// … down to this fraction of the largest cube's edge.
    pub min_edge_fraction: f64,
}

impl CubeSettings {
    /// Defaults: shrink by 10 % at a time, down to half the largest edge.
    pub fn new(workspace: WorkspaceBox, orientation: Matrix3<f64>, commands: Commands) -> Self {
        CubeSettings {
            workspace,
            orientation,
            commands,
            shrink: 0.9,
            min_edge_fraction: 0.5,
        }
    }
}

/// One pose of the plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CubePose {
    /// `P1` … `P5`.
    pub name: String,
    /// Commanded position, measurement (cell) frame [mm].
    pub commanded_mm: [f64; 3],
    /// Commanded `a, b, c` (`R = Rz(c)·Ry(b)·Rx(a)`), cell frame [deg].
    pub commanded_abc_deg: [f64; 3],
    /// Joint command, model convention [rad].
    pub q: Vec<f64>,
    /// Joint command, controller convention [deg].
    pub joints_deg: Vec<f64>,
}

/// The cube actually used and its five poses solved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CubePlan {
    /// The cube (base frame); smaller than the box's largest when a pose of
    /// the larger one could not be solved.
    pub cube: TestCube,
    /// Edge of the largest cube in the box [mm].
    pub largest_edge_mm: f64,
    /// Which model the poses were solved on.
    pub commands: Commands,
    /// The five poses P1 … P5, in order.
    pub poses: Vec<CubePose>,
}

/// The solver of `commands` on `model`.
fn solver(model: &CompensatedModel, commands: Commands) -> IkSolver {
    let m = match commands {
        Commands::Filtered => model.clone(),
        Commands::Nominal => CompensatedModel {
            calibrated: model.nominal.clone(),
            compensator: None,
            ..model.clone()
        },
    };
    IkSolver::new(m, IkSettings::default())
}

/// Lays out the largest cube in the box whose five poses the model reaches
/// (shrinking it about its centre otherwise) and solves them for `commands`.
/// P2 … P5 are seeded from P1's joints, so all five share its branch when
/// they can.
pub fn plan_cube(model: &CompensatedModel, s: &CubeSettings) -> Result<CubePlan, Iso9283Error> {
    if !(s.shrink > 0.0
        && s.shrink < 1.0
        && s.min_edge_fraction > 0.0
        && s.min_edge_fraction <= 1.0)
    {
        return Err(Iso9283Error::InvalidInput(
            "shrink must be in (0, 1) and the smallest edge fraction in (0, 1]".into(),
        ));
    }
    let largest = TestCube::largest_in(&s.workspace)?;
    let ik = solver(model, s.commands);
    let mut f = 1.0;
    let mut last_failure = String::new();
    while f >= s.min_edge_fraction - 1e-12 {
        let cube = largest.scaled(f);
        match solve_poses(model, &ik, &cube, &s.orientation) {
            Ok(poses) => {
                return Ok(CubePlan {
                    cube,
                    largest_edge_mm: largest.edge_mm,
                    commands: s.commands,
                    poses,
                })
            }
            Err(e) => last_failure = e,
        }
        f *= s.shrink;
    }
    Err(Iso9283Error::Unreachable {
        min_edge_mm: largest.edge_mm * s.min_edge_fraction,
        detail: last_failure,
    })
}

fn solve_poses(
    model: &CompensatedModel,
    ik: &IkSolver,
    cube: &TestCube,
    r: &Matrix3<f64>,
) -> Result<Vec<CubePose>, String> {
    let mut seed: Option<Vec<f64>> = None;
    let mut out = Vec::with_capacity(5);
    for (i, p) in cube.poses().iter().enumerate() {
        let name = format!("P{}", i + 1);
        let target = Pose::new(*r, Vector3::from(*p) * 1e-3);
        let options = SolveOptions {
            frame: TargetFrame::Base,
            seed: seed.clone(),
            ..Default::default()
        };
        let sol = ik.solve(&target, &options);
        if !sol.converged {
            let why = sol
                .reason
                .map_or("did not converge".into(), |r| r.to_string());
            return Err(format!("{name} at {p:.1?} mm (base frame): {why}"));
        }
        let cell = model.cell_from_base.compose(&target);
        if seed.is_none() {
            seed = Some(sol.q.clone());
        }
        out.push(CubePose {
            name,
            commanded_mm: [0, 1, 2].map(|k| cell.p[k] * 1e3),
            commanded_abc_deg: fixed_xyz_angles(&cell.r).map(f64::to_degrees),
            joints_deg: ik.controller_degrees(&sol.q),
            q: sol.q,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::preset;

    /// Hand-computed: a 1000 mm cube about the origin has P2 at (−400, −400,
    /// −400) (10 % of the way from C1 (−500, −500, −500) to C7), P3 at (400,
    /// −400, −400), P4 at (400, 400, 400), P5 at (−400, 400, 400).
    #[test]
    fn the_cube_poses_match_a_hand_computation() {
        let b = WorkspaceBox {
            min_mm: [-500.0, -700.0, -500.0],
            max_mm: [500.0, 700.0, 600.0],
        };
        let c = TestCube::largest_in(&b).unwrap();
        assert_eq!(c.edge_mm, 1000.0);
        assert_eq!(c.centre_mm, [0.0, 0.0, 50.0]);
        let p = c.poses();
        let want = [
            [0.0, 0.0, 50.0],
            [-400.0, -400.0, -350.0],
            [400.0, -400.0, -350.0],
            [400.0, 400.0, 450.0],
            [-400.0, 400.0, 450.0],
        ];
        for (a, b) in p.iter().zip(&want) {
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() < 1e-9, "{a:?} vs {b:?}");
            }
        }
        // 10 % of the diagonal √3·1000 from the corner.
        let c1 = c.corner(1);
        let d = ((p[1][0] - c1[0]).powi(2) + (p[1][1] - c1[1]).powi(2) + (p[1][2] - c1[2]).powi(2))
            .sqrt();
        assert!((d - 0.1 * 3f64.sqrt() * 1000.0).abs() < 1e-9);
    }

    #[test]
    fn an_empty_box_is_refused() {
        let b = WorkspaceBox {
            min_mm: [0.0, 0.0, 0.0],
            max_mm: [100.0, 0.0, 100.0],
        };
        assert!(TestCube::largest_in(&b).is_err());
    }

    /// The nominal commands on the nominal model reach the commanded poses
    /// exactly (forward kinematics of the solved joints).
    #[test]
    fn solved_poses_reach_their_commands_on_the_model() {
        let m = CompensatedModel::from_nominal(preset("ur10").unwrap());
        let b = WorkspaceBox {
            min_mm: [300.0, -400.0, 100.0],
            max_mm: [900.0, 400.0, 700.0],
        };
        let down = crate::model::orientation::fixed_xyz_matrix(std::f64::consts::PI, 0.0, 0.0);
        let plan = plan_cube(&m, &CubeSettings::new(b, down, Commands::Nominal)).unwrap();
        assert_eq!(plan.poses.len(), 5);
        for p in &plan.poses {
            let x = m.predict(&p.q).unwrap();
            let want = Vector3::from(p.commanded_mm) * 1e-3;
            assert!((x.p - want).norm() < 1e-6, "{}: {:?}", p.name, x.p);
            assert!((x.r - down).amax() < 1e-6);
        }
        assert!(plan.cube.edge_mm <= 600.0 + 1e-9);
    }
}
