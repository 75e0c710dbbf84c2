//! Measurement plans over HTTP (`/measurement-plans`): the same plan as the
//! core's `make_plan` on the robot's nominal model (independent path: the
//! library), its program parsing back to its joints, the constraints honoured
//! by forward kinematics, and clear errors.

use crate::support::*;
use axum::http::StatusCode;
use robocal::model::kinematics::fk;
use robocal::model::preset;
use robocal::plan::{make_plan, read_plan_csv, PlanSettings, TrackerSight, WorkspaceBox};
use robocal::program::{parse, Language, ProgramFile};
use serde_json::json;

const PLANS: &str = "/v1/robots/{id}/measurement-plans";

#[tokio::test]
async fn a_plan_over_http_is_the_core_plan_and_its_program_parses_back() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let body = json!({
        "poses": 30,
        "workspace": { "min_mm": [500, -1500, 0], "max_mm": [2500, 1500, 2000] },
        "tracker": { "position_mm": [4000, 0, 1000], "max_angle_deg": 60 },
        "noise_mm": 0.02,
        "seed": 4,
        "language": "krl",
        "name": "cal_poses",
        "wait_s": 2
    });
    let r = t.post_json(PLANS, &[&rid], body).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let v = r.json();
    // The library on the same nominal model and settings.
    let nominal = preset("ys100").unwrap();
    let want = make_plan(
        &nominal,
        &PlanSettings {
            poses: 30,
            workspace: Some(WorkspaceBox {
                min_mm: [500.0, -1500.0, 0.0],
                max_mm: [2500.0, 1500.0, 2000.0],
            }),
            tracker: Some(TrackerSight {
                position_mm: [4000.0, 0.0, 1000.0],
                axis: [0.0, 0.0, 1.0],
                max_angle_deg: 60.0,
            }),
            noise_mm: 0.02,
            seed: 4,
            ..PlanSettings::default()
        },
    )
    .unwrap();
    assert_eq!(v["poses"], 30);
    assert_eq!(
        serde_json::to_value(&want.points).unwrap(),
        v["points"],
        "points"
    );
    assert_eq!(
        serde_json::to_value(&want.predicted).unwrap(),
        v["predicted"]
    );
    assert_eq!(serde_json::to_value(want.counts).unwrap(), v["counts"]);
    // The CSV reads back to the points.
    let csv = read_plan_csv(v["joints_csv"].as_str().unwrap()).unwrap();
    assert_eq!(csv, want.points);
    // Every pose inside the box, by forward kinematics of the model joints.
    for q in &want.q {
        let p = fk(&nominal, q).unwrap().p * 1e3;
        assert!(
            (500.0..=2500.0).contains(&p.x)
                && (-1500.0..=1500.0).contains(&p.y)
                && (0.0..=2000.0).contains(&p.z),
            "{p:?}"
        );
    }
    // The program parses back to the same joints, with a wait at each.
    assert_eq!(v["program"]["language"], "krl");
    let files: Vec<ProgramFile> = v["program"]["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| ProgramFile {
            name: f["name"].as_str().unwrap().into(),
            text: f["content"].as_str().unwrap().into(),
        })
        .collect();
    assert!(files[0].text.contains("cal_poses"));
    let back = parse(Language::Krl, &files).unwrap();
    assert_eq!(back.joints.len(), 30);
    for (j, p) in back.joints.iter().zip(&want.points) {
        for (a, b) in j.deg.iter().zip(&p.q_deg) {
            assert!((a - b).abs() < 1e-4, "{:?} vs {:?}", j.deg, p.q_deg);
        }
    }
}

#[tokio::test]
async fn plan_requests_that_cannot_be_met_say_why() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    // No program asked: none returned.
    let r = t.post_json(PLANS, &[&rid], json!({ "poses": 20 })).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert!(r.json()["program"].is_null());
    for (body, words) in [
        (json!({ "poses": 20, "candidates": 10 }), "`candidates`"),
        (
            json!({ "workspace": { "min_mm": [0, 0, 0], "max_mm": [0, 1, 1] } }),
            "below max_mm",
        ),
        (
            json!({ "poses": 10, "workspace": { "min_mm": [90000, 0, 0], "max_mm": [90001, 1, 1] } }),
            "inside the box",
        ),
        (json!({ "wait_s": 3 }), "give `language`"),
        (json!({ "language": "gcode" }), "`language`"),
        (
            json!({ "tracker": { "position_mm": [1, 2, 3], "axis": [0, 0, 0], "max_angle_deg": 30 } }),
            "`tracker.axis`",
        ),
    ] {
        let r = t.post_json(PLANS, &[&rid], body.clone()).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
        assert!(r.text().contains(words), "{body}: {}", r.text());
    }
    let r = t.post_json(PLANS, &["999999"], json!({})).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
}

