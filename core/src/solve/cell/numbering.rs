//! The controller numbers of a cell's tools and work objects (KUKA
//! `TOOL_DATA[n]`/`BASE_DATA[n]`, Fanuc `UTOOL[n]`/`UFRAME[n]`): the one rule
//! by which both the controller export (`cell::export`) and every lookup by
//! number (the program filter, `solve`, `predict`) resolve them.
//!
//! Rule: an item keeps the number the cell gives it; an item without one
//! takes the lowest number from 1 up that no other item of its kind holds,
//! the unnumbered items taking theirs in the order of their names (ASCII case
//! folded, then as written, then their place in the cell), so a cell file and
//! the service's stored cell (listed by name) number alike. Tools and work
//! objects are numbered apart. Two items of one kind with one number are
//! ambiguous: a lookup of that number is refused naming both, and so is an
//! export ([`duplicate`]).

use serde::Serialize;

/// Tool or work object (a closed set: the API's `kind` and the messages'
/// words derive from it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ItemKind {
    /// A production tool (`TOOL_DATA`, `UTOOL`).
    Tool,
    /// A work object or user frame (`BASE_DATA`, `UFRAME`).
    WorkObject,
}

impl ItemKind {
    /// Both kinds, tools first.
    pub const ALL: [ItemKind; 2] = [ItemKind::Tool, ItemKind::WorkObject];

    /// The API's `kind` value: `tool`, `work_object`.
    pub fn as_str(self) -> &'static str {
        match self {
            ItemKind::Tool => "tool",
            ItemKind::WorkObject => "work_object",
        }
    }

    /// The words for messages: `tool`, `work object`.
    pub fn label(self) -> &'static str {
        match self {
            ItemKind::Tool => "tool",
            ItemKind::WorkObject => "work object",
        }
    }
}

/// An item without a number of its own and the number it was given.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct AssignedNumber {
    /// Tool or work object.
    pub kind: ItemKind,
    /// The item's name.
    pub name: String,
    /// The controller number it was given.
    pub number: u32,
}

/// The numbers of one kind's items, in their order: `declared[i]` is item
/// i's name and its own number, if any (see the module docs for the rule).
pub(crate) fn numbers(declared: &[(&str, Option<u32>)]) -> Vec<u32> {
    let held: std::collections::BTreeSet<u32> = declared.iter().filter_map(|(_, n)| *n).collect();
    let mut unnumbered: Vec<usize> = (0..declared.len())
        .filter(|i| declared[*i].1.is_none())
        .collect();
    unnumbered.sort_by(|a, b| {
        let (na, nb) = (declared[*a].0, declared[*b].0);
        na.to_ascii_lowercase()
            .cmp(&nb.to_ascii_lowercase())
            .then_with(|| na.cmp(nb))
            .then(a.cmp(b))
    });
    let mut out: Vec<u32> = declared.iter().map(|(_, n)| n.unwrap_or(0)).collect();
    let mut next = 1u32;
    for i in unnumbered {
        while held.contains(&next) {
            next += 1;
        }
        out[i] = next;
        next += 1;
    }
    out
}

/// The items of `declared` that took a number ([`numbers`]) and the number.
pub(crate) fn assigned(kind: ItemKind, declared: &[(&str, Option<u32>)]) -> Vec<AssignedNumber> {
    numbers(declared)
        .into_iter()
        .zip(declared)
        .filter(|(_, (_, own))| own.is_none())
        .map(|(number, (name, _))| AssignedNumber {
            kind,
            name: name.to_string(),
            number,
        })
        .collect()
}

/// Two items of one kind that hold one number.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{} number {number} is held by both `{first}` and `{second}`: give each its own number", .kind.label())]
pub struct DuplicateNumber {
    pub kind: ItemKind,
    pub number: u32,
    pub first: String,
    pub second: String,
}

/// The first number held twice among `names` numbered `numbers`.
pub(crate) fn duplicate(
    kind: ItemKind,
    names: &[&str],
    numbers: &[u32],
) -> Option<DuplicateNumber> {
    let mut seen: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    for (i, n) in numbers.iter().enumerate() {
        if let Some(j) = seen.insert(*n, i) {
            return Some(DuplicateNumber {
                kind,
                number: *n,
                first: names[j].to_string(),
                second: names[i].to_string(),
            });
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unnumbered_items_take_the_lowest_free_numbers_in_name_order() {
        // `b` holds 2; `c` and `a` have none: `a` (first by name) takes 1,
        // `c` the next free, 3.
        let d = [("c", None), ("b", Some(2)), ("A", None)];
        assert_eq!(numbers(&d), vec![3, 2, 1]);
        let a = assigned(ItemKind::Tool, &d);
        assert_eq!(
            a.iter()
                .map(|x| (x.name.as_str(), x.number))
                .collect::<Vec<_>>(),
            vec![("c", 3), ("A", 1)]
        );
        // The order of the cell does not matter.
        let d2 = [("A", None), ("c", None), ("b", Some(2))];
        assert_eq!(numbers(&d2), vec![1, 3, 2]);
        // Number 0 is kept as given (the export judges it).
        assert_eq!(numbers(&[("x", Some(0)), ("y", None)]), vec![0, 1]);
    }

    #[test]
    fn a_number_held_twice_names_both_items() {
        let e = duplicate(ItemKind::WorkObject, &["t1", "t2", "t3"], &[1, 2, 1]).unwrap();
        assert_eq!(
            (e.first.as_str(), e.second.as_str(), e.number),
            ("t1", "t3", 1)
        );
        assert!(e.to_string().contains("work object number 1"), "{e}");
        assert!(duplicate(ItemKind::Tool, &["a", "b"], &[1, 2]).is_none());
    }
}
