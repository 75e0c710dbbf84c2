//! The ISO 9283 report as a self-contained HTML page (`robocal iso9283
//! --report out.html`, `POST /v1/iso9283` with `Accept: text/html`): first
//! the test conditions (robot, model version and the SHA-256 of its model
//! file, test date, load, speed, cycles and the measurement sets), then ONE
//! table of every figure, a row per pose and characteristic (n, AP,
//! APx/y/z, RP, APa/b/c, ±RPa/b/c) and per pair of poses (n, D_c, AD, ±RD),
//! a column per test side by side and, with two tests or more, the change
//! from the first test to the last (last − first: negative is better for AP,
//! RP, |AD| and RD). The figures are `core::iso9283::assess`'s, in
//! millimetres and degrees, four decimals as the text table
//! (`cli::iso9283::figures_table`); a figure not computed shows its reason.

use super::{page_head, STYLE};
use maud::{html, Markup, DOCTYPE};
use robocal_core::check::iso9283::outcome::{DistanceOutcomes, Outcome, PoseOutcomes};
use robocal_core::check::iso9283::Assessment;
use serde::Serialize;

/// One test's measurement set as the report names it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeasuredSet {
    /// The test's label (e.g. the cycles file's name).
    pub label: String,
    /// Most cycles measured at one pose.
    pub cycles: usize,
    /// SHA-256 of the cycles file's bytes (hex), when the report had them.
    pub sha256: Option<String>,
}

/// The test conditions the report states (`None`: not stated).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Iso9283Conditions {
    /// The robot's name.
    pub robot: Option<String>,
    /// The model version's number or file name.
    pub model_version: Option<String>,
    /// SHA-256 (hex) of the model file's bytes (a version's stored
    /// `model.json`, as `GET …/versions/{v}/model.json` serves it).
    pub model_sha256: Option<String>,
    /// Test date, `YYYY-MM-DD` (UTC).
    pub date: String,
    /// Load carried during the test [kg].
    pub load_kg: Option<f64>,
    /// Speed of the motions between the poses [% of the rated speed].
    pub speed_percent: Option<f64>,
    /// What was measured with what (tracker, reflector, session).
    pub measurement: Option<String>,
    /// The measurement sets the figures come from.
    pub sets: Vec<MeasuredSet>,
    /// The version of robocal that wrote the report.
    pub robocal_version: &'static str,
}

/// Most cycles measured at one pose of an assessment.
pub fn cycles_of(a: &Assessment) -> usize {
    a.poses.iter().map(|p| p.cycles).max().unwrap_or(0)
}

/// `YYYY-MM-DD` of a time since the Unix epoch (UTC; the civil calendar of
/// days since 1970-01-01, proleptic Gregorian).
pub fn utc_date(since_epoch: std::time::Duration) -> String {
    let days = (since_epoch.as_secs() / 86_400) as i64;
    let (y, m, d) = civil_from_days(days);
    format!("{y:04}-{m:02}-{d:02}")
}

/// Year, month, day of `z` days since 1970-01-01 (H. Hinnant's algorithm).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = (if mp < 10 { mp + 3 } else { mp - 9 }) as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

/// Today's date (UTC) as `YYYY-MM-DD`.
pub fn today_utc() -> String {
    utc_date(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap_or_default(),
    )
}

/// Whether `s` is a calendar date `YYYY-MM-DD` (years 1–9999).
pub fn is_date(s: &str) -> bool {
    let b = s.as_bytes();
    if !s.is_ascii() || b.len() != 10 || b[4] != b'-' || b[7] != b'-' {
        return false;
    }
    let num = |r: std::ops::Range<usize>| -> Option<u32> {
        let t = &s[r];
        t.bytes()
            .all(|c| c.is_ascii_digit())
            .then(|| t.parse().ok())?
    };
    let (Some(y), Some(m), Some(d)) = (num(0..4), num(5..7), num(8..10)) else {
        return false;
    };
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let days = match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if leap => 29,
        2 => 28,
        _ => return false,
    };
    y >= 1 && (1..=days).contains(&d)
}