/// A plan over a track over HTTP is `robocal plan --track` on the same
/// track file: the joints CSV and the program byte for byte, the points
/// with their track values and the stations' σ the library's; requests the
/// track cannot carry are 422s naming why.
#[tokio::test]
async fn a_plan_over_a_track_is_the_command_lines() {
    use clap::Parser;
    use robocal::plan::{make_track_plan, TrackPlanSettings};
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let drawing = robocal::sim::track::TrueTrack::drawing_4m();
    let track: serde_json::Value = serde_json::from_str(&drawing.to_json()).unwrap();
    let body = json!({
        "track": track,
        "stations": 6,
        "travel_mm": [500, 3500],
        "tracker": { "position_mm": [0, 0, 0], "max_angle_deg": 60 },
        "seed": 7,
        "language": "rapid",
        "name": "rail_plan",
    });
    let r = t.post_json(PLANS, &[&rid], body).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let v = r.json();
    assert_eq!(v["poses"], 24);
    assert_eq!(v["column"], "e1");
    assert!(
        v.get("predicted").is_none() && v.get("payload_kg").is_none(),
        "{v}"
    );
    // The command line on the same track file.
    let d = tempfile::tempdir().unwrap();
    let file = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    std::fs::write(file("rail.json"), drawing.to_json()).unwrap();
    let argv = [
        "robocal",
        "plan",
        "--model",
        "ys100",
        "--track",
        &file("rail.json"),
        "--stations",
        "6",
        "--travel",
        "500,3500",
        "--tracker",
        "0,0,0",
        "--seed",
        "7",
        "--format",
        "rapid",
        "--name",
        "rail_plan",
        "--wait-s",
        "1",
        "--out",
        &file("plan.mod"),
        "--csv",
        &file("plan.csv"),
    ];
    let robocal::cli::Command::Plan(a) = robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        panic!("not a plan")
    };
    robocal::cli::plan::make(&a.make).unwrap();
    let read = |n: &str| std::fs::read_to_string(file(n)).unwrap();
    assert_eq!(v["joints_csv"].as_str().unwrap(), read("plan.csv"));
    assert_eq!(v["program"]["files"][0]["name"], "rail_plan.mod");
    assert_eq!(
        v["program"]["files"][0]["content"].as_str().unwrap(),
        read("plan.mod")
    );
    // The library's plan: points with their values, the stations' σ.
    let want = make_track_plan(
        &preset("ys100").unwrap(),
        &drawing,
        &TrackPlanSettings {
            stations: Some(6),
            travel_mm: Some([500.0, 3500.0]),
            poses: PlanSettings {
                poses: 4,
                tracker: Some(TrackerSight {
                    position_mm: [0.0; 3],
                    ..TrackerSight::default()
                }),
                seed: 7,
                ..PlanSettings::default()
            },
            ..TrackPlanSettings::default()
        },
    )
    .unwrap();
    assert_eq!(serde_json::to_value(&want.points).unwrap(), v["points"]);
    assert_eq!(v["points"][4]["external"], json!({ "e1": 1100.0 }));
    assert_eq!(serde_json::to_value(&want.stations).unwrap(), v["stations"]);
    // Refused, naming why.
    for (body, words) in [
        (json!({ "stations": 8 }), "give `track` too"),
        (json!({ "track": { "direction": [1, 0, 0] } }), "`track`"),
        (
            json!({ "track": track, "stations": 4 }),
            "at least 5 stations",
        ),
        (json!({ "track": track, "poses": 2 }), "at least 3 poses"),
        (
            json!({ "track": track, "travel_mm": [0, 5000] }),
            "beyond the track model's",
        ),
        (
            json!({ "track": track, "stations": 80 }),
            "at most 100 stations and 300 poses",
        ),
        (json!({ "track": track, "column": "e9" }), "`column`"),
        (
            json!({ "track": track, "language": "urscript" }),
            "no external axes",
        ),
    ] {
        let r = t.post_json(PLANS, &[&rid], body.clone()).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
        assert!(r.text().contains(words), "{body}: {}", r.text());
    }
}

