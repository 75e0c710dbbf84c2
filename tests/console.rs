//! The web console's pages, driven in-process: every page renders from the
//! real store, user text is escaped, the writes the pages' script makes go to
//! the JSON API, and nothing is loaded from outside the page. The whole flow
//! in a real browser is `scripts/console_check.py`.

use axum::body::Body;
use axum::http::{Request, StatusCode};
use robocal::db::Db;
use robocal::http::{app, AppState, ServiceConfig};
use tower::ServiceExt;

async fn state() -> (AppState, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let url = format!("sqlite://{}?mode=rwc", dir.path().join("c.db").display());
    let db = Db::connect(&url).await.unwrap();
    (AppState::new(db, ServiceConfig::default()), dir)
}

async fn call(
    state: &AppState,
    method: &str,
    uri: &str,
    body: Option<&str>,
) -> (StatusCode, String) {
    let mut req = Request::builder().method(method).uri(uri);
    if body.is_some() {
        req = req.header("content-type", "application/json");
    }
    let req = req
        .body(Body::from(body.unwrap_or("").to_string()))
        .unwrap();
    let res = app(state.clone()).oneshot(req).await.unwrap();
    let status = res.status();
    let bytes = axum::body::to_bytes(res.into_body(), 1 << 24)
        .await
        .unwrap();
    (status, String::from_utf8(bytes.to_vec()).unwrap())
}

/// No `src=`/`href=` to another origin and no external style sheet or script.
fn assert_self_contained(html: &str) {
    for bad in ["src=\"http", "href=\"http", "<link", "src=\"//", "@import"] {
        assert!(
            !html.contains(bad),
            "external reference `{bad}` in the page"
        );
    }
}

