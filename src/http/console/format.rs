//! How the console writes numbers: lengths to 0.001 mm, angles to 0.0001°,
//! masses to 0.001 kg, and never a negative zero (`-0.000` is `0.000`).
//! Form fields are prefilled with the same rounding, trailing zeros dropped
//! (`125`, `216.5`), so a value typed in comes back as typed.

/// Decimals of a length [mm].
pub(super) const MM_DECIMALS: usize = 3;
/// Decimals of an angle [deg].
pub(super) const DEG_DECIMALS: usize = 4;
/// Decimals of a mass [kg].
pub(super) const KG_DECIMALS: usize = 3;

/// `x` with `decimals` decimals; `-0.000` written as `0.000`; a value that
/// is not finite as `—`.
pub(super) fn fixed(x: f64, decimals: usize) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    let s = format!("{x:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => s,
    }
}

/// A length [mm] to 0.001 mm.
pub(super) fn mm(x: f64) -> String {
    fixed(x, MM_DECIMALS)
}

/// An angle [deg] to 0.0001°.
pub(super) fn deg(x: f64) -> String {
    fixed(x, DEG_DECIMALS)
}

/// A mass [kg] to 0.001 kg.
pub(super) fn kg(x: f64) -> String {
    fixed(x, KG_DECIMALS)
}

/// `x` rounded to `decimals` decimals with the trailing zeros (and a
/// trailing point) dropped: a form field's value (`125`, `216.5`, `0`).
pub(super) fn trimmed(x: f64, decimals: usize) -> String {
    let s = fixed(x, decimals);
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_and_angles_are_rounded_without_negative_zero() {
        assert_eq!(mm(120.00003431320161), "120.000");
        assert_eq!(mm(-0.0), "0.000");
        assert_eq!(mm(-0.0004), "0.000");
        assert_eq!(mm(-0.0005001), "-0.001");
        assert_eq!(deg(30.000049), "30.0000");
        assert_eq!(deg(-1e-9), "0.0000");
        assert_eq!(kg(2.5), "2.500");
        assert_eq!(mm(f64::NAN), "—");
    }

    #[test]
    fn form_values_drop_trailing_zeros() {
        assert_eq!(trimmed(125.0, MM_DECIMALS), "125");
        assert_eq!(trimmed(216.5, MM_DECIMALS), "216.5");
        assert_eq!(trimmed(-0.00001, MM_DECIMALS), "0");
        assert_eq!(trimmed(120.00003431320161, MM_DECIMALS), "120");
        assert_eq!(trimmed(-12.34567, DEG_DECIMALS), "-12.3457");
        assert_eq!(trimmed(1500.0, 0), "1500");
    }
}
