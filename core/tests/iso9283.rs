//! ISO 9283 pose characteristics (issue "Is it still accurate?", acceptance):
//! the figures against an independent, straightforward computation of the
//! standard's formulas; known repeatability noise and bias recovered from
//! simulated cycles; and the filtered cube program's AP against the nominal
//! one's on a simulated, calibrated robot.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::check::iso9283::{evaluate, plan_cube, Commands, CubeSettings, PoseCycles};
use robocal_core::measure;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::orientation::fixed_xyz_matrix;
use robocal_core::model::preset;
use robocal_core::plan::pose_selection::choose_d_optimal;
use robocal_core::plan::WorkspaceBox;
use robocal_core::sim::{random_configurations, tracker_frame, ys100_table_7_1, TrueRobot};

/// Cycles of `poses` commanded positions with a per-pose bias and isotropic
/// Gaussian noise σ per axis [mm]; angles near ±180° for the wrap.
fn simulated_cycles(
    commanded: &[[f64; 3]],
    bias: [f64; 3],
    sigma: f64,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<PoseCycles> {
    let noise = Normal::new(0.0, sigma).unwrap();
    commanded
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let attained: Vec<[f64; 3]> = (0..n)
                .map(|_| [0, 1, 2].map(|k| c[k] + bias[k] + noise.sample(rng)))
                .collect();
            let abc: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let c = 179.99 + 0.02 * rng.gen::<f64>();
                    let c = if c > 180.0 { c - 360.0 } else { c };
                    [0.5 + noise.sample(rng), -0.2 + noise.sample(rng), c]
                })
                .collect();
            PoseCycles {
                name: format!("P{}", i + 1),
                commanded_mm: *c,
                commanded_abc_deg: Some([0.5, 0.0, 180.0]),
                cycles: (1..=n as u32).collect(),
                attained_mm: attained,
                attained_abc_deg: Some(abc),
            }
        })
        .collect()
}

/// The standard's formulas written out plainly, loop by loop.
mod plain {
    pub fn ap_rp(c: &[f64; 3], x: &[[f64; 3]]) -> (f64, f64) {
        let n = x.len() as f64;
        let (mut sx, mut sy, mut sz) = (0.0, 0.0, 0.0);
        for p in x {
            sx += p[0];
            sy += p[1];
            sz += p[2];
        }
        let (xb, yb, zb) = (sx / n, sy / n, sz / n);
        let ap =
            ((xb - c[0]) * (xb - c[0]) + (yb - c[1]) * (yb - c[1]) + (zb - c[2]) * (zb - c[2]))
                .sqrt();
        let mut l = Vec::new();
        for p in x {
            l.push(((p[0] - xb).powi(2) + (p[1] - yb).powi(2) + (p[2] - zb).powi(2)).sqrt());
        }
        let lb = l.iter().sum::<f64>() / n;
        let mut ss = 0.0;
        for v in &l {
            ss += (v - lb) * (v - lb);
        }
        (ap, lb + 3.0 * (ss / (n - 1.0)).sqrt())
    }

    /// APa and RPa of angles (deg) near one commanded value, unwrapped by hand.
    pub fn angle(c: f64, a: &[f64]) -> (f64, f64) {
        let n = a.len() as f64;
        let d: Vec<f64> = a
            .iter()
            .map(|v| {
                let mut d = v - c;
                while d > 180.0 {
                    d -= 360.0;
                }
                while d <= -180.0 {
                    d += 360.0;
                }
                d
            })
            .collect();
        let m = d.iter().sum::<f64>() / n;
        let s = (d.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0)).sqrt();
        (m, 3.0 * s)
    }

    pub fn ad_rd(c1: &[f64; 3], c2: &[f64; 3], x1: &[[f64; 3]], x2: &[[f64; 3]]) -> (f64, f64) {
        let norm = |a: &[f64; 3], b: &[f64; 3]| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        let dc = norm(c1, c2);
        let d: Vec<f64> = x1.iter().zip(x2).map(|(a, b)| norm(a, b)).collect();
        let n = d.len() as f64;
        let m = d.iter().sum::<f64>() / n;
        let s = (d.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0)).sqrt();
        (m - dc, 3.0 * s)
    }
}