#[tokio::test]
async fn pages_render_the_store_and_escape_user_text() {
    let (state, _dir) = state().await;
    let (s, html) = call(&state, "GET", "/ui", None).await;
    assert_eq!(s, StatusCode::OK);
    assert!(html.contains("No robot yet"), "{html}");
    assert!(html.contains("<form id=\"create-robot\""));
    assert_self_contained(&html);

    // A robot whose name is markup.
    let (s, body) = call(
        &state,
        "POST",
        "/v1/robots",
        Some(r#"{"name": "<script>alert(1)</script>", "preset": "ur5"}"#),
    )
    .await;
    assert_eq!(s, StatusCode::CREATED, "{body}");
    let id = serde_json::from_str::<serde_json::Value>(&body).unwrap()["id"]
        .as_i64()
        .unwrap();
    let (_, html) = call(&state, "GET", "/ui", None).await;
    assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(!html.contains("<script>alert(1)"));
    assert!(html.contains(&format!("href=\"/ui/robots/{id}\"")));

    let (s, html) = call(&state, "GET", &format!("/ui/robots/{id}"), None).await;
    assert_eq!(s, StatusCode::OK);
    assert_self_contained(&html);
    for part in [
        "id=\"sets\"",
        "id=\"upload\"",
        "id=\"calibrations\"",
        "id=\"calibrate\"",
        "id=\"versions\"",
        "id=\"solve\"",
        "data-action=\"solve\"",
    ] {
        assert!(html.contains(part), "robot page lacks {part}");
    }
    assert!(!html.contains("<script>alert(1)"));
    // Every orientation convention of a measurement upload is offered.
    for c in robocal::measure::convention::MeasuredOrientation::ALL {
        assert!(
            html.contains(&format!("<option value=\"{}\"", c.name())),
            "{}",
            c.name()
        );
    }
    assert!(html.contains("name=\"orientation\""));
    // Every calibration method is offered.
    for m in robocal::calibrate::identify::Method::ALL {
        assert!(
            html.contains(&format!("value=\"{}\"", m.name())),
            "{}",
            m.name()
        );
    }
}

#[tokio::test]
async fn unknown_robot_page_is_a_problem_404() {
    let (state, _dir) = state().await;
    let (s, body) = call(&state, "GET", "/ui/robots/4242", None).await;
    assert_eq!(s, StatusCode::NOT_FOUND);
    assert!(body.contains("robot 4242"), "{body}");
    let (s, _) = call(&state, "GET", "/ui/robots/abc", None).await;
    assert_eq!(s, StatusCode::BAD_REQUEST);
}

/// The value a form's input `name` is prefilled with (`None`: no value).
fn input_value(form: &str, name: &str) -> Option<String> {
    let at = form.find(&format!("name=\"{name}\""))?;
    let tag = &form[at..at + form[at..].find('>')?];
    let v = tag.find("value=\"")? + "value=\"".len();
    Some(tag[v..v + tag[v..].find('"')?].to_string())
}

/// The option selected in a form's select `name`.
fn selected(form: &str, name: &str) -> Option<String> {
    let at = form.find(&format!("<select name=\"{name}\""))?;
    let select = &form[at..at + form[at..].find("</select>")?];
    let opt = select.find(" selected")?;
    let start = select[..opt].rfind("value=\"")? + "value=\"".len();
    Some(select[start..start + select[start..].find('"')?].to_string())
}

#[tokio::test]
async fn a_tools_edit_form_holds_every_stored_field() {
    let (state, _dir) = state().await;
    let (_, body) = call(
        &state,
        "POST",
        "/v1/robots",
        Some(r#"{"name": "cell", "preset": "ur5"}"#),
    )
    .await;
    let id = serde_json::from_str::<serde_json::Value>(&body).unwrap()["id"]
        .as_i64()
        .unwrap();
    let tool = r#"{"number": 3, "xyz_mm": [125, -0.0, 216.5], "rpy_deg": [0, 30, -12.25],
        "load": {"mass_kg": 2.5, "com_mm": [1.5, 0, 80], "frame": "tool", "inertia_kgm2": [0.01, 0.02, 0.03]}}"#;
    let (s, body) = call(
        &state,
        "PUT",
        &format!("/v1/robots/{id}/tools/torch"),
        Some(tool),
    )
    .await;
    assert_eq!(s, StatusCode::CREATED, "{body}");
    let (s, body) = call(
        &state,
        "PUT",
        &format!("/v1/robots/{id}/frames/table"),
        Some(r#"{"number": 2, "frame": "measurement", "xyz_mm": [450, -100, 50], "rpy_deg": [0, 0, 20]}"#),
    )
    .await;
    assert_eq!(s, StatusCode::CREATED, "{body}");
    // What the API stores, read back independently of the page.
    let (_, stored) = call(&state, "GET", &format!("/v1/robots/{id}/tools/torch"), None).await;
    let stored: serde_json::Value = serde_json::from_str(&stored).unwrap();
    let load = &stored["load"];

    let (_, html) = call(&state, "GET", &format!("/ui/robots/{id}"), None).await;
    let at = html
        .find("id=\"edit-tools-torch\"")
        .expect("no edit form for the tool");
    let form = &html[at..at + html[at..].find("</form>").unwrap()];
    // Lengths to 0.001 mm, angles to 0.0001°, masses to 0.001 kg, inertia
    // to 1e-6 kg·m², as the console writes them.
    let f = |x: &serde_json::Value, decimals: i32| {
        let k = 10f64.powi(decimals);
        let s = format!("{}", (x.as_f64().unwrap() * k).round() / k);
        if s == "-0" {
            "0".to_string()
        } else {
            s
        }
    };
    assert_eq!(input_value(form, "name").as_deref(), Some("torch"));
    assert_eq!(input_value(form, "number").as_deref(), Some("3"));
    for (i, k) in ["x", "y", "z"].iter().enumerate() {
        assert_eq!(
            input_value(form, k),
            Some(f(&stored["xyz_mm"][i], 3)),
            "{k}"
        );
    }
    for (i, k) in ["rx", "ry", "rz"].iter().enumerate() {
        assert_eq!(
            input_value(form, k),
            Some(f(&stored["rpy_deg"][i], 4)),
            "{k}"
        );
    }
    assert_eq!(
        input_value(form, "load_mass_kg"),
        Some(f(&load["mass_kg"], 3))
    );
    for (i, k) in ["load_com_x", "load_com_y", "load_com_z"]
        .iter()
        .enumerate()
    {
        assert_eq!(input_value(form, k), Some(f(&load["com_mm"][i], 3)), "{k}");
    }
    assert_eq!(
        selected(form, "load_frame"),
        load["frame"].as_str().map(str::to_string)
    );
    for (i, k) in ["load_ixx", "load_iyy", "load_izz"].iter().enumerate() {
        assert_eq!(
            input_value(form, k),
            Some(f(&load["inertia_kgm2"][i], 6)),
            "{k}"
        );
    }
    // The values typed in come back as typed (no `-0`, no trailing zeros).
    assert_eq!(input_value(form, "y").as_deref(), Some("0"));
    assert_eq!(input_value(form, "z").as_deref(), Some("216.5"));

    let at = html
        .find("id=\"edit-frames-table\"")
        .expect("no edit form for the work object");
    let form = &html[at..at + html[at..].find("</form>").unwrap()];
    assert_eq!(input_value(form, "number").as_deref(), Some("2"));
    assert_eq!(selected(form, "frame").as_deref(), Some("measurement"));
    assert_eq!(input_value(form, "rz").as_deref(), Some("20"));
    // Deleting asks first.
    assert!(html.contains(&format!(
        "data-delete=\"/v1/robots/{id}/tools/torch\" data-confirm=\"Delete tool torch?"
    )));
}

/// The form `<form id="{id}"` of a page, from its opening tag to its end.
fn form<'a>(html: &'a str, id: &str) -> &'a str {
    let at = html
        .find(&format!("<form id=\"{id}\""))
        .unwrap_or_else(|| panic!("no form {id}"));
    &html[at..at + html[at..].find("</form>").unwrap()]
}

