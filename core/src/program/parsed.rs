//! A program as parsed, what every language's parser builds and the filter
//! reads: its files, its sites (where a target's values are, its pose, flags,
//! tool and work object), its motions and joint targets, and the
//! configuration flags of each controller. Units as `program`'s module docs
//! say: the programs' own in the text, SI (m, rad) in [`Site::pose`].

use crate::model::orientation::OrientationConvention;
use crate::model::Pose;
use crate::solve::cell::{CellRef, Load};
use crate::solve::ik::{Configuration, Elbow, Shoulder};
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// The program languages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Language {
    /// KUKA KRL: `.src` and `.dat` files.
    Krl,
    /// ABB RAPID modules.
    Rapid,
    /// Fanuc TP programs, ASCII `.ls`.
    Fanuc,
    /// Universal Robots URScript.
    #[serde(rename = "urscript")]
    UrScript,
}

/// A language name that is not one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown program language `{0}` (use krl, rapid, fanuc or urscript)")]
pub struct UnknownLanguage(pub String);

impl std::str::FromStr for Language {
    type Err = UnknownLanguage;
    fn from_str(s: &str) -> Result<Self, UnknownLanguage> {
        match s.trim().to_ascii_lowercase().as_str() {
            "krl" | "kuka" => Ok(Language::Krl),
            "rapid" | "abb" => Ok(Language::Rapid),
            "fanuc" | "ls" | "tp" => Ok(Language::Fanuc),
            "urscript" | "ur" | "script" => Ok(Language::UrScript),
            other => Err(UnknownLanguage(other.to_string())),
        }
    }
}

impl Language {
    /// The language of a file name by its extension (`.src`/`.dat`,
    /// `.mod`/`.modx`/`.prg`/`.sys`, `.ls`, `.script`/`.urscript`).
    pub fn of_file(name: &str) -> Option<Language> {
        let ext = name.rsplit_once('.')?.1.to_ascii_lowercase();
        match ext.as_str() {
            "src" | "dat" => Some(Language::Krl),
            "mod" | "modx" | "prg" | "sys" => Some(Language::Rapid),
            "ls" => Some(Language::Fanuc),
            "script" | "urscript" => Some(Language::UrScript),
            _ => None,
        }
    }
}

/// One file of a program.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ProgramFile {
    /// The file's name, with its extension (which tells the language).
    pub name: String,
    /// The file's text.
    pub text: String,
}

/// A program that cannot be parsed: where and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct ParseError {
    /// The file's name.
    pub file: String,
    /// 1-based.
    pub line: usize,
    /// 1-based, in characters.
    pub column: usize,
    /// What is wrong, for the user.
    pub message: String,
}

/// The tool or work object a target is taught with.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum FrameSpec {
    /// By the controller's number or name (looked up in the cell).
    Ref(CellRef),
    /// Given in the program itself (flange → TCP, or base → work object) [m].
    Inline(Pose),
    /// A work object given in the program on the positioner's face plate
    /// (RAPID's object frame of a `wobjdata` with `ufprog FALSE`): face
    /// plate → work object [m] (`program::axes`).
    FacePlate(Pose),
    /// The program does not say.
    Unset,
}

/// Configuration flags of a target as the program writes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Flags {
    /// None given: the controller takes the solution nearest its current joints.
    Nearest,
    /// KUKA status `S` (bit 0 overhead, bit 1 elbow, bit 2 A5 < 0) and turn
    /// `T` (bit i: axis i+1 < 0), each optional.
    Kuka {
        /// Status `S`, when given.
        s: Option<u32>,
        /// Turn `T`, when given.
        t: Option<u32>,
    },
    /// ABB `[cf1, cf4, cf6, cfx]`: quadrants `⌊A/90°⌋` of axes 1, 4, 6 and
    /// `cfx = 4·back + 2·down + [A5 < 0]`.
    Abb {
        /// `[cf1, cf4, cf6, cfx]`.
        cf: [i32; 4],
    },
    /// Fanuc `CONFIG : 'F|N U|D T|B, t1, t4, t6'`: axis 5 < 0, elbow up,
    /// wrist centre in front, turn numbers `⌊(A + 180°)/360°⌋` of axes 1, 4, 6.
    Fanuc {
        /// `F` (axis 5 < 0) rather than `N`.
        flip: bool,
        /// `U` (elbow up) rather than `D`.
        up: bool,
        /// `T` (wrist centre in front) rather than `B`.
        front: bool,
        /// Turn numbers `t1, t4, t6` of axes 1, 4 and 6.
        turns: [i32; 3],
    },
}

