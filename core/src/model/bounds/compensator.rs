//! Bounds of a calibrated model file's learned compensator (`compensator`)
//! and of where it was trained (`compensator_support`): every stored number
//! finite and within the bound of its quantity ([`super`]), the sizes that
//! set the cost of one prediction capped. SI units, as the network computes
//! (inputs rad, kg, N·m; outputs m). The consistency of the sizes (weights
//! for the layers, one range per joint) is the compensator's own check
//! (`StoredCompensator::validate`, `Support::validate`).

use super::{
    check_above, check_all, check_count, Bound, ERROR_SCALE, GP_COEFFICIENT, GP_VARIANCE_M2,
    INPUT_CENTRE, INPUT_SCALE, INVERSE_LENGTH_SCALE, JOINT_DISTANCE_RAD, JOINT_RAD, NETWORK_WEIGHT,
    OUTPUT_SCALE, RBF_NORMALISED, RESIDUAL_M,
};
use crate::compensate::support::MAX_POINTS;
use crate::compensate::{Gp, Mlp, Normalisation, Rbf, StoredCompensator, Support};
use crate::model::description::ModelError;

/// Most hidden units of an MLP (the largest trained has 40).
pub const MAX_MLP_HIDDEN: usize = 1000;
/// Most units of an RBF network (training grows at most 40 by default).
pub const MAX_RBF_UNITS: usize = 10_000;
/// Most inducing configurations of a GP (300 by default; its variance
/// matrix holds the square of this).
pub const MAX_GP_UNITS: usize = 5000;

const C: &str = "compensator";