/// The predict form takes the external axes' values `e1`, `e2`, `e3` as
/// numbers, each labelled with what it is, empty by default; its frame and
/// the solve form's are sent only when chosen (a positioner's values put
/// the poses and targets on its face plate, where the API refuses a frame),
/// and the solve section says a targets CSV may carry the axes' columns.
#[tokio::test]
async fn the_predict_form_takes_the_external_axes_values() {
    let (state, _dir) = state().await;
    let robot = post_json(
        &state,
        "/v1/robots",
        &serde_json::json!({ "name": "cell", "preset": "ur5" }),
        StatusCode::CREATED,
    )
    .await;
    let id = robot["id"].as_i64().unwrap();
    let (s, html) = call(&state, "GET", &format!("/ui/robots/{id}"), None).await;
    assert_eq!(s, StatusCode::OK);
    let predict = form(&html, "predict");
    assert!(predict.contains(&format!(
        "<form id=\"predict\" data-action=\"predict\" data-robot=\"{id}\""
    )));
    for (name, label) in [
        (
            "e1",
            "e1 (track [mm], or the positioner's tilt [°] without a track)",
        ),
        (
            "e2",
            "e2 (the positioner's tilt [°] beside a track, else its rotate)",
        ),
        ("e3", "e3 (the positioner's rotate [°] beside a track)"),
    ] {
        let input = format!("<input name=\"{name}\" type=\"number\" step=\"any\">");
        let at = predict
            .find(&input)
            .unwrap_or_else(|| panic!("the predict form lacks {input}"));
        let open = predict[..at].rfind("<label").unwrap();
        let text = predict[open..at]
            .replace("&#39;", "'")
            .replace("&apos;", "'");
        assert!(text.ends_with(&format!("{label} ")), "{name}: {text}");
        assert_eq!(input_value(predict, name), None, "{name} is prefilled");
    }
    // The frame: none sent unless base or a work object is chosen.
    for f in [predict, form(&html, "solve")] {
        let at = f.find("<select name=\"frame\">").expect("no frame select");
        assert!(
            f[at..].starts_with("<select name=\"frame\"><option value=\"\">"),
            "{}",
            &f[at..]
        );
        assert!(!f.contains("value=\"cell\""));
        assert!(f.contains("<option value=\"base\">robot base</option>"));
    }
    assert!(html.contains("<p class=\"note\" id=\"predict-axes-note\">External axes"));
    let at = html
        .find("<p class=\"note\" id=\"solve-axes-note\">")
        .expect("no note on the solve form's axes");
    let note = &html[at..at + html[at..].find("</p>").unwrap()];
    for part in [
        "an e1 column alone is the track",
        "e1, e2 the positioner",
        "e1, e2, e3 the track",
    ] {
        assert!(note.contains(part), "{note}");
    }
}

