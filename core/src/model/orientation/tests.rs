use super::*;
use nalgebra::{Rotation3, Unit, UnitQuaternion};
use proptest::prelude::*;
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, PI};

const ALL: [OrientationConvention; 6] = OrientationConvention::ALL;

/// Independent reference: elementary rotations from nalgebra, degrees.
fn rx(deg: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&Vector3::x_axis(), deg.to_radians()).into_inner()
}
fn ry(deg: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&Vector3::y_axis(), deg.to_radians()).into_inner()
}
fn rz(deg: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), deg.to_radians()).into_inner()
}

fn max_diff(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    (a - b).amax()
}

fn assert_mat_close(a: &Matrix3<f64>, b: &Matrix3<f64>, tol: f64) {
    let d = max_diff(a, b);
    assert!(d <= tol, "matrices differ by {d:e} > {tol:e}:\n{a}\n{b}");
}

fn assert_vec_close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) {
    let d = (a - b).amax();
    assert!(d <= tol, "vectors differ by {d:e}: {a} vs {b}");
}

/// Angle difference in degrees modulo 360, in [0, 180].
fn angle_diff_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

fn is_orthonormal(r: &Matrix3<f64>) -> bool {
    (r.transpose() * r - Matrix3::identity()).amax() < 1e-12 && r.determinant() > 0.0
}

// ---- names / metadata -------------------------------------------------

#[test]
fn n_values_and_column_names_agree() {
    let expected = [4, 3, 3, 9, 3, 4];
    for (conv, n) in ALL.into_iter().zip(expected) {
        assert_eq!(conv.n_values(), n);
        assert_eq!(conv.column_names().len(), n);
    }
    assert_eq!(
        OrientationConvention::Quaternion.column_names(),
        &["qw", "qx", "qy", "qz"]
    );
    assert_eq!(
        OrientationConvention::KukaAbc.column_names(),
        &["a", "b", "c"]
    );
    assert_eq!(
        OrientationConvention::FanucWpr.column_names(),
        &["w", "p", "r"]
    );
    assert_eq!(
        OrientationConvention::Matrix.column_names(),
        &["r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33"]
    );
}

#[test]
fn from_name_accepts_aliases_case_insensitively() {
    use OrientationConvention::*;
    let cases = [
        ("quaternion", Quaternion),
        ("QUAT", Quaternion),
        ("wxyz", Quaternion),
        ("ABB", Quaternion),
        ("kuka_abc", KukaAbc),
        ("Abc", KukaAbc),
        ("KUKA", KukaAbc),
        ("kuka-abc", KukaAbc),
        ("fanuc_wpr", FanucWpr),
        ("WPR", FanucWpr),
        (" Fanuc ", FanucWpr),
        ("matrix", Matrix),
        ("Rotation_Matrix", Matrix),
    ];
    for (name, conv) in cases {
        assert_eq!(OrientationConvention::from_name(name), Ok(conv), "{name}");
        assert_eq!(name.parse::<OrientationConvention>(), Ok(conv), "{name}");
    }
    for conv in ALL {
        assert_eq!(OrientationConvention::from_name(conv.name()), Ok(conv));
    }
}

#[test]
fn from_name_rejects_unknown() {
    let err = OrientationConvention::from_name("xyzw").unwrap_err();
    assert_eq!(
        err,
        OrientationError::UnknownConvention {
            name: "xyzw".into()
        }
    );
    let msg = err.to_string();
    assert!(msg.contains("'xyzw'") && msg.contains("kuka_abc"), "{msg}");
}

#[test]
fn serde_uses_snake_case_names() {
    for conv in ALL {
        let json = serde_json::to_string(&conv).unwrap();
        assert_eq!(json, format!("\"{}\"", conv.name()));
        let back: OrientationConvention = serde_json::from_str(&json).unwrap();
        assert_eq!(back, conv);
    }
}

// ---- closed-form expectations -----------------------------------------