const CUBE: [[f64; 3]; 5] = [
    [1400.0, 0.0, 700.0],
    [1080.0, -320.0, 380.0],
    [1720.0, -320.0, 380.0],
    [1720.0, 320.0, 1020.0],
    [1080.0, 320.0, 1020.0],
];

#[test]
fn figures_equal_an_independent_computation() {
    let mut rng = ChaCha8Rng::seed_from_u64(9283);
    let poses = simulated_cycles(&CUBE, [0.3, -0.1, 0.25], 0.05, 30, &mut rng);
    let f = evaluate(&poses).unwrap();
    for (p, fig) in poses.iter().zip(&f.poses) {
        let (ap, rp) = plain::ap_rp(&p.commanded_mm, &p.attained_mm);
        assert!(
            (fig.ap_mm - ap).abs() < 1e-9,
            "{}: AP {} vs {ap}",
            p.name,
            fig.ap_mm
        );
        assert!(
            (fig.rp_mm - rp).abs() < 1e-9,
            "{}: RP {} vs {rp}",
            p.name,
            fig.rp_mm
        );
        let abc = p.attained_abc_deg.as_ref().unwrap();
        let c = p.commanded_abc_deg.unwrap();
        for k in 0..3 {
            let a: Vec<f64> = abc.iter().map(|v| v[k]).collect();
            let (apa, rpa) = plain::angle(c[k], &a);
            assert!((fig.ap_abc_deg.unwrap()[k] - apa).abs() < 1e-9);
            assert!((fig.rp_abc_deg.unwrap()[k] - rpa).abs() < 1e-9);
        }
    }
    assert_eq!(f.distances.len(), 10);
    for d in &f.distances {
        let i = poses.iter().position(|p| p.name == d.from).unwrap();
        let j = poses.iter().position(|p| p.name == d.to).unwrap();
        let (ad, rd) = plain::ad_rd(
            &poses[i].commanded_mm,
            &poses[j].commanded_mm,
            &poses[i].attained_mm,
            &poses[j].attained_mm,
        );
        assert!((d.ad_mm - ad).abs() < 1e-9 && (d.rd_mm - rd).abs() < 1e-9);
    }
}

/// With a bias b and isotropic noise σ per axis, the barycentre tends to
/// command + b (AP → |b|) and l to σ·χ₃, so l̄ → 2σ·√(2/π) and
/// S_l → σ·√(3 − 8/π): RP → σ·(2√(2/π) + 3·√(3 − 8/π)) ≈ 3.616·σ. A
/// distance between two poses with the same bias keeps D_c on average
/// (AD → 0) and varies with σ·√2 along the line (RD → 3·√2·σ).
#[test]
fn known_bias_and_repeatability_are_recovered() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let (bias, sigma, n) = ([0.3, -0.4, 0.0], 0.02, 20_000);
    let poses = simulated_cycles(&CUBE, bias, sigma, n, &mut rng);
    let f = evaluate(&poses).unwrap();
    let rp_expected = sigma
        * (2.0 * (2.0 / std::f64::consts::PI).sqrt()
            + 3.0 * (3.0 - 8.0 / std::f64::consts::PI).sqrt());
    for p in &f.poses {
        // Standard error of the barycentre: σ/√n ≈ 1.4e-4 mm per axis.
        assert!((p.ap_mm - 0.5).abs() < 1e-3, "{}: AP {}", p.pose, p.ap_mm);
        assert!((p.ap_xyz_mm[0] - 0.3).abs() < 1e-3);
        assert!(
            (p.rp_mm - rp_expected).abs() < 0.02 * rp_expected,
            "{}: RP {} vs {rp_expected}",
            p.pose,
            p.rp_mm
        );
        // a, b: σ noise → RPa ≈ 3σ; c uniform over 0.02° across ±180° → 3·0.02/√12.
        let rp = p.rp_abc_deg.unwrap();
        assert!((rp[0] - 3.0 * sigma).abs() < 0.03 * 3.0 * sigma, "{rp:?}");
        let rpc = 3.0 * 0.02 / 12f64.sqrt();
        assert!((rp[2] - rpc).abs() < 0.03 * rpc, "{rp:?}");
        let ap = p.ap_abc_deg.unwrap();
        assert!((ap[2] - 0.0).abs() < 1e-3, "APc {}", ap[2]);
    }
    for d in &f.distances {
        assert!(d.ad_mm.abs() < 2e-3, "{}-{}: AD {}", d.from, d.to, d.ad_mm);
        let rd = 3.0 * 2f64.sqrt() * sigma;
        assert!((d.rd_mm - rd).abs() < 0.03 * rd, "RD {} vs {rd}", d.rd_mm);
    }
}