/// The filter form takes the controller's track and its positioner or
/// turntable (a file or pasted JSON, the kind chosen) and "correct the
/// axes' values"; the plan form chooses what to plan, each subject's inputs
/// in its fieldset, hidden until chosen, empty for the API's defaults.
#[tokio::test]
async fn the_filter_and_plan_forms_take_the_external_axes() {
    let (state, _dir) = state().await;
    let robot = post_json(
        &state,
        "/v1/robots",
        &serde_json::json!({ "name": "cell", "preset": "ur5" }),
        StatusCode::CREATED,
    )
    .await;
    let id = robot["id"].as_i64().unwrap();
    let (s, html) = call(&state, "GET", &format!("/ui/robots/{id}"), None).await;
    assert_eq!(s, StatusCode::OK);
    let filter = form(&html, "filter");
    for field in [
        "<input type=\"file\" name=\"controller_track_file\"",
        "<textarea name=\"controller_track\"",
        "<select name=\"controller_plate_kind\"><option value=\"positioner\">",
        "<option value=\"turntable\">turntable</option>",
        "<input type=\"file\" name=\"controller_plate_file\"",
        "<textarea name=\"controller_plate\"",
        "<input type=\"checkbox\" name=\"correct_axes\" value=\"true\">",
    ] {
        assert!(filter.contains(field), "the filter form lacks {field}");
    }
    assert!(html.contains("<p id=\"filter-axes\" hidden>"));
    let plan = form(&html, "measurement-plan");
    assert!(plan.contains("<select name=\"what\"><option value=\"robot\">robot poses</option>"));
    for what in ["track", "positioner", "turntable"] {
        let open = format!("<fieldset class=\"plan-what\" data-what=\"{what}\" hidden>");
        let at = plan
            .find(&open)
            .unwrap_or_else(|| panic!("no hidden fieldset for {what}"));
        let set = &plan[at..at + plan[at..].find("</fieldset>").unwrap()];
        assert!(set.contains(&format!("name=\"{what}_file\"")), "{set}");
        assert!(
            set.contains(&format!("<textarea name=\"{what}_json\"")),
            "{set}"
        );
        assert_eq!(
            set.contains(&format!("<textarea name=\"{what}_reflectors\"")),
            what != "track",
            "{set}"
        );
    }
    for name in [
        "stations",
        "track_travel_min",
        "travel_min",
        "tilt_min",
        "tilt_values",
        "rotate_max",
        "travel_values",
    ] {
        assert_eq!(input_value(plan, name), None, "{name} is prefilled");
    }
    for id in ["plan-stations", "plan-sigma"] {
        assert!(
            html.contains(&format!("<table id=\"{id}\" hidden>")),
            "{id}"
        );
    }
}

/// The controller data form offers the external axes (KRL): "none" first
/// (nothing sent), then every kind the API takes (`AxesKind::ALL`, by its
/// serde name, labelled in words); the answer's not-held table and held
/// downloads wait hidden under the text.
#[tokio::test]
async fn the_export_form_offers_every_external_axes_kind() {
    let (state, _dir) = state().await;
    let robot = post_json(
        &state,
        "/v1/robots",
        &serde_json::json!({ "name": "cell", "preset": "ur5" }),
        StatusCode::CREATED,
    )
    .await;
    let id = robot["id"].as_i64().unwrap();
    let (s, html) = call(&state, "GET", &format!("/ui/robots/{id}"), None).await;
    assert_eq!(s, StatusCode::OK);
    let export = form(&html, "export-cell");
    assert!(export.contains(&format!(
        "<form id=\"export-cell\" data-action=\"export-cell\" data-robot=\"{id}\""
    )));
    let at = export
        .find("<select name=\"axes\">")
        .expect("no axes select");
    let select = &export[at..at + export[at..].find("</select>").unwrap()];
    let open = export[..at].rfind("<label").unwrap();
    assert!(
        export[open..at].ends_with(">External axes (KRL) "),
        "{}",
        &export[open..at]
    );
    let mut want = String::from("<select name=\"axes\"><option value=\"\">none</option>");
    for k in robocal::program::controller::AxesKind::ALL {
        let name = serde_json::to_value(k).unwrap();
        let name = name.as_str().unwrap();
        want += &format!(
            "<option value=\"{name}\">{}</option>",
            name.replace('_', " ")
        );
    }
    assert_eq!(select, want);
    assert_eq!(selected(export, "axes"), None, "an axes kind is chosen");
    for part in [
        "<div id=\"export-kinematics\" hidden>",
        "<p id=\"export-held-downloads\"></p>",
        "<p id=\"export-all-held\" hidden>Every calibrated term is held.</p>",
        "<table id=\"export-not-held\"><thead><tr><th>Not held</th><th>Value</th><th>Miss [mm]</th></tr></thead>",
    ] {
        assert!(html.contains(part), "the page lacks {part}");
    }
}

