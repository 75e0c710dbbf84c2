//! Bounds of a calibrated model file's learned compensator (`compensator`)
//! and of where it was trained (`compensator_support`): every stored number
//! finite and within the bound of its quantity ([`super`]), the sizes that
//! set the cost of one prediction capped. SI units, as the network computes
//! (inputs rad, kg, N·m; outputs m). The consistency of the sizes (weights
//! for the layers, one range per joint) is the compensator's own check
//! (`StoredCompensator::validate`, `Support::validate`).
//! The orientation part (`compensator_orientation`) is a network of the same
//! kinds whose outputs are a rotation vector [rad]: its output quantities
//! have bounds of their own (`outputs.rs`).

use super::outputs::{Outputs, ORIENTATION_OUTPUTS, POSITION_OUTPUTS};
use super::{
    check_above, check_all, check_count, Bound, ERROR_SCALE, INPUT_CENTRE, INPUT_SCALE,
    INVERSE_LENGTH_SCALE, JOINT_DISTANCE_RAD, JOINT_RAD, NETWORK_WEIGHT, RBF_NORMALISED,
};
use crate::model::calibrated::gp::Gp;
use crate::model::calibrated::mlp::{Mlp, Normalisation};
use crate::model::calibrated::orientation::StoredOrientation;
use crate::model::calibrated::rbf::Rbf;
use crate::model::calibrated::stored::StoredCompensator;
use crate::model::calibrated::support::{Support, MAX_POINTS};
use crate::model::error::ModelError;

/// Most hidden units of an MLP (the largest trained has 40).
pub const MAX_MLP_HIDDEN: usize = 1000;
/// Most units of an RBF network (training grows at most 40 by default).
pub const MAX_RBF_UNITS: usize = 10_000;
/// Most inducing configurations of a GP (300 by default; its variance
/// matrix holds the square of this).
pub const MAX_GP_UNITS: usize = 5000;

/// Checks every value of `c`, of `support` and of the orientation part
/// against its bound; the error names the field
/// (`compensator.weights[12]`, `compensator_orientation.network.alpha[3]`),
/// its value and the bound.
pub fn check_compensator(
    c: &StoredCompensator,
    support: Option<&Support>,
    orientation: Option<&StoredOrientation>,
) -> Result<(), ModelError> {
    check_network("compensator", c, &POSITION_OUTPUTS)?;
    if let Some(s) = support {
        check_support(s)?;
    }
    if let Some(o) = orientation {
        const O: &str = "compensator_orientation";
        check_all(&format!("{O}.point_m"), &o.point_m, &POINT_M)?;
        check_network(&format!("{O}.network"), &o.network, &ORIENTATION_OUTPUTS)?;
    }
    Ok(())
}

/// The measured point of the orientation part, flange frame [m]: the
/// model's tool points are bounded by [`super::POINT_MM`] (300 m).
const POINT_M: Bound = Bound {
    min: -300.0,
    max: 300.0,
    unit: "m",
};

/// The family's bounds ([`crate::model::calibrated::stored::StoredFamily::check_bounds`]).
fn check_network(f: &str, c: &StoredCompensator, out: &Outputs) -> Result<(), ModelError> {
    c.check_bounds(f, out)
}

fn check_norm(
    field: &str,
    n: &Normalisation,
    centre: &Bound,
    scale: &Bound,
    positive: bool,
) -> Result<(), ModelError> {
    check_all(&format!("{field}.centre"), &n.centre, centre)?;
    if positive {
        for (i, s) in n.scale.iter().enumerate() {
            check_above(&format!("{field}.scale[{i}]"), *s, scale)?;
        }
        Ok(())
    } else {
        check_all(&format!("{field}.scale"), &n.scale, scale)
    }
}

/// An MLP's bounds (its family's `check_bounds`).
pub(crate) fn check_mlp(f: &str, m: &Mlp, out: &Outputs) -> Result<(), ModelError> {
    check_count(
        &format!("{f}.hidden"),
        m.hidden,
        MAX_MLP_HIDDEN,
        "hidden units",
    )?;
    check_all(&format!("{f}.weights"), &m.weights, &NETWORK_WEIGHT)?;
    check_norm(
        &format!("{f}.input_norm"),
        &m.input_norm,
        &INPUT_CENTRE,
        &INPUT_SCALE,
        false,
    )?;
    check_norm(
        &format!("{f}.output_norm"),
        &m.output_norm,
        &out.residual,
        &out.output_scale,
        true,
    )
}

