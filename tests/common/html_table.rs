//! The tables of robocal's HTML pages read back for tests: a table by its
//! `id`, each row's cell texts (`th` or `td`) with tags stripped and maud's
//! escapes undone.

/// The rows of the HTML table `id`: each row's cell texts (`th` or `td`),
/// tags stripped and maud's escapes undone.
pub fn table_rows(html: &str, id: &str) -> Vec<Vec<String>> {
    let start = html
        .find(&format!("<table id=\"{id}\""))
        .unwrap_or_else(|| panic!("no table {id} in {html}"));
    let end = start + html[start..].find("</table>").unwrap();
    let strip = |t: &str| {
        let mut out = String::new();
        let mut inside = false;
        for c in t.chars() {
            match c {
                '<' => inside = true,
                '>' => inside = false,
                c if !inside => out.push(c),
                _ => {}
            }
        }
        out.replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&quot;", "\"")
            .replace("&amp;", "&")
    };
    html[start..end]
        .split("<tr>")
        .skip(1)
        .map(|row| {
            let row = row.split("</tr>").next().unwrap().replace("</th>", "</td>");
            let pieces: Vec<&str> = row.split("</td>").collect();
            pieces[..pieces.len() - 1]
                .iter()
                .map(|piece| {
                    let open = piece.rfind("<td").max(piece.rfind("<th")).unwrap();
                    let body = &piece[open..];
                    strip(&body[body.find('>').unwrap() + 1..])
                })
                .collect()
        })
        .collect()
}

/// The value cells (after pose, characteristic and unit) of the row of
/// `item` and `characteristic`.
pub fn cell<'a>(rows: &'a [Vec<String>], item: &str, characteristic: &str) -> &'a [String] {
    let row = rows
        .iter()
        .find(|r| r.len() > 3 && r[0] == item && r[1] == characteristic)
        .unwrap_or_else(|| panic!("no row {item} {characteristic} in {rows:?}"));
    &row[3..]
}
