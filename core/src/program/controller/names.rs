//! The identifiers a controller's data are declared under (RAPID `tooldata`
//! and `wobjdata`, URScript feature variables), made from the cell's names:
//! valid, within the language's length, not a reserved word, and distinct.
//!
//! Rules (RAPID kernel reference: an identifier is a letter followed by
//! letters, digits or `_`, at most 32 characters, case not significant, not
//! a reserved word; `tooldata` and `wobjdata` of one module share one name
//! space, and `tool0`, `wobj0`, `load0` are the system's own):
//! 1. every character that is not an ASCII letter, digit or `_` becomes `_`;
//!    a name that then does not start with a letter gets the kind's prefix
//!    (`tool`, `wobj`, `feature`);
//! 2. cut to the language's length;
//! 3. a reserved or predefined word, or an identifier an item before it
//!    already has, takes the suffix `_2`, `_3`, … (cut further to fit).
//!
//! Items are named tools first, then work objects, each in the order of
//! their names (ASCII case folded), so the result does not depend on the
//! cell's order. Every identifier that differs from its name is reported
//! ([`Renamed`]), naming the item that had it first.

use crate::solve::cell::ItemKind;
use serde::Serialize;

/// RAPID's longest identifier.
pub(super) const RAPID_IDENTIFIER_MAX: usize = 32;

/// RAPID's reserved words.
pub(super) const RAPID_RESERVED: [&str; 58] = [
    "ALIAS",
    "AND",
    "BACKWARD",
    "CASE",
    "CONNECT",
    "CONST",
    "DEFAULT",
    "DIV",
    "DO",
    "ELSE",
    "ELSEIF",
    "ENDFOR",
    "ENDFUNC",
    "ENDIF",
    "ENDMODULE",
    "ENDPROC",
    "ENDRECORD",
    "ENDTEST",
    "ENDTRAP",
    "ENDWHILE",
    "ERROR",
    "EXIT",
    "FALSE",
    "FOR",
    "FROM",
    "FUNC",
    "GOTO",
    "IF",
    "INOUT",
    "LOCAL",
    "MOD",
    "MODULE",
    "NOSTEPIN",
    "NOT",
    "NOVIEW",
    "OR",
    "PERS",
    "PROC",
    "RAISE",
    "READONLY",
    "RECORD",
    "RETRY",
    "RETURN",
    "STEP",
    "SYSMODULE",
    "TASK",
    "TEST",
    "THEN",
    "TO",
    "TRAP",
    "TRUE",
    "TRYNEXT",
    "UNDO",
    "VAR",
    "VIEWONLY",
    "WHILE",
    "WITH",
    "XOR",
];

/// RAPID's predefined data (the flange, the base frame, no load).
const RAPID_PREDEFINED: [&str; 3] = ["tool0", "wobj0", "load0"];

/// URScript's keywords.
pub(super) const URSCRIPT_RESERVED: [&str; 22] = [
    "and", "break", "continue", "def", "elif", "else", "end", "False", "for", "global", "halt",
    "if", "join", "kill", "local", "not", "or", "return", "run", "thread", "True", "while",
];

/// Why an identifier differs from the item's name (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RenameReason {
    /// Characters the language does not take, or no leading letter.
    Characters,
    /// Longer than the language allows.
    Length,
    /// A reserved word or the system's own data.
    Reserved,
    /// Another item has that identifier.
    Taken,
}

impl RenameReason {
    /// Every reason, in declaration order.
    pub const ALL: [RenameReason; 4] = [
        RenameReason::Characters,
        RenameReason::Length,
        RenameReason::Reserved,
        RenameReason::Taken,
    ];

    /// The reason's name in the export's answer (snake_case, as serialized).
    pub fn as_str(self) -> &'static str {
        match self {
            RenameReason::Characters => "characters",
            RenameReason::Length => "length",
            RenameReason::Reserved => "reserved",
            RenameReason::Taken => "taken",
        }
    }
}

/// The item that first had an identifier.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TakenBy {
    pub kind: ItemKind,
    pub name: String,
}

