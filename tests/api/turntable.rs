//! A robot's one-axis turntable over HTTP: fitted from one measurement file
//! per face-plate reflector (`POST …/turntable/calibrate`), stored, read
//! back, refitted and deleted. The turntable is the example one of
//! `robocal turntable simulate` (`robocal::sim::turntable_example`: a true
//! axis tilted 0.05° and offset ~0.5 mm, a zero offset, a scale error and a
//! nod the model lacks; 0.01 mm tracker noise). The same files go through
//! `robocal turntable calibrate`: HTTP and the command line give the same
//! turntable, the same report and the same held-out figures. A turntable
//! fit needs no calibrated version, so the robot is only created.

use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::measure::csv::write_set;
use robocal::measure::external::ExternalAxis;
use robocal::model::external::Turntable;
use robocal::sim::turntable_example::{held_out, nominal, sweep, truth, turntable_set, DESIGN_MM};
use serde_json::{json, Value};
use std::path::Path;

const CALIBRATE: &str = "/v1/robots/{id}/turntable/calibrate";
const TURNTABLE: &str = "/v1/robots/{id}/turntable";

/// Reflector `k`'s readings at `values` [deg] in `column`, as a measurement
/// file's text.
fn set_text(k: usize, values: &[f64], column: ExternalAxis, seed: u64) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    write_set(&turntable_set(&truth(0.003), k, values, column, &mut rng))
}