impl Flags {
    /// Whether controller joints `q_deg` of configuration `c` carry these flags.
    pub fn admits(&self, q_deg: &[f64], c: Option<Configuration>) -> bool {
        self.mismatch(q_deg, c).is_none()
    }

    /// Which flag controller joints `q_deg` of configuration `c` do not carry.
    pub fn mismatch(&self, q_deg: &[f64], c: Option<Configuration>) -> Option<String> {
        match *self {
            Flags::Nearest => None,
            Flags::Kuka { s, t } => {
                if let Some(s) = s {
                    match c.map(|c| kuka_status(q_deg, c)) {
                        None => return Some("no configuration to compare S with".into()),
                        Some(got) if got != s & 7 => {
                            return Some(format!("status S would be {got}, the program has {s}"))
                        }
                        _ => {}
                    }
                }
                let got = kuka_turn(q_deg);
                match t {
                    Some(t) if got != t & 63 => {
                        let axis = (0..6).find(|i| (got ^ t) >> i & 1 == 1).unwrap_or(0) + 1;
                        Some(format!(
                            "turn T would be {got}, the program has {t} (A{axis} changes sign)"
                        ))
                    }
                    _ => None,
                }
            }
            Flags::Fanuc { .. } => {
                let Some(c) = c else {
                    return Some("no configuration to compare CONFIG with".into());
                };
                let got = fanuc_config(q_deg, c);
                (got != *self).then(|| {
                    format!(
                        "CONFIG would be {}, the program has {}",
                        fanuc_config_text(&got),
                        fanuc_config_text(self)
                    )
                })
            }
            Flags::Abb { cf } => {
                let Some(c) = c else {
                    return Some("no configuration to compare cfx with".into());
                };
                let got = abb_cf(q_deg, c);
                (got != cf)
                    .then(|| format!("[cf1,cf4,cf6,cfx] would be {got:?}, the program has {cf:?}"))
            }
        }
    }
}

impl Flags {
    /// The flags a program in `language` gives for controller joints `q_deg`
    /// of configuration `c` (URScript has none: the nearest solution).
    pub fn of(language: Language, q_deg: &[f64], c: Configuration) -> Flags {
        match language {
            Language::Krl => Flags::Kuka {
                s: Some(kuka_status(q_deg, c)),
                t: Some(kuka_turn(q_deg)),
            },
            Language::Rapid => Flags::Abb {
                cf: abb_cf(q_deg, c),
            },
            Language::Fanuc => fanuc_config(q_deg, c),
            Language::UrScript => Flags::Nearest,
        }
    }
}

impl std::fmt::Display for Flags {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Flags::Nearest => f.write_str("(none)"),
            Flags::Kuka { s, t } => {
                let show = |v: &Option<u32>| v.map_or("-".to_string(), |v| v.to_string());
                write!(f, "S {} T {}", show(s), show(t))
            }
            Flags::Abb { cf } => write!(f, "{cf:?}"),
            Flags::Fanuc { .. } => f.write_str(&fanuc_config_text(self)),
        }
    }
}

/// KUKA status bits of controller joints `q_deg` in configuration `c`.
pub fn kuka_status(q_deg: &[f64], c: Configuration) -> u32 {
    u32::from(c.shoulder == Shoulder::Back)
        | u32::from(c.elbow == Elbow::Down) << 1
        | u32::from(q_deg.get(4).is_some_and(|a5| *a5 < 0.0)) << 2
}

/// ABB `[cf1, cf4, cf6, cfx]` of controller joints `q_deg` in configuration `c`.
pub fn abb_cf(q_deg: &[f64], c: Configuration) -> [i32; 4] {
    let quadrant = |k: usize| q_deg.get(k).map_or(0, |a| (a / 90.0).floor() as i32);
    let cfx = 4 * i32::from(c.shoulder == Shoulder::Back)
        + 2 * i32::from(c.elbow == Elbow::Down)
        + i32::from(q_deg.get(4).is_some_and(|a5| *a5 < 0.0));
    [quadrant(0), quadrant(3), quadrant(5), cfx]
}

