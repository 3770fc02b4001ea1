//! Reading a scene: the file or text parsed against the schema, then each `--set FIELD=VALUE`
//! override applied to the TOML table and checked against the schema again, so that every
//! parse error names the line, or the override, that caused it.

use std::path::Path;

use crate::scene::error::SceneError;
use crate::scene::schema::Scene;

/// Reads a scene file, applying `--set` overrides (`path=value`).
pub fn load(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        file: file.clone(),
        source,
    })?;
    parse(&text, &file, overrides)
}

/// Parses scene text (`file` names it in errors), applying overrides.
///
/// The text must match the schema on its own; then each override is applied in turn and the
/// result checked against the schema again, so that an unknown field or a wrong type is
/// reported against the `--set` that introduced it.
pub fn parse(text: &str, file: &str, overrides: &[String]) -> Result<Scene, SceneError> {
    let parse_err = |e: toml::de::Error| SceneError::Parse {
        file: file.to_string(),
        message: parse_message(&e, text),
    };
    let mut scene: Scene = toml::from_str(text).map_err(parse_err)?;
    if overrides.is_empty() && !scene.title.contains('{') {
        return Ok(scene);
    }
    let mut table: toml::Table = text.parse().map_err(parse_err)?;
    for assignment in overrides {
        let override_err = |reason: String| SceneError::Override {
            file: file.to_string(),
            assignment: assignment.clone(),
            reason,
        };
        apply_override(&mut table, assignment).map_err(override_err)?;
        toml::Value::Table(table.clone())
            .try_into::<Scene>()
            .map_err(|e| override_err(one_line(&e.to_string())))?;
    }
    if !overrides.is_empty() {
        scene = toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| SceneError::Parse {
                file: file.to_string(),
                message: format!("after --set overrides: {}", one_line(&e.to_string())),
            })?;
    }
    scene.title = resolve_title(&scene.title, &table)
        .map_err(|reason| SceneError::invalid(file, "title", reason))?;
    Ok(scene)
}

/// The title with each `{FIELD}` replaced by the value of the scene field at that dotted path
/// (the `--set` syntax) after the overrides, and each `{-FIELD}` by the negated number, so
/// that a title states the value solved with, never a stale one: `F0 = {-static_loads.0.value}
/// N` reads `F0 = 120 N` for a pre-load of -120 N along y. `{{` and `}}` are literal braces.
pub(crate) fn resolve_title(title: &str, table: &toml::Table) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = title;
    while let Some(i) = rest.find(['{', '}']) {
        out.push_str(&rest[..i]);
        let brace = &rest[i..i + 1];
        if rest[i + 1..].starts_with(brace) {
            out.push_str(brace);
            rest = &rest[i + 2..];
            continue;
        }
        if brace == "}" {
            return Err("`}` without `{` (write `}}` for a brace)".to_string());
        }
        let Some(end) = rest[i..].find('}') else {
            return Err("`{` without `}` (write `{{` for a brace)".to_string());
        };
        let inner = rest[i + 1..i + end].trim();
        let (negate, path) = match inner.strip_prefix('-') {
            Some(p) => (true, p.trim()),
            None => (false, inner),
        };
        // A field the scene does not have (a pre-load removed with `--set static_loads=`)
        // reads "none": the scene's own checks then report what is missing, not the title.
        let Some(value) = field_value(table, path) else {
            out.push_str("none");
            rest = &rest[i + end + 1..];
            continue;
        };
        let number = value
            .as_float()
            .or_else(|| value.as_integer().map(|v| v as f64));
        let text = match (number, value) {
            (Some(v), _) => format!("{}", if negate { -v } else { v }),
            (None, _) if negate => {
                return Err(format!("`{{{inner}}}`: `{path}` is not a number to negate"));
            }
            (None, toml::Value::String(s)) => s.clone(),
            (None, other) => other.to_string(),
        };
        out.push_str(&text);
        rest = &rest[i + end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The value at a dotted path (table keys, array indices) of a scene table.
fn field_value<'a>(table: &'a toml::Table, path: &str) -> Option<&'a toml::Value> {
    let mut segments = path.split('.');
    let mut node = table.get(segments.next()?)?;
    for segment in segments {
        node = match node {
            toml::Value::Table(t) => t.get(segment)?,
            toml::Value::Array(a) => a.get(segment.parse::<usize>().ok()?)?,
            _ => return None,
        };
    }
    Some(node)
}

/// A parser error as `line L, column C: message` (one line, so that the first line of the
/// report names the field), followed by the offending source line.
fn parse_message(e: &toml::de::Error, text: &str) -> String {
    let located = e.span().and_then(|span| {
        let before = text.get(..span.start)?;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let line_no = before.matches('\n').count() + 1;
        let column = before[line_start..].chars().count() + 1;
        let source = text[line_start..].lines().next().unwrap_or("");
        Some(format!(
            "line {line_no}, column {column}: {}\n  | {source}",
            one_line(e.message())
        ))
    });
    located.unwrap_or_else(|| one_line(&e.to_string()))
}

