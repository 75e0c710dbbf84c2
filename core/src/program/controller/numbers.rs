//! The numbers a controller's tool and frame data take (one table; the
//! export's checks and messages derive from it), and the position registers
//! a Fanuc export may write.
//!
//! - KRL (`$config.dat` of KSS 8 as shipped): `TOOL_DATA[1..16]` (with
//!   `LOAD_DATA` of the same index) and `BASE_DATA[1..32]`; the arrays start
//!   at 1, and the flange and the robot base are `$NULLFRAME`, not an index.
//! - Fanuc (R-30iB as shipped): `UTOOL[1..10]` (with the payload schedule
//!   `$PLST_GRP1` of the same index) and `UFRAME[1..9]`; tool frame 0 is the
//!   faceplate and user frame 0 the world frame, which cannot be set.
//! - RAPID and URScript name their data; they have no numbers.

use crate::program::Language;
use crate::solve::cell::ItemKind;
use serde::Serialize;

/// The numbers one kind of a controller's data takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct NumberRange {
    /// The data's name in the language (`TOOL_DATA`, `UFRAME`, …).
    pub data: &'static str,
    /// Lowest number the data take (1 on every controller here).
    pub first: u32,
    /// Highest number the data take (16 or 32 in KRL, 10 or 9 in Fanuc).
    pub last: u32,
    /// What number 0 is on that controller.
    pub zero: &'static str,
}

/// The numbers of `kind` in `language`; `None` where data are named.
pub(super) fn range(language: Language, kind: ItemKind) -> Option<NumberRange> {
    let r = |data, last, zero| {
        Some(NumberRange {
            data,
            first: 1,
            last,
            zero,
        })
    };
    match (language, kind) {
        (Language::Krl, ItemKind::Tool) => r("TOOL_DATA", 16, "the flange ($NULLFRAME)"),
        (Language::Krl, ItemKind::WorkObject) => r("BASE_DATA", 32, "the robot base ($NULLFRAME)"),
        (Language::Fanuc, ItemKind::Tool) => r("UTOOL", 10, "the faceplate, which cannot be set"),
        (Language::Fanuc, ItemKind::WorkObject) => {
            r("UFRAME", 9, "the world frame, which cannot be set")
        }
        (Language::Rapid | Language::UrScript, _) => None,
    }
}

/// The position registers a Fanuc export may overwrite, `first..=last`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct RegisterRange {
    /// First register the export may write.
    pub first: u32,
    /// Last register the export may write (inclusive).
    pub last: u32,
}

/// Largest register number accepted (the controller's own count, 100 as
/// shipped, is not known here: the registers must exist on it).
pub(super) const REGISTER_MAX: u32 = 9999;

impl RegisterRange {
    /// `first..=last`, or what is wrong with it.
    pub fn new(first: u32, last: u32) -> Result<Self, String> {
        if first < 1 || last > REGISTER_MAX || last < first {
            return Err(format!(
                "position registers {first}..{last}: give FIRST..LAST with 1 ≤ FIRST ≤ LAST ≤ {REGISTER_MAX}"
            ));
        }
        Ok(RegisterRange { first, last })
    }

    /// How many registers the range holds.
    pub fn count(&self) -> usize {
        (self.last - self.first + 1) as usize
    }
}

impl std::str::FromStr for RegisterRange {
    type Err = String;
    /// `91..99` (or `91-99`; one number is a range of one).
    fn from_str(s: &str) -> Result<Self, String> {
        let t = s.trim();
        let (a, b) = t
            .split_once("..")
            .or_else(|| t.split_once('-'))
            .unwrap_or((t, t));
        let num = |v: &str| {
            v.trim()
                .parse::<u32>()
                .map_err(|_| format!("position registers `{s}`: give FIRST..LAST, e.g. 91..99"))
        };
        RegisterRange::new(num(a)?, num(b)?)
    }
}

impl std::fmt::Display for RegisterRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}..{}", self.first, self.last)
    }
}

/// One register the export writes and the item it holds.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct UsedRegister {
    /// The position register number (`PR[n]`).
    pub register: u32,
    /// Tool or work object.
    pub kind: ItemKind,
    /// The item's name in the cell.
    pub name: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn register_ranges_read_and_refuse() {
        assert_eq!(
            "91..99".parse::<RegisterRange>(),
            Ok(RegisterRange {
                first: 91,
                last: 99
            })
        );
        assert_eq!("5-6".parse::<RegisterRange>().unwrap().count(), 2);
        assert_eq!("7".parse::<RegisterRange>().unwrap().count(), 1);
        for bad in ["0..3", "9..3", "a..b", "1..10000", ""] {
            let e = bad.parse::<RegisterRange>().unwrap_err();
            assert!(e.contains("FIRST..LAST"), "{bad}: {e}");
        }
    }
}