/// An RBF network's bounds (its family's `check_bounds`).
pub(crate) fn check_rbf(f: &str, r: &Rbf) -> Result<(), ModelError> {
    check_count(&format!("{f}.centres"), r.units(), MAX_RBF_UNITS, "units")?;
    check_above(&format!("{f}.spread"), r.spread, &positive(&RBF_NORMALISED))?;
    check_all(&format!("{f}.centres"), &r.centres, &RBF_NORMALISED)?;
    check_all(&format!("{f}.weights"), &r.weights, &NETWORK_WEIGHT)?;
    check_norm(
        &format!("{f}.input_norm"),
        &r.input_norm,
        &INPUT_CENTRE,
        &INPUT_SCALE,
        false,
    )
}

/// A Gaussian process's bounds (its family's `check_bounds`).
pub(crate) fn check_gp(f: &str, g: &Gp, out: &Outputs) -> Result<(), ModelError> {
    check_count(
        &format!("{f}.alpha"),
        g.units(),
        MAX_GP_UNITS,
        "inducing configurations",
    )?;
    check_all(
        &format!("{f}.inverse_length_scales"),
        &g.inverse_length_scales,
        &INVERSE_LENGTH_SCALE,
    )?;
    check_above(
        &format!("{f}.signal_variance"),
        g.signal_variance,
        &out.variance,
    )?;
    check_above(
        &format!("{f}.noise_variance"),
        g.noise_variance,
        &out.variance,
    )?;
    check_all(&format!("{f}.mean"), &g.mean, &out.residual)?;
    check_all(&format!("{f}.inducing"), &g.inducing, &JOINT_RAD)?;
    check_all(&format!("{f}.alpha"), &g.alpha, &out.coefficient)?;
    check_all(&format!("{f}.variance"), &g.variance, &out.coefficient)?;
    check_above(&format!("{f}.error_scale"), g.error_scale, &ERROR_SCALE)?;
    super::check(
        &format!("{f}.uncompensated_rms"),
        g.uncompensated_rms,
        &positive(&out.residual),
    )?;
    Ok(())
}

fn check_support(s: &Support) -> Result<(), ModelError> {
    const S: &str = "compensator_support";
    check_count(
        &format!("{S}.points_rad"),
        s.points_rad.len(),
        MAX_POINTS,
        "training configurations",
    )?;
    for (i, r) in s.ranges_rad.iter().enumerate() {
        check_all(&format!("{S}.ranges_rad[{i}]"), r, &JOINT_RAD)?;
    }
    for (i, p) in s.points_rad.iter().enumerate() {
        check_all(&format!("{S}.points_rad[{i}]"), p, &JOINT_RAD)?;
    }
    super::check(&format!("{S}.fade_rad"), s.fade_rad, &JOINT_DISTANCE_RAD)?;
    super::check(
        &format!("{S}.radius_rad"),
        s.radius_rad,
        &JOINT_DISTANCE_RAD,
    )?;
    Ok(())
}

/// `b` from 0 up (its non-negative half).
fn positive(b: &Bound) -> Bound {
    Bound { min: 0.0, ..*b }
}

#[cfg(test)]
mod tests {
    use crate::calibrate::compensate::{
        train, CompensatorSpec, GpSettings, LmTrainSettings, MlpSettings, MlpSpec, RbfSettings,
        Sample, Trainer,
    };
    use crate::model::calibrated::{
        parse_compensated, CalibratedModelFile, CompensatedModel, Support,
    };
    use crate::model::preset;
    use nalgebra::Vector3;
    use rand::SeedableRng;

    /// A calibrated-model file of ys100 whose compensator of `spec` was
    /// trained on 60 poses with a sub-millimetre residual of the kind a
    /// gear leaves (`A·sin q`), its support from the same poses.
    fn trained_file(spec: &CompensatorSpec) -> serde_json::Value {
        let nominal = preset("ys100").unwrap();
        let mut m = CompensatedModel::from_nominal(nominal.clone());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(35);
        let qs = crate::sim::random_configurations(&nominal, 60, &mut rng);
        let samples: Vec<Sample> = qs
            .iter()
            .map(|q| Sample {
                q: q.clone(),
                tau: m.torques(q).unwrap(),
                payload_kg: 110.0,
                residual: Vector3::new(2e-4 * q[1].sin(), 1e-4 * q[2].cos(), 5e-5 * q[0].sin()),
            })
            .collect();
        let (c, _) = train(spec, &samples, &mut rng, &mut |_, _| true).unwrap();
        let refs: Vec<&[f64]> = qs.iter().map(|q| q.as_slice()).collect();
        let support = Support::of(&refs, 0.087);
        m.compensator = Some(c.into_arc_oriented(None, Some(support)));
        let text = CalibratedModelFile::from_compensated(&m, "ys100", "skcm-x").to_json();
        serde_json::from_str(&text).unwrap()
    }

