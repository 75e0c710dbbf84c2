//! Inline SVG charts of the calibration report: overlaid histograms (linear or
//! logarithmic bins), scatter views of pose positions coloured by error, and a
//! line chart for convergence curves.
//!
//! Hand-written rather than a plotting crate: the page must stay one
//! self-contained HTML file with text that maud escapes, and the Rust plotting
//! crates (plotters) emit whole SVG documents without per-point `<title>`
//! tooltips. Every bin and every point carries a `<title>` tooltip.
//!
//! Coordinates: a chart is `W × H` user units with a margin for the axes; data
//! are mapped linearly (or by log10) onto it. Units are those of the data
//! (millimetres throughout the report).

use super::format::num;
use maud::{html, Markup, PreEscaped};

const W: f64 = 640.0;
const H: f64 = 300.0;
const LEFT: f64 = 58.0;
const RIGHT: f64 = 14.0;
const TOP: f64 = 12.0;
const BOTTOM: f64 = 44.0;

/// One data series of a chart.
pub struct Series<'a> {
    /// The series' name in the legend and tooltips.
    pub name: &'a str,
    /// Its CSS colour.
    pub color: &'a str,
    /// Its values, in the data's unit.
    pub values: Vec<f64>,
}

/// A linear or logarithmic axis over `[lo, hi]`, mapped to `[a, b]` pixels.
#[derive(Clone, Copy)]
struct Axis {
    lo: f64,
    hi: f64,
    a: f64,
    b: f64,
    log: bool,
}

impl Axis {
    fn new(lo: f64, hi: f64, a: f64, b: f64, log: bool) -> Axis {
        let (lo, hi) = if log {
            (
                lo.max(f64::MIN_POSITIVE).log10(),
                hi.max(f64::MIN_POSITIVE).log10(),
            )
        } else {
            (lo, hi)
        };
        let (lo, hi) = if hi > lo {
            (lo, hi)
        } else {
            (lo - 0.5, lo + 0.5)
        };
        Axis { lo, hi, a, b, log }
    }
    fn px(&self, v: f64) -> f64 {
        let v = if self.log { v.max(1e-300).log10() } else { v };
        self.a + (v - self.lo) / (self.hi - self.lo) * (self.b - self.a)
    }
    /// Tick values with their labels.
    fn ticks(&self) -> Vec<(f64, String)> {
        if self.log {
            let (k0, k1) = (self.lo.floor() as i32, self.hi.ceil() as i32);
            return (k0..=k1)
                .map(|k| 10f64.powi(k))
                .filter(|v| (self.lo - 1e-9..=self.hi + 1e-9).contains(&v.log10()))
                .map(|v| (v, num(v, 3)))
                .collect();
        }
        let span = self.hi - self.lo;
        let raw = span / 6.0;
        let mag = 10f64.powf(raw.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0]
            .iter()
            .map(|m| m * mag)
            .find(|s| span / s <= 7.0)
            .unwrap_or(10.0 * mag);
        let mut v = (self.lo / step).ceil() * step;
        let mut out = Vec::new();
        while v <= self.hi + step * 1e-9 {
            let t = if v.abs() < step * 1e-9 { 0.0 } else { v };
            out.push((t, num(t, 3)));
            v += step;
        }
        out
    }
}

fn frame(x: &Axis, y: &Axis, x_label: &str, y_label: &str) -> Markup {
    html! {
        rect x=(LEFT) y=(TOP) width=(W - LEFT - RIGHT) height=(H - TOP - BOTTOM) class="plot" {}
        @for (v, l) in x.ticks() {
            line x1=(f1(x.px(v))) x2=(f1(x.px(v))) y1=(TOP) y2=(H - BOTTOM) class="grid" {}
            text x=(f1(x.px(v))) y=(H - BOTTOM + 16.0) text-anchor="middle" { (l) }
        }
        @for (v, l) in y.ticks() {
            line x1=(LEFT) x2=(W - RIGHT) y1=(f1(y.px(v))) y2=(f1(y.px(v))) class="grid" {}
            text x=(LEFT - 6.0) y=(f1(y.px(v) + 4.0)) text-anchor="end" { (l) }
        }
        text x=((LEFT + W - RIGHT) / 2.0) y=(H - 6.0) text-anchor="middle" class="label" { (x_label) }
        text x="14" y=((TOP + H - BOTTOM) / 2.0) text-anchor="middle" class="label"
            transform=(format!("rotate(-90 14 {})", (TOP + H - BOTTOM) / 2.0)) { (y_label) }
    }
}

fn f1(v: f64) -> String {
    format!("{v:.1}")
}

fn svg(label: &str, body: Markup) -> Markup {
    html! {
        svg.chart viewBox=(format!("0 0 {W} {H}")) role="img" aria-label=(label)
            { (body) }
    }
}

