//! ISO 9283 pose accuracy (AP, APa/b/c), pose repeatability (RP, RPa/b/c) and
//! distance accuracy and repeatability (AD, RD) from measured cycles; the
//! formulas are in the module header ([`super`]).

use super::Iso9283Error;
use serde::{Deserialize, Serialize};

/// One pose: its command and the positions (and orientations) attained in
/// each cycle [mm, deg].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseCycles {
    /// The pose's name (`P1` … `P5`).
    pub name: String,
    /// Commanded position [mm].
    pub commanded_mm: [f64; 3],
    /// Commanded `a, b, c` [deg], when known.
    pub commanded_abc_deg: Option<[f64; 3]>,
    /// Cycle numbers, one per attained position (distances pair equal cycles).
    pub cycles: Vec<u32>,
    /// Attained positions, one per cycle, in the order of `cycles` [mm].
    pub attained_mm: Vec<[f64; 3]>,
    /// Attained `a, b, c` [deg], one per cycle, when measured.
    pub attained_abc_deg: Option<Vec<[f64; 3]>>,
}

/// The standard's figures for one pose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseFigures {
    /// The pose's name.
    pub pose: String,
    /// Number of cycles `n`.
    pub cycles: usize,
    /// Barycentre of the attained positions (x̄, ȳ, z̄) [mm].
    pub barycentre_mm: [f64; 3],
    /// AP [mm].
    pub ap_mm: f64,
    /// APx, APy, APz [mm].
    pub ap_xyz_mm: [f64; 3],
    /// APa, APb, APc [deg] (commanded and attained orientations known).
    pub ap_abc_deg: Option<[f64; 3]>,
    /// l̄ [mm].
    pub l_mean_mm: f64,
    /// S_l [mm] (n − 1).
    pub s_l_mm: f64,
    /// RP = l̄ + 3·S_l [mm].
    pub rp_mm: f64,
    /// RPa, RPb, RPc = ±3·S [deg] (attained orientations measured).
    pub rp_abc_deg: Option<[f64; 3]>,
}

/// Distance accuracy and repeatability between two poses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DistanceFigures {
    /// Name of the distance's first pose.
    pub from: String,
    /// Name of the distance's second pose.
    pub to: String,
    /// Cycles measured at both poses.
    pub cycles: usize,
    /// D_c [mm].
    pub commanded_mm: f64,
    /// D̄ [mm].
    pub mean_mm: f64,
    /// AD = D̄ − D_c [mm].
    pub ad_mm: f64,
    /// S_D [mm] (n − 1).
    pub s_d_mm: f64,
    /// RD = ±3·S_D [mm].
    pub rd_mm: f64,
}

/// Every pose's figures and the distances between every pair of poses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Iso9283Figures {
    /// The figures of each pose, in the order given.
    pub poses: Vec<PoseFigures>,
    /// The figures of each pair of poses.
    pub distances: Vec<DistanceFigures>,
}

/// The figures of `poses` (each with at least 2 cycles); distances for every
/// pair, over the cycles both poses have.
pub fn evaluate(poses: &[PoseCycles]) -> Result<Iso9283Figures, Iso9283Error> {
    let figures = poses
        .iter()
        .map(pose_figures)
        .collect::<Result<Vec<_>, _>>()?;
    let mut distances = Vec::new();
    for (i, p) in poses.iter().enumerate() {
        for q in &poses[i + 1..] {
            if let Some(d) = distance_figures(p, q) {
                distances.push(d);
            }
        }
    }
    Ok(Iso9283Figures {
        poses: figures,
        distances,
    })
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Sample standard deviation (n − 1).
fn sample_std(v: &[f64], m: f64) -> f64 {
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() as f64 - 1.0)).sqrt()
}