/// A pose characteristic of the table (a closed set: every pose row derives
/// from [`PoseRow::ALL`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoseRow {
    /// `n`: cycles measured.
    Cycles,
    /// Pose accuracy AP [mm].
    Ap,
    /// APx [mm].
    ApX,
    /// APy [mm].
    ApY,
    /// APz [mm].
    ApZ,
    /// Pose repeatability RP [mm].
    Rp,
    /// Orientation accuracy APa [deg].
    ApA,
    /// Orientation accuracy APb [deg].
    ApB,
    /// Orientation accuracy APc [deg].
    ApC,
    /// Orientation repeatability ±RPa [deg].
    RpA,
    /// Orientation repeatability ±RPb [deg].
    RpB,
    /// Orientation repeatability ±RPc [deg].
    RpC,
}

impl PoseRow {
    /// Every row, in table order.
    pub const ALL: [PoseRow; 12] = [
        PoseRow::Cycles,
        PoseRow::Ap,
        PoseRow::ApX,
        PoseRow::ApY,
        PoseRow::ApZ,
        PoseRow::Rp,
        PoseRow::ApA,
        PoseRow::ApB,
        PoseRow::ApC,
        PoseRow::RpA,
        PoseRow::RpB,
        PoseRow::RpC,
    ];

    /// The characteristic's name and unit as the table heads its row.
    pub fn name(self) -> (&'static str, &'static str) {
        match self {
            PoseRow::Cycles => ("n", "cycles"),
            PoseRow::Ap => ("AP", "mm"),
            PoseRow::ApX => ("APx", "mm"),
            PoseRow::ApY => ("APy", "mm"),
            PoseRow::ApZ => ("APz", "mm"),
            PoseRow::Rp => ("RP", "mm"),
            PoseRow::ApA => ("APa", "deg"),
            PoseRow::ApB => ("APb", "deg"),
            PoseRow::ApC => ("APc", "deg"),
            PoseRow::RpA => ("±RPa", "deg"),
            PoseRow::RpB => ("±RPb", "deg"),
            PoseRow::RpC => ("±RPc", "deg"),
        }
    }

    fn value(self, p: &PoseOutcomes) -> Value {
        let abc = |o: Option<[f64; 3]>, k: usize| o.map(|v| v[k]);
        match self {
            PoseRow::Cycles => Value::Count(p.cycles),
            PoseRow::Ap => of(&p.ap, |a| Some(a.ap_mm)),
            PoseRow::ApX => of(&p.ap, |a| Some(a.ap_xyz_mm[0])),
            PoseRow::ApY => of(&p.ap, |a| Some(a.ap_xyz_mm[1])),
            PoseRow::ApZ => of(&p.ap, |a| Some(a.ap_xyz_mm[2])),
            PoseRow::Rp => of(&p.rp, |r| Some(r.rp_mm)),
            PoseRow::ApA => of(&p.ap_abc, |a| abc(Some(a.ap_abc_deg), 0)),
            PoseRow::ApB => of(&p.ap_abc, |a| abc(Some(a.ap_abc_deg), 1)),
            PoseRow::ApC => of(&p.ap_abc, |a| abc(Some(a.ap_abc_deg), 2)),
            PoseRow::RpA => of(&p.rp_abc, |r| abc(Some(r.rp_abc_deg), 0)),
            PoseRow::RpB => of(&p.rp_abc, |r| abc(Some(r.rp_abc_deg), 1)),
            PoseRow::RpC => of(&p.rp_abc, |r| abc(Some(r.rp_abc_deg), 2)),
        }
    }
}

/// A distance characteristic of the table (every distance row derives from
/// [`DistanceRow::ALL`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DistanceRow {
    /// `n`: cycles measured at both poses.
    Cycles,
    /// The commanded distance D_c [mm].
    Commanded,
    /// Distance accuracy AD [mm].
    Ad,
    /// Distance repeatability ±RD [mm].
    Rd,
}

impl DistanceRow {
    /// Every row, in table order.
    pub const ALL: [DistanceRow; 4] = [
        DistanceRow::Cycles,
        DistanceRow::Commanded,
        DistanceRow::Ad,
        DistanceRow::Rd,
    ];

