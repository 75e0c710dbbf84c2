//! The cell over HTTP: tools and work objects per robot (`/tools`, `/frames`),
//! program filtering (`/programs/filter`) checked against `robocal filter` on
//! the same model and cell file, and solves with a tool and a work object
//! checked against the core's `CellSolver`.

use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use robocal::cli::filter::{filter_to_string, FilterArgs};
use robocal::model::orientation::{rotation_from, OrientationConvention};
use robocal::model::Pose;
use robocal::solve::cell::{CellDescription, CellOptions, CellSolver};
use robocal::solve::ik::IkSettings;
use robocal_core::model::calibrated::CalibratedModelFile;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

const TOOLS: &str = "/v1/robots/{id}/tools";
const TOOL: &str = "/v1/robots/{id}/tools/{name}";
const FRAMES: &str = "/v1/robots/{id}/frames";
const FRAME: &str = "/v1/robots/{id}/frames/{name}";
const FILTER: &str = "/v1/robots/{id}/programs/filter";
const SOLVE: &str = "/v1/robots/{id}/solve";

pub(crate) fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/programs")
}

fn cell_file() -> Value {
    serde_json::from_str(&std::fs::read_to_string(examples().join("cell.json")).unwrap()).unwrap()
}

async fn put(t: &TestApp, template: &str, args: &[&str], body: Value) -> Resp {
    t.put_json(template, args, body).await
}

async fn delete(t: &TestApp, template: &str, args: &[&str]) -> Resp {
    t.send("DELETE", template, args, "", None, Vec::new()).await
}

