//! `--set KEY=VALUE` overrides: a dotted key path (`shock[1].peak_g` for an
//! entry of the shock list) and a TOML literal (anything else is taken as a
//! string), applied to the scene file's table before it is parsed.

use super::ConfigError;

/// Applies one `key.path=value` override to a TOML table.
pub fn apply_override(table: &mut toml::Table, arg: &str) -> Result<(), ConfigError> {
    let bad = |why: &str| ConfigError::Override { arg: arg.to_string(), why: why.to_string() };
    let (key, text) = arg.split_once('=').ok_or_else(|| bad("expected KEY=VALUE"))?;
    let parts: Vec<&str> = key.trim().split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(bad("empty key segment"));
    }
    let value = parse_literal(text.trim());
    let (last, sections) = parts.split_last().ok_or_else(|| bad("empty key"))?;
    let mut cursor = table;
    for (depth, part) in sections.iter().enumerate() {
        let entry = if let Some(index) = part.strip_prefix("shock[").and_then(|s| s.strip_suffix(']')) {
            let index: usize = index.parse().map_err(|_| bad("shock index must be a number"))?;
            cursor
                .get_mut("shock")
                .and_then(|s| s.as_array_mut())
                .and_then(|a| a.get_mut(index))
                .ok_or_else(|| bad("no such shock entry"))?
        } else {
            cursor.entry(part.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new()))
        };
        cursor = entry.as_table_mut().ok_or_else(|| bad(&format!("`{}` is not a table", parts[..=depth].join("."))))?;
    }
    cursor.insert(last.to_string(), value);
    Ok(())
}

/// A `--set` value: a TOML literal, else the text as a string.
pub(super) fn parse_literal(text: &str) -> toml::Value {
    toml::from_str::<toml::Table>(&format!("v = {text}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(text.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_and_strings() {
        let mut t = toml::Table::new();
        apply_override(&mut t, "controller.law=relev").unwrap();
        apply_override(&mut t, "controller.params.hold_ms=5").unwrap();
        apply_override(&mut t, "controller.params.note=\"a b\"").unwrap();
        assert_eq!(t["controller"]["law"].as_str(), Some("relev"));
        assert_eq!(t["controller"]["params"]["hold_ms"].as_integer(), Some(5));
        assert_eq!(t["controller"]["params"]["note"].as_str(), Some("a b"));
        assert!(apply_override(&mut t, "novalue").is_err());
        assert!(apply_override(&mut t, "controller.law.x=1").is_err());
    }
}