/// A positioner's plan over HTTP is `robocal plan --positioner` on the same
/// nominal file: the CSV byte for byte, the points and predicted σ the
/// library's; what does not apply to a positioner is a 422 naming it.
#[tokio::test]
async fn a_positioners_plan_is_the_command_lines() {
    use clap::Parser;
    use robocal::plan::{make_positioner_plan, PositionerPlanSettings};
    use robocal::sim::positioner_example as example;
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let nominal = example::nominal();
    let description: serde_json::Value = serde_json::from_str(&nominal.to_json()).unwrap();
    let positioner = json!({
        "nominal": description,
        "reflectors": [[400, 0, 20], [-150, 100, 20]],
        "tilt_deg": [-60, 60],
        "tilt_values": 7,
    });
    let r = t
        .post_json(
            PLANS,
            &[&rid],
            json!({ "positioner": positioner, "noise_mm": 0.02 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let v = r.json();
    assert_eq!(v["poses"], 19);
    assert!(
        v.get("counts").is_none() && v.get("predicted").is_none(),
        "{v}"
    );
    let d = tempfile::tempdir().unwrap();
    let file = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    std::fs::write(file("stn.json"), nominal.to_json()).unwrap();
    let argv = [
        "robocal",
        "plan",
        "--positioner",
        &file("stn.json"),
        "--reflector",
        "400,0,20",
        "--reflector",
        "-150,100,20",
        "--tilt",
        "-60,60",
        "--tilt-values",
        "7",
        "--noise-mm",
        "0.02",
        "--out",
        &file("plan.csv"),
    ];
    let robocal::cli::Command::Plan(a) = robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        panic!("not a plan")
    };
    robocal::cli::plan::make(&a.make).unwrap();
    let csv = std::fs::read_to_string(file("plan.csv")).unwrap();
    assert_eq!(v["joints_csv"].as_str().unwrap(), csv);
    assert!(csv.starts_with("point,e1,e2\n"));
    // Its program (the positioner's axes alone), as `--format rapid` writes it.
    let r = t
        .post_json(
            PLANS,
            &[&rid],
            json!({ "positioner": positioner, "noise_mm": 0.02, "language": "rapid", "name": "stn", "wait_s": 2 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let mut with_program = argv.to_vec();
    let out = file("stn.mod");
    with_program.extend(["--format", "rapid", "--name", "stn", "--wait-s", "2"]);
    *with_program
        .iter_mut()
        .find(|a| a.ends_with("plan.csv"))
        .unwrap() = &out;
    let robocal::cli::Command::Plan(b) = robocal::cli::Cli::try_parse_from(&with_program)
        .unwrap()
        .command
    else {
        panic!("not a plan")
    };
    robocal::cli::plan::make(&b.make).unwrap();
    let program = r.json()["program"].clone();
    assert_eq!(program["language"], "rapid");
    assert_eq!(
        program["files"][0]["content"].as_str().unwrap(),
        std::fs::read_to_string(&out).unwrap()
    );
    assert!(program["files"][0]["content"]
        .as_str()
        .unwrap()
        .contains("MoveExtJ [[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09],[0.0000,-165.0000,9E+09,9E+09,9E+09,9E+09]], vrot10, fine; ! P1"));
    let want = make_positioner_plan(
        &nominal,
        &PositionerPlanSettings {
            reflectors_mm: example::DESIGN_MM.to_vec(),
            tilt_deg: [-60.0, 60.0],
            tilt_values: 7,
            noise_mm: 0.02,
            ..PositionerPlanSettings::default()
        },
    )
    .unwrap();
    assert_eq!(serde_json::to_value(&want.points).unwrap(), v["points"]);
    assert_eq!(
        v["points"][0],
        json!({ "name": "P1", "q_deg": [], "external": { "e1": 0.0, "e2": -165.0 } })
    );
    assert_eq!(serde_json::to_value(want.sigma).unwrap(), v["sigma"]);
    assert_eq!(
        serde_json::to_value(&want.reflector_sigma_mm).unwrap(),
        v["reflector_sigma_mm"]
    );
    for (body, words) in [
        (
            json!({ "positioner": positioner, "poses": 10 }),
            "`poses` lays out robot poses",
        ),
        (
            json!({ "positioner": positioner, "language": "urscript" }),
            "URScript programs carry no external axes",
        ),
        (
            json!({ "positioner": { "nominal": description, "reflectors": [[400, 0, 20]], "tilt_column": "e3" }, "language": "fanuc" }),
            "give the tilt a column before the rotate's",
        ),
        (
            json!({ "positioner": { "nominal": {}, "reflectors": [[400, 0, 20]] } }),
            "`positioner.nominal`",
        ),
        (
            json!({ "positioner": { "nominal": description, "reflectors": [[5, 0, 20]] } }),
            "5.0 mm from axis 2",
        ),
        (
            json!({ "positioner": { "nominal": description, "reflectors": [[400, 0, 20]], "tilt_deg": [-30, 30] } }),
            "spans 60°",
        ),
        (
            json!({ "positioner": { "nominal": description, "reflectors": [[400, 0, 20]], "rotate_column": "e1" } }),
            "both axes",
        ),
    ] {
        let r = t.post_json(PLANS, &[&rid], body.clone()).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
        assert!(r.text().contains(words), "{body}: {}", r.text());
    }
}

/// A turntable's plan over HTTP is `robocal plan --turntable` on the same
/// nominal file: the CSV and the Fanuc program byte for byte, the points and
/// predicted σ the library's; what does not apply is a 422 naming it.
#[tokio::test]
async fn a_turntables_plan_is_the_command_lines() {
    use clap::Parser;
    use robocal::plan::{make_turntable_plan, TurntablePlanSettings};
    use robocal::sim::turntable_example as example;
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let nominal = example::nominal();
    let description: serde_json::Value = serde_json::from_str(&nominal.to_json()).unwrap();
    let turntable = json!({
        "nominal": description,
        "reflectors": [[400, 0, 20], [-150, 100, 20]],
        "travel_deg": [-120, 150],
        "values": 9,
    });
    let body = json!({ "turntable": turntable, "noise_mm": 0.02, "language": "fanuc", "name": "tt", "wait_s": 2 });
    let r = t.post_json(PLANS, &[&rid], body).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let v = r.json();
    assert_eq!(v["poses"], 9);
    let d = tempfile::tempdir().unwrap();
    let file = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    std::fs::write(file("tt.json"), nominal.to_json()).unwrap();
    let (tt, csv, ls) = (file("tt.json"), file("plan.csv"), file("tt.ls"));
    let argv = [
        "robocal",
        "plan",
        "--turntable",
        &tt,
        "--reflector",
        "400,0,20",
        "--reflector",
        "-150,100,20",
        "--travel=-120,150",
        "--values",
        "9",
        "--noise-mm",
        "0.02",
        "--format",
        "fanuc",
        "--name",
        "tt",
        "--out",
        &ls,
        "--csv",
        &csv,
    ];
    let robocal::cli::Command::Plan(a) = robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        panic!("not a plan")
    };
    robocal::cli::plan::make(&a.make).unwrap();
    let written = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(v["joints_csv"].as_str().unwrap(), written);
    assert!(written.starts_with("point,e1\nP1,-120\n"), "{written}");
    assert_eq!(
        v["program"]["files"][0]["content"].as_str().unwrap(),
        std::fs::read_to_string(&ls).unwrap()
    );
    let want = make_turntable_plan(
        &nominal,
        &TurntablePlanSettings {
            reflectors_mm: example::DESIGN_MM.to_vec(),
            travel_deg: [-120.0, 150.0],
            values: 9,
            noise_mm: 0.02,
            ..TurntablePlanSettings::default()
        },
    )
    .unwrap();
    assert_eq!(serde_json::to_value(&want.points).unwrap(), v["points"]);
    assert_eq!(serde_json::to_value([want.sigma]).unwrap(), v["sigma"]);
    assert_eq!(v["sigma"][0]["axis"], "rotate");
    assert_eq!(
        serde_json::to_value(&want.reflector_sigma_mm).unwrap(),
        v["reflector_sigma_mm"]
    );
    for (body, words) in [
        (
            json!({ "turntable": turntable, "poses": 10 }),
            "`poses` lays out robot poses",
        ),
        (
            json!({ "turntable": turntable, "positioner": { "nominal": {}, "reflectors": [[1, 2, 3]] } }),
            "give one",
        ),
        (
            json!({ "turntable": { "nominal": {}, "reflectors": [[400, 0, 20]] } }),
            "`turntable.nominal`",
        ),
        (
            json!({ "turntable": { "nominal": description, "reflectors": [[5, 0, 20]] } }),
            "5.0 mm from the axis",
        ),
        (
            json!({ "turntable": { "nominal": description, "reflectors": [[400, 0, 20]], "travel_deg": [-30, 30] } }),
            "spans 60°",
        ),
        (
            json!({ "turntable": { "nominal": description, "reflectors": [] } }),
            "`turntable.reflectors`",
        ),
    ] {
        let r = t.post_json(PLANS, &[&rid], body.clone()).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
        assert!(r.text().contains(words), "{body}: {}", r.text());
    }
}