/// Overlaid histograms of several series over common bins: log10-spaced bins
/// when `log` (error norms spanning decades), linear ones otherwise. Each
/// series is a translucent step area; each bin has a tooltip with the counts.
pub fn histogram(series: &[Series], log: bool, bins: usize, x_label: &str) -> Markup {
    let finite = |v: &f64| v.is_finite() && (!log || *v > 0.0);
    let all: Vec<f64> = series
        .iter()
        .flat_map(|s| s.values.iter().copied().filter(finite))
        .collect();
    if all.is_empty() {
        return html! { p.note { "No finite values to plot." } };
    }
    let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let x = Axis::new(lo, hi, LEFT, W - RIGHT, log);
    let bins = bins.max(1);
    let bin_of = |v: f64| {
        let t = (if log { v.log10() } else { v } - x.lo) / (x.hi - x.lo);
        ((t * bins as f64).floor() as usize).min(bins - 1)
    };
    let edge = |i: usize| {
        let t = x.lo + (x.hi - x.lo) * i as f64 / bins as f64;
        if log {
            10f64.powf(t)
        } else {
            t
        }
    };
    let counts: Vec<Vec<usize>> = series
        .iter()
        .map(|s| {
            let mut c = vec![0; bins];
            for v in s.values.iter().copied().filter(finite) {
                c[bin_of(v)] += 1;
            }
            c
        })
        .collect();
    let top = counts.iter().flatten().copied().max().unwrap_or(1).max(1);
    let y = Axis::new(0.0, top as f64 * 1.05, H - BOTTOM, TOP, false);
    let step_path = |c: &[usize]| {
        let mut d = format!("M{} {}", f1(x.px(edge(0))), f1(y.px(0.0)));
        for (i, n) in c.iter().enumerate() {
            let yy = f1(y.px(*n as f64));
            d += &format!(
                " L{} {yy} L{} {yy}",
                f1(x.px(edge(i))),
                f1(x.px(edge(i + 1)))
            );
        }
        d + &format!(" L{} {} Z", f1(x.px(edge(bins))), f1(y.px(0.0)))
    };
    let body = html! {
        (frame(&x, &y, x_label, "poses"))
        @for (s, c) in series.iter().zip(&counts) {
            path d=(step_path(c)) fill=(s.color) fill-opacity="0.18" stroke=(s.color) stroke-width="1.6" {}
        }
        @for i in 0..bins {
            rect.hit x=(f1(x.px(edge(i)))) y=(TOP) width=(f1(x.px(edge(i + 1)) - x.px(edge(i))))
                height=(H - TOP - BOTTOM) {
                title {
                    (num(edge(i), 3)) " – " (num(edge(i + 1), 3)) ": "
                    @for (k, (s, c)) in series.iter().zip(&counts).enumerate() {
                        @if k > 0 { ", " }
                        (s.name) " " (c[i])
                    }
                }
            }
        }
    };
    svg(x_label, body)
}

/// Colour of `t` in [0, 1] on a perceptually ordered ramp (viridis, five
/// stops, linear between them).
pub fn ramp(t: f64) -> String {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    } * 4.0;
    let i = (t.floor() as usize).min(3);
    let f = t - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let c = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    format!("#{:02x}{:02x}{:02x}", c(a.0, b.0), c(a.1, b.1), c(a.2, b.2))
}

/// A point of a scatter view: coordinates, the value that colours it and its
/// tooltip.
pub struct Point {
    /// Horizontal coordinate, in the data's unit.
    pub x: f64,
    /// Vertical coordinate, in the data's unit.
    pub y: f64,
    /// The value its colour shows.
    pub value: f64,
    /// Its tooltip text.
    pub tip: String,
}

/// Scatter of positions coloured by value on the scale `[0, vmax]` (values
/// above `vmax` take the top colour). Equal scales on both axes, so the view
/// is not distorted; the largest values are drawn last (on top).
pub fn scatter(points: &[Point], vmax: f64, x_label: &str, y_label: &str) -> Markup {
    let xs = || points.iter().map(|p| p.x).filter(|v| v.is_finite());
    let ys = || points.iter().map(|p| p.y).filter(|v| v.is_finite());
    let (Some(x0), Some(y0)) = (xs().reduce(f64::min), ys().reduce(f64::min)) else {
        return html! { p.note { "No positions to plot." } };
    };
    let x1 = xs().fold(f64::NEG_INFINITY, f64::max);
    let y1 = ys().fold(f64::NEG_INFINITY, f64::max);
    // Equal scale: widen the narrower range around its centre.
    let (pw, ph) = (W - LEFT - RIGHT, H - TOP - BOTTOM);
    let scale = ((x1 - x0) / pw).max((y1 - y0) / ph).max(1e-9) * 1.06;
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let x = Axis::new(
        cx - scale * pw / 2.0,
        cx + scale * pw / 2.0,
        LEFT,
        W - RIGHT,
        false,
    );
    let y = Axis::new(
        cy - scale * ph / 2.0,
        cy + scale * ph / 2.0,
        H - BOTTOM,
        TOP,
        false,
    );
    let mut order: Vec<&Point> = points
        .iter()
        .filter(|p| p.x.is_finite() && p.y.is_finite())
        .collect();
    order.sort_by(|a, b| a.value.total_cmp(&b.value));
    let r = if points.len() > 400 { 2.6 } else { 3.6 };
    let body = html! {
        (frame(&x, &y, x_label, y_label))
        @for p in order {
            circle cx=(f1(x.px(p.x))) cy=(f1(y.px(p.y))) r=(r) fill=(ramp(p.value / vmax)) {
                title { (p.tip) }
            }
        }
    };
    svg(x_label, body)
}

