//! Orientation conventions and standard-deviation columns of the measurement
//! CSV. Expected rotations are built with nalgebra's own rotations
//! (`Rotation3::from_axis_angle`, `euler_angles`, `UnitQuaternion`), not with
//! the reader's conversions.

use super::*;
use crate::measure::convention::MeasuredOrientation;
use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn rot(axis: usize, deg: f64) -> Rotation3<f64> {
    let a = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()][axis];
    Rotation3::from_axis_angle(&a, deg.to_radians())
}

/// The stored fixed-axis angles as a rotation, by nalgebra:
/// `from_euler_angles(roll, pitch, yaw) = Rz(yaw)·Ry(pitch)·Rx(roll)`.
fn stored(r: &MeasuredPose) -> Rotation3<f64> {
    let [a, b, c] = r.rpy_deg.expect("orientation read").map(f64::to_radians);
    Rotation3::from_euler_angles(a, b, c)
}

/// Seeded random rotations, plus the gimbal-lock ones (pitch ±90°).
fn rotations() -> Vec<Rotation3<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let mut out: Vec<Rotation3<f64>> = (0..40)
        .map(|_| {
            let axis = Vector3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            Rotation3::new(axis.normalize() * rng.gen_range(0.0..std::f64::consts::PI))
        })
        .collect();
    out.push(rot(2, 30.0) * rot(1, 90.0) * rot(0, 10.0));
    out.push(rot(0, -20.0) * rot(1, -90.0) * rot(2, 50.0));
    out.push(rot(0, 0.0));
    out
}

/// One file in each convention of the same rotations reads back to them
/// to 1e-12; the default (fixed-axis) file keeps its angles bit for bit.
#[test]
fn three_conventions_read_back_to_the_same_rotation() {
    let rs = rotations();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (mut fixed, mut intrinsic, mut quat) = (
        String::from("q1,q2,q3,q4,q5,q6,x,y,z,rx,ry,rz\n"),
        String::from("# tracker export, intrinsic X-Y'-Z''\nq1,q2,q3,q4,q5,q6,x,y,z,rx,ry,rz\n"),
        String::from("q1,q2,q3,q4,q5,q6,x,y,z,qw,qx,qy,qz\n"),
    );
    let mut fixed_angles = Vec::new();
    for r in &rs {
        let lead = "10,20,30,40,50,60,1500,-200,900";
        // Fixed axis: nalgebra's roll, pitch, yaw.
        let (a, b, c) = r.euler_angles();
        let f = [a, b, c].map(f64::to_degrees);
        fixed_angles.push(f);
        fixed.push_str(&format!("{lead},{},{},{}\n", f[0], f[1], f[2]));
        // Intrinsic: Rx(a)·Ry(b)·Rz(c) = R  ⇔  Rz(−c)·Ry(−b)·Rx(−a) = Rᵀ,
        // the fixed-axis form of the transpose.
        let (ta, tb, tc) = r.transpose().euler_angles();
        let i = [-ta, -tb, -tc].map(f64::to_degrees);
        let built = rot(0, i[0]) * rot(1, i[1]) * rot(2, i[2]);
        assert!((built.matrix() - r.matrix()).amax() < 1e-14, "construction");
        intrinsic.push_str(&format!("{lead},{},{},{}\n", i[0], i[1], i[2]));
        // Quaternion: either sign, slightly off unit norm.
        let q = UnitQuaternion::from_rotation_matrix(r);
        let s = if rng.gen_bool(0.5) { -1.0 } else { 1.0 } * (1.0 + rng.gen_range(-5e-4..5e-4));
        quat.push_str(&format!(
            "{lead},{},{},{},{}\n",
            s * q.w,
            s * q.i,
            s * q.j,
            s * q.k
        ));
    }
    let read = |text: &str, orientation| {
        parse_opts(
            text,
            &ReadOptions {
                orientation,
                ..ReadOptions::default()
            },
        )
        .unwrap()
    };
    let from_fixed = read(&fixed, None);
    let from_fixed_declared = read(&fixed, Some(MeasuredOrientation::FixedXyz));
    let from_intrinsic = read(&intrinsic, Some(MeasuredOrientation::IntrinsicXyz));
    let from_quat = read(&quat, None);
    let from_quat_declared = read(&quat, Some(MeasuredOrientation::Quaternion));
    for (k, r) in rs.iter().enumerate() {
        assert_eq!(
            from_fixed[k].rpy_deg,
            Some(fixed_angles[k]),
            "fixed kept as written"
        );
        assert_eq!(from_fixed_declared[k], from_fixed[k]);
        assert_eq!(from_quat_declared[k], from_quat[k]);
        for (name, rows) in [
            ("fixed", &from_fixed),
            ("intrinsic", &from_intrinsic),
            ("quaternion", &from_quat),
        ] {
            let e = (stored(&rows[k]).matrix() - r.matrix()).amax();
            assert!(e < 1e-12, "{name}, rotation {k}: {e:e}");
        }
    }
    // Read as fixed-axis, the intrinsic file is a different rotation.
    let wrong = read(&intrinsic, None);
    let e = (stored(&wrong[0]).matrix() - rs[0].matrix()).amax();
    assert!(e > 1e-3, "{e}");
}