/// The robot page's `#axes-section`, from its opening tag to its end.
fn axes_section(html: &str) -> &str {
    let at = html
        .find("<section id=\"axes-section\"")
        .expect("no external axes section");
    &html[at..at + html[at..].find("</section>").unwrap()]
}

/// The text of the cell `<td class="{class}">` in `table`.
fn cell<'a>(table: &'a str, class: &str) -> &'a str {
    let open = format!("<td class=\"{class}\">");
    let at = table
        .find(&open)
        .unwrap_or_else(|| panic!("no cell {class}"))
        + open.len();
    &table[at..at + table[at..].find("</td>").unwrap()]
}

/// `POST`s `body` and returns the JSON answer, asserting `want`.
async fn post_json(
    state: &AppState,
    uri: &str,
    body: &serde_json::Value,
    want: StatusCode,
) -> serde_json::Value {
    let (s, text) = call(state, "POST", uri, Some(&body.to_string())).await;
    assert_eq!(s, want, "{uri}: {text}");
    serde_json::from_str(&text).unwrap()
}

/// A ys100 robot with a KM calibration of 30 simulated poses (the thesis's
/// Table 7.1 robot, 0.01 mm tracker noise) as its active version; its id.
async fn calibrated_ys100(state: &AppState) -> i64 {
    use rand::SeedableRng;
    let robot = post_json(
        state,
        "/v1/robots",
        &serde_json::json!({ "name": "rail robot", "preset": "ys100" }),
        StatusCode::CREATED,
    )
    .await;
    let id = robot["id"].as_i64().unwrap();
    let mut truth = robocal::sim::TrueRobot::new(robocal::sim::ys100_table_7_1());
    truth.tracker_from_base = robocal::sim::tracker_frame(0.0, 0.0, 90.0, [500.0, -3240.0, 0.0]);
    truth.noise_mm = 0.01;
    let nominal = robocal::model::preset("ys100").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let qs = robocal::sim::try_random_configurations(
        &nominal,
        30,
        &robocal::sim::PoseFilter::default(),
        &mut rng,
        |q| truth.true_position(q, Some(110.0)).is_ok(),
    )
    .unwrap();
    let rows = truth.measure(&qs, Some(110.0), None, &mut rng).unwrap();
    let req = Request::builder()
        .method("POST")
        .uri(format!(
            "/v1/robots/{id}/measurement-sets?role=identification"
        ))
        .header("content-type", "text/csv")
        .body(Body::from(robocal::measure::csv::write(&rows)))
        .unwrap();
    let res = app(state.clone()).oneshot(req).await.unwrap();
    assert_eq!(res.status(), StatusCode::CREATED);
    let job = post_json(
        state,
        &format!("/v1/robots/{id}/calibrations"),
        &serde_json::json!({ "methods": ["km"], "seed": 1 }),
        StatusCode::ACCEPTED,
    )
    .await;
    let url = format!("/v1/robots/{id}/calibrations/{}", job["id"]);
    let end = std::time::Instant::now() + std::time::Duration::from_secs(300);
    loop {
        let (_, text) = call(state, "GET", &url, None).await;
        let j: serde_json::Value = serde_json::from_str(&text).unwrap();
        match j["status"].as_str().unwrap() {
            "succeeded" => return id,
            "queued" | "running" if std::time::Instant::now() < end => {
                tokio::time::sleep(std::time::Duration::from_millis(200)).await
            }
            _ => panic!("the calibration did not succeed: {j}"),
        }
    }
}