    /// The characteristic's name and unit as the table heads its row.
    pub fn name(self) -> (&'static str, &'static str) {
        match self {
            DistanceRow::Cycles => ("n", "cycles"),
            DistanceRow::Commanded => ("D_c", "mm"),
            DistanceRow::Ad => ("AD", "mm"),
            DistanceRow::Rd => ("±RD", "mm"),
        }
    }

    fn value(self, d: &DistanceOutcomes) -> Value {
        match self {
            DistanceRow::Cycles => Value::Count(d.cycles),
            DistanceRow::Commanded => of(&d.ad, |a| Some(a.commanded_mm)),
            DistanceRow::Ad => of(&d.ad, |a| Some(a.ad_mm)),
            DistanceRow::Rd => of(&d.rd, |r| Some(r.rd_mm)),
        }
    }
}

/// One cell of a test's column.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Count(usize),
    Number(f64),
    /// Not computed: the reason's code.
    Not(&'static str),
    /// The test has no such pose or pair.
    Absent,
}

impl Value {
    fn number(&self) -> Option<f64> {
        match self {
            Value::Count(n) => Some(*n as f64),
            Value::Number(x) => Some(*x),
            Value::Not(_) | Value::Absent => None,
        }
    }

    fn text(&self) -> String {
        match self {
            Value::Count(n) => n.to_string(),
            Value::Number(x) => format!("{x:.4}"),
            Value::Not(reason) => format!("— ({reason})"),
            Value::Absent => "—".to_string(),
        }
    }
}

fn of<T>(o: &Outcome<T>, f: impl Fn(&T) -> Option<f64>) -> Value {
    match o {
        Outcome::Computed(v) => f(v).map_or(Value::Absent, Value::Number),
        Outcome::NotComputed { reason, .. } => Value::Not(reason.code()),
    }
}

/// The change from the first value to the last, when both are numbers.
fn change(values: &[Value]) -> String {
    match (
        values.first().and_then(Value::number),
        values.last().and_then(Value::number),
    ) {
        (Some(a), Some(b)) if matches!(values[0], Value::Count(_)) => format!("{:+}", b - a),
        (Some(a), Some(b)) => format!("{:+.4}", b - a),
        _ => "—".to_string(),
    }
}

/// The names of the poses (or pairs) of every test, first test's order first.
fn names<'a>(lists: impl Iterator<Item = Vec<String>> + 'a) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for list in lists {
        for n in list {
            if !out.contains(&n) {
                out.push(n);
            }
        }
    }
    out
}

/// One row of the table: the item (pose or pair), the characteristic, its
/// unit, a value per test, and the change when there are two tests or more.
struct Row {
    item: String,
    name: &'static str,
    unit: &'static str,
    values: Vec<Value>,
}

fn rows(tests: &[(String, Assessment)]) -> Vec<Row> {
    let mut out = Vec::new();
    let poses = names(
        tests
            .iter()
            .map(|(_, a)| a.poses.iter().map(|p| p.pose.clone()).collect()),
    );
    for pose in &poses {
        for r in PoseRow::ALL {
            let (name, unit) = r.name();
            let values = tests
                .iter()
                .map(|(_, a)| {
                    a.poses
                        .iter()
                        .find(|p| &p.pose == pose)
                        .map_or(Value::Absent, |p| r.value(p))
                })
                .collect();
            out.push(Row {
                item: pose.clone(),
                name,
                unit,
                values,
            });
        }
    }
    let pair = |d: &DistanceOutcomes| format!("{}–{}", d.from, d.to);
    let pairs = names(
        tests
            .iter()
            .map(|(_, a)| a.distances.iter().map(pair).collect()),
    );
    for p in &pairs {
        for r in DistanceRow::ALL {
            let (name, unit) = r.name();
            let values = tests
                .iter()
                .map(|(_, a)| {
                    a.distances
                        .iter()
                        .find(|d| &pair(d) == p)
                        .map_or(Value::Absent, |d| r.value(d))
                })
                .collect();
            out.push(Row {
                item: p.clone(),
                name,
                unit,
                values,
            });
        }
    }
    out
}

fn stated(v: &Option<String>) -> String {
    v.clone().unwrap_or_else(|| "not stated".to_string())
}

fn stated_number(v: Option<f64>, unit: &str) -> String {
    v.map_or("not stated".to_string(), |x| format!("{x} {unit}"))
}