fn err(text: &str, orientation: Option<MeasuredOrientation>) -> CsvError {
    parse_opts(
        text,
        &ReadOptions {
            orientation,
            ..ReadOptions::default()
        },
    )
    .unwrap_err()
}

#[test]
fn bad_orientation_headers_and_quaternions_are_refused_with_line_and_column() {
    let both = "# c\nq1,q2,x,y,z,rx,ry,rz,qw,qx,qy,qz\n1,2,100,0,0,0,0,0,1,0,0,0\n";
    let e = err(both, None);
    assert!(
        matches!(e, CsvError::OrientationColumns { line: 2, .. }),
        "{e}"
    );
    assert!(
        e.to_string().contains("rx, ry, rz and qw, qx, qy, qz"),
        "{e}"
    );

    let angles = "q1,q2,x,y,z,rx,ry,rz\n1,2,100,0,0,0,0,0\n";
    let e = err(angles, Some(MeasuredOrientation::Quaternion));
    assert!(
        e.to_string()
            .starts_with("line 1: the orientation is declared quaternion"),
        "{e}"
    );

    let quat = "q1,q2,x,y,z,qw,qx,qy,qz\n1,2,100,0,0,1,0,0,0\n1,2,100,0,0,0.5,0.5,0.5,0.6\n";
    let e = err(quat, Some(MeasuredOrientation::IntrinsicXyz));
    assert!(e.to_string().contains("declared intrinsic_xyz"), "{e}");
    // 0.25·3 + 0.36 = 1.11: norm 1.0536.
    let e = err(quat, None);
    assert_eq!(
        e,
        CsvError::NonUnitQuaternion {
            line: 3,
            norm: 1.11f64.sqrt()
        }
    );
    assert!(
        e.to_string()
            .starts_with("line 3, columns qw, qx, qy, qz: the quaternion's norm is 1.053565"),
        "{e}"
    );
    // A zero quaternion is refused, not turned into NaN.
    let e = err("q1,q2,x,y,z,qw,qx,qy,qz\n1,2,100,0,0,0,0,0,0\n", None);
    assert!(
        matches!(e, CsvError::NonUnitQuaternion { line: 2, .. }),
        "{e}"
    );

    let e = err("q1,q2,x,y,z,qw,qx,qy\n1,2,100,0,0,1,0,0\n", None);
    assert_eq!(
        e,
        CsvError::MissingColumn {
            line: 1,
            column: "qz".into()
        }
    );
    let e = err("q1,q2,x,y,z,qw,qx,qy,qz\n1,2,100,0,0,1,0,,0\n", None);
    assert_eq!(
        e,
        CsvError::PartialColumns {
            line: 2,
            columns: "qw, qx, qy, qz".into()
        }
    );
    assert!(e.to_string().contains("give all 4 values or none"), "{e}");
    let e = err("q1,q2,x,y,z,qw,qx,qy,qz\n1,2,100,0,0,1,0,x,0\n", None);
    assert!(
        matches!(e, CsvError::NotNumeric { line: 2, ref column, .. } if column == "qy"),
        "{e}"
    );
    // An empty orientation is no orientation.
    let rows = parse("q1,q2,x,y,z,qw,qx,qy,qz\n1,2,100,0,0,,,,\n").unwrap();
    assert_eq!(rows[0].rpy_deg, None);
}

#[test]
fn names_derive_from_the_one_enum() {
    for c in MeasuredOrientation::ALL {
        assert_eq!(MeasuredOrientation::from_name(c.name()), Some(c));
        assert_eq!(
            serde_json::to_string(&c).unwrap(),
            format!("\"{}\"", c.name())
        );
    }
    assert_eq!(
        MeasuredOrientation::names(),
        "fixed_xyz, intrinsic_xyz, quaternion"
    );
    assert_eq!(MeasuredOrientation::from_name("euler"), None);
}

