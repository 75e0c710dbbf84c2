//! Number formatting and method names shared by the HTML report and the
//! command line's text report.

use crate::calibrate::identify::Method;

/// Display name of a calibration method (`km` → `KM`, the table's label), the
/// same in the command line's table and the HTML report.
pub fn method_label(method: Method) -> &'static str {
    method.label()
}

/// [`method_label`] of a method name as a stored report keys it; a name of
/// no method (a report of another version) stays as it is.
pub fn key_label(key: &str) -> &str {
    match Method::from_name(key) {
        Some(m) => method_label(m),
        None => key,
    }
}

/// `x` with `sig` significant digits, scientific outside [1e-3, 1e6); "—"
/// for a value that is not finite.
pub fn num(x: f64, sig: usize) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let sig = sig.clamp(1, 17);
    let e = x.abs().log10().floor() as i32;
    if !(-3..6).contains(&e) {
        return format!("{:.*e}", sig - 1, x);
    }
    let decimals = sig as i32 - 1 - e;
    if decimals >= 0 {
        let decimals = decimals as usize;
        return format!("{x:.decimals$}");
    }
    // Round the integer part too: 1735 with 2 digits is 1700.
    let p = 10f64.powi(-decimals);
    format!("{:.0}", (x / p).round() * p)
}

/// An optional value, "—" when missing.
pub fn opt(x: Option<f64>, sig: usize) -> String {
    x.map_or_else(|| "—".into(), |v| num(v, sig))
}

/// A parameter value in its display unit: fixed decimals for mm and deg, so a
/// column lines up; significant digits otherwise; no "-0.0000".
pub fn param(x: f64, unit: &str) -> String {
    let s = match unit {
        "mm" => format!("{x:.4}"),
        "deg" => format!("{x:.5}"),
        _ => num(x, 5),
    };
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(num(0.012345, 3), "0.0123");
        assert_eq!(num(12.345, 3), "12.3");
        assert_eq!(num(1735.0, 2), "1700");
        assert_eq!(num(2.5e-7, 2), "2.5e-7");
        assert_eq!(num(f64::INFINITY, 3), "—");
        assert_eq!(param(-0.00001, "mm"), "0.0000");
        assert_eq!(method_label(Method::SkcmTlbo), "SKCM-C (TLBO)");
        assert_eq!(key_label("skcm-tlbo"), "SKCM-C (TLBO)");
        assert_eq!(key_label("skcm-tlbonn"), "SKCM-TLBONN");
        assert_eq!(key_label("tlbo"), "tlbo");
        assert_eq!(key_label("new"), "new");
    }
}
