//! The roles swapped, for every language that has them: a stationary tool
//! and a work piece the robot carries past it, against the flange-payload
//! truth.

use super::*;

/// The roles swapped: a fixed tool (its tip 300 mm from its mount, tilted
/// 35°, measured in the tracker frame) and a work piece the robot carries
/// (gripper frame 200 mm out on the flange, tilted 30°). Joints: 40 around a
/// middle configuration, away from flag boundaries and singular branches.
pub struct Swapped {
    /// Flange → work object (the wobjdata's uframe, robhold TRUE).
    pub held: Pose,
    /// The fixed tool's TCP in the tracker frame (truth) and in the
    /// controller's base frame (the tooldata's tframe, robhold FALSE).
    pub fixed_cell: Pose,
    pub fixed_base: Pose,
    pub joints: Vec<Vec<f64>>,
    /// The nominal controller without a tool.
    pub bare: RobotModel,
}

pub fn swapped(f: &Fixture) -> Swapped {
    let mut bare = f.controller.clone();
    bare.tool = Default::default();
    let ik = AnalyticIk::new(&bare).unwrap();
    let r = rpy_matrix(0.0, 30f64.to_radians(), 0.0);
    let held = Pose::new(r, r * Vector3::new(0.0, 0.05, 0.2));
    let q0 = f.joints[0].clone();
    let deg = |q: &[f64]| -> Vec<f64> {
        bare.joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect()
    };
    // The work piece meets the tool tip 80 mm from its origin at q0.
    let mut t0 = Pose::from_translation(Vector3::new(0.08, -0.03, 0.0));
    t0.rot_x(std::f64::consts::PI);
    let flange = |q: &[f64]| f.true_tcp(q).compose(&f.truth.tool.inverse());
    let fixed_cell = flange(&q0).compose(&held).compose(&t0);
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut joints = Vec::new();
    while joints.len() < 40 {
        let q: Vec<f64> = q0
            .iter()
            .map(|v| v + rng.gen_range(-15f64..15.0).to_radians())
            .collect();
        let d = deg(&q);
        let off_quadrant = |a: f64| (a / 90.0 - (a / 90.0).round()).abs() * 90.0 > 5.0;
        let flags_clear = [0, 3, 5].iter().all(|&k| off_quadrant(d[k])) && d[4].abs() > 10.0;
        let branch = (0..13).all(|k| {
            let mut p = q.clone();
            if k > 0 {
                p[(k - 1) / 2] += if k % 2 == 0 { 0.087 } else { -0.087 };
            }
            ik.configuration(&p) == ik.configuration(&q)
        });
        if flags_clear && branch && bare.within_limits(&q, 0.087) {
            joints.push(q);
        }
    }
    // The mount 300 mm behind the tip along the tool's axis, tilted 35°.
    let tilt = rpy_matrix(35f64.to_radians(), 0.0, 0.0);
    let tool_on_mount = Pose::new(tilt, tilt * Vector3::new(0.0, 0.0, 0.3));
    let mount = fixed_cell.compose(&tool_on_mount.inverse());
    assert!((mount.p - fixed_cell.p).norm() >= 0.25);
    Swapped {
        held,
        fixed_base: f.model.cell_to_base(&fixed_cell),
        fixed_cell,
        joints,
        bare,
    }
}

impl Swapped {
    /// The true flange at commanded `q` (tracker frame).
    pub fn flange(&self, f: &Fixture, q: &[f64]) -> Pose {
        f.true_tcp(q).compose(&f.truth.tool.inverse())
    }

    /// Target `i`: the fixed tool's tip in the truly carried work object at `joints[i]`.
    pub fn target(&self, f: &Fixture, i: usize) -> Pose {
        self.flange(f, &self.joints[i])
            .compose(&self.held)
            .inverse()
            .compose(&self.fixed_cell)
    }

    /// Runs the module through the nominal controller (flange goal
    /// `S·(W_f·T)⁻¹` on the target's flags, nearest the previous joints) and
    /// returns the distance [mm] of the true tool tip in the truly carried
    /// work object from each target (`None`: no solution on the flags).
    pub fn run(&self, f: &Fixture, language: Language, files: &[ProgramFile]) -> Vec<Option<f64>> {
        let ik = AnalyticIk::new(&self.bare).unwrap();
        let program = parse(language, files).unwrap();
        assert_eq!(program.sites.len(), self.joints.len());
        let mut previous: Option<Vec<f64>> = None;
        let mut errors = Vec::new();
        for (i, site) in program.sites.iter().enumerate() {
            let goal = self
                .fixed_base
                .compose(&self.held.compose(&site.pose.unwrap()).inverse());
            let q = ik
                .solve(&goal, previous.as_deref())
                .into_iter()
                .filter(|s| s.within_limits)
                .map(|s| s.q.to_vec())
                .filter(|q| {
                    let deg: Vec<f64> = self
                        .bare
                        .joints_to_controller(q)
                        .iter()
                        .map(|v| v.to_degrees())
                        .collect();
                    site.flags.admits(&deg, ik.configuration(q))
                })
                .min_by(|a, b| {
                    let d = |x: &[f64]| match &previous {
                        Some(p) => x.iter().zip(p).map(|(u, v)| (u - v).abs()).sum::<f64>(),
                        None => 0.0,
                    };
                    d(a).total_cmp(&d(b))
                });
            let Some(q) = q else {
                errors.push(None);
                continue;
            };
            let tip = self
                .flange(f, &q)
                .compose(&self.held)
                .inverse()
                .compose(&self.fixed_cell);
            errors.push(Some((tip.p - self.target(f, i).p).norm() * 1e3));
            previous = Some(q);
        }
        errors
    }
}
