//! ISO 9283 pose characteristics: the test cube, its poses solved to joint
//! commands, and accuracy and repeatability from measured cycles.
//!
//! The standard (ISO 9283:1998, "Manipulating industrial robots —
//! Performance criteria and related test methods", clauses on the test cube,
//! pose accuracy and repeatability, and distance accuracy and repeatability):
//!
//! - **Test cube** ([`cube`]): the largest cube in the part of the workspace
//!   that is used (here: an axis-aligned box given in the robot's base frame),
//!   edges parallel to the base frame. Corners (offsets from the centre in
//!   units of half the edge): C1 (−,−,−), C2 (+,−,−), C3 (+,+,−), C4 (−,+,−),
//!   C5 (−,−,+), C6 (+,−,+), C7 (+,+,+), C8 (−,+,+). The poses lie on the
//!   diagonal plane C1–C2–C7–C8: P1 the cube's centre; P2, P3, P4, P5 on the
//!   plane's diagonals C1–C7 and C2–C8 at 10 % of the diagonal's length from
//!   C1, C2, C7 and C8. All poses share one orientation. n = 30 cycles
//!   P1 → P2 → … → P5.
//! - **Pose accuracy** ([`figures`]), per pose, from the `n` attained
//!   positions `(x_j, y_j, z_j)` and the commanded `(x_c, y_c, z_c)`:
//!   barycentre `x̄ = (1/n)·Σ x_j` (and ȳ, z̄);
//!   `AP = √((x̄ − x_c)² + (ȳ − y_c)² + (z̄ − z_c)²)`, `APx = x̄ − x_c`, …;
//!   for the angles `a, b, c` (rotations about x, y, z):
//!   `APa = ā − a_c`, `APb = b̄ − b_c`, `APc = c̄ − c_c`.
//!   AP is the distance of the barycentre, not the mean single-shot error.
//! - **Pose repeatability**: `l_j = √((x_j − x̄)² + (y_j − ȳ)² + (z_j − z̄)²)`,
//!   `l̄ = (1/n)·Σ l_j`, `S_l = √(Σ (l_j − l̄)² / (n − 1))`, `RP = l̄ + 3·S_l`;
//!   `RPa = ±3·S_a`, `S_a = √(Σ (a_j − ā)² / (n − 1))` (and b, c).
//! - **Distance accuracy and repeatability** between two poses P and Q over
//!   the same cycles: `D_c = |P_c − Q_c|`, `D_j = |P_j − Q_j|`,
//!   `D̄ = (1/n)·Σ D_j`, `AD = D̄ − D_c`, `RD = ±3·S_D`,
//!   `S_D = √(Σ (D_j − D̄)² / (n − 1))`.
//!
//! Frames and units: positions in millimetres in the frame the attained
//! positions are measured in (the calibrated model's measurement (cell)
//! frame; the base frame for an unregistered model); angles in degrees,
//! `a, b, c` the fixed-axis rotations of robocal's one convention
//! `R = Rz(c)·Ry(b)·Rx(a)` (the measurement CSV's `rx_deg, ry_deg, rz_deg`,
//! Fanuc W, P, R). Angle deviations are taken from the commanded angle (the
//! first cycle's when none is commanded) and wrapped to (−180°, 180°], so a
//! pose near ±180° averages correctly.

pub mod csv;
pub mod cube;
pub mod figures;
pub mod join;
pub mod outcome;
pub mod program;

pub use cube::{plan_cube, Commands, CubePlan, CubePose, CubeSettings, TestCube};
pub use figures::{evaluate, DistanceFigures, Iso9283Figures, PoseCycles, PoseFigures};
pub use outcome::{assess, Assessment, NotComputedReason, Outcome};

/// Why the ISO 9283 plan or figures cannot be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Iso9283Error {
    /// An input is out of range or missing; the message says which.
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// A pose has fewer than 2 cycles.
    #[error("pose {pose}: {cycles} cycle(s); the standard's statistics need at least 2 (30 recommended)")]
    TooFewCycles {
        /// The pose's name.
        pose: String,
        /// Cycles measured at it.
        cycles: usize,
    },
    /// No cube down to the smallest edge has all five poses solved.
    #[error(
        "no cube of edge ≥ {min_edge_mm:.1} mm in the box has all five poses reachable: {detail}"
    )]
    Unreachable {
        /// Smallest edge accepted [mm] (`min_edge_fraction` of the largest cube's).
        min_edge_mm: f64,
        /// Why the last pose tried could not be solved.
        detail: String,
    },
    /// A plan or cycles CSV cannot be read.
    #[error("line {line}: {message}")]
    Csv {
        /// 1-based line (0 when the text as a whole cannot be read).
        line: usize,
        /// What is wrong, naming the column where one applies.
        message: String,
    },
    /// A CSV row whose field count is not its header's.
    #[error(transparent)]
    FieldCount(#[from] crate::measure::csv_text::FieldCount),
}