/// The external axes section: "none stored" for a fresh robot; the stored
/// track and positioner as tables once fitted through the API (each from
/// the files `robocal track simulate` and `positioner simulate` write: the
/// robot on the rail is the active version's geometry), with their figures
/// as the API gives them and a delete that asks first.
#[tokio::test]
async fn the_robot_page_shows_its_stored_track_and_positioner() {
    let (state, dir) = state().await;
    let id = calibrated_ys100(&state).await;
    let page = format!("/ui/robots/{id}");
    let (s, html) = call(&state, "GET", &page, None).await;
    assert_eq!(s, StatusCode::OK);
    let section = axes_section(&html);
    assert!(section.contains("No track stored."), "{section}");
    assert!(section.contains("No positioner stored."), "{section}");
    assert!(!section.contains("id=\"track-stored\""));
    assert!(!section.contains("id=\"positioner-stored\""));
    for part in [
        "<form id=\"calibrate-track\" data-action=\"calibrate-track\"",
        "<form id=\"calibrate-positioner\" data-action=\"calibrate-positioner\"",
        "name=\"sets\" multiple",
    ] {
        assert!(section.contains(part), "the section lacks {part}");
    }
    assert_eq!(selected(section, "column").as_deref(), Some("e1"));
    assert_eq!(selected(section, "tilt_column").as_deref(), Some("e1"));
    assert_eq!(selected(section, "rotate_column").as_deref(), Some("e2"));
    assert_eq!(input_value(section, "sigma_mm").as_deref(), Some("0.01"));
    assert_eq!(input_value(section, "max_order").as_deref(), Some("6"));

    // The track, from the active version's model file on the simulated rail.
    let (s, model) = call(
        &state,
        "GET",
        &format!("/v1/robots/{id}/versions/1/model.json"),
        None,
    )
    .await;
    assert_eq!(s, StatusCode::OK);
    let files = dir.path().join("axes");
    std::fs::create_dir_all(&files).unwrap();
    let model_path = files.join("model.json");
    std::fs::write(&model_path, model).unwrap();
    robocal::cli::track_sim::simulate_to_string(&robocal::cli::track_sim::SimulateArgs {
        out_dir: files.display().to_string(),
        robot: model_path.display().to_string(),
        seed: 5,
        noise_mm: 0.01,
        poses: 15,
    })
    .unwrap();
    let csv = std::fs::read_to_string(files.join("stations.csv")).unwrap();
    post_json(
        &state,
        &format!("/v1/robots/{id}/track/calibrate"),
        &serde_json::json!({ "csv": csv }),
        StatusCode::CREATED,
    )
    .await;
    // The positioner, from the files `positioner simulate` writes.
    robocal::cli::positioner_sim::simulate_to_string(&robocal::cli::positioner_sim::SimulateArgs {
        out_dir: files.display().to_string(),
        robot: None,
        seed: 1,
        noise_mm: 0.01,
        wobble_deg: 0.003,
    })
    .unwrap();
    let read = |name: &str| std::fs::read_to_string(files.join(name)).unwrap();
    let nominal: serde_json::Value = serde_json::from_str(&read("nominal.json")).unwrap();
    post_json(
        &state,
        &format!("/v1/robots/{id}/positioner/calibrate"),
        &serde_json::json!({
            "sets": [read("r0.csv"), read("r1.csv")],
            "reflectors": robocal::sim::positioner_example::DESIGN_MM,
            "nominal": nominal,
        }),
        StatusCode::CREATED,
    )
    .await;

    let (_, html) = call(&state, "GET", &page, None).await;
    let section = axes_section(&html);
    assert!(!section.contains("No track stored."), "{section}");
    assert!(!section.contains("No positioner stored."), "{section}");
    let get = |what: &'static str| {
        let state = state.clone();
        async move {
            let (s, text) = call(&state, "GET", &format!("/v1/robots/{id}/{what}"), None).await;
            assert_eq!(s, StatusCode::OK, "{text}");
            serde_json::from_str::<serde_json::Value>(&text).unwrap()
        }
    };
    let mm = |v: &serde_json::Value| format!("{:.3}", v.as_f64().unwrap());
    let track = get("track").await;
    let at = section
        .find("<table id=\"track-stored\"")
        .expect("no track table");
    let table = &section[at..at + section[at..].find("</table>").unwrap()];
    assert_eq!(cell(table, "column"), "e1");
    assert_eq!(cell(table, "from"), "a posted file");
    assert!(table.contains(&format!("<a href=\"/v1/robots/{id}/track/fit-request\"")));
    assert_eq!(cell(table, "version"), "v1");
    assert_eq!(cell(table, "stations"), "11");
    assert_eq!(cell(table, "stations"), track["stations"].to_string());
    assert_eq!(cell(table, "readings"), track["readings"].to_string());
    assert_eq!(cell(table, "rms"), mm(&track["rms_mm"]));
    assert_eq!(cell(table, "max"), mm(&track["max_mm"]));
    assert_eq!(cell(table, "sigma"), "0.010");
    assert!(table.contains(&format!(
        "<time datetime=\"{}\">",
        track["created_at"].as_str().unwrap()
    )));
    assert!(table.contains(&format!(
        "data-delete=\"/v1/robots/{id}/track\" data-confirm=\"Delete the track of robot {id} (rail robot)?"
    )));
    // The same file as station sets (the upload form's track column), each
    // listed with its track value, and the track refitted from them (the
    // track form's set ids): the table says which.
    assert!(form(&html, "upload")
        .contains("<select name=\"track_column\"><option value=\"\">none</option>"));
    for c in ["e1", "e6"] {
        assert!(form(&html, "upload").contains(&format!("<option value=\"{c}\">{c}</option>")));
    }
    assert!(form(section, "calibrate-track").contains("name=\"set_ids\""));
    let req = Request::builder()
        .method("POST")
        .uri(format!("/v1/robots/{id}/track/measurement-sets?column=e1"))
        .header("content-type", "text/csv")
        .body(Body::from(csv.clone()))
        .unwrap();
    let res = app(state.clone()).oneshot(req).await.unwrap();
    assert_eq!(res.status(), StatusCode::CREATED);
    let bytes = axum::body::to_bytes(res.into_body(), 1 << 24)
        .await
        .unwrap();
    let uploaded: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
    let sets = uploaded["measurement_sets"].as_array().unwrap();
    let ids: Vec<i64> = sets.iter().map(|s| s["id"].as_i64().unwrap()).collect();
    post_json(
        &state,
        &format!("/v1/robots/{id}/track/calibrate"),
        &serde_json::json!({ "set_ids": ids }),
        StatusCode::OK,
    )
    .await;
    let (_, html) = call(&state, "GET", &page, None).await;
    for s in sets {
        let value = s["station"]["value_mm"].as_f64().unwrap();
        assert!(
            html.contains(&format!("<td class=\"station\">e1 = {value} mm</td>")),
            "set {} at {value} mm",
            s["id"]
        );
    }
    let section = axes_section(&html);
    let at = section.find("<table id=\"track-stored\"").unwrap();
    let table = &section[at..at + section[at..].find("</table>").unwrap()];
    assert_eq!(
        cell(table, "from"),
        format!("station sets {}–{}", ids[0], ids[ids.len() - 1])
    );
    let positioner = get("positioner").await;
    let at = section
        .find("<table id=\"positioner-stored\"")
        .expect("no positioner table");
    let table = &section[at..at + section[at..].find("</table>").unwrap()];
    assert_eq!(cell(table, "tilt"), "e1");
    assert_eq!(cell(table, "rotate"), "e2");
    assert_eq!(positioner["readings_from"]["kind"], "tracker");
    assert_eq!(cell(table, "from"), "tracker");
    assert_eq!(cell(table, "reflectors"), "2");
    assert_eq!(cell(table, "readings"), positioner["readings"].to_string());
    assert_eq!(cell(table, "rms"), mm(&positioner["rms_mm"]));
    assert_eq!(cell(table, "max"), mm(&positioner["max_mm"]));
    assert!(table.contains(&format!(
        "data-delete=\"/v1/robots/{id}/positioner\" data-confirm=\"Delete the positioner of robot {id} (rail robot)?"
    )));
}

