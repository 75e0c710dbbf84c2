//! Configuration (branch) flags of a 6R arm: shoulder, elbow and wrist.
//!
//! Definitions (geometric, independent of the sign conventions of a model; see
//! `analytic` for how they are evaluated):
//! - **Shoulder** `Front`: the wrist point lies in front of joint 1, i.e. its x
//!   coordinate in the frame of link 1 (after the base rotation θ1) is ≥ 0;
//!   `Back`: the arm reaches over its back.
//! - **Elbow** `Up`: seen with the shoulder in front, the elbow lies on the +z
//!   side (the side of the base z axis) of the line from the shoulder to the
//!   wrist point; `Down` otherwise. Like controllers' status bits, the flag is
//!   defined in the arm's own frame, so with the shoulder at the back an `Up`
//!   elbow is physically below that line.
//! - **Wrist** `NoFlip`: sin θ5 ≥ 0 for the chain angle θ5 = q5 + θ5-offset of
//!   joint 5 (1-based); `Flip`: sin θ5 < 0.
//!
//! Branch index: bit 0 = `Back`, bit 1 = `Down`, bit 2 = `Flip` (0..=7).

use serde::{Deserialize, Serialize};
use std::fmt;

/// Where the wrist point lies about joint 1 (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shoulder {
    /// Wrist point in front of joint 1 (x ≥ 0 in link 1's frame).
    Front,
    /// Wrist point behind joint 1: the arm reaches over its back.
    Back,
}

/// Where the elbow lies about the shoulder–wrist line, in the arm's own frame (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Elbow {
    /// Elbow on the +z side of the shoulder–wrist line.
    Up,
    /// Elbow on the −z side of the shoulder–wrist line.
    Down,
}

/// The sign of sin θ5 (chain angle of joint 5, 1-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Wrist {
    /// sin θ5 ≥ 0.
    NoFlip,
    /// sin θ5 < 0.
    Flip,
}

/// One configuration branch of a 6R arm (see module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Configuration {
    /// Front or back: where the wrist point lies about joint 1.
    pub shoulder: Shoulder,
    /// Up or down: the elbow's side of the shoulder–wrist line.
    pub elbow: Elbow,
    /// No flip or flip: the sign of sin θ5.
    pub wrist: Wrist,
}

impl Configuration {
    /// The branch with these flags.
    pub const fn new(shoulder: Shoulder, elbow: Elbow, wrist: Wrist) -> Self {
        Configuration {
            shoulder,
            elbow,
            wrist,
        }
    }

    /// All eight branches, in index order.
    pub fn all() -> [Configuration; 8] {
        std::array::from_fn(|i| Configuration::from_index(i).expect("index < 8"))
    }

    /// Branch index 0..=7 (bit 0 `Back`, bit 1 `Down`, bit 2 `Flip`).
    pub fn index(&self) -> usize {
        usize::from(self.shoulder == Shoulder::Back)
            | usize::from(self.elbow == Elbow::Down) << 1
            | usize::from(self.wrist == Wrist::Flip) << 2
    }

    /// The branch of index `i` (bit 0 `Back`, bit 1 `Down`, bit 2 `Flip`), or `None` beyond 7.
    pub fn from_index(i: usize) -> Option<Configuration> {
        if i >= 8 {
            return None;
        }
        Some(Configuration {
            shoulder: if i & 1 == 0 {
                Shoulder::Front
            } else {
                Shoulder::Back
            },
            elbow: if i & 2 == 0 { Elbow::Up } else { Elbow::Down },
            wrist: if i & 4 == 0 {
                Wrist::NoFlip
            } else {
                Wrist::Flip
            },
        })
    }

    /// Parses `front,up,noflip` (any order and separators `,` `-` `/` or
    /// spaces; `flip`/`noflip`, also `no-flip`) or a branch index `0`..`7`.
    /// Flags left out default to `front`, `up`, `noflip`.
    pub fn parse(text: &str) -> Result<Configuration, BranchError> {
        let t = text.trim().to_ascii_lowercase();
        if let Ok(i) = t.parse::<usize>() {
            return Configuration::from_index(i).ok_or(BranchError::Index { index: i });
        }
        let t = t.replace("no-flip", "noflip").replace("no_flip", "noflip");
        let mut c = Configuration::new(Shoulder::Front, Elbow::Up, Wrist::NoFlip);
        let mut any = false;
        for word in t
            .split(|ch: char| ch == ',' || ch == '-' || ch == '/' || ch.is_whitespace())
            .filter(|w| !w.is_empty())
        {
            any = true;
            match word {
                "front" => c.shoulder = Shoulder::Front,
                "back" => c.shoulder = Shoulder::Back,
                "up" => c.elbow = Elbow::Up,
                "down" => c.elbow = Elbow::Down,
                "noflip" => c.wrist = Wrist::NoFlip,
                "flip" => c.wrist = Wrist::Flip,
                other => {
                    return Err(BranchError::UnknownFlag {
                        flag: other.to_string(),
                    })
                }
            }
        }
        if !any {
            return Err(BranchError::Empty);
        }
        Ok(c)
    }
}

/// Why a text is not a configuration branch.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BranchError {
    /// A number that is not a branch index.
    #[error("branch index must be 0..=7, got {index}")]
    Index {
        /// The number given.
        index: usize,
    },
    /// A word that is not a flag.
    #[error("unknown branch flag `{flag}`; use front|back, up|down, noflip|flip or an index 0..7")]
    UnknownFlag {
        /// The word given.
        flag: String,
    },
    /// The text holds no flag.
    #[error("empty branch")]
    Empty,
}

impl fmt::Display for Configuration {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self.shoulder {
            Shoulder::Front => "front",
            Shoulder::Back => "back",
        };
        let e = match self.elbow {
            Elbow::Up => "up",
            Elbow::Down => "down",
        };
        let w = match self.wrist {
            Wrist::NoFlip => "noflip",
            Wrist::Flip => "flip",
        };
        write!(f, "{s}-{e}-{w}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_parse_and_display_round_trip() {
        for (i, c) in Configuration::all().iter().enumerate() {
            assert_eq!(c.index(), i);
            assert_eq!(Configuration::parse(&c.to_string()).unwrap(), *c);
            assert_eq!(Configuration::parse(&i.to_string()).unwrap(), *c);
        }
        let c = Configuration::parse("Back, no-flip").unwrap();
        assert_eq!(
            c,
            Configuration::new(Shoulder::Back, Elbow::Up, Wrist::NoFlip)
        );
        assert_eq!(
            Configuration::parse("front,sideways"),
            Err(BranchError::UnknownFlag {
                flag: "sideways".into()
            })
        );
        assert_eq!(
            Configuration::parse("9"),
            Err(BranchError::Index { index: 9 })
        );
        assert_eq!(Configuration::parse(" ,/ "), Err(BranchError::Empty));
    }
}