/// Fanuc configuration of controller joints `q_deg` in configuration `c`.
pub fn fanuc_config(q_deg: &[f64], c: Configuration) -> Flags {
    let turn = |k: usize| {
        q_deg
            .get(k)
            .map_or(0, |a| ((a + 180.0) / 360.0).floor() as i32)
    };
    Flags::Fanuc {
        flip: q_deg.get(4).is_some_and(|a5| *a5 < 0.0),
        up: c.elbow == Elbow::Up,
        front: c.shoulder == Shoulder::Front,
        turns: [turn(0), turn(3), turn(5)],
    }
}

/// `N U T, 0, 0, 0` (without quotes) of Fanuc flags; empty for other flags.
pub fn fanuc_config_text(flags: &Flags) -> String {
    match flags {
        Flags::Fanuc {
            flip,
            up,
            front,
            turns,
        } => format!(
            "{} {} {}, {}, {}, {}",
            if *flip { 'F' } else { 'N' },
            if *up { 'U' } else { 'D' },
            if *front { 'T' } else { 'B' },
            turns[0],
            turns[1],
            turns[2]
        ),
        _ => String::new(),
    }
}

/// KUKA turn bits of controller joints `q_deg`: bit i set when axis i+1 < 0.
pub fn kuka_turn(q_deg: &[f64]) -> u32 {
    q_deg
        .iter()
        .take(6)
        .enumerate()
        .map(|(i, q)| u32::from(*q < 0.0) << i)
        .sum()
}

/// One Cartesian target found in a program.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Site {
    /// Index of the file in the program.
    pub file: usize,
    /// 1-based line of the target.
    pub line: usize,
    /// The point's name, or `inline`.
    pub name: String,
    /// TCP pose in the work object [m] (None: the program gives no complete pose).
    pub pose: Option<Pose>,
    /// Configuration flags as the program writes them.
    pub flags: Flags,
    /// The tool the target is taught with.
    pub tool: FrameSpec,
    /// The load the program declares for the tool in use (flange frame), if
    /// it declares one (RAPID `tload`, KRL `$LOAD`, URScript `set_payload`).
    pub load: Option<Load>,
    /// The work object the target is taught in.
    pub work_object: FrameSpec,
    /// Byte ranges of x, y, z and the orientation values, in `convention` order.
    pub slots: Vec<Range<usize>>,
    /// How the program writes the orientation (quaternion, KUKA ABC, Fanuc WPR,
    /// rotation vector, …).
    pub convention: OrientationConvention,
    /// Program length unit in metres (1e-3 for mm).
    pub unit_m: f64,
    /// Decimals written for lengths and for orientation values.
    pub decimals: [usize; 2],
    /// Bytes the mark of an unsolved target replaces (empty: an insertion),
    /// in the same file.
    pub mark_at: Range<usize>,
    /// The controller joints [deg] of the joint move just before this target,
    /// if any (where the controller starts from).
    pub after_joints: Option<Vec<f64>>,
    /// Why the target is not filtered even though it is a Cartesian target
    /// (an incomplete aggregate, a point set at run time, used with
    /// different tools, ...): reported `skipped`.
    pub skip: Option<String>,
    /// Why the target is refused before any solve (it moves another motion
    /// group, or an external axis computed at run time): reported `failed`
    /// and marked.
    pub refuse: Option<String>,
    /// The external axes' values the target carries (KRL `E1..E6`, RAPID
    /// `eax_a..eax_f` other than 9E9, Fanuc `E1..` of `GP1`), in the
    /// program's order. The filter composes the cell's track through axis 1
    /// and refuses any other axis in use (`program::axes`).
    pub axes: Vec<AxisValue>,
    /// The roles swapped (RAPID `robhold FALSE` tooldata with a `robhold
    /// TRUE` wobjdata): `tool` is a stationary tool's pose in the base frame
    /// and `work_object` the work object on the flange (flange → work
    /// object); the robot carries the work object past the tool.
    pub stationary_tool: bool,
}