    fn specs() -> Vec<(&'static str, CompensatorSpec)> {
        vec![
            (
                "mlp",
                CompensatorSpec::Mlp(MlpSettings {
                    spec: MlpSpec::SKCM_NN,
                    trainer: Trainer::Lm(LmTrainSettings {
                        max_epochs: 20,
                        ..Default::default()
                    }),
                }),
            ),
            (
                "rbf",
                CompensatorSpec::Rbf(RbfSettings {
                    max_neurons: 15,
                    ..Default::default()
                }),
            ),
            (
                "gp",
                CompensatorSpec::Gp(GpSettings {
                    inducing: 25,
                    ..Default::default()
                }),
            ),
        ]
    }

    fn load(v: &serde_json::Value) -> Result<CompensatedModel, String> {
        parse_compensated(&v.to_string()).map_err(|e| e.to_string())
    }

    /// The error of `v` with `field` (a JSON pointer under the file) set to
    /// `value`.
    fn refused(v: &serde_json::Value, pointer: &str, value: serde_json::Value) -> String {
        let mut v = v.clone();
        *v.pointer_mut(pointer)
            .unwrap_or_else(|| panic!("{pointer}")) = value;
        load(&v).expect_err(pointer)
    }

    #[test]
    fn trained_compensators_of_every_kind_are_accepted() {
        for (kind, spec) in specs() {
            let v = trained_file(&spec);
            assert_eq!(v["compensator"]["kind"], kind);
            let m = load(&v).unwrap_or_else(|e| panic!("{kind}: {e}"));
            assert!(m.compensator.is_some(), "{kind}");
        }
    }

    /// The orientation part is checked as the position part is, under its
    /// own name and with its outputs in radians: a GP's mean of 50 rad is a
    /// turn no residual makes though 50 m would pass the position bound.
    #[test]
    fn the_orientation_part_is_checked_under_its_own_name() {
        let gp = trained_file(&specs()[2].1);
        let mut v = gp.clone();
        v["compensator_orientation"] = serde_json::json!({
            "point_m": [0.0, 0.0, 0.1],
            "network": gp["compensator"].clone(),
        });
        let m = load(&v).expect("a trained network as the orientation part");
        assert!(m.compensator.is_some());
        let e = refused(&v, "/compensator_orientation/network/mean/0", 50.0.into());
        assert!(
            e.contains("compensator_orientation.network.mean") && e.contains("rad"),
            "{e}"
        );
        assert!(load(&{
            let mut p = v.clone();
            p["compensator"]["mean"][0] = 50.0.into();
            p
        })
        .is_ok());
        let e = refused(&v, "/compensator_orientation/point_m/2", 1e6.into());
        assert!(e.contains("compensator_orientation.point_m"), "{e}");
        let e = refused(&v, "/compensator_orientation/network/alpha/0", 1e308.into());
        assert!(e.contains("compensator_orientation.network.alpha"), "{e}");
    }

    /// Each hostile value written at `pointer` of `file` is refused, the
    /// message naming the field, the value and the bound it breaks.
    fn assert_hostile_refused(file: &serde_json::Value, cases: &[(&str, f64, &str, &str)]) {
        for &(pointer, value, field, bound) in cases {
            let e = refused(file, pointer, value.into());
            assert!(e.contains(&format!("`{field}`")), "{pointer}: {e}");
            assert!(
                e.contains(&crate::model::bounds::show(value)),
                "{pointer}: {e}"
            );
            assert!(e.contains(bound), "{pointer}: {e}");
        }
    }