/// An item declared under an identifier other than its name.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Renamed {
    /// Tool or work object.
    pub kind: ItemKind,
    /// The item's name in the cell.
    pub name: String,
    /// The identifier the export declares it under.
    pub identifier: String,
    /// Why the identifier differs from the name (one or more).
    pub reasons: Vec<RenameReason>,
    /// The item that had the identifier first, when the reason is
    /// [`RenameReason::Taken`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub taken_by: Option<TakenBy>,
}

impl Renamed {
    /// One line for the export's header comment.
    pub fn describe(&self) -> String {
        let why: Vec<String> = self
            .reasons
            .iter()
            .map(|r| match r {
                RenameReason::Characters => "characters the language does not take".to_string(),
                RenameReason::Length => "too long".to_string(),
                RenameReason::Reserved => "a reserved word".to_string(),
                RenameReason::Taken => match &self.taken_by {
                    Some(t) => format!("taken by {} `{}`", t.kind.label(), t.name),
                    None => "taken".to_string(),
                },
            })
            .collect();
        format!(
            "{} `{}` is declared as {} ({})",
            self.kind.label(),
            self.name,
            self.identifier,
            why.join(", ")
        )
    }
}

/// A language's identifier rules.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rules {
    pub max_len: Option<usize>,
    pub reserved: &'static [&'static str],
    pub predefined: &'static [&'static str],
    pub case_sensitive: bool,
    /// The prefix of a work object's name that does not start with a letter.
    pub frame_prefix: &'static str,
}

pub(super) const RAPID: Rules = Rules {
    max_len: Some(RAPID_IDENTIFIER_MAX),
    reserved: &RAPID_RESERVED,
    predefined: &RAPID_PREDEFINED,
    case_sensitive: false,
    frame_prefix: "wobj",
};

pub(super) const URSCRIPT: Rules = Rules {
    max_len: None,
    reserved: &URSCRIPT_RESERVED,
    predefined: &[],
    case_sensitive: true,
    frame_prefix: "feature",
};

/// The identifiers of the tools and work objects, in their order, and the
/// items renamed.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub(super) struct Identifiers {
    pub tools: Vec<String>,
    pub frames: Vec<String>,
    pub renamed: Vec<Renamed>,
}

fn cut(s: &str, max: Option<usize>) -> String {
    match max {
        Some(m) => s.chars().take(m).collect(),
        None => s.to_string(),
    }
}