#[test]
fn kuka_a90_maps_x_to_y() {
    let r = rotation_from(OrientationConvention::KukaAbc, &[90.0, 0.0, 0.0]).unwrap();
    assert_vec_close(&(r * Vector3::x()), &Vector3::y(), 1e-15);
    assert_vec_close(&(r * Vector3::z()), &Vector3::z(), 1e-15);
}

#[test]
fn kuka_b90_maps_z_to_x_and_c90_maps_y_to_z() {
    let r = rotation_from(OrientationConvention::KukaAbc, &[0.0, 90.0, 0.0]).unwrap();
    assert_vec_close(&(r * Vector3::z()), &Vector3::x(), 1e-15);
    let r = rotation_from(OrientationConvention::KukaAbc, &[0.0, 0.0, 90.0]).unwrap();
    assert_vec_close(&(r * Vector3::y()), &Vector3::z(), 1e-15);
}

#[test]
fn kuka_order_is_rz_ry_rx() {
    // A=90, C=90: tool y -> (Rx) z -> (Rz) z; tool z -> (Rx) -y -> (Rz) x.
    let r = rotation_from(OrientationConvention::KukaAbc, &[90.0, 0.0, 90.0]).unwrap();
    assert_vec_close(&(r * Vector3::y()), &Vector3::z(), 1e-15);
    assert_vec_close(&(r * Vector3::z()), &Vector3::x(), 1e-15);
    let (a, b, c) = (30.0, -20.0, 110.0);
    let r = rotation_from(OrientationConvention::KukaAbc, &[a, b, c]).unwrap();
    assert_mat_close(&r, &(rz(a) * ry(b) * rx(c)), 1e-15);
}

#[test]
fn fanuc_w90_maps_y_to_z() {
    let r = rotation_from(OrientationConvention::FanucWpr, &[90.0, 0.0, 0.0]).unwrap();
    assert_vec_close(&(r * Vector3::y()), &Vector3::z(), 1e-15);
    assert_vec_close(&(r * Vector3::x()), &Vector3::x(), 1e-15);
}

#[test]
fn fanuc_r90_is_about_z_and_order_is_fixed_xyz() {
    let r = rotation_from(OrientationConvention::FanucWpr, &[0.0, 0.0, 90.0]).unwrap();
    assert_vec_close(&(r * Vector3::x()), &Vector3::y(), 1e-15);
    // W=90 then R=90 about fixed axes: tool y -> z (W) -> z (R).
    // tool z -> -y (W) -> x (R).
    let r = rotation_from(OrientationConvention::FanucWpr, &[90.0, 0.0, 90.0]).unwrap();
    assert_vec_close(&(r * Vector3::y()), &Vector3::z(), 1e-15);
    assert_vec_close(&(r * Vector3::z()), &Vector3::x(), 1e-15);
    let (w, p, rr) = (-45.0, 33.0, 170.0);
    let r = rotation_from(OrientationConvention::FanucWpr, &[w, p, rr]).unwrap();
    assert_mat_close(&r, &(rz(rr) * ry(p) * rx(w)), 1e-15);
}

#[test]
fn ur_rotvec_is_axis_times_angle_in_radians() {
    let r = rotation_from(OrientationConvention::UrRotvec, &[0.0, 0.0, FRAC_PI_2]).unwrap();
    assert_mat_close(&r, &rz(90.0), 1e-15);
    // 120° about (1,1,1)/√3 permutes the axes x → y → z → x.
    let a = 2.0 * PI / 3.0 / 3f64.sqrt();
    let r = rotation_from(OrientationConvention::UrRotvec, &[a, a, a]).unwrap();
    let perm = Matrix3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    assert_mat_close(&r, &perm, 1e-15);
    let back = rotation_to(OrientationConvention::UrRotvec, &perm);
    for v in back {
        assert!((v - a).abs() < 1e-15, "{v}");
    }
    // Names that cannot be read as degrees or as another convention.
    assert_eq!(
        OrientationConvention::UrRotvec.column_names(),
        &["ur_rx_rad", "ur_ry_rad", "ur_rz_rad"]
    );
    assert_eq!(
        OrientationConvention::from_name("rotvec"),
        Ok(OrientationConvention::UrRotvec)
    );
}