    /// 1e308 stands for any huge value; JSON has no NaN, so a non-finite
    /// value reaches the check only from a caller in Rust (below).
    #[test]
    fn hostile_values_are_refused_naming_field_value_and_bound() {
        let [mlp, rbf, gp] = [0, 1, 2].map(|i| trained_file(&specs()[i].1));
        assert_hostile_refused(
            &mlp,
            &[
                (
                    "/compensator/weights/7",
                    1e308,
                    "compensator.weights[7]",
                    "[-1e12, 1e12]",
                ),
                (
                    "/compensator/input_norm/scale/2",
                    -1.0,
                    "compensator.input_norm.scale[2]",
                    "[0, 1e13]",
                ),
                (
                    "/compensator/output_norm/scale/0",
                    0.0,
                    "compensator.output_norm.scale[0]",
                    "(0, 1e13] 1/m",
                ),
                (
                    "/compensator/output_norm/centre/1",
                    1e5,
                    "compensator.output_norm.centre[1]",
                    "[-100, 100] m",
                ),
                (
                    "/compensator_support/points_rad/0/3",
                    -1e200,
                    "compensator_support.points_rad[0][3]",
                    "[-1000, 1000] rad",
                ),
            ],
        );
        assert_hostile_refused(
            &rbf,
            &[
                (
                    "/compensator/spread",
                    -0.5,
                    "compensator.spread",
                    "(0, 1000000]",
                ),
                (
                    "/compensator/centres/3",
                    -1e300,
                    "compensator.centres[3]",
                    "[-1000000, 1000000]",
                ),
                (
                    "/compensator/weights/0",
                    1e15,
                    "compensator.weights[0]",
                    "[-1e12, 1e12]",
                ),
            ],
        );
        assert_hostile_refused(
            &gp,
            &[
                (
                    "/compensator/inverse_length_scales/1",
                    -2.0,
                    "compensator.inverse_length_scales[1]",
                    "[0, 1000000] 1/rad",
                ),
                (
                    "/compensator/signal_variance",
                    1e308,
                    "compensator.signal_variance",
                    "(0, 10000] m²",
                ),
                (
                    "/compensator/noise_variance",
                    0.0,
                    "compensator.noise_variance",
                    "(0, 10000] m²",
                ),
                (
                    "/compensator/alpha/4",
                    1e308,
                    "compensator.alpha[4]",
                    "[-1e30, 1e30]",
                ),
                (
                    "/compensator/inducing/5",
                    1e4,
                    "compensator.inducing[5]",
                    "[-1000, 1000] rad",
                ),
                (
                    "/compensator/error_scale",
                    -1.0,
                    "compensator.error_scale",
                    "(0, 1000000]",
                ),
                (
                    "/compensator_support/fade_rad",
                    -0.1,
                    "compensator_support.fade_rad",
                    "[0, 10000] rad",
                ),
                (
                    "/compensator_support/ranges_rad/2/1",
                    1e308,
                    "compensator_support.ranges_rad[2][1]",
                    "[-1000, 1000] rad",
                ),
            ],
        );
    }

    #[test]
    fn mismatched_sizes_and_oversized_networks_are_refused() {
        let [mlp, rbf, gp] = [0, 1, 2].map(|i| trained_file(&specs()[i].1));
        let mut v = gp.clone();
        v["compensator"]["inverse_length_scales"]
            .as_array_mut()
            .unwrap()
            .pop();
        assert!(load(&v).unwrap_err().contains("gp"));
        let mut v = rbf.clone();
        v["compensator"]["centres"].as_array_mut().unwrap().pop();
        assert!(load(&v).unwrap_err().contains("centres"));
        let mut v = mlp.clone();
        v["compensator"]["input_norm"]["scale"]
            .as_array_mut()
            .unwrap()
            .pop();
        assert!(load(&v).unwrap_err().contains("mlp input"));
        let mut v = mlp.clone();
        v["compensator_support"]["ranges_rad"]
            .as_array_mut()
            .unwrap()
            .pop();
        assert!(load(&v).unwrap_err().contains("joint ranges"));
        let e = refused(&mlp, "/compensator/hidden", 5000.into());
        assert!(
            e.contains("`compensator.hidden`")
                && e.contains("5000 hidden units is more than the bound 1000"),
            "{e}"
        );
    }

    #[test]
    fn non_finite_values_are_refused_by_name() {
        use crate::model::calibrated::StoredCompensator;
        let v = trained_file(&specs()[2].1);
        let mut c: StoredCompensator = serde_json::from_value(v["compensator"].clone()).unwrap();
        if let StoredCompensator::Gp(g) = &mut c {
            g.variance[3] = f64::NAN;
        }
        let e = super::check_compensator(&c, None, None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`compensator.variance[3]`: NaN is outside"),
            "{e}"
        );
        if let StoredCompensator::Gp(g) = &mut c {
            g.variance[3] = 0.0;
            g.mean[1] = f64::NEG_INFINITY;
        }
        let e = super::check_compensator(&c, None, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`compensator.mean[1]`: -inf is outside"), "{e}");
    }
}