/// The identifiers of `tools` and `frames` (names) under `rules`.
pub(super) fn identifiers(rules: &Rules, tools: &[&str], frames: &[&str]) -> Identifiers {
    let key = |s: &str| {
        if rules.case_sensitive {
            s.to_string()
        } else {
            s.to_ascii_lowercase()
        }
    };
    let mut taken: std::collections::HashMap<String, Option<TakenBy>> = rules
        .reserved
        .iter()
        .chain(rules.predefined)
        .map(|w| (key(w), None))
        .collect();
    let mut out = Identifiers {
        tools: vec![String::new(); tools.len()],
        frames: vec![String::new(); frames.len()],
        renamed: Vec::new(),
    };
    for (kind, names) in [(ItemKind::Tool, tools), (ItemKind::WorkObject, frames)] {
        let mut order: Vec<usize> = (0..names.len()).collect();
        order.sort_by(|a, b| {
            let (x, y) = (names[*a], names[*b]);
            x.to_ascii_lowercase()
                .cmp(&y.to_ascii_lowercase())
                .then_with(|| x.cmp(y))
                .then(a.cmp(b))
        });
        for i in order {
            let name = names[i];
            let mut reasons = Vec::new();
            let mut base: String = name
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '_' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            if !base.starts_with(|c: char| c.is_ascii_alphabetic()) {
                let prefix = match kind {
                    ItemKind::Tool => "tool",
                    ItemKind::WorkObject => rules.frame_prefix,
                };
                base = format!("{prefix}{base}");
            }
            if base != name {
                reasons.push(RenameReason::Characters);
            }
            let cut_base = cut(&base, rules.max_len);
            if cut_base != base {
                reasons.push(RenameReason::Length);
            }
            let mut id = cut_base.clone();
            let mut taken_by = None;
            if let Some(holder) = taken.get(&key(&id)) {
                match holder {
                    None => reasons.push(RenameReason::Reserved),
                    Some(t) => {
                        reasons.push(RenameReason::Taken);
                        taken_by = Some(t.clone());
                    }
                }
                let mut k = 2;
                loop {
                    let suffix = format!("_{k}");
                    let room = rules.max_len.map(|m| m - suffix.len());
                    id = format!("{}{suffix}", cut(&cut_base, room));
                    if !taken.contains_key(&key(&id)) {
                        break;
                    }
                    k += 1;
                }
            }
            taken.insert(
                key(&id),
                Some(TakenBy {
                    kind,
                    name: name.to_string(),
                }),
            );
            if !reasons.is_empty() {
                out.renamed.push(Renamed {
                    kind,
                    name: name.to_string(),
                    identifier: id.clone(),
                    reasons,
                    taken_by,
                });
            }
            match kind {
                ItemKind::Tool => out.tools[i] = id,
                ItemKind::WorkObject => out.frames[i] = id,
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn valid_rapid(id: &str) -> bool {
        id.len() <= RAPID_IDENTIFIER_MAX
            && id.starts_with(|c: char| c.is_ascii_alphabetic())
            && id.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            && !RAPID_RESERVED.iter().any(|w| w.eq_ignore_ascii_case(id))
    }

    #[test]
    fn rapid_identifiers_are_valid_and_distinct_and_every_change_is_reported() {
        let long = "x".repeat(64);
        let tools = [
            "a.b-c",
            "a_b_c",
            long.as_str(),
            "torch",
            "PROC",
            "7axis",
            "tool0",
        ];
        let frames = ["torch", "TORCH2", "wobj0"];
        let ids = identifiers(&RAPID, &tools, &frames);
        let all: Vec<&String> = ids.tools.iter().chain(&ids.frames).collect();
        let mut keys: Vec<String> = all.iter().map(|s| s.to_ascii_lowercase()).collect();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), all.len(), "{all:?}");
        for id in &all {
            assert!(valid_rapid(id), "{id}");
        }
        // `a.b-c` comes before `a_b_c` by name ('.' < '_'): it keeps
        // a_b_c, the real `a_b_c` takes the suffix and says by whom.
        assert_eq!(ids.tools[0], "a_b_c");
        assert_eq!(ids.tools[1], "a_b_c_2");
        let r = ids.renamed.iter().find(|r| r.name == "a_b_c").unwrap();
        assert_eq!(r.reasons, vec![RenameReason::Taken]);
        assert_eq!(
            r.taken_by,
            Some(TakenBy {
                kind: ItemKind::Tool,
                name: "a.b-c".into()
            })
        );
        assert_eq!(ids.tools[2], "x".repeat(32));
        assert_eq!(ids.tools[4], "PROC_2");
        assert_eq!(ids.tools[5], "tool7axis");
        assert_eq!(ids.tools[6], "tool0_2");
        // The work object `torch` meets the tool `torch`.
        assert_eq!(ids.frames[0], "torch_2");
        let r = ids
            .renamed
            .iter()
            .find(|r| r.kind == ItemKind::WorkObject && r.name == "torch");
        assert!(
            r.unwrap().describe().contains("taken by tool `torch`"),
            "{r:?}"
        );
        // `TORCH2` is free (`torch_2` is not `torch2`), `wobj0` is the system's.
        assert_eq!(ids.frames[1], "TORCH2");
        assert_eq!(ids.frames[2], "wobj0_2");
        // Names already valid and distinct are kept and not reported.
        assert!(!ids.renamed.iter().any(|r| r.name == "TORCH2"));
        // Two 64-character names that differ only at their end stay distinct.
        let (a, b) = ("y".repeat(63) + "a", "y".repeat(63) + "b");
        let ids = identifiers(&RAPID, &[&a, &b], &[]);
        assert_eq!(ids.tools[0], "y".repeat(32));
        assert_eq!(ids.tools[1], "y".repeat(30) + "_2");
    }

    #[test]
    fn the_order_of_the_cell_does_not_change_the_identifiers() {
        let a = identifiers(&RAPID, &["a_b_c", "a.b-c"], &[]);
        let b = identifiers(&RAPID, &["a.b-c", "a_b_c"], &[]);
        assert_eq!(a.tools, vec![b.tools[1].clone(), b.tools[0].clone()]);
    }
}