#[tokio::test]
async fn tools_and_work_objects_are_stored_per_robot_by_unique_name_and_number() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let other = t.create_robot("ur5").await.to_string();

    let r = t.get(TOOLS, &[&rid]).await;
    assert_eq!(
        r.json(),
        json!({ "robot_id": rid.parse::<i64>().unwrap(), "tools": [] })
    );
    let torch = json!({ "number": 1, "xyz_mm": [125.0, 0.0, 216.5], "rpy_deg": [0.0, 30.0, 0.0] });
    let r = put(&t, TOOL, &[&rid, "torch"], torch.clone()).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["xyz_mm"], json!([125.0, 0.0, 216.5]));
    // Names are identities: another letter case is a conflict naming the
    // stored tool, never a rename; its own name replaces it, found in any case.
    let mut moved = torch.clone();
    moved["xyz_mm"] = json!([130.0, 0.0, 216.5]);
    let r = put(&t, TOOL, &[&rid, "TORCH"], moved.clone()).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("`torch`"), "{}", r.detail());
    let r = put(&t, TOOL, &[&rid, "torch"], moved).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let r = t.get(TOOL, &[&rid, "Torch"]).await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.json()["name"], "torch");
    assert_eq!(r.json()["xyz_mm"][0], 130.0);
    assert_eq!(r.json()["rpy_deg"], json!([0.0, 30.0, 0.0]));
    // A number is the robot's one tool's; another robot may use it.
    let r = put(
        &t,
        TOOL,
        &[&rid, "gripper"],
        json!({ "number": 1, "xyz_mm": [0, 0, 100] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("number 1"), "{}", r.detail());
    let r = put(
        &t,
        TOOL,
        &[&other, "gripper"],
        json!({ "number": 1, "xyz_mm": [0, 0, 100] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::CREATED);
    // Bad input: 422 naming what is wrong.
    for (name, body, part) in [
        ("gripper", json!({ "xyz_mm": [0, 0] }), "xyz_mm"),
        ("gripper", json!({ "xyz_mm": [0, 0, 1e6] }), "xyz_mm"),
        (
            "gripper",
            json!({ "xyz_mm": [0, 0, 1], "rpy_deg": [0, 400, 0] }),
            "rpy_deg",
        ),
        (
            "gripper",
            json!({ "xyz_mm": [0, 0, 1], "number": 1000 }),
            "number",
        ),
        (
            "gripper",
            json!({ "xyz_mm": [0, 0, 1], "frame": "base" }),
            "frame",
        ),
        (
            "gripper",
            json!({ "xyz_mm": [0, 0, 1], "name": "gripper" }),
            "name",
        ),
        ("bad%20name", json!({ "xyz_mm": [0, 0, 1] }), "name"),
    ] {
        let r = put(&t, TOOL, &[&rid, name], body.clone()).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
        assert!(r.detail().contains(part), "{body}: {}", r.detail());
    }
    // Unknown robot or item: 404.
    for r in [
        t.get(TOOLS, &["999"]).await,
        t.get(TOOL, &[&rid, "nothing"]).await,
        put(&t, TOOL, &["999", "torch"], torch.clone()).await,
        delete(&t, TOOL, &["999", "torch"]).await,
        delete(&t, TOOL, &[&rid, "nothing"]).await,
        put(&t, FRAMES, &["999"], json!({ "work_objects": [] })).await,
    ] {
        assert_eq!(r.status, StatusCode::NOT_FOUND, "{}", r.text());
    }

    // Work objects: the whole list at once, from a cell file.
    let cell = cell_file();
    let r = put(
        &t,
        FRAMES,
        &[&rid],
        json!({ "work_objects": cell["work_objects"] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let table = &r.json()["work_objects"][0];
    assert_eq!(
        (table["name"].as_str(), table["frame"].as_str()),
        (Some("table"), Some("base"))
    );
    let r = put(
        &t,
        FRAME,
        &[&rid, "fixture"],
        json!({ "number": 3, "frame": "measurement", "xyz_mm": [2000, 100, 0] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::CREATED);
    assert_eq!(r.json()["rpy_deg"], json!([0.0, 0.0, 0.0]));
    let r = t.get(FRAMES, &[&rid]).await;
    let names: Vec<String> = r.json()["work_objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["name"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(names, ["fixture", "table"]);
    // A list with a name or number twice conflicts with itself, an entry
    // without a name is invalid; either way nothing changes.
    for (list, status) in [
        (
            json!([{ "name": "a", "xyz_mm": [0, 0, 0] }, { "name": "A", "xyz_mm": [0, 0, 0] }]),
            StatusCode::CONFLICT,
        ),
        (
            json!([{ "name": "a", "number": 4, "xyz_mm": [0, 0, 0] }, { "name": "b", "number": 4, "xyz_mm": [0, 0, 0] }]),
            StatusCode::CONFLICT,
        ),
        (
            json!([{ "xyz_mm": [0, 0, 0] }]),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
    ] {
        let r = put(&t, FRAMES, &[&rid], json!({ "work_objects": list })).await;
        assert_eq!(r.status, status, "{list}");
    }
    assert_eq!(
        t.get(FRAMES, &[&rid]).await.json()["work_objects"]
            .as_array()
            .unwrap()
            .len(),
        2
    );
    // Delete, then it is gone; deleting the robot takes its cell with it.
    assert_eq!(
        delete(&t, FRAME, &[&rid, "FIXTURE"]).await.status,
        StatusCode::NO_CONTENT
    );
    assert_eq!(
        t.get(FRAME, &[&rid, "fixture"]).await.status,
        StatusCode::NOT_FOUND
    );
    assert_eq!(
        delete(&t, "/v1/robots/{id}", &[&other]).await.status,
        StatusCode::NO_CONTENT
    );
    assert_eq!(t.get(TOOLS, &[&other]).await.status, StatusCode::NOT_FOUND);
}

/// A YS100 with a km calibration of simulated measurements (active version 1)
/// and the cell of `examples/programs/cell.json`.
pub(crate) async fn calibrated_robot_with_cell(t: &TestApp) -> (i64, String) {
    let (robot, rid) = t.km_calibrated_robot().await;
    let cell = cell_file();
    let r = put(t, TOOLS, &[&rid], json!({ "tools": cell["tools"] })).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let r = put(
        t,
        FRAMES,
        &[&rid],
        json!({ "work_objects": cell["work_objects"] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    (robot, rid)
}

/// The robot's active model as a calibrated model file on disk.
pub(crate) async fn model_file(t: &TestApp, rid: &str, dir: &Path) -> PathBuf {
    let r = t
        .get("/v1/robots/{id}/versions/{version}/model.json", &[rid, "1"])
        .await;
    assert_eq!(r.status, StatusCode::OK);
    let path = dir.join("model.json");
    std::fs::write(&path, r.body).unwrap();
    path
}

fn file_json(path: &Path) -> Value {
    json!({
        "name": path.file_name().unwrap().to_str().unwrap(),
        "content": std::fs::read_to_string(path).unwrap(),
    })
}

#[tokio::test]
async fn a_program_filtered_over_http_is_what_robocal_filter_writes() {
    let t = setup().await;
    let (_, rid) = calibrated_robot_with_cell(&t).await;
    let dir = tempfile::tempdir().unwrap();
    let model = model_file(&t, &rid, dir.path()).await;
    let (src, dat) = (
        examples().join("krl/seam.src"),
        examples().join("krl/seam.dat"),
    );

    let r = t
        .post_json(
            FILTER,
            &[&rid],
            json!({ "language": "krl", "files": [file_json(&src), file_json(&dat)] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    assert_eq!(
        (http["version"].as_i64(), http["method"].as_str()),
        (Some(1), Some("km"))
    );

    // The CLI on the same model and cell file: the same files and report.
    let out_dir = dir.path().join("out");
    let cell_path = examples().join("cell.json");
    let argv = [
        "robocal",
        "filter",
        "--model",
        model.to_str().unwrap(),
        "--cell",
        cell_path.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        src.to_str().unwrap(),
        dat.to_str().unwrap(),
    ];
    let args: FilterArgs = match robocal::cli::Cli::try_parse_from(argv).unwrap().command {
        robocal::cli::Command::Filter(a) => a,
        other => panic!("{other:?}"),
    };
    let cli_report: Value = serde_json::from_str(&filter_to_string(&args).unwrap()).unwrap();
    assert_eq!(http["report"], cli_report);
    assert_eq!(cli_report["filtered"], 6, "{cli_report}");
    for f in http["files"].as_array().unwrap() {
        let name = f["name"].as_str().unwrap();
        let written = std::fs::read_to_string(out_dir.join(name)).unwrap();
        assert_eq!(f["content"].as_str().unwrap(), written, "{name}");
    }
    // The targets moved: the filtered .dat differs from the input.
    assert_ne!(
        http["files"][1]["content"].as_str().unwrap(),
        std::fs::read_to_string(&dat).unwrap()
    );

    // A program without targets comes back byte for byte.
    let plain = "DEF idle()\r\n  ; no motion here\r\n  $OUT[2] = TRUE\r\n  WAIT SEC 0.5\r\nEND\r\n";
    let r = t
        .post_json(
            FILTER,
            &[&rid],
            json!({ "language": "krl", "files": [{ "name": "idle.src", "content": plain }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["files"][0]["content"].as_str(), Some(plain));
    assert_eq!(r.json()["report"]["targets"], json!([]));

    // A program that cannot be parsed: 422 with file, line and column.
    let r = t
        .post_json(
            FILTER,
            &[&rid],
            json!({ "language": "krl", "files": [{ "name": "bad.src", "content": "DEF bad()\nLIN {X 1,\nEND\n" }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    let p = r.json();
    assert_eq!(p["type"], "urn:robocal:problem:unparsable-program");
    assert_eq!(
        (p["file"].as_str(), p["line"].as_u64()),
        (Some("bad.src"), Some(2))
    );
    assert!(p["column"].as_u64().unwrap() >= 1);
    // Other refusals.
    for (body, status) in [
        (
            json!({ "language": "krl", "files": [] }),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({ "files": [{ "name": "a.src", "content": "" }] }),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({ "language": "krl", "files": [{ "name": "a/b.src", "content": "" }] }),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({ "files": [{ "name": "a.src", "content": "" }], "language": "cobol" }),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({ "language": "krl", "files": [{ "name": "a.src", "content": "" }], "version": 7 }),
            StatusCode::CONFLICT,
        ),
    ] {
        let r = t.post_json(FILTER, &[&rid], body.clone()).await;
        assert_eq!(r.status, status, "{body}: {}", r.text());
    }
    let r = t
        .post_json(
            FILTER,
            &["999"],
            json!({ "language": "krl", "files": [file_json(&src)] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
}

/// The TCP of the tool "torch" of a cell file.
fn torch(cell: &Value) -> Pose {
    let cell = CellDescription::from_json(&cell.to_string())
        .unwrap()
        .to_cell()
        .unwrap();
    cell.tool(&robocal::solve::cell::CellRef::Name("torch".into()))
        .unwrap()
        .tcp
}

/// The cell options of the branch the solves below ask for.
fn front_up_noflip() -> CellOptions {
    CellOptions {
        branch: Some(robocal::solve::ik::Configuration::parse("front,up,noflip").unwrap()),
        seed: None,
    }
}

fn pose_of(xyz_mm: [f64; 3], abc_deg: [f64; 3]) -> Pose {
    let r = rotation_from(OrientationConvention::KukaAbc, &abc_deg).unwrap();
    Pose::new(r, nalgebra::Vector3::from(xyz_mm) * 1e-3)
}

#[tokio::test]
async fn a_solve_with_a_tool_and_a_work_object_is_the_cell_solvers() {
    let t = setup().await;
    let (_, rid) = calibrated_robot_with_cell(&t).await;
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(model_file(&t, &rid, dir.path()).await).unwrap();
    let model = CalibratedModelFile::from_json(&text)
        .unwrap()
        .to_compensated()
        .unwrap();
    let cell = CellDescription::from_json(&cell_file().to_string())
        .unwrap()
        .to_cell()
        .unwrap();
    let wobj = cell
        .work_object(&robocal::solve::cell::CellRef::Number(2))
        .unwrap();
    let solver = CellSolver::new(&model, &torch(&cell_file()), IkSettings::default());

    let targets = [
        ([0.0, 0.0, 0.0], [0.0, 0.0, 180.0]),
        ([100.0, 150.0, 30.0], [10.0, 5.0, 175.0]),
    ];
    let body_targets: Vec<Value> = targets
        .iter()
        .map(|(p, o)| json!({ "x": p[0], "y": p[1], "z": p[2], "orientation": { "values": o } }))
        .collect();
    let stored = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({ "targets": body_targets, "convention": "kuka_abc", "tool": "torch", "work_object": "table", "branch": "front,up,noflip" }),
        )
        .await;
    assert_eq!(stored.status, StatusCode::OK, "{}", stored.text());
    let stored = stored.json();
    assert_eq!(stored["frame"], "work_object");
    let c = &cell_file();
    let inline = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({ "targets": body_targets, "convention": "kuka_abc", "branch": "front,up,noflip",
                    "tool": { "xyz_mm": c["tools"][0]["xyz_mm"], "rpy_deg": c["tools"][0]["rpy_deg"] },
                    "work_object": { "xyz_mm": c["work_objects"][0]["xyz_mm"], "rpy_deg": c["work_objects"][0]["rpy_deg"] } }),
        )
        .await
        .json();
    for (i, (p, o)) in targets.iter().enumerate() {
        let want = solver.solve(&wobj, &pose_of(*p, *o), &front_up_noflip());
        assert!(want.solution.converged);
        let ft = want.false_target.unwrap();
        for got in [&stored["results"][i], &inline["results"][i]] {
            assert_eq!(got["status"], "ok", "{got}");
            let f = &got["false_target"];
            let xyz: Vec<f64> = ["x", "y", "z"]
                .iter()
                .map(|k| f[k].as_f64().unwrap())
                .collect();
            let d = ((xyz[0] - ft.p.x * 1e3).powi(2)
                + (xyz[1] - ft.p.y * 1e3).powi(2)
                + (xyz[2] - ft.p.z * 1e3).powi(2))
            .sqrt();
            assert!(
                d < 1e-6,
                "target {i}: false target {xyz:?} vs {:?} mm",
                ft.p * 1e3
            );
            let vals: Vec<f64> = f["values"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let r = rotation_from(OrientationConvention::KukaAbc, &vals).unwrap();
            assert!((r - ft.r).norm() < 1e-9, "target {i}");
        }
        // The false target differs from the target by the calibration.
        assert!(((ft.p * 1e3) - nalgebra::Vector3::from(*p)).norm() > 0.01);
    }
    // A stored name that the robot lacks is a 404; with a work object
    // `frame` does not apply.
    let r = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({ "targets": [{ "x": 0, "y": 0, "z": 0 }], "tool": "spindle" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND, "{}", r.text());
    let r = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({ "targets": [body_targets[0]], "convention": "kuka_abc", "tool": "torch",
                    "work_object": "table", "branch": "front,up,noflip", "frame": "base" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(
        r.json()["results"][0]["false_target"],
        stored["results"][0]["false_target"]
    );
    // Solvers are kept per tool: the torch moved by 10 mm along its z axis
    // solves as the cell solver of the moved torch, not the kept one.
    let mut tools = c["tools"].clone();
    let z = tools[0]["xyz_mm"][2].as_f64().unwrap();
    tools[0]["xyz_mm"][2] = json!(z + 10.0);
    let r = put(&t, TOOLS, &[&rid], json!({ "tools": tools })).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let moved = torch(&json!({ "tools": tools }));
    let want = CellSolver::new(&model, &moved, IkSettings::default()).solve(
        &wobj,
        &pose_of(targets[0].0, targets[0].1),
        &front_up_noflip(),
    );
    let ft = want.false_target.unwrap();
    let r = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({ "targets": [body_targets[0]], "convention": "kuka_abc", "tool": "torch",
                    "work_object": "table", "branch": "front,up,noflip" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let f = &r.json()["results"][0]["false_target"];
    let xyz = crate::common::json_xyz(f);
    assert!(
        (xyz - ft.p * 1e3).norm() < 1e-6,
        "{xyz} vs {} mm",
        ft.p * 1e3
    );
    assert_ne!(f, &stored["results"][0]["false_target"]);
}

#[tokio::test]
async fn a_tool_carries_its_load_and_the_cell_exports_for_the_controller() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    // 12 kg, 100 mm back from the TCP along the torch (tool frame): 150 mm
    // along it from the flange, tilted 30° about y.
    let load = json!({ "mass_kg": 12.0, "com_mm": [0.0, 0.0, -100.0], "frame": "tool" });
    let body = json!({ "number": 1, "xyz_mm": [125.0, 0.0, 216.50635094610965], "rpy_deg": [0.0, 30.0, 0.0], "load": load });
    let r = put(&t, TOOL, &[&rid, "torch"], body).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let r = t.get(TOOL, &[&rid, "torch"]).await;
    assert_eq!(r.json()["load"], load);
    // A load is a tool's; its values are bounded.
    for (kind, body, part) in [
        (
            FRAME,
            json!({ "xyz_mm": [0, 0, 1], "load": { "mass_kg": 1.0 } }),
            "only a tool",
        ),
        (
            TOOL,
            json!({ "xyz_mm": [0, 0, 1], "load": { "mass_kg": -1.0 } }),
            "mass_kg",
        ),
        (
            TOOL,
            json!({ "xyz_mm": [0, 0, 1], "load": { "mass_kg": 1.0, "frame": "wrist" } }),
            "wrist",
        ),
    ] {
        let r = put(&t, kind, &[&rid, "x"], body).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
        assert!(r.text().contains(part), "{}", r.text());
    }
    let r = put(
        &t,
        FRAME,
        &[&rid, "table"],
        json!({ "number": 2, "xyz_mm": [1300.0, -600.0, 300.0], "rpy_deg": [0.0, 0.0, 20.0] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let r = t
        .post_json(
            "/v1/robots/{id}/cell/export",
            &[&rid],
            json!({ "language": "krl", "version": "nominal" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let text = r.json()["text"].as_str().unwrap().to_string();
    assert!(
        text.contains("LOAD_DATA[1]={M 12.000000,CM {X 75.000000,Y 0.000000,Z 129.903811,"),
        "{text}"
    );
    assert!(text.contains("BASE_DATA[2]={X 1300.000000,Y -600.000000,Z 300.000000,A 20.000000000,B 0.000000000,C 0.000000000}"), "{text}");
    let r = t
        .post_json(
            "/v1/robots/{id}/cell/export",
            &[&rid],
            json!({ "language": "cobol", "version": "nominal" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
}

#[tokio::test]
async fn the_cell_exports_one_number_per_item_and_registers_only_when_asked() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let items = [
        (
            TOOL,
            "gun",
            json!({ "number": 2, "xyz_mm": [0.0, 0.0, 200.0] }),
        ),
        (TOOL, "torch", json!({ "xyz_mm": [0.0, 0.0, 300.0] })),
        (
            FRAME,
            "table",
            json!({ "number": 1, "xyz_mm": [1000.0, 0.0, 0.0] }),
        ),
        (FRAME, "fixture", json!({ "xyz_mm": [1500.0, 0.0, 0.0] })),
    ];
    for (kind, name, body) in &items {
        let r = put(&t, kind, &[&rid, name], body.clone()).await;
        assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    }
    let export = |body: Value| {
        let t = &t;
        let rid = rid.clone();
        async move {
            t.post_json("/v1/robots/{id}/cell/export", &[&rid], body)
                .await
        }
    };
    let r = export(json!({ "language": "krl", "version": "nominal" })).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let krl = r.json();
    let text = krl["text"].as_str().unwrap().to_string();
    for data in [
        "TOOL_DATA[1]=",
        "TOOL_DATA[2]=",
        "BASE_DATA[1]=",
        "BASE_DATA[2]=",
    ] {
        assert_eq!(text.matches(data).count(), 1, "{data}: {text}");
    }
    assert_eq!(
        krl["assigned"],
        json!([{ "kind": "tool", "name": "torch", "number": 1 }, { "kind": "work_object", "name": "fixture", "number": 2 }])
    );
    // The command line on the same cell (written in another order) gives
    // the same text.
    let dir = tempfile::tempdir().unwrap();
    let mut file = json!({ "tools": [], "work_objects": [] });
    for (kind, name, body) in items.iter().rev() {
        let mut b = body.clone();
        b["name"] = json!(name);
        let list = if *kind == TOOL {
            "tools"
        } else {
            "work_objects"
        };
        file[list].as_array_mut().unwrap().push(b);
    }
    let cell_path = dir.path().join("cell.json");
    std::fs::write(&cell_path, file.to_string()).unwrap();
    let cli = |language: &str, more: &[&str]| {
        let argv = [
            &[
                "robocal",
                "cell",
                "export",
                "--model",
                "ys100",
                "--cell",
                cell_path.to_str().unwrap(),
                "--language",
                language,
            ][..],
            more,
        ]
        .concat();
        let robocal::cli::Command::Cell(a) =
            robocal::cli::Cli::try_parse_from(argv).unwrap().command
        else {
            panic!("cell")
        };
        let robocal::cli::cell::CellCommand::Export(e) = a.command;
        robocal::cli::cell::export_to_string(&e)
    };
    assert_eq!(cli("krl", &[]).unwrap(), text);
    // Fanuc: no register without `registers`; the ones given, stated.
    let r = export(json!({ "language": "fanuc", "version": "nominal" })).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    assert!(!b["text"].as_str().unwrap().contains("PR["), "{b}");
    assert_eq!(b["registers"], json!([]));
    let r = export(json!({ "language": "fanuc", "version": "nominal", "registers": { "first": 91, "last": 99 } })).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    let tp = b["text"].as_str().unwrap();
    assert!(tp.contains("! robocal overwrites PR[91..94] ;"), "{tp}");
    assert_eq!(
        b["registers"][0],
        json!({ "register": 91, "kind": "tool", "name": "torch" })
    );
    assert_eq!(b["registers"].as_array().unwrap().len(), 4);
    assert_eq!(cli("fanuc", &["--registers", "91..99"]).unwrap(), tp);
    // The range is the request's, the items the robot's: too short is a conflict.
    let r = export(json!({ "language": "fanuc", "version": "nominal", "registers": { "first": 91, "last": 92 } })).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("needs 4 position registers"),
        "{}",
        r.detail()
    );
    // RAPID: a tool and a work object of one name are declared apart.
    let r = put(
        &t,
        FRAME,
        &[&rid, "torch"],
        json!({ "xyz_mm": [0.0, 500.0, 0.0] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let r = export(json!({ "language": "rapid", "version": "nominal" })).await;
    let b = r.json();
    let module = b["text"].as_str().unwrap();
    assert!(
        module.contains("PERS tooldata torch:=") && module.contains("PERS wobjdata torch_2:="),
        "{module}"
    );
    assert_eq!(b["renamed"][0]["identifier"], "torch_2", "{b}");
    assert_eq!(
        b["renamed"][0]["taken_by"],
        json!({ "kind": "tool", "name": "torch" }),
        "{b}"
    );
    // Number 0 is the flange on KRL: a conflict naming the tool.
    let r = put(
        &t,
        TOOL,
        &[&rid, "gun"],
        json!({ "number": 0, "xyz_mm": [0.0, 0.0, 200.0] }),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let r = export(json!({ "language": "krl", "version": "nominal" })).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("tool `gun` has number 0"),
        "{}",
        r.detail()
    );
}