/// The test conditions as a two-column table.
fn conditions_table(c: &Iso9283Conditions) -> Markup {
    let cycles: Vec<String> = c
        .sets
        .iter()
        .map(|s| format!("{}: {}", s.label, s.cycles))
        .collect();
    html! {
        section {
            h2 { "Test conditions" }
            table #iso9283-conditions {
                tbody {
                    tr { th { "Robot" } td { (stated(&c.robot)) } }
                    tr { th { "Model version" } td { (stated(&c.model_version)) } }
                    tr { th { "Model SHA-256" } td { code { (stated(&c.model_sha256)) } } }
                    tr { th { "Test date" } td { (c.date) } }
                    tr { th { "Load" } td { (stated_number(c.load_kg, "kg")) } }
                    tr { th { "Speed" } td { (stated_number(c.speed_percent, "% of rated")) } }
                    tr { th { "Cycles" } td { (cycles.join("; ")) } }
                    tr { th { "Measurement" } td { (stated(&c.measurement)) } }
                    @for s in &c.sets {
                        tr { th { "Measurement set" } td { (s.label) @if let Some(h) = &s.sha256 { " · SHA-256 " code { (h) } } } }
                    }
                    tr { th { "robocal" } td { (c.robocal_version) } }
                }
            }
        }
    }
}

/// The single table of figures: a column per test and the change.
pub fn figures_table(tests: &[(String, Assessment)]) -> Markup {
    let with_change = tests.len() >= 2;
    let caption = match (tests.first(), tests.last()) {
        (Some((first, _)), Some((last, _))) if with_change => {
            format!("Side by side; change = {last} − {first}")
        }
        _ => String::new(),
    };
    html! {
        section {
            h2 { "ISO 9283 pose characteristics" }
            table #iso9283-figures {
                @if with_change { caption { (caption) } }
                thead { tr {
                    th { "pose" } th { "characteristic" } th { "unit" }
                    @for (label, _) in tests { th { (label) } }
                    @if with_change { th { "change" } }
                } }
                tbody {
                    @for r in rows(tests) {
                        tr {
                            td { (r.item) } td { (r.name) } td { (r.unit) }
                            @for v in &r.values { td { (v.text()) } }
                            @if with_change { td { (change(&r.values)) } }
                        }
                    }
                }
            }
        }
    }
}

/// The page: the conditions, then one table of every test's figures.
pub fn render_iso9283_html(
    conditions: &Iso9283Conditions,
    tests: &[(String, Assessment)],
) -> String {
    let title = match &conditions.robot {
        Some(r) => format!("ISO 9283 report: {r}"),
        None => "ISO 9283 report".to_string(),
    };
    html! {
        (DOCTYPE)
        html lang="en" {
            (page_head(&title, STYLE))
            body {
                main {
                    header.top { p.kicker { "robocal " (conditions.robocal_version) " · ISO 9283 · " (conditions.date) } h1 { (title) } }
                    (conditions_table(conditions))
                    (figures_table(tests))
                    footer {
                        "AP: distance from the commanded position to the barycentre of the attained ones; "
                        "RP = l̄ + 3·S_l; APa/b/c and ±3·S for the orientation angles; AD = D̄ − D_c, "
                        "RD = ±3·S_D between poses (ISO 9283:1998). Millimetres in the frame the attained "
                        "positions were measured in, degrees. “— (reason)”: not computed, and why."
                    }
                }
            }
        }
    }
    .into_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_from_days_since_the_epoch() {
        let day = |d: u64| utc_date(std::time::Duration::from_secs(d * 86_400 + 3600));
        assert_eq!(day(0), "1970-01-01");
        assert_eq!(day(59), "1970-03-01");
        // 2000-01-01 is day 30·365 + 7 (the leap days of 1972 … 1996).
        assert_eq!(day(30 * 365 + 7), "2000-01-01");
        assert_eq!(day(30 * 365 + 7 + 59), "2000-02-29");
        assert_eq!(day(30 * 365 + 7 + 60), "2000-03-01");
        assert!(is_date("2024-02-29") && !is_date("2023-02-29"));
        assert!(!is_date("2024-13-01") && !is_date("2024-1-01") && !is_date("0000-01-01"));
    }
}