/// `robocal turntable calibrate r0.csv r1.csv --nominal nominal.json
/// --reflector … --out t.json` and `extra`, run in-process; what it prints.
fn cli_calibrate(d: &Path, extra: &[&str]) -> anyhow::Result<String> {
    let p = |name: &str| d.join(name).to_str().unwrap().to_string();
    let reflectors: Vec<String> = DESIGN_MM
        .iter()
        .map(|r| format!("{},{},{}", r[0], r[1], r[2]))
        .collect();
    let mut argv: Vec<String> = ["robocal", "turntable", "calibrate"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    argv.extend([
        p("r0.csv"),
        p("r1.csv"),
        "--nominal".into(),
        p("nominal.json"),
    ]);
    for r in &reflectors {
        argv.extend(["--reflector".to_string(), r.clone()]);
    }
    argv.extend(["--out".to_string(), p("t.json")]);
    argv.extend(extra.iter().map(|s| s.to_string()));
    match robocal::cli::Cli::try_parse_from(argv).unwrap().command {
        robocal::cli::Command::Turntable(a) => match a.command {
            robocal::cli::turntable::TurntableCommand::Calibrate(c) => {
                robocal::cli::turntable::calibrate_to_string(&c)
            }
            other => panic!("{other:?}"),
        },
        other => panic!("{other:?}"),
    }
}

/// The calibrate body of `sets` (texts) with `extra` fields.
fn body(sets: &[&str], extra: Value) -> Value {
    let mut b = json!({
        "sets": sets,
        "reflectors": DESIGN_MM,
        "nominal": serde_json::from_str::<Value>(&nominal().to_json()).unwrap(),
    });
    for (k, v) in extra.as_object().unwrap() {
        b[k] = v.clone();
    }
    b
}

#[tokio::test]
async fn a_turntable_fitted_over_http_is_the_command_lines() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("nominal.json"), nominal().to_json()).unwrap();
    let texts = [
        set_text(0, &sweep(), ExternalAxis::E1, 1),
        set_text(1, &sweep(), ExternalAxis::E1, 2),
        set_text(0, &held_out(), ExternalAxis::E1, 3),
        set_text(1, &held_out(), ExternalAxis::E1, 4),
    ];
    for (name, text) in ["r0.csv", "r1.csv", "v0.csv", "v1.csv"].iter().zip(&texts) {
        std::fs::write(d.join(name), text).unwrap();
    }

    // No turntable yet: 404 naming the route that fits one.
    let r = t.get(TURNTABLE, &[&rid]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND, "{}", r.text());
    assert!(
        r.detail().contains("/turntable/calibrate"),
        "{}",
        r.detail()
    );

    // The fit over HTTP, stored; the same files through the command line.
    super::fit_request::none_without_a_fit(&t, &rid, "turntable").await;
    let posted = body(
        &[&texts[0], &texts[1]],
        json!({ "validate": [&texts[2], &texts[3]] }),
    );
    let r = t.post_json(CALIBRATE, &[&rid], posted.clone()).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let fitted = r.json();
    assert_eq!(fitted["fitted"], true);
    assert_eq!(fitted["readings"], 2 * sweep().len());
    assert_eq!(fitted["reflectors"], 2);
    assert_eq!(fitted["column"], "e1");
    assert_eq!(fitted["sigma_mm"], 0.01);
    let (v0, v1) = (d.join("v0.csv"), d.join("v1.csv"));
    let printed = cli_calibrate(
        d,
        &[
            "--validate",
            v0.to_str().unwrap(),
            "--validate",
            v1.to_str().unwrap(),
            "--json",
        ],
    )
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    assert_eq!(fitted["fit"], by_cli["fit"], "the fit's report");
    assert_eq!(fitted["rms_mm"], by_cli["fit"]["rms_mm"]);
    let mut cli_validation = by_cli["validation"].clone();
    cli_validation.as_object_mut().unwrap().remove("files");
    assert_eq!(fitted["validation"], cli_validation, "the held-out figures");
    let v = &fitted["validation"];
    println!(
        "fit residuals: rms {:.4} mm, max {:.4} mm; held out: {} readings at {} values, rms {:.4} mm, max {:.4} mm",
        fitted["rms_mm"].as_f64().unwrap(),
        fitted["max_mm"].as_f64().unwrap(),
        v["readings"],
        v["values"],
        v["rms_mm"].as_f64().unwrap(),
        v["max_mm"].as_f64().unwrap()
    );
    assert_eq!(v["readings"], 2 * held_out().len());
    assert_eq!(v["values"], held_out().len());
    let file_text = std::fs::read_to_string(d.join("t.json")).unwrap();
    let stored = t.get(TURNTABLE, &[&rid]).await;
    assert_eq!(stored.status, StatusCode::OK);
    let stored = stored.json();
    assert_eq!(
        stored["turntable"],
        serde_json::from_str::<Value>(&file_text).unwrap(),
        "the stored turntable is the file"
    );
    assert_eq!(stored["created_at"], fitted["created_at"]);
    Turntable::from_json(&stored["turntable"].to_string()).unwrap();
    super::fit_request::refits_from_its_request(&t, &rid, "turntable", &posted).await;

    // A refit replaces it (200); a refused refit (σ 0.001 mm against the
    // 0.01 mm noise) is the command line's refusal and keeps it.
    let r = t
        .post_json(
            CALIBRATE,
            &[&rid],
            body(&[&texts[0], &texts[1]], json!({ "sigma_mm": 0.02 })),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["validation"], Value::Null);
    let refit = t.get(TURNTABLE, &[&rid]).await.json();
    assert_eq!(refit["sigma_mm"], 0.02);
    let r = t
        .post_json(
            CALIBRATE,
            &[&rid],
            body(&[&texts[0], &texts[1]], json!({ "sigma_mm": 0.001 })),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(
        r.detail().starts_with("not fitted (residuals_too_large): "),
        "{}",
        r.detail()
    );
    let cli_error = cli_calibrate(d, &["--sigma-mm", "0.001"]).unwrap_err();
    assert_eq!(r.detail(), cli_error.to_string());
    assert_eq!(t.get(TURNTABLE, &[&rid]).await.json(), refit);

    // A file without the column is a 422 naming it; bad input is a 422
    // naming the field; nothing is replaced.
    let in_e2 = set_text(0, &sweep(), ExternalAxis::E2, 1);
    let r = t
        .post_json(CALIBRATE, &[&rid], body(&[&in_e2, &texts[1]], json!({})))
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(
        r.detail().starts_with("`sets[0]`: ") && r.detail().contains("e1"),
        "{}",
        r.detail()
    );
    let mut bad_nominal = body(&[&texts[0], &texts[1]], json!({}));
    bad_nominal["nominal"]["axis"]["scale"] = json!(1.5);
    let mut one_reflector = body(&[&texts[0], &texts[1]], json!({}));
    one_reflector["reflectors"] = json!([[400, 0, 20]]);
    for (b, field) in [
        (bad_nominal, "`nominal`"),
        (one_reflector, "`reflectors`"),
        (
            body(&[&texts[0], &texts[1]], json!({ "column": "e7" })),
            "`column`",
        ),
        (
            body(&[&texts[0], &texts[1]], json!({ "sigma_mm": 0 })),
            "`sigma_mm`",
        ),
        (
            body(
                &[&texts[0], &texts[1]],
                json!({ "validate": ["x,y\n1,2\n"] }),
            ),
            "`validate[0]`",
        ),
    ] {
        let r = t.post_json(CALIBRATE, &[&rid], b).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{field}");
        assert!(r.detail().contains(field), "{field}: {}", r.detail());
    }
    assert_eq!(t.get(TURNTABLE, &[&rid]).await.json(), refit);

    // DELETE removes it (204, then 404); a missing robot is 404.
    let r = t
        .send("DELETE", TURNTABLE, &[&rid], "", None, Vec::new())
        .await;
    assert_eq!(r.status, StatusCode::NO_CONTENT);
    assert_eq!(
        t.get(TURNTABLE, &[&rid]).await.status,
        StatusCode::NOT_FOUND
    );
    let r = t
        .send("DELETE", TURNTABLE, &[&rid], "", None, Vec::new())
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    let r = t
        .post_json(
            CALIBRATE,
            &["99999"],
            body(&[&texts[0], &texts[1]], json!({})),
        )
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
}