/// Calibrate a simulated YS100 (SKCM, as in end_to_end.rs), lay out the cube,
/// run 30 cycles of the nominal and of the filtered commands on the true
/// robot (tracker noise as repeatability) and compare the AP.
#[test]
fn the_filtered_cube_program_is_at_least_ten_times_more_accurate() {
    let nominal = preset("ys100").unwrap();
    let payload = nominal.payload.mass;
    let mut truth = TrueRobot::new(ys100_table_7_1());
    truth.noise_mm = 0.01;
    truth.tracker_from_base = tracker_frame(2.0, -1.0, 95.0, [1200.0, -3240.0, 400.0]);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let candidates = random_configurations(&nominal, 500, &mut rng);
    let q_id = choose_d_optimal(&nominal, &candidates, 30, payload, true);
    let q_va = random_configurations(&nominal, 20, &mut rng);
    let rows = |q: &[Vec<f64>], rng: &mut ChaCha8Rng| {
        measure::to_measurements(
            &nominal,
            &truth.measure(q, Some(payload), None, rng).unwrap(),
            payload,
        )
    };
    let (id, va) = (rows(&q_id, &mut rng), rows(&q_va, &mut rng));
    let opts = CalibrationOptions {
        methods: vec![Method::Skcm],
        ..Default::default()
    };
    let report = calibrate(&nominal, &id, &va, &opts, &|_| true).unwrap();
    let model = CompensatedModel {
        calibrated: report.methods["skcm"].calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: report.tracker_to_base.inverse(),
        payload_kg: payload,
        compensator: None,
    };
    let workspace = WorkspaceBox {
        min_mm: [1000.0, -400.0, 300.0],
        max_mm: [1800.0, 400.0, 1100.0],
    };
    let down = fixed_xyz_matrix(std::f64::consts::PI, 0.0, 0.0);
    let mut ap = Vec::new();
    for commands in Commands::ALL {
        let plan = plan_cube(&model, &CubeSettings::new(workspace, down, commands)).unwrap();
        assert_eq!(
            plan.cube.edge_mm, 800.0,
            "the whole box's cube is reachable"
        );
        // 30 cycles P1 → P5, measured by the tracker.
        let mut poses: Vec<PoseCycles> = plan
            .poses
            .iter()
            .map(|p| PoseCycles {
                name: p.name.clone(),
                commanded_mm: p.commanded_mm,
                commanded_abc_deg: None,
                cycles: Vec::new(),
                attained_mm: Vec::new(),
                attained_abc_deg: None,
            })
            .collect();
        for cycle in 1..=30 {
            let qs: Vec<Vec<f64>> = plan.poses.iter().map(|p| p.q.clone()).collect();
            let m = truth.measure(&qs, Some(payload), None, &mut rng).unwrap();
            for (p, row) in poses.iter_mut().zip(&m) {
                p.cycles.push(cycle);
                p.attained_mm.push(row.xyz_mm);
            }
        }
        let f = evaluate(&poses).unwrap();
        let worst = f.poses.iter().map(|p| p.ap_mm).fold(0.0, f64::max);
        eprintln!(
            "{}: AP per pose {:?} mm, RP {:?} mm",
            commands.name(),
            f.poses
                .iter()
                .map(|p| (p.ap_mm * 1e4).round() / 1e4)
                .collect::<Vec<_>>(),
            f.poses
                .iter()
                .map(|p| (p.rp_mm * 1e4).round() / 1e4)
                .collect::<Vec<_>>()
        );
        ap.push(worst);
    }
    let (nominal_ap, filtered_ap) = (ap[0], ap[1]);
    assert!(
        nominal_ap >= 10.0 * filtered_ap,
        "worst AP: nominal {nominal_ap} mm, filtered {filtered_ap} mm"
    );
}