/// An angle difference wrapped to (−180°, 180°].
fn wrap_deg(d: f64) -> f64 {
    let w = d.rem_euclid(360.0);
    if w > 180.0 {
        w - 360.0
    } else {
        w
    }
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn check(p: &PoseCycles) -> Result<(), Iso9283Error> {
    let n = p.attained_mm.len();
    if n < 2 {
        return Err(Iso9283Error::TooFewCycles {
            pose: p.name.clone(),
            cycles: n,
        });
    }
    if p.cycles.len() != n || p.attained_abc_deg.as_ref().is_some_and(|a| a.len() != n) {
        return Err(Iso9283Error::InvalidInput(format!(
            "pose {}: cycle numbers, positions and orientations differ in count",
            p.name
        )));
    }
    let finite = p.commanded_mm.iter().all(|v| v.is_finite())
        && p.attained_mm.iter().flatten().all(|v| v.is_finite())
        && p.commanded_abc_deg.iter().flatten().all(|v| v.is_finite())
        && p.attained_abc_deg
            .iter()
            .flatten()
            .flatten()
            .all(|v| v.is_finite());
    if !finite {
        return Err(Iso9283Error::InvalidInput(format!(
            "pose {}: a value is not a finite number",
            p.name
        )));
    }
    Ok(())
}

/// AP, APa/b/c, RP and RPa/b/c of one pose.
pub fn pose_figures(p: &PoseCycles) -> Result<PoseFigures, Iso9283Error> {
    check(p)?;
    let n = p.attained_mm.len();
    let axis = |k: usize| -> Vec<f64> { p.attained_mm.iter().map(|x| x[k]).collect() };
    let bary = [mean(&axis(0)), mean(&axis(1)), mean(&axis(2))];
    let ap_xyz = [
        bary[0] - p.commanded_mm[0],
        bary[1] - p.commanded_mm[1],
        bary[2] - p.commanded_mm[2],
    ];
    let l: Vec<f64> = p.attained_mm.iter().map(|x| dist(x, &bary)).collect();
    let l_mean = mean(&l);
    let s_l = sample_std(&l, l_mean);
    let (ap_abc, rp_abc) = match &p.attained_abc_deg {
        None => (None, None),
        Some(abc) => {
            let reference = p.commanded_abc_deg.unwrap_or(abc[0]);
            let mut ap = [0.0; 3];
            let mut rp = [0.0; 3];
            for k in 0..3 {
                let dev: Vec<f64> = abc.iter().map(|a| wrap_deg(a[k] - reference[k])).collect();
                let m = mean(&dev);
                ap[k] = m;
                rp[k] = 3.0 * sample_std(&dev, m);
            }
            (p.commanded_abc_deg.map(|_| ap), Some(rp))
        }
    };
    Ok(PoseFigures {
        pose: p.name.clone(),
        cycles: n,
        barycentre_mm: bary,
        ap_mm: (ap_xyz[0].powi(2) + ap_xyz[1].powi(2) + ap_xyz[2].powi(2)).sqrt(),
        ap_xyz_mm: ap_xyz,
        ap_abc_deg: ap_abc,
        l_mean_mm: l_mean,
        s_l_mm: s_l,
        rp_mm: l_mean + 3.0 * s_l,
        rp_abc_deg: rp_abc,
    })
}

/// AD and RD between `p` and `q` over the cycles both have (`None` when
/// fewer than 2 are shared).
pub fn distance_figures(p: &PoseCycles, q: &PoseCycles) -> Option<DistanceFigures> {
    let d: Vec<f64> = p
        .cycles
        .iter()
        .zip(&p.attained_mm)
        .filter_map(|(c, x)| {
            let k = q.cycles.iter().position(|c2| c2 == c)?;
            Some(dist(x, &q.attained_mm[k]))
        })
        .collect();
    if d.len() < 2 {
        return None;
    }
    let commanded = dist(&p.commanded_mm, &q.commanded_mm);
    let m = mean(&d);
    let s = sample_std(&d, m);
    Some(DistanceFigures {
        from: p.name.clone(),
        to: q.name.clone(),
        cycles: d.len(),
        commanded_mm: commanded,
        mean_mm: m,
        ad_mm: m - commanded,
        s_d_mm: s,
        rd_mm: 3.0 * s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(name: &str, c: [f64; 3], x: Vec<[f64; 3]>) -> PoseCycles {
        PoseCycles {
            name: name.into(),
            commanded_mm: c,
            commanded_abc_deg: None,
            cycles: (1..=x.len() as u32).collect(),
            attained_mm: x,
            attained_abc_deg: None,
        }
    }

    /// Hand-computed: attained (0,0,0), (2,0,0), (4,0,0), commanded (1,1,0):
    /// barycentre (2,0,0), AP = √2; l = 2, 0, 2, l̄ = 4/3,
    /// S_l = √(((2/3)² + (4/3)² + (2/3)²)/2) = √(4/3), RP = 4/3 + 3·√(4/3).
    #[test]
    fn ap_and_rp_match_a_hand_computation() {
        let mut p = pose(
            "P1",
            [1.0, 1.0, 0.0],
            vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [4.0, 0.0, 0.0]],
        );
        // a: 10, 12, 14 commanded 11 → APa 1, S_a 2, RPa 6; b constant;
        // c: 179, −179, 180 commanded 180 → deviations −1, 1, 0 → APc 0, RPc 3.
        p.commanded_abc_deg = Some([11.0, 5.0, 180.0]);
        p.attained_abc_deg = Some(vec![
            [10.0, 5.0, 179.0],
            [12.0, 5.0, -179.0],
            [14.0, 5.0, 180.0],
        ]);
        let f = pose_figures(&p).unwrap();
        let close = |a: f64, b: f64| assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        assert_eq!(f.barycentre_mm, [2.0, 0.0, 0.0]);
        close(f.ap_mm, 2f64.sqrt());
        assert_eq!(f.ap_xyz_mm, [1.0, -1.0, 0.0]);
        close(f.l_mean_mm, 4.0 / 3.0);
        close(f.s_l_mm, (4.0f64 / 3.0).sqrt());
        close(f.rp_mm, 4.0 / 3.0 + 3.0 * (4.0f64 / 3.0).sqrt());
        let ap = f.ap_abc_deg.unwrap();
        let rp = f.rp_abc_deg.unwrap();
        close(ap[0], 1.0);
        close(ap[1], 0.0);
        close(ap[2], 0.0);
        close(rp[0], 6.0);
        close(rp[1], 0.0);
        close(rp[2], 3.0);
    }

    /// Commanded distance 5 (3-4-5); attained distances 5, 6, 7 → AD 1, S_D 1, RD 3.
    #[test]
    fn ad_and_rd_match_a_hand_computation() {
        let p = pose("P2", [0.0; 3], vec![[0.0; 3]; 3]);
        let q = pose(
            "P4",
            [3.0, 4.0, 0.0],
            vec![[3.0, 4.0, 0.0], [3.6, 4.8, 0.0], [4.2, 5.6, 0.0]],
        );
        let d = distance_figures(&p, &q).unwrap();
        assert_eq!(d.cycles, 3);
        assert!((d.commanded_mm - 5.0).abs() < 1e-12);
        assert!((d.ad_mm - 1.0).abs() < 1e-12);
        assert!((d.s_d_mm - 1.0).abs() < 1e-12);
        assert!((d.rd_mm - 3.0).abs() < 1e-12);
    }

    #[test]
    fn one_cycle_and_non_finite_values_are_refused() {
        let p = pose("P1", [0.0; 3], vec![[0.0; 3]]);
        assert!(matches!(
            pose_figures(&p),
            Err(Iso9283Error::TooFewCycles { cycles: 1, .. })
        ));
        let p = pose("P1", [0.0; 3], vec![[0.0; 3], [f64::NAN, 0.0, 0.0]]);
        assert!(matches!(
            pose_figures(&p),
            Err(Iso9283Error::InvalidInput(_))
        ));
    }

    #[test]
    fn distances_pair_equal_cycles_only() {
        let p = pose("P1", [0.0; 3], vec![[0.0; 3], [0.0; 3], [0.0; 3]]);
        let mut q = pose(
            "P2",
            [1.0, 0.0, 0.0],
            vec![[1.0, 0.0, 0.0], [9.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        );
        q.cycles = vec![1, 7, 3];
        let d = distance_figures(&p, &q).unwrap();
        assert_eq!(d.cycles, 2);
        assert!((d.mean_mm - 1.5).abs() < 1e-12);
    }
}