impl Site {
    /// `self` with `skip` (a reason already set is kept).
    pub fn with_skip(mut self, skip: Option<String>) -> Self {
        self.skip = self.skip.or(skip);
        self
    }
}

/// One external axis's value on a target, as the program writes it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisValue {
    /// The motion group the axis belongs to: 1 for the robot's own (every
    /// KRL and RAPID axis, Fanuc's `GP1`), 2 for Fanuc's `GP2` (a positioner).
    pub group: u32,
    /// The controller's axis number in its group, 1-based (KRL `E1`, RAPID
    /// `eax_a`, Fanuc `E1` of `GP1` and `J1` of `GP2` are 1).
    pub number: usize,
    /// The axis as the language names it (`E1`, `eax_a`).
    pub name: String,
    /// The value in the program's unit (mm for a linear axis, degrees for a
    /// rotary one); `None` when it is computed at run time.
    pub value: Option<f64>,
    /// The value as written (with its unit where the program gives one).
    pub text: String,
    /// Bytes of the number in the site's file, which a corrected value
    /// replaces (`None`: the parser cannot point at it).
    #[serde(skip)]
    pub slot: Option<Range<usize>>,
}

impl AxisValue {
    /// Whether the value moves an axis: KRL's `E6POS` writes every external
    /// axis, 0 for one the robot does not have; RAPID leaves an axis out
    /// with 9E9 (never kept here) and Fanuc writes only the axes it has.
    pub fn in_use(&self, language: Language) -> bool {
        !(language == Language::Krl && self.value == Some(0.0))
    }
}

/// Why a target with external-axis values is refused: the axis and its
/// value, in the program's unit.
pub fn external_axis_refusal(axis: &str, value: &str) -> String {
    format!(
        "the target sets external axis {axis} to {value}, which the cell does not model: not filtered"
    )
}

/// A joint target of a program, in the controller's convention.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointTarget {
    /// Index of the file in the program.
    pub file: usize,
    /// 1-based.
    pub line: usize,
    /// Axis values [deg].
    pub deg: Vec<f64>,
}

/// One position a motion instruction goes to: a circular motion has two
/// (its via point and its end point), any other motion one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Motion {
    /// Index of the file in the program.
    pub file: usize,
    /// 1-based line of the instruction.
    pub line: usize,
    /// The instruction as written (`LIN`, `MoveC`, `L`, `movel`).
    pub instruction: String,
    /// The position as written (`XP1`, `p10`, `P[3]`, `PR[3]`), or `inline`.
    pub name: String,
    /// What the position is: a site, axis values, a run-time position or an
    /// undeclared name.
    pub target: MotionTarget,
    /// Where the mark of a failure goes when the position has no site (an
    /// insertion at the end of the instruction's line, or the comment of a
    /// Fanuc position reference), in the same file.
    pub mark_at: Range<usize>,
}

/// What a motion goes to.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum MotionTarget {
    /// A Cartesian target whose values are in the files: `sites[i]`.
    Site(usize),
    /// Axis values (a joint motion): nothing to filter.
    Joints {
        /// Why the motion counts as one without axis values in the files
        /// (KUKA's `XHOME`, held in `$config.dat`).
        note: Option<String>,
    },
    /// A position the program computes or sets at run time, or a motion
    /// relative to where the robot is: not filtered, for this reason.
    RunTime(String),
    /// A name no file of the program declares.
    Undeclared,
}

/// What a parser finds: the Cartesian targets (in the order the program
/// runs them, points no motion uses last), every position of every motion
/// instruction (in the order of the files and lines) and the joint targets
/// (in file order).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Targets {
    /// Cartesian targets, in the order the program runs them (points no motion
    /// uses last).
    pub sites: Vec<Site>,
    /// Every position of every motion instruction, in the order of the files and lines.
    pub motions: Vec<Motion>,
    /// Joint targets, in file order.
    pub joints: Vec<JointTarget>,
}

/// A parsed program: its targets and motions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Program {
    /// The language the program is written in.
    pub language: Language,
    /// Cartesian targets, in the order the program runs them (points no motion
    /// uses last).
    pub sites: Vec<Site>,
    /// Every position of every motion instruction, in the order of the files and lines.
    pub motions: Vec<Motion>,
    /// Joint targets, in file order.
    pub joints: Vec<JointTarget>,
}
