//! What a careless or hostile user sends (issue 35): models beyond physical
//! bounds, names with control characters, CSV cells a spreadsheet would run,
//! a name in another letter case.

use crate::support::*;
use axum::http::StatusCode;
use serde_json::{json, Value};

const ROBOTS: &str = "/v1/robots";
const SOLVE: &str = "/v1/robots/{id}/solve";
const TOOL: &str = "/v1/robots/{id}/tools/{name}";

/// The ys100 preset's description with `edit` applied.
fn model_with(edit: impl Fn(&mut Value)) -> Value {
    let d = robocal::model::presets::preset_description("ys100").unwrap();
    let mut v = serde_json::to_value(d).unwrap();
    edit(&mut v);
    v
}

/// A change to a model's JSON.
type Edit = Box<dyn Fn(&mut Value)>;

/// The models get 422 naming the field, its value and the bound.
#[tokio::test]
async fn models_beyond_physical_bounds_are_refused_naming_field_value_and_bound() {
    let t = setup().await;
    let cases: Vec<(&str, &str, Edit)> = vec![
        (
            "tool.xyz_mm[0]",
            "1e308",
            Box::new(|v| v["tool"]["xyz_mm"] = json!([1e308, 0, 0])),
        ),
        (
            "joints[1].compliance_rad_per_nm",
            "1e308",
            Box::new(|v| v["joints"][1]["compliance_rad_per_nm"] = json!(1e308)),
        ),
        (
            "joints[2].d_mm",
            "1e308",
            Box::new(|v| v["joints"][2]["d_mm"] = json!(1e308)),
        ),
        (
            "joints[1].a_mm",
            "1e15",
            Box::new(|v| v["joints"][1]["a_mm"] = json!(1e15)),
        ),
        (
            "joints[3].mass_kg",
            "1e308",
            Box::new(|v| v["joints"][3]["mass_kg"] = json!(1e308)),
        ),
        (
            "joints[0].limits_deg[0]",
            "-1e308",
            Box::new(|v| v["joints"][0]["limits_deg"] = json!([-1e308, 1e308])),
        ),
        (
            "joints[0].zero_deg",
            "1e308",
            Box::new(|v| v["joints"][0]["zero_deg"] = json!(1e308)),
        ),
    ];
    for (field, value, edit) in cases {
        let r = t
            .post_json(ROBOTS, &[], json!({ "model": model_with(edit) }))
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{field}");
        let d = r.detail();
        assert!(d.contains(&format!("`{field}`")), "{field}: {d}");
        assert!(d.contains(&format!(" {value} ")), "{field}: {d}");
        assert!(d.contains("outside the bound ["), "{field}: {d}");
    }
    // At the bound it is accepted.
    let r = t
        .post_json(
            ROBOTS,
            &[],
            json!({ "model": model_with(|v| v["tool"]["xyz_mm"] = json!([100000, 0, 0])) }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
}

/// A robot name with a line break (which would inject a CSV row) is 422,
/// in the body's `name` and in the model's.
#[tokio::test]
async fn names_with_control_characters_are_refused() {
    let t = setup().await;
    for body in [
        json!({ "preset": "ys100", "name": "arm\n=1+1,evil" }),
        json!({ "preset": "ys100", "name": "arm\rx" }),
        json!({ "preset": "ys100", "name": "tab\there" }),
        json!({ "model": model_with(|v| v["name"] = json!("two\nlines")) }),
    ] {
        let r = t.post_json(ROBOTS, &[], body.clone()).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
        assert!(r.detail().contains("control characters"), "{}", r.detail());
    }
    let r = t
        .post_json(
            ROBOTS,
            &[],
            json!({ "preset": "ys100", "name": "=cmd|' /C calc'!A0" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "a formula-like name is text");
}

/// Target ids a spreadsheet would run come back as text in a CSV answer; an
/// id that is a plain number and every numeric column stay numbers (a
/// negative coordinate is `-…`, not text).
#[tokio::test]
async fn formula_cells_in_a_solve_csv_answer_are_neutralised() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let text = "id,x,y,z\n\"=cmd|' /C calc'!A0\",1500,0,1200\n+SUM(1;2),1500,100,1200\n@x,1500,-100,1200\n-2,1500,0,1300\nplain,1500,0,1250\n";
    let r = t
        .send_with(
            "POST",
            SOLVE,
            &[&rid],
            "?version=nominal&position_only=true",
            &[("content-type", "text/csv"), ("accept", "text/csv")],
            text.as_bytes().to_vec(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let answer = r.text();
    let ids: Vec<String> = answer
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect();
    assert_eq!(
        ids,
        ["'=cmd|' /C calc'!A0", "'+SUM(1;2)", "'@x", "-2", "plain"],
        "{answer}"
    );
    // The answer read as CSV: ids back as sent, numbers as numbers.
    let table = robocal::measure::csv_text::read(&answer, Default::default())
        .unwrap()
        .unwrap();
    let col = |name: &str| table.header.iter().position(|h| h == name).unwrap();
    let sent = ["=cmd|' /C calc'!A0", "+SUM(1;2)", "@x", "-2", "plain"];
    let status = col("status");
    assert_eq!(table.records.len(), sent.len());
    for (r, id) in table.records.iter().zip(sent) {
        assert_eq!(robocal_core::csv_write::read_text(&r.fields[0]), id);
        assert_eq!(r.fields[status], "ok", "{answer}");
        for name in [
            "j1_deg",
            "false_x_mm",
            "false_y_mm",
            "false_z_mm",
            "position_residual_mm",
        ] {
            let v = &r.fields[col(name)];
            assert!(table.number(v).is_some(), "{name} `{v}` in {answer}");
        }
    }
    let y = col("false_y_mm");
    assert!(
        table.records.iter().any(|r| r.fields[y].starts_with('-')),
        "a negative false y: {answer}"
    );
}

/// PUT of a tool name that exists in another letter case is a 409 naming
/// the existing tool; the tool is unchanged.
#[tokio::test]
async fn a_name_in_another_case_is_a_conflict_not_a_rename() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let put = |name: &'static str, body: Value| {
        let t = &t;
        let rid = rid.clone();
        async move {
            t.send(
                "PUT",
                TOOL,
                &[&rid, name],
                "",
                Some("application/json"),
                body.to_string().into_bytes(),
            )
            .await
        }
    };
    let r = put(
        "torch",
        json!({ "number": 1, "xyz_mm": [125, 0, 216.5], "rpy_deg": [0, 30, 0] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let r = put(
        "TORCH",
        json!({ "xyz_mm": [0, 0, 0], "rpy_deg": [0, 0, 0] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("`torch`"), "{}", r.detail());
    let r = t.get(TOOL, &[&rid, "torch"]).await;
    assert_eq!(r.status, StatusCode::OK);
    let tool = r.json();
    assert_eq!(tool["name"], "torch");
    assert_eq!(tool["number"], 1);
    assert_eq!(tool["xyz_mm"], json!([125.0, 0.0, 216.5]));
    // The same name in its own case still replaces it.
    let r = put(
        "torch",
        json!({ "number": 1, "xyz_mm": [126, 0, 216.5], "rpy_deg": [0, 30, 0] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
}
