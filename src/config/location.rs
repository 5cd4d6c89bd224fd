//! Where a scenario error is: the dotted path of the field serde was reading (also
//! inside a material, whose `model` tag hides it), and the line and column of the
//! text.

use crate::error::Error;

/// A material is read through its `model` tag, which hides the key inside it from
/// the path serde reports (`materials.steel` in a scenario, `material` in a
/// material file): the path with the key whose value is what `message` complains of
/// appended, when one key's is (`table` gives the text as read).
pub(super) fn within_material(
    path: String,
    message: &str,
    table: impl FnOnce() -> Option<toml::Table>,
) -> String {
    // A scenario's `materials.<name>`, or a material file's one `material`.
    let lookup: Vec<String> = if path == "material" {
        vec!["material".into()]
    } else {
        match path.strip_prefix("materials.").filter(|n| !n.contains('.')) {
            Some(name) => vec!["materials".into(), name.into()],
            None => return path,
        }
    };
    let found = table().and_then(|t| {
        let mut v = t.get(&lookup[0])?;
        for k in &lookup[1..] {
            v = v.get(k)?;
        }
        key_of_unexpected(v.as_table()?, message)
    });
    match found {
        Some(key) => format!("{path}.{key}"),
        None => path,
    }
}

/// The key (dotted, within the material's table) whose value is the one a
/// "invalid type: <what>, expected ..." message names, when exactly one key's value
/// is.
fn key_of_unexpected(material: &toml::Table, message: &str) -> Option<String> {
    let what = message
        .strip_prefix("invalid type: ")?
        .split(", expected")
        .next()?;
    fn describe(v: &toml::Value) -> String {
        match v {
            toml::Value::String(s) => format!("string {s:?}"),
            toml::Value::Integer(i) => format!("integer `{i}`"),
            toml::Value::Float(f) => format!("floating point `{f}`"),
            toml::Value::Boolean(b) => format!("boolean `{b}`"),
            toml::Value::Array(_) => "sequence".into(),
            toml::Value::Table(_) => "map".into(),
            toml::Value::Datetime(d) => format!("datetime `{d}`"),
        }
    }
    fn search(t: &toml::Table, prefix: &str, what: &str, out: &mut Vec<String>) {
        for (k, v) in t {
            let key = format!("{prefix}{k}");
            if let toml::Value::Table(inner) = v {
                search(inner, &format!("{key}."), what, out);
            }
            if describe(v) == what {
                out.push(key);
            }
        }
    }
    let mut found = Vec::new();
    search(material, "", what, &mut found);
    (found.len() == 1).then(|| found.remove(0))
}

/// The dotted path of a field as serde saw it (`bodies[0].thickness`), or
/// `scenario` at the top.
pub(super) fn field_path(p: &serde_path_to_error::Path) -> String {
    let s = p.to_string();
    if s.is_empty() || s == "." {
        "scenario".into()
    } else {
        s
    }
}

/// Line and column (from 1) of a byte offset of `text`.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text.as_bytes()[..offset.min(text.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let column = String::from_utf8_lossy(&before[line_start..])
        .chars()
        .count()
        + 1;
    (line, column)
}

pub(super) fn toml_error(text: &str, e: toml::de::Error) -> Error {
    let at = e.span().map(|s| {
        let (line, column) = line_column(text, s.start);
        format!("line {line}, column {column}")
    });
    Error::config(
        at.unwrap_or_else(|| "scenario".into()),
        e.message().to_string(),
    )
}

#[cfg(test)]
mod tests {
    use super::line_column;

    #[test]
    fn lines_and_columns_count_from_one_in_characters() {
        assert_eq!(line_column("ab\ncd", 0), (1, 1));
        assert_eq!(line_column("ab\ncd", 4), (2, 2));
        // Columns count characters, not bytes.
        let t = "ε = 1\nν = x";
        let at = t.find('x').unwrap();
        assert_eq!(line_column(t, at), (2, 5));
        assert_eq!(line_column(t, 10_000), (2, 6));
    }
}