#[tokio::test]
async fn writing_a_turntable_needs_the_admin_role() {
    let t = setup_config(robocal::http::ServiceConfig {
        api_keys: robocal::service::keys::parse_keys("a1:admin,o1:operate,r1:read").unwrap(),
        ..robocal::http::ServiceConfig::default()
    })
    .await;
    let rid = t.create_robot("ys100").await.to_string();
    // Past the role check: one file of three readings, too few angles.
    let body = body(
        &["e1,x,y,z\n0,1,2,3\n30,1,2,3\n60,1,2,3\n"],
        json!({ "reflectors": [[400, 0, 20]] }),
    )
    .to_string();
    for (key, post, delete) in [
        ("r1", StatusCode::FORBIDDEN, StatusCode::FORBIDDEN),
        ("o1", StatusCode::FORBIDDEN, StatusCode::FORBIDDEN),
        (
            "a1",
            StatusCode::UNPROCESSABLE_ENTITY,
            StatusCode::NOT_FOUND,
        ),
    ] {
        let uri = format!("/v1/robots/{rid}/turntable");
        let r = t
            .raw(
                "POST",
                &format!("{uri}/calibrate"),
                Some("application/json"),
                body.clone().into_bytes(),
                Some(key),
            )
            .await;
        assert_eq!(r.status, post, "{key} POST: {}", r.text());
        let r = t.raw("GET", &uri, None, Vec::new(), Some(key)).await;
        assert_eq!(r.status, StatusCode::NOT_FOUND, "{key} GET: {}", r.text());
        let r = t.raw("DELETE", &uri, None, Vec::new(), Some(key)).await;
        assert_eq!(r.status, delete, "{key} DELETE: {}", r.text());
        let r = t.raw("GET", &uri, None, Vec::new(), None).await;
        assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    }
}