/// A possibly multi-line message on one line: trimmed lines joined by spaces.
pub(super) fn one_line(message: &str) -> String {
    message
        .trim()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Applies one `a.b.0.c=value` override to a TOML table. The value is read as TOML (number,
/// boolean, array, quoted string) and otherwise taken as a bare string; an empty value removes
/// the field or array entry. Missing tables on the path are created; array entries must exist.
/// The result is not checked against the schema.
pub fn apply_override(table: &mut toml::Table, assignment: &str) -> Result<(), String> {
    let (path, raw) = assignment
        .split_once('=')
        .ok_or_else(|| "expected FIELD=VALUE".to_string())?;
    let path = path.trim();
    if path.is_empty() {
        return Err("empty field path".into());
    }
    // An empty value removes the field (e.g. `harmonics.max=` before giving `harmonics.list`).
    let value: Option<toml::Value> = if raw.trim().is_empty() {
        None
    } else {
        Some(match format!("v = {}", raw.trim()).parse::<toml::Table>() {
            Ok(mut t) => t.remove("v").expect("parsed key v"),
            Err(_) => toml::Value::String(raw.trim().to_string()),
        })
    };
    let segments: Vec<&str> = path.split('.').collect();
    let mut current = toml::Value::Table(std::mem::take(table));
    let result = set_path(&mut current, &segments, value, path);
    if let toml::Value::Table(t) = current {
        *table = t;
    }
    result
}

/// Sets (or, when `value` is `None`, removes) the entry at `segments` below `node`: table
/// keys and array indices; `full` is the whole path, for messages.
fn set_path(
    node: &mut toml::Value,
    segments: &[&str],
    value: Option<toml::Value>,
    full: &str,
) -> Result<(), String> {
    let (head, rest) = segments.split_first().expect("non-empty path");
    let child: &mut toml::Value = match node {
        toml::Value::Table(t) => {
            if rest.is_empty() {
                match value {
                    Some(v) => {
                        t.insert(head.to_string(), v);
                    }
                    None => {
                        t.remove(*head)
                            .ok_or_else(|| format!("no field `{head}` to remove in `{full}`"))?;
                    }
                }
                return Ok(());
            }
            if value.is_none() && !t.contains_key(*head) {
                return Err(format!("no field `{head}` to remove in `{full}`"));
            }
            // A table the file omits (e.g. `[effects]`) is created; whether the key belongs to
            // the schema is checked by the caller.
            t.entry(head.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        }
        toml::Value::Array(a) => {
            let i: usize = head
                .parse()
                .map_err(|_| format!("`{head}` is not an array index in `{full}`"))?;
            let len = a.len();
            let slot = a
                .get_mut(i)
                .ok_or_else(|| format!("index {i} out of range (length {len}) in `{full}`"))?;
            if rest.is_empty() {
                match value {
                    Some(v) => *slot = v,
                    None => {
                        a.remove(i);
                    }
                }
                return Ok(());
            }
            slot
        }
        _ => {
            return Err(format!(
                "`{head}` is below a value that is not a table or array in `{full}`"
            ))
        }
    };
    set_path(child, rest, value, full)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        text.parse().unwrap()
    }

    /// Placeholders show the field's value (negated with `-`), braces doubled are literal, a
    /// placeholder naming no field reads "none", and negating text is refused.
    #[test]
    fn title_placeholders_show_the_scene_values() {
        let t = table(
            "title = \"x\"\n[[static_loads]]\ndof = \"yD\"\nvalue = -120.0\n\
             [harmonics]\nmax = 3\n",
        );
        let resolve = |title: &str| resolve_title(title, &t);
        assert_eq!(
            resolve("F0 = {-static_loads.0.value} N, H = {harmonics.max}").unwrap(),
            "F0 = 120 N, H = 3"
        );
        assert_eq!(
            resolve("load on {static_loads.0.dof}").unwrap(),
            "load on yD"
        );
        assert_eq!(resolve("{{not}} a {{field}}").unwrap(), "{not} a {field}");
        assert_eq!(resolve("plain").unwrap(), "plain");
        assert_eq!(resolve("{static_loads.1.value}").unwrap(), "none");
        for (bad, says) in [
            ("{-static_loads.0.dof}", "not a number"),
            ("open {", "without `}`"),
            ("close }", "without `{`"),
        ] {
            let e = resolve(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    /// The title is resolved after the overrides; a placeholder naming a field the scene lacks
    /// reads "none", and a malformed one is an error on `title`.
    #[test]
    fn titles_follow_the_overrides() {
        let text = crate::scene::PAPER_DEFAULT_SCENE;
        let scene = parse(text, "paper", &[]).unwrap();
        assert!(scene.title.contains("F0 = 120 N"), "{}", scene.title);
        let scene = parse(text, "paper", &["static_loads.0.value=-1".to_string()]).unwrap();
        assert!(scene.title.contains("F0 = 1 N"), "{}", scene.title);
        let scene = parse(
            text,
            "paper",
            &["title=\"F0 = {static_loads.9.value}\"".to_string()],
        )
        .unwrap();
        assert_eq!(scene.title, "F0 = none");
        let e = parse(text, "paper", &["title=\"F0 = {static_loads\"".to_string()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("title") && e.contains("without `}`"), "{e}");
    }
}