#[test]
fn abb_q1q4_is_the_scalar_first_quaternion() {
    let q = [FRAC_1_SQRT_2, 0.0, 0.0, FRAC_1_SQRT_2];
    let r = rotation_from(OrientationConvention::AbbQ1q4, &q).unwrap();
    assert_mat_close(&r, &rz(90.0), 1e-15);
    assert_eq!(
        OrientationConvention::AbbQ1q4.column_names(),
        &["q1", "q2", "q3", "q4"]
    );
    // Every name and column is unique across conventions.
    let mut names: Vec<&str> = ALL.iter().map(|c| c.name()).collect();
    names.extend(ALL.iter().flat_map(|c| c.column_names().iter().copied()));
    let n = names.len();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), n);
}

#[test]
fn quaternion_cos45_sin45_is_rz90() {
    let q = [FRAC_1_SQRT_2, 0.0, 0.0, FRAC_1_SQRT_2];
    let r = rotation_from(OrientationConvention::Quaternion, &q).unwrap();
    assert_mat_close(&r, &rz(90.0), 1e-15);
    assert_vec_close(&(r * Vector3::x()), &Vector3::y(), 1e-15);
}

#[test]
fn quaternion_of_x_axis_half_turn() {
    let r = rotation_from(OrientationConvention::Quaternion, &[0.0, 1.0, 0.0, 0.0]).unwrap();
    assert_mat_close(
        &r,
        &Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0)),
        0.0,
    );
    // Sign canonicalisation for w = 0.
    assert_eq!(quaternion_from_matrix(&r), [0.0, 1.0, 0.0, 0.0]);
    let r = matrix_from_quaternion([0.0, 0.0, -1.0, 0.0]);
    assert_eq!(quaternion_from_matrix(&r), [0.0, 0.0, 1.0, 0.0]);
}

#[test]
fn quaternion_and_abc_of_hand_built_rotation_agree() {
    // Hand-built: 120 deg about (1,1,1)/sqrt3 permutes axes x->y->z->x.
    let perm = Matrix3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    let h = 0.5;
    let q = [h, h, h, h];
    let rq = rotation_from(OrientationConvention::Quaternion, &q).unwrap();
    assert_mat_close(&rq, &perm, 1e-15);
    // perm = Rz(90)*Ry(0)*Rx(90): check by hand above; extract and compare.
    let abc = rotation_to(OrientationConvention::KukaAbc, &perm);
    assert!(angle_diff_deg(abc[0], 90.0) < 1e-12, "{abc:?}");
    assert!(angle_diff_deg(abc[1], 0.0) < 1e-12, "{abc:?}");
    assert!(angle_diff_deg(abc[2], 90.0) < 1e-12, "{abc:?}");
    let rabc = rotation_from(OrientationConvention::KukaAbc, &abc).unwrap();
    assert_mat_close(&rabc, &rq, 1e-15);
    let q_back = rotation_to(OrientationConvention::Quaternion, &rabc);
    for (x, y) in q_back.iter().zip(q) {
        assert!((x - y).abs() < 1e-15, "{q_back:?}");
    }
    // WPR of the same rotation is the reversed triple.
    let wpr = rotation_to(OrientationConvention::FanucWpr, &perm);
    assert!(angle_diff_deg(wpr[0], 90.0) < 1e-12, "{wpr:?}");
    assert!(angle_diff_deg(wpr[1], 0.0) < 1e-12, "{wpr:?}");
    assert!(angle_diff_deg(wpr[2], 90.0) < 1e-12, "{wpr:?}");
}