/// A horizontal colour bar for [`scatter`]'s scale.
pub fn colour_bar(vmax: f64, label: &str) -> Markup {
    let stops: String = (0..=10)
        .map(|i| {
            format!(
                "<stop offset=\"{}%\" stop-color=\"{}\"/>",
                i * 10,
                ramp(i as f64 / 10.0)
            )
        })
        .collect();
    html! {
        svg.bar viewBox="0 0 320 34" role="img" aria-label=(label) {
            defs { linearGradient #ramp x1="0" x2="1" y1="0" y2="0" { (PreEscaped(stops)) } }
            rect x="10" y="2" width="300" height="12" fill="url(#ramp)" {}
            text x="10" y="30" { "0" }
            text x="160" y="30" text-anchor="middle" { (label) }
            text x="310" y="30" text-anchor="end" { "≥ " (num(vmax, 3)) }
        }
    }
}

/// Each joint's trained range [deg] as a bar over −180…180°, with its fade
/// band beyond it: where a compensator applies fully, fades, and is off.
pub fn ranges(ranges_deg: &[[f64; 2]], fade_deg: f64) -> Markup {
    let row = 18.0;
    let h = row * ranges_deg.len() as f64 + 22.0;
    let x = |d: f64| 40.0 + (d.clamp(-180.0, 180.0) + 180.0) / 360.0 * 560.0;
    html! {
        svg.ranges viewBox=(format!("0 0 620 {}", f1(h))) role="img" aria-label="Trained joint ranges" {
            @for (i, r) in ranges_deg.iter().enumerate() {
                @let y = 4.0 + row * i as f64;
                text x="4" y=(f1(y + 11.0)) { "J" (i + 1) }
                rect x=(f1(x(-180.0))) y=(f1(y + 5.0)) width="560" height="2" fill="#ddd" {}
                rect x=(f1(x(r[0] - fade_deg))) y=(f1(y + 1.0)) width=(f1(x(r[1] + fade_deg) - x(r[0] - fade_deg))) height="10" fill="#c6dbef" {}
                rect x=(f1(x(r[0]))) y=(f1(y + 1.0)) width=(f1(x(r[1]) - x(r[0]))) height="10" fill="#3182bd" {
                    title { "J" (i + 1) ": " (format!("{:.1}", r[0])) "° to " (format!("{:.1}", r[1])) "°" }
                }
            }
            @for d in [-180.0, -90.0, 0.0, 90.0, 180.0] {
                text x=(f1(x(d))) y=(f1(h - 4.0)) text-anchor="middle" { (format!("{d:.0}")) "°" }
            }
        }
    }
}

/// A line chart of one series against its index (1-based), log y when `log`.
pub fn line(values: &[f64], log: bool, color: &str, x_label: &str, y_label: &str) -> Markup {
    let pts: Vec<(f64, f64)> = values
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite() && (!log || **v > 0.0))
        .map(|(i, v)| ((i + 1) as f64, *v))
        .collect();
    if pts.is_empty() {
        return html! { p.note { "No values to plot." } };
    }
    let lo = pts.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let hi = pts.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    let x = Axis::new(1.0, pts.len().max(2) as f64, LEFT, W - RIGHT, false);
    let y = Axis::new(lo, hi, H - BOTTOM, TOP, log);
    let d: String = pts
        .iter()
        .enumerate()
        .map(|(i, (a, b))| {
            format!(
                "{}{} {} ",
                if i == 0 { "M" } else { "L" },
                f1(x.px(*a)),
                f1(y.px(*b))
            )
        })
        .collect();
    let body = html! {
        (frame(&x, &y, x_label, y_label))
        path d=(d) fill="none" stroke=(color) stroke-width="1.8" {}
        @for (a, b) in &pts {
            circle.pt cx=(f1(x.px(*a))) cy=(f1(y.px(*b))) r="2.2" fill=(color) {
                title { (x_label) " " (a) ": " (num(*b, 4)) }
            }
        }
    };
    svg(y_label, body)
}