/// Checks every value of `c` and of `support` against its bound; the error
/// names the field (`compensator.weights[12]`), its value and the bound.
pub fn check_compensator(
    c: &StoredCompensator,
    support: Option<&Support>,
) -> Result<(), ModelError> {
    match c {
        StoredCompensator::Mlp(m) => check_mlp(m)?,
        StoredCompensator::Rbf(r) => check_rbf(r)?,
        StoredCompensator::Gp(g) => check_gp(g)?,
    }
    if let Some(s) = support {
        check_support(s)?;
    }
    Ok(())
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

fn check_mlp(m: &Mlp) -> Result<(), ModelError> {
    check_count(
        &format!("{C}.hidden"),
        m.hidden,
        MAX_MLP_HIDDEN,
        "hidden units",
    )?;
    check_all(&format!("{C}.weights"), &m.weights, &NETWORK_WEIGHT)?;
    check_norm(
        &format!("{C}.input_norm"),
        &m.input_norm,
        &INPUT_CENTRE,
        &INPUT_SCALE,
        false,
    )?;
    check_norm(
        &format!("{C}.output_norm"),
        &m.output_norm,
        &RESIDUAL_M,
        &OUTPUT_SCALE,
        true,
    )
}

fn check_rbf(r: &Rbf) -> Result<(), ModelError> {
    check_count(&format!("{C}.centres"), r.units(), MAX_RBF_UNITS, "units")?;
    check_above(&format!("{C}.spread"), r.spread, &positive(&RBF_NORMALISED))?;
    check_all(&format!("{C}.centres"), &r.centres, &RBF_NORMALISED)?;
    check_all(&format!("{C}.weights"), &r.weights, &NETWORK_WEIGHT)?;
    check_norm(
        &format!("{C}.input_norm"),
        &r.input_norm,
        &INPUT_CENTRE,
        &INPUT_SCALE,
        false,
    )
}

fn check_gp(g: &Gp) -> Result<(), ModelError> {
    check_count(
        &format!("{C}.alpha"),
        g.units(),
        MAX_GP_UNITS,
        "inducing configurations",
    )?;
    check_all(
        &format!("{C}.inverse_length_scales"),
        &g.inverse_length_scales,
        &INVERSE_LENGTH_SCALE,
    )?;
    check_above(
        &format!("{C}.signal_variance"),
        g.signal_variance,
        &GP_VARIANCE_M2,
    )?;
    check_above(
        &format!("{C}.noise_variance"),
        g.noise_variance,
        &GP_VARIANCE_M2,
    )?;
    check_all(&format!("{C}.mean"), &g.mean, &RESIDUAL_M)?;
    check_all(&format!("{C}.inducing"), &g.inducing, &JOINT_RAD)?;
    check_all(&format!("{C}.alpha"), &g.alpha, &GP_COEFFICIENT)?;
    check_all(&format!("{C}.variance"), &g.variance, &GP_COEFFICIENT)?;
    check_above(&format!("{C}.error_scale"), g.error_scale, &ERROR_SCALE)?;
    super::check(
        &format!("{C}.uncompensated_rms"),
        g.uncompensated_rms,
        &positive(&RESIDUAL_M),
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
    use crate::compensate::{
        parse_compensated, train, CalibratedModelFile, CompensatedModel, CompensatorSpec,
        GpSettings, LmTrainSettings, MlpSpec, RbfSettings, Sample, Support, Trainer,
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
        m.compensator = Some(c.into_arc_supported(Some(support)));
        let text = CalibratedModelFile::from_compensated(&m, "ys100", "skcm-x").to_json();
        serde_json::from_str(&text).unwrap()
    }

    fn specs() -> Vec<(&'static str, CompensatorSpec)> {
        vec![
            (
                "mlp",
                CompensatorSpec::Mlp {
                    spec: MlpSpec::SKCM_NN,
                    trainer: Trainer::Lm(LmTrainSettings {
                        max_epochs: 20,
                        ..Default::default()
                    }),
                },
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

    /// 1e308 stands for any huge value; JSON has no NaN, so a non-finite
    /// value reaches the check only from a caller in Rust (below).
    #[test]
    fn hostile_values_are_refused_naming_field_value_and_bound() {
        let [mlp, rbf, gp] = [0, 1, 2].map(|i| trained_file(&specs()[i].1));
        let cases = [
            (
                &mlp,
                "/compensator/weights/7",
                1e308,
                "compensator.weights[7]",
                "[-1e12, 1e12]",
            ),
            (
                &mlp,
                "/compensator/input_norm/scale/2",
                -1.0,
                "compensator.input_norm.scale[2]",
                "[0, 1e13]",
            ),
            (
                &mlp,
                "/compensator/output_norm/scale/0",
                0.0,
                "compensator.output_norm.scale[0]",
                "(0, 1e13] 1/m",
            ),
            (
                &mlp,
                "/compensator/output_norm/centre/1",
                1e5,
                "compensator.output_norm.centre[1]",
                "[-100, 100] m",
            ),
            (
                &rbf,
                "/compensator/spread",
                -0.5,
                "compensator.spread",
                "(0, 1000000]",
            ),
            (
                &rbf,
                "/compensator/centres/3",
                -1e300,
                "compensator.centres[3]",
                "[-1000000, 1000000]",
            ),
            (
                &rbf,
                "/compensator/weights/0",
                1e15,
                "compensator.weights[0]",
                "[-1e12, 1e12]",
            ),
            (
                &gp,
                "/compensator/inverse_length_scales/1",
                -2.0,
                "compensator.inverse_length_scales[1]",
                "[0, 1000000] 1/rad",
            ),
            (
                &gp,
                "/compensator/signal_variance",
                1e308,
                "compensator.signal_variance",
                "(0, 10000] m²",
            ),
            (
                &gp,
                "/compensator/noise_variance",
                0.0,
                "compensator.noise_variance",
                "(0, 10000] m²",
            ),
            (
                &gp,
                "/compensator/alpha/4",
                1e308,
                "compensator.alpha[4]",
                "[-1e30, 1e30]",
            ),
            (
                &gp,
                "/compensator/inducing/5",
                1e4,
                "compensator.inducing[5]",
                "[-1000, 1000] rad",
            ),
            (
                &gp,
                "/compensator/error_scale",
                -1.0,
                "compensator.error_scale",
                "(0, 1000000]",
            ),
            (
                &gp,
                "/compensator_support/fade_rad",
                -0.1,
                "compensator_support.fade_rad",
                "[0, 10000] rad",
            ),
            (
                &gp,
                "/compensator_support/ranges_rad/2/1",
                1e308,
                "compensator_support.ranges_rad[2][1]",
                "[-1000, 1000] rad",
            ),
            (
                &mlp,
                "/compensator_support/points_rad/0/3",
                -1e200,
                "compensator_support.points_rad[0][3]",
                "[-1000, 1000] rad",
            ),
        ];
        for (file, pointer, value, field, bound) in cases {
            let e = refused(file, pointer, value.into());
            assert!(e.contains(&format!("`{field}`")), "{pointer}: {e}");
            assert!(
                e.contains(&crate::model::bounds::show(value)),
                "{pointer}: {e}"
            );
            assert!(e.contains(bound), "{pointer}: {e}");
        }
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
        use crate::compensate::StoredCompensator;
        let v = trained_file(&specs()[2].1);
        let mut c: StoredCompensator = serde_json::from_value(v["compensator"].clone()).unwrap();
        if let StoredCompensator::Gp(g) = &mut c {
            g.variance[3] = f64::NAN;
        }
        let e = super::check_compensator(&c, None).unwrap_err().to_string();
        assert!(
            e.contains("`compensator.variance[3]`: NaN is outside"),
            "{e}"
        );
        if let StoredCompensator::Gp(g) = &mut c {
            g.variance[3] = 0.0;
            g.mean[1] = f64::NEG_INFINITY;
        }
        let e = super::check_compensator(&c, None).unwrap_err().to_string();
        assert!(e.contains("`compensator.mean[1]`: -inf is outside"), "{e}");
    }
}