#[test]
fn standard_deviations_are_read_converted_and_written_back() {
    let text = "q1,q2,x,y,z,rx,ry,rz,std_x,std_y,std_z,std_rx,std_ry,std_rz\n\
                1,2,100,0,0,1,2,3,0.01,0.02,0.03,0.001,0.002,0.003\n\
                1,2,100,0,0,,,,0.1,0.2,0.3,,,\n";
    let rows = parse(text).unwrap();
    assert_eq!(rows[0].std_mm, Some([0.01, 0.02, 0.03]));
    assert_eq!(rows[0].std_deg, Some([0.001, 0.002, 0.003]));
    assert_eq!(rows[1].std_mm, Some([0.1, 0.2, 0.3]));
    assert_eq!(rows[1].std_deg, None);
    assert_eq!(parse(&write(&rows)).unwrap(), rows);
    let si = RowStd::from_axes([0.01, 0.02, 0.03], Some([0.001, 0.002, 0.003]));
    // √((1 + 4 + 9)/3)·0.01 mm, the same for the degrees.
    let rms = (14.0f64 / 3.0).sqrt();
    assert!((si.position - rms * 1e-5).abs() < 1e-18);
    assert!((si.orientation.unwrap() - (rms * 1e-3).to_radians()).abs() < 1e-18);

    // Metres and radians declared: the deviations convert with the values.
    let opts = ReadOptions {
        metres: true,
        radians: true,
        ..ReadOptions::default()
    };
    let rows = parse_opts(
        "q1,q2,x,y,z,rx,ry,rz,std_x,std_y,std_z,std_rx,std_ry,std_rz\n\
         0.1,0.2,1.5,0,0,0,0,0,0.00002,0.00002,0.00002,0.001,0.001,0.001\n",
        &opts,
    )
    .unwrap();
    assert!((rows[0].std_mm.unwrap()[0] - 0.02).abs() < 1e-15);
    assert!((rows[0].std_deg.unwrap()[0] - 0.001f64.to_degrees()).abs() < 1e-15);
}

#[test]
fn bad_standard_deviations_are_refused_with_line_and_column() {
    let head = "q1,q2,x,y,z,std_x,std_y,std_z\n";
    let e = parse(&format!(
        "{head}1,2,100,0,0,0.1,0.1,0.1\n1,2,100,0,0,0.1,,0.1\n"
    ))
    .unwrap_err();
    assert!(
        matches!(e, CsvError::BadStd { line: 3, ref column, .. } if column == "std_y"),
        "{e}"
    );
    assert!(e.to_string().contains("every row gives them"), "{e}");
    let e = parse(&format!("{head}1,2,100,0,0,0.1,0,0.1\n")).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("line 2, column `std_y`: 0 is not a standard deviation"),
        "{e}"
    );
    let e = parse(&format!("{head}1,2,100,0,0,0.1,-1,0.1\n")).unwrap_err();
    assert!(matches!(e, CsvError::BadStd { line: 2, .. }), "{e}");
    let e = parse("q1,q2,x,y,z,std_x,std_y\n1,2,100,0,0,0.1,0.1\n").unwrap_err();
    assert_eq!(
        e,
        CsvError::MissingColumn {
            line: 1,
            column: "std_z".into()
        }
    );
    let e =
        parse("q1,q2,x,y,z,rx,ry,rz,std_rx,std_ry,std_rz\n1,2,100,0,0,0,0,0,1,1,1\n").unwrap_err();
    assert_eq!(
        e,
        CsvError::MissingColumn {
            line: 1,
            column: "std_x".into()
        }
    );
    let e = parse("q1,q2,x,y,z,std_x,std_y,std_z,std_rx,std_ry,std_rz\n1,2,100,0,0,1,1,1,1,1,1\n")
        .unwrap_err();
    assert!(
        matches!(e, CsvError::OrientationColumns { line: 1, .. }),
        "{e}"
    );
    let e = parse(
        "q1,q2,x,y,z,rx,ry,rz,std_x,std_y,std_z,std_rx,std_ry,std_rz\n1,2,100,0,0,,,,1,1,1,1,1,1\n",
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("on a row without an orientation"),
        "{e}"
    );
    let e = parse(
        "q1,q2,x,y,z,rx,ry,rz,std_x,std_y,std_z,std_rx,std_ry,std_rz\n1,2,100,0,0,1,1,1,1,1,1,,1,1\n",
    )
    .unwrap_err();
    assert!(
        matches!(e, CsvError::BadStd { line: 2, ref column, .. } if column == "std_rx"),
        "{e}"
    );
}
