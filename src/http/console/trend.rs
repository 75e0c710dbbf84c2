//! The trend of a robot's checks as inline SVG: the mean position error
//! [mm] of every check against its time (x: UTC time of the check, ticks at
//! round intervals), the degraded and recalibrate thresholds as dashed lines
//! over coloured bands, and a mark where the version scored changes.
//!
//! Scaling: the y axis runs from 0 to
//! `max(1.5 · recalibrate_mm, min(largest mean, 3 · median mean))` (and 5 %
//! room), so the thresholds are always in the upper part of the plot and one
//! outlier does not squash the other checks to the bottom: a check above
//! the top is drawn on the top edge as an upward triangle labelled with its
//! value.

use super::format::{fixed, mm, trimmed, MM_DECIMALS};
use crate::records::CheckRow;
use crate::service::checks::shift_of;
use maud::{html, Markup};
use robocal_core::check::CheckThresholds;

/// Plot size and margins [px].
const W: f64 = 760.0;
const H: f64 = 240.0;
const LEFT: f64 = 56.0;
const RIGHT: f64 = 120.0;
const TOP: f64 = 22.0;
const BOTTOM: f64 = 40.0;

/// Seconds since 1970-01-01 UTC of a stored time (`YYYY-MM-DDTHH:MM:SS[.f]Z`,
/// as the store writes it); `None` for another text.
pub(super) fn epoch_seconds(stamp: &str) -> Option<f64> {
    let b = stamp.as_bytes();
    if b.len() < 19 || b[4] != b'-' || b[7] != b'-' || b[13] != b':' || b[16] != b':' {
        return None;
    }
    let num = |r: std::ops::Range<usize>| stamp.get(r)?.parse::<i64>().ok();
    let (y, mo, d) = (num(0..4)?, num(5..7)?, num(8..10)?);
    let (h, mi) = (num(11..13)?, num(14..16)?);
    let s: f64 = stamp
        .get(17..)?
        .trim_end_matches('Z')
        .trim_end_matches("+00:00")
        .parse()
        .ok()?;
    Some((days_from_civil(y, mo, d) * 86_400 + h * 3_600 + mi * 60) as f64 + s)
}

/// Days from 1970-01-01 to a proleptic Gregorian date (H. Hinnant's
/// `days_from_civil`).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// The date of a day count from 1970-01-01 (the inverse of [`days_from_civil`]).
fn civil_from_days(z: i64) -> (i64, i64, i64) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

/// A tick label of time `t` [s since epoch, UTC] for ticks `step` seconds apart.
fn time_label(t: f64, step: f64) -> String {
    let secs = t.floor() as i64;
    let (y, m, d) = civil_from_days(secs.div_euclid(86_400));
    let sod = secs.rem_euclid(86_400);
    let (h, mi, s) = (sod / 3600, sod % 3600 / 60, sod % 60);
    if step >= 86_400.0 {
        format!("{y}-{m:02}-{d:02}")
    } else if step >= 60.0 {
        format!("{m:02}-{d:02} {h:02}:{mi:02}")
    } else {
        format!("{h:02}:{mi:02}:{s:02}")
    }
}

/// Tick spacings of the time axis [s].
const TIME_STEPS: [f64; 20] = [
    1.0,
    2.0,
    5.0,
    10.0,
    15.0,
    30.0,
    60.0,
    120.0,
    300.0,
    900.0,
    1800.0,
    3600.0,
    10_800.0,
    21_600.0,
    43_200.0,
    86_400.0,
    172_800.0,
    604_800.0,
    2_592_000.0,
    31_536_000.0,
];

/// The y axis' top [mm]: see the module's header.
pub(super) fn y_top(means: &[f64], t: &CheckThresholds) -> f64 {
    let mut m: Vec<f64> = means.iter().copied().filter(|x| x.is_finite()).collect();
    m.sort_by(f64::total_cmp);
    let shown = match (m.last(), m.len()) {
        (Some(&max), n) => {
            let median = if n % 2 == 1 {
                m[n / 2]
            } else {
                0.5 * (m[n / 2 - 1] + m[n / 2])
            };
            max.min(3.0 * median)
        }
        (None, _) => 0.0,
    };
    (1.5 * t.recalibrate_mm).max(shown) * 1.05
}

