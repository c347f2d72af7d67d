//! `docs/wire-protocol.md` gives every message's type name, size and field offsets in a
//! table; this test reads those tables and compares them with `controller::wire::layouts()`
//! (the Rust definitions), naming each difference, so the page a port is written from cannot
//! drift from the code.
#![cfg(feature = "ipc")]

use controller::wire::layouts;

#[test]
fn the_protocol_page_tables_are_the_rust_layouts() {
    let page = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/wire-protocol.md");
    let text = std::fs::read_to_string(&page).unwrap();
    let mut differences = Vec::new();
    for m in layouts() {
        let heading = format!("### `{}` — type name `{}`, {} bytes, align {}", m.name, m.type_name, m.size, m.align);
        let Some(at) = text.find(&heading) else {
            differences.push(format!("no heading {heading:?}"));
            continue;
        };
        // The table rows after the heading: `| offset | size | `field` | …`.
        let rows: Vec<(usize, usize, String)> = text[at..]
            .lines()
            .skip(1)
            .skip_while(|l| !l.starts_with('|'))
            .take_while(|l| l.starts_with('|'))
            .filter_map(|l| {
                let cells: Vec<&str> = l.split('|').map(str::trim).collect();
                let offset = cells.get(1)?.parse().ok()?;
                let size = cells.get(2)?.parse().ok()?;
                Some((offset, size, cells.get(3)?.trim_matches('`').to_string()))
            })
            .collect();
        let rust: Vec<(usize, usize, String)> =
            m.fields.iter().map(|f| (f.offset, f.size, f.name.to_string())).collect();
        if rows != rust {
            let i = rows.iter().zip(&rust).position(|(a, b)| a != b).unwrap_or(rows.len().min(rust.len()));
            differences.push(format!(
                "{}: row {i}: the page has (offset, size, field) {:?}, Rust {:?} ({} rows on the page, {} fields)",
                m.name,
                rows.get(i),
                rust.get(i),
                rows.len(),
                rust.len()
            ));
        }
    }
    assert!(differences.is_empty(), "docs/wire-protocol.md differs from controller::wire:\n{}", differences.join("\n"));
}
