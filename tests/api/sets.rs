use crate::support::*;
use axum::http::StatusCode;
use robocal::measure::{csv, MeasuredPose, SetRole};
use robocal::model::preset;
use serde_json::{json, Value};

#[tokio::test]
async fn csv_and_json_uploads_are_stored_losslessly() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();

    // CSV: rows read back bit for bit; the original text verbatim.
    let text = simulated_csv(3, 25);
    let set = t.upload_csv(robot, &text, "?session=tracker-A").await;
    assert_eq!(set["role"], "identification");
    assert_eq!(set["session"], "tracker-A");
    assert_eq!(set["format"], "csv");
    let sid = set["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid])
        .await;
    let rows: Vec<MeasuredPose> = serde_json::from_value(r.json()["rows"].clone()).unwrap();
    assert_eq!(rows, csv::parse(&text).unwrap());
    let r = t
        .get(
            "/v1/robots/{id}/measurement-sets/{sid}/original",
            &[&rid, &sid],
        )
        .await;
    assert!(r.content_type.starts_with("text/csv"));
    assert_eq!(r.text(), text);

    // JSON: every optional field, role taken from the rows' common `set`.
    let mut rows = simulated_rows(4, 10, Some(SetRole::Validation));
    rows[0].rpy_deg = Some([1.5, -2.25, 179.0]);
    rows[1].temperature_c = Some(21.5);
    rows[2].payload_kg = Some(55.5);
    let body = json!({ "name": "q3", "payload_kg": 110.0, "rows": rows });
    let r = t
        .post_json("/v1/robots/{id}/measurement-sets", &[&rid], body.clone())
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["role"], "validation");
    assert_eq!(r.json()["format"], "json");
    let sid2 = r.json()["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid2])
        .await;
    let back: Vec<MeasuredPose> = serde_json::from_value(r.json()["rows"].clone()).unwrap();
    assert_eq!(back, rows);

    // Declared units: metres and radians are converted to mm and deg.
    let si: Vec<Value> = rows
        .iter()
        .map(|r| {
            json!({ "q": r.q_deg.iter().map(|d| d.to_radians()).collect::<Vec<_>>(),
                    "xyz": r.xyz_mm.map(|v| v / 1e3) })
        })
        .collect();
    let r = t
        .post_json(
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            json!({ "length_unit": "m", "angle_unit": "rad", "rows": si }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["units"]["length"], "m");
    let sid3 = r.json()["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid3])
        .await;
    let conv: Vec<MeasuredPose> = serde_json::from_value(r.json()["rows"].clone()).unwrap();
    for (a, b) in conv.iter().zip(&rows) {
        assert!((a.xyz_mm[0] - b.xyz_mm[0]).abs() < 1e-9);
        assert!((a.q_deg[1] - b.q_deg[1]).abs() < 1e-9);
    }
    // A CSV in metres.
    let metres =
        "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,1.5,-3.2,1.1\n10,80,5,0,20,0,1.4,-3.1,1.2\n";
    let set = t
        .upload_csv(robot, metres, "?length_unit=m&role=training")
        .await;
    let sid4 = set["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid4])
        .await;
    assert_eq!(
        r.json()["rows"][0]["xyz_mm"],
        json!([1500.0, -3200.0, 1100.0])
    );

    // List, delete.
    let r = t.get("/v1/robots/{id}/measurement-sets", &[&rid]).await;
    assert_eq!(r.json()["measurement_sets"].as_array().unwrap().len(), 4);
    assert!(r.json()["measurement_sets"][0].get("rows").is_none());
    let r = t
        .send(
            "DELETE",
            "/v1/robots/{id}/measurement-sets/{sid}",
            &[&rid, &sid],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::NO_CONTENT);
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid])
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert!(r.detail().contains("measurement set"));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn payloads_beyond_10_tonnes_are_refused_before_any_work() {
    let t = setup().await;
    let (_, rid) = t.robot_with_identification_set().await;
    // The calibration that used to panic the worker.
    for p in ["1e308", "1e200", "10000.5", "-1"] {
        let r = t
            .send(
                "POST",
                "/v1/robots/{id}/calibrations",
                &[&rid],
                "",
                Some("application/json"),
                format!(r#"{{"methods": ["km"], "payload_kg": {p}}}"#).into_bytes(),
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{p}");
        assert!(r.detail().contains("payload_kg"), "{}", r.detail());
    }
    let r = t.get("/v1/robots/{id}/calibrations", &[&rid]).await;
    assert_eq!(r.json()["total"], 0, "no job was queued");
    // Uploads: the query, a JSON row, a CSV column.
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            "?payload_kg=1e308",
            Some("text/csv"),
            simulated_csv(6, 30).into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let mut rows = simulated_rows(7, 30, None);
    rows[3].payload_kg = Some(1e308);
    let r = t
        .post_json(
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            json!({ "rows": rows.iter().map(|r| json!({"q": r.q_deg, "xyz": r.xyz_mm, "payload_kg": r.payload_kg})).collect::<Vec<_>>() }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("row 4"), "{}", r.detail());
    let csv_text = csv::write(&rows);
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            "",
            Some("text/csv"),
            csv_text.into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    // Solve and robot models.
    let r = t
        .post_json(
            "/v1/robots/{id}/solve",
            &[&rid],
            json!({"version": "nominal", "payload_kg": 1e308, "targets": [{"x": 1500, "y": 0, "z": 1200}]}),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let mut model: Value = serde_json::from_str(&preset("ys100").unwrap().to_json()).unwrap();
    model["payload"]["mass_kg"] = json!(1e308);
    let r = t
        .post_json("/v1/robots", &[], json!({ "model": model }))
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
}

#[tokio::test]
async fn locale_csv_and_dif_sign_uploads_read_like_the_canonical_file() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let rows_of = |set: &Value| {
        let t = &t;
        let rid = rid.clone();
        let sid = set["id"].as_i64().unwrap().to_string();
        async move {
            let r = t
                .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid])
                .await;
            serde_json::from_value::<Vec<MeasuredPose>>(r.json()["rows"].clone()).unwrap()
        }
    };

    // `;`-separated with decimal commas (detected, and declared).
    let text = simulated_csv(5, 8);
    let semi: String = text
        .lines()
        .map(|l| l.replace(',', ";").replace('.', ","))
        .collect::<Vec<_>>()
        .join("\n");
    for query in ["", "?decimal=comma"] {
        let set = t.upload_csv(robot, &semi, query).await;
        assert_eq!(rows_of(&set).await, csv::parse(&text).unwrap(), "{query}");
    }

    // The real-data layout with the opposite `dif` sign.
    let real = "joint_1,joint_2,joint_3,joint_4,joint_5,joint_6,x_t,y_t,z_t,x_dif,y_dif,z_dif\n\
                10,80,-20,5,30,0,1500,100,1200,0.5,-0.25,1\n";
    let plus = rows_of(&t.upload_csv(robot, real, "").await).await;
    let minus = rows_of(&t.upload_csv(robot, real, "?dif_sign=minus").await).await;
    assert_eq!(plus[0].xyz_mm, [1500.5, 99.75, 1201.0]);
    assert_eq!(minus[0].xyz_mm, [1499.5, 100.25, 1199.0]);

    // Bad options name themselves; the delimiter is always detected.
    for (query, status, expect) in [
        ("?dif_sign=up", StatusCode::UNPROCESSABLE_ENTITY, "dif_sign"),
        ("?delimiter=;", StatusCode::BAD_REQUEST, "delimiter"),
    ] {
        let r = t
            .send(
                "POST",
                "/v1/robots/{id}/measurement-sets",
                &[&rid],
                query,
                Some("text/csv"),
                text.clone().into_bytes(),
            )
            .await;
        assert_eq!(r.status, status, "{query}");
        assert!(r.detail().contains(expect), "{query}: {}", r.detail());
    }
    // A declared decimal comma in a comma-separated file: quoted fields.
    let quoted = "q1,q2,q3,q4,q5,q6,x,y,z\n0,\"90,5\",0,0,0,0,\"1500,25\",0,1000\n";
    let set = t.upload_csv(robot, quoted, "?decimal=comma").await;
    let rows = rows_of(&set).await;
    assert_eq!((rows[0].q_deg[1], rows[0].xyz_mm[0]), (90.5, 1500.25));
    // The CSV reading options do not apply to JSON rows, which declare their
    // units in the body: `dif_sign` and `length_unit` change nothing.
    let sent = simulated_rows(6, 3, None);
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            "?dif_sign=minus&length_unit=m&angle_unit=rad",
            Some("application/json"),
            json!({ "rows": sent }).to_string().into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["units"], json!({"length": "mm", "angle": "deg"}));
    assert_eq!(rows_of(&r.json()).await, sent);
}

/// The `orientation` upload parameter declares the `rx, ry, rz` columns
/// intrinsic; quaternion columns are recognised by name. Both are stored as
/// the fixed-axis rows of the same rotation (built here with nalgebra's
/// rotations, not the reader's); std columns are kept; wrong declarations
/// and non-unit quaternions are 422s naming line and columns.
#[tokio::test]
async fn declared_orientation_conventions_and_std_columns_upload() {
    use nalgebra::{Rotation3, UnitQuaternion, Vector3};
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let rows_of = |set: &Value| {
        let t = &t;
        let rid = rid.clone();
        let sid = set["id"].as_i64().unwrap().to_string();
        async move {
            let r = t
                .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid])
                .await;
            serde_json::from_value::<Vec<MeasuredPose>>(r.json()["rows"].clone()).unwrap()
        }
    };
    let ax = |i: usize, deg: f64| {
        let a = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()][i];
        Rotation3::from_axis_angle(&a, f64::to_radians(deg))
    };
    // R = Rx(20)·Ry(-35)·Rz(110), the intrinsic X-Y'-Z'' angles.
    let r = ax(0, 20.0) * ax(1, -35.0) * ax(2, 110.0);
    let lead = "q1,q2,q3,q4,q5,q6,x,y,z";
    let vals = "10,80,-20,5,30,0,1500,100,1200";
    let intrinsic =
        format!("{lead},rx,ry,rz,std_x,std_y,std_z\n{vals},20,-35,110,0.02,0.02,0.05\n");
    let q = UnitQuaternion::from_rotation_matrix(&r);
    let quat = format!(
        "{lead},qw,qx,qy,qz\n{vals},{},{},{},{}\n",
        -q.w, -q.i, -q.j, -q.k
    );
    let stored = |rows: &[MeasuredPose]| {
        let [a, b, c] = rows[0].rpy_deg.unwrap().map(f64::to_radians);
        Rotation3::from_euler_angles(a, b, c)
    };
    let a = rows_of(
        &t.upload_csv(robot, &intrinsic, "?orientation=intrinsic_xyz")
            .await,
    )
    .await;
    assert!((stored(&a).matrix() - r.matrix()).amax() < 1e-12);
    assert_eq!(a[0].std_mm, Some([0.02, 0.02, 0.05]));
    let b = rows_of(&t.upload_csv(robot, &quat, "").await).await;
    assert!((stored(&b).matrix() - r.matrix()).amax() < 1e-12);
    // Undeclared, the same angles are fixed-axis and stored as written.
    let c = rows_of(&t.upload_csv(robot, &intrinsic, "").await).await;
    assert_eq!(c[0].rpy_deg, Some([20.0, -35.0, 110.0]));

    let bad_quat = format!("{lead},qw,qx,qy,qz\n{vals},1,0.1,0,0\n");
    for (text, query, expect) in [
        (
            intrinsic.as_str(),
            "?orientation=euler",
            "`orientation` must be one of fixed_xyz, intrinsic_xyz, quaternion",
        ),
        (
            intrinsic.as_str(),
            "?orientation=quaternion",
            "line 1: the orientation is declared quaternion",
        ),
        (
            quat.as_str(),
            "?orientation=intrinsic_xyz",
            "line 1: the orientation is declared intrinsic_xyz",
        ),
        (
            bad_quat.as_str(),
            "",
            "line 2, columns qw, qx, qy, qz: the quaternion's norm is 1.004988",
        ),
    ] {
        let r = t
            .send(
                "POST",
                "/v1/robots/{id}/measurement-sets",
                &[&rid],
                query,
                Some("text/csv"),
                text.as_bytes().to_vec(),
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{query}");
        assert!(r.detail().contains(expect), "{query}: {}", r.detail());
    }

    // The spec's enum is the convention enum's names.
    let yaml: serde_yaml::Value = serde_yaml::from_str(robocal::http::OPENAPI_YAML).unwrap();
    let doc = serde_json::to_value(yaml).unwrap();
    let params = doc["paths"]["/v1/robots/{id}/measurement-sets"]["post"]["parameters"]
        .as_array()
        .unwrap();
    let p = params.iter().find(|p| p["name"] == "orientation").unwrap();
    let names: Vec<&str> = robocal::measure::convention::MeasuredOrientation::ALL
        .iter()
        .map(|c| c.name())
        .collect();
    assert_eq!(p["schema"]["enum"], json!(names));

    // JSON rows read back (with their std) upload again unchanged.
    let r = t
        .post_json(
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            json!({ "rows": a }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(rows_of(&r.json()).await, a);
}

/// The issue's set: `length_unit: m` with standard deviations of 1e306 m
/// (1e309 mm, infinite once converted) was stored with a 201 and every GET
/// of it was then a 500. Bounds apply to the values as stored, in every
/// upload form: 422 naming the field (row or line and column), the value and
/// the bound, and nothing stored.
#[tokio::test]
async fn values_beyond_their_bound_once_converted_are_refused() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let rows = simulated_rows(8, 3, None);
    let row = |r: &MeasuredPose, std: [f64; 3]| json!({ "q": r.q_deg, "xyz": r.xyz_mm.map(|v| v / 1e3), "std_mm": std });
    let huge: Vec<Value> = rows.iter().map(|r| row(r, [1e306, 1e306, 1e306])).collect();
    let r = t
        .post_json(
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            json!({ "length_unit": "m", "rows": huge }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert_eq!(
        r.detail(),
        "row 1: `std_mm[0]` = 1e306 m is outside the bound [1e-8, 1] m"
    );
    // 2 m is 2000 mm: beyond the bound although 2 is a small number.
    let two: Vec<Value> = rows
        .iter()
        .map(|r| row(r, [0.00002, 2.0, 0.00002]))
        .collect();
    let r = t
        .post_json(
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            json!({ "length_unit": "m", "rows": two }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("`std_mm[1]` = 2 m"), "{}", r.detail());
    // Temperatures and orientation angles have bounds too.
    for (field, value, want) in [
        (
            "temperature_c",
            json!(1e300),
            "`temperature_c` = 1e300 °C is outside the bound [-100, 200] °C",
        ),
        (
            "rpy",
            json!([0, 720, 0]),
            "`rpy[1]` = 720 deg is outside the bound [-360, 360] deg",
        ),
    ] {
        let mut body = json!({ "q": rows[0].q_deg, "xyz": rows[0].xyz_mm });
        body[field] = value;
        let r = t
            .post_json(
                "/v1/robots/{id}/measurement-sets",
                &[&rid],
                json!({ "rows": [body] }),
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
        assert_eq!(r.detail(), format!("row 1: {want}"));
    }
    // The same set as a CSV in metres: the line and the column.
    let mut text = String::from("q1,q2,q3,q4,q5,q6,x,y,z,std_x,std_y,std_z\n");
    for r in &rows {
        let q: Vec<String> = r.q_deg.iter().map(f64::to_string).collect();
        let x: Vec<String> = r.xyz_mm.iter().map(|v| (v / 1e3).to_string()).collect();
        text.push_str(&format!(
            "{},{},1e306,1e306,1e306\n",
            q.join(","),
            x.join(",")
        ));
    }
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            "?length_unit=m",
            Some("text/csv"),
            text.into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert_eq!(
        r.detail(),
        "measurement CSV: line 2, column `std_x`: inf mm is outside [1e-5, 1000] mm"
    );
    // Nothing was stored; every set the robot has reads back.
    let r = t.get("/v1/robots/{id}/measurement-sets", &[&rid]).await;
    assert_eq!(r.json()["total"], 0, "{}", r.text());
}