/// A round step for about `ticks` ticks over `span`: 1, 2 or 5 × 10^k.
fn nice_step(span: f64, ticks: f64) -> f64 {
    let raw = span / ticks;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|k| k * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

/// The trend plot of `checks` (oldest first).
pub(super) fn trend(checks: &[CheckRow], t: &CheckThresholds) -> Markup {
    let times: Vec<Option<f64>> = checks
        .iter()
        .map(|c| epoch_seconds(&c.created_at))
        .collect();
    let known: Vec<f64> = times.iter().flatten().copied().collect();
    let (t0, t1) = match (
        known.iter().copied().reduce(f64::min),
        known.iter().copied().reduce(f64::max),
    ) {
        (Some(a), Some(b)) if b - a >= 1.0 => (a, b),
        (Some(a), _) => (a - 30.0, a + 30.0),
        _ => (0.0, 1.0),
    };
    // Checks without a readable time keep their place between their neighbours.
    let tx: Vec<f64> = (0..checks.len())
        .map(|i| times[i].unwrap_or(t0 + (t1 - t0) * i as f64 / checks.len().max(2) as f64))
        .collect();
    let top = y_top(&checks.iter().map(|c| c.mean_mm).collect::<Vec<_>>(), t);
    let x = |s: f64| LEFT + (W - LEFT - RIGHT) * (s - t0) / (t1 - t0);
    let y = |v: f64| H - BOTTOM - (H - TOP - BOTTOM) * (v.clamp(0.0, top) / top);
    let step = TIME_STEPS
        .into_iter()
        .find(|s| (t1 - t0) / s <= 6.0)
        .unwrap_or(31_536_000.0);
    let ticks: Vec<f64> = {
        let first = (t0 / step).ceil() * step;
        (0..)
            .map(|k| first + k as f64 * step)
            .take_while(|s| *s <= t1)
            .collect()
    };
    let ystep = nice_step(top, 4.0);
    let yticks: Vec<f64> = (0..)
        .map(|k| k as f64 * ystep)
        .take_while(|v| *v <= top)
        .collect();
    let points: String = tx
        .iter()
        .zip(checks)
        .map(|(s, c)| format!("{:.1},{:.1}", x(*s), y(c.mean_mm)))
        .collect::<Vec<_>>()
        .join(" ");
    let bands = [
        (0.0, t.degraded_mm, "#e9f5ec"),
        (t.degraded_mm, t.recalibrate_mm, "#fbf3dc"),
        (t.recalibrate_mm, top, "#fbe7e5"),
    ];
    html! {
        svg #check-trend width=(W) height=(H) viewBox={ "0 0 " (W) " " (H) } role="img"
            data-top-mm=(fixed(top, 6))
            aria-label="mean position error of every check against time, with the thresholds" {
            @for (lo, hi, colour) in bands {
                @if hi > lo {
                    rect x=(LEFT) y=(y(hi)) width=(W - LEFT - RIGHT) height=(y(lo) - y(hi)) fill=(colour) {}
                }
            }
            line x1=(LEFT) y1=(H - BOTTOM) x2=(W - RIGHT) y2=(H - BOTTOM) stroke="#5b6475" {}
            line x1=(LEFT) y1=(TOP) x2=(LEFT) y2=(H - BOTTOM) stroke="#5b6475" {}
            text x="4" y=(TOP - 8.0) font-size="11" fill="#5b6475" { "mean [mm]" }
            @for v in &yticks {
                line x1=(LEFT - 4.0) y1=(y(*v)) x2=(LEFT) y2=(y(*v)) stroke="#5b6475" {}
                text.y-tick x=(LEFT - 6.0) y=(y(*v) + 4.0) font-size="10" fill="#5b6475" text-anchor="end" { (trimmed(*v, MM_DECIMALS)) }
            }
            @for s in &ticks {
                line x1=(x(*s)) y1=(H - BOTTOM) x2=(x(*s)) y2=(H - BOTTOM + 4.0) stroke="#5b6475" {}
                text.time-tick x=(x(*s)) y=(H - BOTTOM + 16.0) font-size="10" fill="#5b6475" text-anchor="middle" { (time_label(*s, step)) }
            }
            text x=(W - RIGHT) y=(H - 6.0) font-size="10" fill="#5b6475" text-anchor="end" { "time (UTC)" }
            @for (mm_, name, colour) in [(t.degraded_mm, "degraded", "#b07d00"), (t.recalibrate_mm, "recalibrate", "#b3261e")] {
                line.threshold data-threshold=(name) x1=(LEFT) y1=(y(mm_)) x2=(W - RIGHT) y2=(y(mm_)) stroke=(colour) stroke-dasharray="5 4" {
                    title { (name) " above " (mm(mm_)) " mm" }
                }
                text x=(W - RIGHT + 4.0) y=(y(mm_) + 4.0) font-size="10" fill=(colour) { (name) " " (mm(mm_)) }
            }
            @for i in 1..checks.len() {
                @if checks[i - 1].version != checks[i].version {
                    @let mx = 0.5 * (x(tx[i]) + x(tx[i - 1]));
                    line.version-change x1=(mx) y1=(TOP) x2=(mx) y2=(H - BOTTOM) stroke="#1f5fbf" stroke-dasharray="2 3" {}
                    text x=(mx + 2.0) y=(TOP - 4.0) font-size="10" fill="#1f5fbf" { "v" (checks[i].version) }
                }
            }
            @if checks.len() > 1 {
                polyline points=(points) fill="none" stroke="#1d2330" stroke-width="1.5" {}
            }
            @for (s, c) in tx.iter().zip(checks) {
                @let (cx, cy) = (x(*s), y(c.mean_mm));
                @let title = html! {
                    title {
                        (c.created_at) ": " (mm(c.mean_mm)) " mm, " (c.status)
                        @if let Some(f) = shift_of(c) { " by a frame shift of " (mm(f.translation_mm)) " mm, " (super::format::deg(f.rotation_deg)) "°" }
                        ", v" (c.version)
                    }
                };
                @if c.mean_mm > top {
                    polygon.check-point.off-scale points=(format!("{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}", cx - 5.0, cy + 6.0, cx + 5.0, cy + 6.0, cx, cy - 3.0))
                        fill=(super::status::row_colour(c)) data-status=(c.status) data-check=(c.id) { (title) }
                    text.off-scale-label x=(cx + 7.0) y=(cy + 8.0) font-size="10" fill="#1d2330" { "↑ " (mm(c.mean_mm)) }
                } @else {
                    circle.check-point cx=(format!("{cx:.1}")) cy=(format!("{cy:.1}")) r="4"
                        fill=(super::status::row_colour(c)) data-status=(c.status) data-check=(c.id) { (title) }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stored_times_read_as_epoch_seconds() {
        assert_eq!(epoch_seconds("1970-01-01T00:00:00Z"), Some(0.0));
        // 2000-03-01 is day 11017 (30 years, 7 leap days, Jan + Feb 2000).
        assert_eq!(
            epoch_seconds("2000-03-01T00:00:01.500Z"),
            Some(11_017.0 * 86_400.0 + 1.5)
        );
        assert_eq!(epoch_seconds("not a time"), None);
        for days in [-1000, 0, 11_017, 20_000, 25_000] {
            let (y, m, d) = civil_from_days(days);
            assert_eq!(days_from_civil(y, m, d), days);
        }
        assert_eq!(
            time_label(11_017.0 * 86_400.0 + 3_723.0, 900.0),
            "03-01 01:02"
        );
        assert_eq!(time_label(11_017.0 * 86_400.0, 86_400.0), "2000-03-01");
    }

    #[test]
    fn one_outlier_does_not_squash_the_thresholds() {
        let t = CheckThresholds::default();
        // Five checks near 0.3 mm and one at 40 mm: the top stays at 1.5 × the
        // recalibrate level (1 mm), the outlier is drawn off scale.
        let top = y_top(&[0.3, 0.31, 0.29, 40.0, 0.32, 0.3], &t);
        assert!((top - 1.5 * 1.05).abs() < 1e-12, "{top}");
        // Every check far above the thresholds: all of them fit.
        let top = y_top(&[8.0, 9.0, 10.0], &t);
        assert!((top - 10.0 * 1.05).abs() < 1e-12, "{top}");
        // No check: the thresholds alone.
        assert!((y_top(&[], &t) - 1.575).abs() < 1e-12);
    }

    #[test]
    fn value_ticks_are_round() {
        for (span, step) in [(1.575, 0.5), (10.5, 5.0), (0.07, 0.02)] {
            assert!((nice_step(span, 4.0) - step).abs() < 1e-12 * step, "{span}");
        }
    }
}