/// The turntable and the positioner's touches: a robot without versions
/// shows "No turntable stored.", the turntable's form and, for touches, a
/// version number field and a select of its stored tools (hidden until
/// touches are chosen); its turntable, fitted through the API from the
/// files `robocal turntable simulate` writes, is shown with every figure as
/// `GET …/turntable` gives it (the axis's line, zero offset and scale from
/// the stored JSON) and a delete that asks first.
#[tokio::test]
async fn the_robot_page_shows_its_stored_turntable_and_the_touches_choice() {
    let (state, dir) = state().await;
    let robot = serde_json::json!({ "name": "table robot", "preset": "ys100" });
    let id = post_json(&state, "/v1/robots", &robot, StatusCode::CREATED).await["id"].clone();
    let tools = serde_json::json!({ "tools": [{ "name": "pointer", "xyz_mm": [0, 0, 200], "rpy_deg": [0, 0, 0] }] });
    let (s, text) = call(
        &state,
        "PUT",
        &format!("/v1/robots/{id}/tools"),
        Some(&tools.to_string()),
    )
    .await;
    assert_eq!(s, StatusCode::OK, "{text}");
    let page = format!("/ui/robots/{id}");
    let (_, html) = call(&state, "GET", &page, None).await;
    let section = axes_section(&html);
    for part in [
        "No turntable stored.",
        "<form id=\"calibrate-turntable\" data-action=\"calibrate-turntable\"",
        "<p class=\"note files\" id=\"turntable-files\">",
        "<input type=\"radio\" name=\"readings_from\" value=\"tracker\" checked>",
        "<fieldset id=\"positioner-touches\" hidden>",
        "<input name=\"touched_version\" type=\"number\"",
        "<select name=\"touched_tool\"><option value=\"pointer\">pointer</option></select>",
    ] {
        assert!(
            section.contains(part),
            "the section lacks {part}: {section}"
        );
    }
    let files = dir.path().join("turntable");
    robocal::cli::turntable::simulate_to_string(&robocal::cli::turntable::SimulateArgs {
        out_dir: files.display().to_string(),
        seed: 1,
        noise_mm: 0.01,
        wobble_deg: 0.003,
    })
    .unwrap();
    let read = |name: &str| std::fs::read_to_string(files.join(name)).unwrap();
    let nominal: serde_json::Value = serde_json::from_str(&read("nominal.json")).unwrap();
    let body = serde_json::json!({
        "sets": [read("r0.csv"), read("r1.csv")],
        "reflectors": robocal::sim::turntable_example::DESIGN_MM,
        "nominal": nominal,
    });
    let uri = format!("/v1/robots/{id}/turntable/calibrate");
    post_json(&state, &uri, &body, StatusCode::CREATED).await;
    let (_, html) = call(&state, "GET", &page, None).await;
    let section = axes_section(&html);
    assert!(!section.contains("No turntable stored."), "{section}");
    let (_, text) = call(&state, "GET", &format!("/v1/robots/{id}/turntable"), None).await;
    let stored: serde_json::Value = serde_json::from_str(&text).unwrap();
    let at = section
        .find("<table id=\"turntable-stored\"")
        .expect("no turntable table");
    let table = &section[at..at + section[at..].find("</table>").unwrap()];
    // As the page writes numbers: never "-0".
    let fixed = |v: &serde_json::Value, d: usize| {
        let s = format!("{:.d$}", v.as_f64().unwrap());
        let unsigned = s.trim_start_matches('-');
        match unsigned.bytes().all(|b| b == b'0' || b == b'.') {
            true => unsigned.to_string(),
            false => s,
        }
    };
    let axis = &stored["turntable"]["axis"];
    let three = |k: &str, d: usize| {
        (0..3)
            .map(|i| fixed(&axis[k][i], d))
            .collect::<Vec<_>>()
            .join(", ")
    };
    assert_eq!(cell(table, "column"), "e1");
    assert_eq!(cell(table, "reflectors"), "2");
    assert_eq!(cell(table, "readings"), stored["readings"].to_string());
    assert_eq!(cell(table, "direction"), three("direction", 6));
    assert_eq!(cell(table, "point"), three("point_mm", 3));
    assert_eq!(cell(table, "zero"), fixed(&axis["zero_offset_deg"], 4));
    assert_eq!(cell(table, "scale"), fixed(&axis["scale"], 6));
    assert_eq!(cell(table, "rms"), fixed(&stored["rms_mm"], 3));
    assert_eq!(cell(table, "max"), fixed(&stored["max_mm"], 3));
    assert_eq!(cell(table, "sigma"), "0.010");
    assert!(table.contains(&format!(
        "data-delete=\"/v1/robots/{id}/turntable\" data-confirm=\"Delete the turntable of robot {id} (table robot)?"
    )));
}