#[test]
fn quaternion_matches_nalgebra_for_a_generic_rotation() {
    let axis = Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
    let uq = UnitQuaternion::from_axis_angle(&axis, 1.234);
    let q = [uq.w, uq.i, uq.j, uq.k];
    let r = rotation_from(OrientationConvention::Quaternion, &q).unwrap();
    assert_mat_close(&r, &uq.to_rotation_matrix().into_inner(), 1e-15);
}

#[test]
fn matrix_is_row_major() {
    let r = rz(90.0); // columns: x->y, y->-x
    let v = rotation_to(OrientationConvention::Matrix, &r);
    let expected = [0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    for (x, y) in v.iter().zip(expected) {
        assert!((x - y).abs() < 1e-15, "{v:?}");
    }
    let back = rotation_from(OrientationConvention::Matrix, &expected).unwrap();
    assert_mat_close(&back, &r, 1e-15);
}

#[test]
fn matrix_input_is_reorthonormalised() {
    let r = rz(20.0) * ry(-40.0) * rx(75.0);
    let mut v = rotation_to(OrientationConvention::Matrix, &r);
    // Perturb by ~1e-7 (e.g. values printed with 7 decimals).
    for (i, x) in v.iter_mut().enumerate() {
        *x += 1e-7 * ((i as f64) * 1.7).sin();
    }
    let back = rotation_from(OrientationConvention::Matrix, &v).unwrap();
    assert!(is_orthonormal(&back));
    assert!(max_diff(&back, &r) < 1e-6);
}

#[test]
fn gimbal_lock_puts_everything_in_a_or_r() {
    for b in [90.0, -90.0] {
        for (a, c) in [(10.0, 20.0), (-170.0, 50.0), (0.0, -30.0)] {
            let r = rz(a) * ry(b) * rx(c);
            let abc = rotation_to(OrientationConvention::KukaAbc, &r);
            assert_eq!(abc[2], 0.0, "{abc:?}");
            assert!(angle_diff_deg(abc[1], b) < 1e-6, "{abc:?}");
            // Rz(a)Ry(±90)Rx(c) = Rz(a ∓ c)Ry(±90)
            let a_eff = if b > 0.0 { a - c } else { a + c };
            assert!(angle_diff_deg(abc[0], a_eff) < 1e-6, "{abc:?} vs {a_eff}");
            let back = rotation_from(OrientationConvention::KukaAbc, &abc).unwrap();
            assert_mat_close(&back, &r, 1e-12);

            let wpr = rotation_to(OrientationConvention::FanucWpr, &r);
            assert_eq!(wpr[0], 0.0, "{wpr:?}");
            assert!(angle_diff_deg(wpr[2], a_eff) < 1e-6, "{wpr:?}");
            let back = rotation_from(OrientationConvention::FanucWpr, &wpr).unwrap();
            assert_mat_close(&back, &r, 1e-12);
        }
    }
}

#[test]
fn euler_output_range_is_half_open() {
    // A = 180 must be reported as +180, never -180.
    let r = rz(180.0);
    let abc = rotation_to(OrientationConvention::KukaAbc, &r);
    assert_eq!(abc, vec![180.0, 0.0, 0.0]);
    let r = rx(-180.0);
    let wpr = rotation_to(OrientationConvention::FanucWpr, &r);
    assert_eq!(wpr, vec![180.0, 0.0, 0.0]);
    // Identity gives exact (positive) zeros.
    let abc = rotation_to(OrientationConvention::KukaAbc, &Matrix3::identity());
    assert!(abc.iter().all(|v| *v == 0.0 && v.is_sign_positive()));
}

#[test]
fn rotation_angle_between_small_and_large() {
    let i = Matrix3::identity();
    assert_eq!(rotation_angle_between(&i, &i), 0.0);
    // acos(trace) would return 0 or ~1e-8 for this; atan2 gets it right.
    let tiny = 1e-10;
    let r = Rotation3::from_axis_angle(&Vector3::y_axis(), tiny).into_inner();
    let got = rotation_angle_between(&i, &r);
    assert!((got - tiny).abs() < 1e-20, "{got:e}");
    assert!((rotation_angle_between(&i, &rz(90.0)) - FRAC_PI_2).abs() < 1e-15);
    assert!((rotation_angle_between(&i, &rx(180.0)) - PI).abs() < 1e-15);
    // Relative: angle of aᵀb, independent of a common left factor.
    let a = rz(40.0) * ry(10.0);
    let b = a * rx(25.0);
    assert!((rotation_angle_between(&a, &b) - 25f64.to_radians()).abs() < 1e-14);
    assert!((rotation_angle_between(&b, &a) - 25f64.to_radians()).abs() < 1e-14);
}

// ---- error cases ------------------------------------------------------

#[test]
fn wrong_count_error() {
    for conv in ALL {
        let vals = vec![0.0; conv.n_values() + 1];
        let err = rotation_from(conv, &vals).unwrap_err();
        assert_eq!(
            err,
            OrientationError::WrongCount {
                convention: conv,
                expected: conv.n_values(),
                got: conv.n_values() + 1,
            }
        );
    }
    let msg = rotation_from(OrientationConvention::KukaAbc, &[1.0, 2.0])
        .unwrap_err()
        .to_string();
    assert_eq!(msg, "kuka_abc orientation needs 3 values (a, b, c), got 2");
}

#[test]
fn not_finite_error() {
    let err = rotation_from(OrientationConvention::FanucWpr, &[0.0, f64::NAN, 0.0]).unwrap_err();
    match &err {
        OrientationError::NotFinite {
            convention,
            index,
            column,
            value,
        } => {
            assert_eq!(*convention, OrientationConvention::FanucWpr);
            assert_eq!(*index, 1);
            assert_eq!(*column, "p");
            assert!(value.is_nan());
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(err.to_string().contains("'p'"), "{err}");
    let err = rotation_from(
        OrientationConvention::Quaternion,
        &[1.0, 0.0, 0.0, f64::INFINITY],
    )
    .unwrap_err();
    assert_eq!(
        err,
        OrientationError::NotFinite {
            convention: OrientationConvention::Quaternion,
            index: 3,
            column: "qz",
            value: f64::INFINITY,
        }
    );
    let mut m = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    m[8] = f64::NEG_INFINITY;
    assert!(matches!(
        rotation_from(OrientationConvention::Matrix, &m),
        Err(OrientationError::NotFinite { column: "r33", .. })
    ));
}

#[test]
fn non_unit_quaternion_error_and_normalisation() {
    let err = rotation_from(OrientationConvention::Quaternion, &[1.2, 0.0, 0.0, 0.0]).unwrap_err();
    assert_eq!(err, OrientationError::NonUnitQuaternion { norm: 1.2 });
    assert!(
        err.to_string()
            .starts_with("quaternion (w,x,y,z) has norm 1.2000; expected a unit quaternion"),
        "{err}"
    );
    assert!(matches!(
        rotation_from(OrientationConvention::Quaternion, &[0.0; 4]),
        Err(OrientationError::NonUnitQuaternion { norm }) if norm == 0.0
    ));
    // Within tolerance: normalised silently.
    let s = 1.0 + 5e-4;
    let q = [s * FRAC_1_SQRT_2, 0.0, 0.0, s * FRAC_1_SQRT_2];
    let r = rotation_from(OrientationConvention::Quaternion, &q).unwrap();
    assert!(is_orthonormal(&r));
    assert_mat_close(&r, &rz(90.0), 1e-15);
}

#[test]
fn not_a_rotation_errors() {
    // Not orthonormal (scaled).
    let scaled = [1.01, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let err = rotation_from(OrientationConvention::Matrix, &scaled).unwrap_err();
    match &err {
        OrientationError::NotARotation { detail } => {
            assert!(detail.contains("orthonormal"), "{detail}")
        }
        other => panic!("unexpected {other:?}"),
    }
    // Reflection.
    let mirror = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0];
    let err = rotation_from(OrientationConvention::Matrix, &mirror).unwrap_err();
    match &err {
        OrientationError::NotARotation { detail } => {
            assert!(detail.contains("determinant is -1.0000"), "{detail}")
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(err.to_string().starts_with("matrix is not a rotation:"));
    // Column-major input of a rotation is still a rotation (its
    // transpose), so the only thing we can catch is non-rotations.
    let zeros = [0.0; 9];
    assert!(matches!(
        rotation_from(OrientationConvention::Matrix, &zeros),
        Err(OrientationError::NotARotation { .. })
    ));
}

// ---- property tests ---------------------------------------------------

/// Uniformly random rotation from a normalised 4-vector.
fn arb_rotation() -> impl Strategy<Value = Matrix3<f64>> {
    prop::array::uniform4(-1.0f64..1.0)
        .prop_filter("non-degenerate", |q| {
            q.iter().map(|v| v * v).sum::<f64>() > 1e-3
        })
        .prop_map(|q| {
            let uq =
                UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
            uq.to_rotation_matrix().into_inner()
        })
}

/// Rotations at or within a hair of gimbal lock: B = ±90 ± δ (degrees).
fn arb_near_gimbal() -> impl Strategy<Value = Matrix3<f64>> {
    let offsets = prop::sample::select(vec![
        0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-7, -1e-7, 1e-4, -1e-4,
    ]);
    (-180.0f64..180.0, prop::bool::ANY, offsets, -180.0f64..180.0).prop_map(|(a, pos, d, c)| {
        let b = if pos { 90.0 } else { -90.0 } + d;
        rz(a) * ry(b) * rx(c)
    })
}

/// Euler-angle triples away from gimbal lock, in the output range.
fn arb_regular_angles() -> impl Strategy<Value = [f64; 3]> {
    (-179.9f64..180.0, -89.0f64..89.0, -179.9f64..180.0).prop_map(|(a, b, c)| [a, b, c])
}

fn check_round_trip(r: &Matrix3<f64>) -> Result<(), TestCaseError> {
    for conv in ALL {
        let vals = rotation_to(conv, r);
        prop_assert_eq!(vals.len(), conv.n_values());
        let back =
            rotation_from(conv, &vals).map_err(|e| TestCaseError::fail(format!("{conv}: {e}")))?;
        let d = max_diff(&back, r);
        prop_assert!(d < 1e-12, "{}: diff {:e}, values {:?}", conv, d, vals);
        prop_assert!(rotation_angle_between(&back, r) < 1e-12);
        match conv {
            OrientationConvention::UrRotvec => {
                let angle = vals.iter().map(|v| v * v).sum::<f64>().sqrt();
                prop_assert!(angle <= PI + 1e-12, "{:?}", vals);
                // Against nalgebra's own rotation vector (up to the sign at π).
                let n = nalgebra::Rotation3::from_matrix_unchecked(*r).scaled_axis();
                if angle < PI - 1e-6 {
                    for k in 0..3 {
                        prop_assert!((vals[k] - n[k]).abs() < 1e-9, "{:?} vs {}", vals, n);
                    }
                }
            }
            OrientationConvention::Quaternion | OrientationConvention::AbbQ1q4 => {
                prop_assert!(vals[0] >= 0.0, "w < 0: {:?}", vals);
                let n: f64 = vals.iter().map(|v| v * v).sum::<f64>().sqrt();
                prop_assert!((n - 1.0).abs() < 1e-15);
            }
            OrientationConvention::KukaAbc | OrientationConvention::FanucWpr => {
                for v in &vals {
                    prop_assert!(*v > -180.0 && *v <= 180.0, "{:?}", vals);
                }
                prop_assert!(vals[1].abs() <= 90.0, "{:?}", vals);
            }
            OrientationConvention::Matrix => {}
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 512,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed),
        ..ProptestConfig::default()
    })]

    #[test]
    fn round_trip_random_rotations(r in arb_rotation()) {
        check_round_trip(&r)?;
    }

    #[test]
    fn round_trip_near_gimbal(r in arb_near_gimbal()) {
        check_round_trip(&r)?;
    }

    #[test]
    fn quaternion_building_blocks_round_trip(r in arb_rotation()) {
        let q = quaternion_from_matrix(&r);
        prop_assert!(max_diff(&matrix_from_quaternion(q), &r) < 1e-14);
        // Agrees with nalgebra up to sign.
        let uq = UnitQuaternion::from_matrix(&r);
        let s = if uq.w < 0.0 { -1.0 } else { 1.0 };
        let n = [uq.w, uq.i, uq.j, uq.k];
        for k in 0..4 {
            prop_assert!((q[k] - s * n[k]).abs() < 1e-12, "{:?} vs {:?}", q, n);
        }
    }

    #[test]
    fn euler_angles_round_trip_away_from_gimbal(abc in arb_regular_angles()) {
        let r = rotation_from(OrientationConvention::KukaAbc, &abc).unwrap();
        prop_assert!(max_diff(&r, &(rz(abc[0]) * ry(abc[1]) * rx(abc[2]))) < 1e-14);
        let back = rotation_to(OrientationConvention::KukaAbc, &r);
        for k in 0..3 {
            prop_assert!(angle_diff_deg(back[k], abc[k]) < 1e-9, "{:?} vs {:?}", back, abc);
        }
        let wpr = [abc[2], abc[1], abc[0]];
        let rf = rotation_from(OrientationConvention::FanucWpr, &wpr).unwrap();
        prop_assert!(max_diff(&rf, &r) < 1e-15);
        let back = rotation_to(OrientationConvention::FanucWpr, &rf);
        for k in 0..3 {
            prop_assert!(angle_diff_deg(back[k], wpr[k]) < 1e-9, "{:?} vs {:?}", back, wpr);
        }
    }

    #[test]
    fn rotation_angle_matches_quaternion_angle(a in arb_rotation(), b in arb_rotation()) {
        let theta = rotation_angle_between(&a, &b);
        prop_assert!((0.0..=PI).contains(&theta));
        let q = quaternion_from_matrix(&(a.transpose() * b));
        let expected = 2.0 * q[1..].iter().map(|v| v * v).sum::<f64>().sqrt().atan2(q[0]);
        prop_assert!((theta - expected).abs() < 1e-12, "{} vs {}", theta, expected);
        prop_assert!((rotation_angle_between(&b, &a) - theta).abs() < 1e-12);
    }
}

/// Half turns: the skew part of R vanishes, so the axis must come from the
/// symmetric part. Each half turn's logarithm has length π and rebuilds R
/// (regression: a half turn about z, diag(−1, −1, 1), gave the zero vector).
#[test]
fn rotation_log_of_half_turns() {
    let axes = [
        Vector3::x(),
        Vector3::y(),
        Vector3::z(),
        Vector3::new(1.0, 1.0, 0.0),
        Vector3::new(-1.0, 2.0, 3.0),
        Vector3::new(0.3, -0.2, -0.9),
    ];
    for axis in axes {
        for angle in [PI, PI - 1e-9, PI - 1e-4, PI - 0.3] {
            let a = Unit::new_normalize(axis);
            let r = *Rotation3::from_axis_angle(&a, angle).matrix();
            let v = rotation_log(&r);
            assert!((v.norm() - angle).abs() < 1e-9, "{axis:?} {angle}: {v:?}");
            let back = *Rotation3::new(v).matrix();
            assert_mat_close(&back, &r, 1e-12);
            if angle < PI {
                assert_vec_close(&v, &(a.into_inner() * angle), 1e-9);
            }
        }
    }
}
