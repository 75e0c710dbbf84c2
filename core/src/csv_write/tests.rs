use super::*;
use crate::measure::csv_text::{read, Dialect};
use proptest::prelude::*;

/// The cells a spreadsheet would see in `text` split at line breaks and at
/// `sep` (no quoting: the worst case of a spreadsheet in another locale).
fn split_cells(text: &str, sep: char) -> Vec<String> {
    text.split(['\n', '\r'])
        .flat_map(|line| line.split(sep))
        .map(str::to_string)
        .collect()
}

/// What a spreadsheet runs: a cell whose first character after blanks and
/// quotes is `=`, `+`, `-` or `@`, unless it reads as a number with digits
/// (checked with Rust's own float parser, not this module's).
fn live(cell: &str) -> bool {
    let c = cell.trim_start_matches(|c: char| c.is_whitespace() || c == '"');
    let number = c.trim_end_matches('"').trim();
    matches!(c.chars().next(), Some('=' | '+' | '-' | '@'))
        && !(number.parse::<f64>().is_ok() && number.contains(|d: char| d.is_ascii_digit()))
}

#[test]
fn the_issues_robot_name_in_a_comment_line_is_no_live_cell() {
    let name = "cell,=cmd|' /C calc'!A0";
    let line = comment_line(&format!("robocal export: km model of {name}, standard DH"));
    assert_eq!(
        line,
        "# robocal export: km model of cell,'=cmd|' /C calc'!A0, standard DH\n"
    );
    for sep in SPLITS {
        for cell in split_cells(line.trim_end(), sep) {
            assert!(!live(&cell), "{sep:?}: {cell}");
        }
    }
    // A line break in a name would start a row: it is a space.
    assert_eq!(comment_line("arm\n=1+1,x"), "# arm =1+1,x\n");
    assert_eq!(comment_line("a,\n=1"), "# a,' =1\n");
    assert_eq!(comment_line("a\r\u{85}b"), "# a  b\n");
}

#[test]
fn numbers_stay_numbers_and_formulas_become_text() {
    for (text, want) in [
        ("-20", "-20"),
        ("+1.5e3", "+1.5e3"),
        ("-.5", "-.5"),
        ("=cmd|' /C calc'!A0", "'=cmd|' /C calc'!A0"),
        ("+SUM(1;2)", "'+SUM(1;2)"),
        ("-1+1", "'-1+1"),
        ("@A1", "'@A1"),
        ("  =1", "'  =1"),
        ("\"=1\"", "'\"=1\""),
        ("a;=b\t-c,@d", "a;'=b\t'-c,'@d"),
        ("1,-2;+3", "1,'-2;+3"),
        ("1,-2,3", "1,-2,3"),
        ("a\n=cmd", "a\n'=cmd"),
        ("-1\n-2", "-1\n-2"),
        ("-2;=x", "'-2;'=x"),
        ("-inf", "'-inf"),
        ("p1", "p1"),
        ("a=b", "a=b"),
        ("", ""),
    ] {
        assert_eq!(neutralise(text), want, "{text:?}");
        assert_eq!(read_text(&neutralise(text)), text, "{text:?}");
    }
    assert_eq!(Cell::fixed(-20.0, 3).csv(), "-20.000");
    assert_eq!(Cell::num(-1e-17).csv(), "-0.00000000000000001");
    assert_eq!(Cell::num(-1.2345e-30).csv(), "-1.2345e-30");
    assert_eq!(Cell::sci(-0.00125, 2).csv(), "-1.25e-3");
    assert_eq!(Cell::num(f64::NAN).csv(), "");
    assert_eq!(Cell::fixed(f64::NEG_INFINITY, 2).csv(), "");
    assert_eq!(Cell::int(-3i64).csv(), "-3");
    assert_eq!(Cell::text("-3 mm").csv(), "'-3 mm");
    assert_eq!(Cell::text("-3 mm").shown(), "-3 mm");
}

#[test]
fn texts_with_separators_quotes_and_line_breaks_are_quoted() {
    assert_eq!(text_cell("a,b"), "\"a,b\"");
    assert_eq!(text_cell("say \"hi\""), "\"say \"\"hi\"\"\"");
    assert_eq!(text_cell("x,=1"), "\"x,'=1\"");
    assert_eq!(text_cell("two\nlines"), "\"two\nlines\"");
    assert_eq!(text_cell("plain"), "plain");
}

#[test]
fn rows_read_back_through_the_reader() {
    let cells = [
        Cell::text("=HYPERLINK(\"x\")"),
        Cell::fixed(-20.0, 1),
        Cell::text("a,b;=c"),
        Cell::empty(),
        Cell::text("-2"),
    ];
    let mut text = String::new();
    push_header(&mut text, ["id", "v", "note", "e", "n"]);
    push_row(&mut text, &cells);
    assert_eq!(
        text,
        "id,v,note,e,n\n\"'=HYPERLINK(\"\"x\"\")\",-20.0,\"a,b;'=c\",,-2\n"
    );
    let t = read(&text, Dialect::default()).unwrap().unwrap();
    let back: Vec<String> = t.records[0]
        .fields
        .iter()
        .map(|f| read_text(f).into_owned())
        .collect();
    assert_eq!(back, ["=HYPERLINK(\"x\")", "-20.0", "a,b;=c", "", "-2"]);
    assert_eq!(t.number(&t.records[0].fields[1]), Some(-20.0));
}

proptest! {
    /// Every text reads back as written, and no cell a spreadsheet splits a
    /// neutralised text into is live, whichever separator it splits at.
    #[test]
    fn neutralising_is_undone_by_reading_and_leaves_no_live_cell(
        text in "[-=+@'\" ;,\t\na-c0-9.eE]{0,16}"
    ) {
        let safe = neutralise(&text);
        prop_assert_eq!(read_text(&safe), text.as_str());
        for sep in SPLITS {
            for cell in split_cells(&safe, sep) {
                prop_assert!(!live(&cell), "{:?} in {:?}", cell, safe);
            }
        }
    }
}

/// A cell that starts with a blank part: split at `,`, `"\t-0\ta"` is one
/// cell whose first shown character is `-`, though split at a tab `-0` is a
/// number of its own.
#[test]
fn a_formula_after_a_leading_tab_is_marked_for_the_comma_split() {
    let safe = neutralise("\t-0\ta");
    assert_eq!(safe, "\t'-0\ta");
    assert_eq!(read_text(&safe), "\t-0\ta");
    // A number after blanks that is the whole cell in every split stays a number.
    assert_eq!(neutralise("\t-0"), "\t-0");
    assert_eq!(neutralise(" ;-0"), " ;-0");
}
