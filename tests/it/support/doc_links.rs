//! Relative links of the Markdown documentation (README.md, docs/**/*.md, benches/README.md):
//! every `[text](target)` and `![alt](target)` outside code whose target is not a URL must name
//! a file or folder that exists, and its `#anchor`, if any, a heading of that Markdown file
//! (GitHub's anchors: the heading's text lowercased, punctuation dropped, spaces turned into
//! '-', a repeated heading suffixed -1, -2, …; mdBook's are the same).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The Markdown files checked: README.md, benches/README.md and every `.md` under docs/
/// (not the built book, docs/book/).
pub fn documentation_files(root: &Path) -> Vec<PathBuf> {
    let mut files = vec![root.join("README.md"), root.join("benches/README.md")];
    let mut stack = vec![root.join("docs")];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries {
            let path = entry.expect("folder entry").path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n != "book") {
                    stack.push(path);
                }
            } else if path.extension().is_some_and(|e| e == "md") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// Every broken link of `files`, as `file:line: target: why` (paths relative to `root`).
pub fn broken_links(root: &Path, files: &[PathBuf]) -> Vec<String> {
    let mut problems = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(file).expect("documentation file is readable");
        let dir = file.parent().expect("a file has a folder");
        let shown = file
            .strip_prefix(root)
            .unwrap_or(file)
            .display()
            .to_string();
        for (line_no, line) in prose_lines(&text) {
            for target in link_targets(&line) {
                let (path, anchor) = target.split_once('#').unwrap_or((target.as_str(), ""));
                let linked = if path.is_empty() {
                    file.clone()
                } else {
                    dir.join(path)
                };
                if !linked.exists() {
                    problems.push(format!("{shown}:{line_no}: {target}: no such file"));
                    continue;
                }
                let is_markdown = linked.extension().is_some_and(|e| e == "md");
                if !anchor.is_empty() && is_markdown {
                    let text = std::fs::read_to_string(&linked).unwrap_or_default();
                    if !anchors(&text).contains(anchor) {
                        problems.push(format!("{shown}:{line_no}: {target}: no such heading"));
                    }
                }
            }
        }
    }
    problems
}

/// The lines of `text` outside fenced code blocks, numbered from 1.
fn unfenced_lines(text: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            out.push((k + 1, line));
        }
    }
    out
}

/// The lines of `text` outside fenced code blocks, numbered from 1, with inline code removed.
fn prose_lines(text: &str) -> Vec<(usize, String)> {
    unfenced_lines(text)
        .into_iter()
        .map(|(k, line)| (k, without_inline_code(line)))
        .collect()
}

/// `line` without its `code spans`.
fn without_inline_code(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut in_code = false;
    for c in line.chars() {
        if c == '`' {
            in_code = !in_code;
        } else if !in_code {
            out.push(c);
        }
    }
    out
}

/// The targets of the links in `line` that are not URLs (no scheme such as `https:`).
fn link_targets(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        let end = after
            .find(|c: char| c == ')' || c.is_whitespace())
            .unwrap_or(after.len());
        let target = after[..end].trim_start_matches('<').trim_end_matches('>');
        let scheme = target
            .split_once(':')
            .is_some_and(|(s, _)| !s.is_empty() && s.chars().all(|c| c.is_ascii_alphabetic()));
        if !target.is_empty() && !scheme {
            out.push(target.to_string());
        }
        rest = &after[end..];
    }
    out
}

/// The anchors of a Markdown text: one per heading (repeats suffixed -1, -2, …) and every
/// `<a id="…">` or `<a name="…">`.
pub fn anchors(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (_, line) in unfenced_lines(text) {
        let line = line.replace('`', "");
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if (1..=6).contains(&hashes) && line[hashes..].starts_with(' ') {
            let base = anchor(&line[hashes..]);
            let mut id = base.clone();
            let mut n = 0;
            while out.contains(&id) {
                n += 1;
                id = format!("{base}-{n}");
            }
            out.insert(id);
        }
        for key in ["<a id=\"", "<a name=\""] {
            let mut rest = line.as_str();
            while let Some(at) = rest.find(key) {
                let after = &rest[at + key.len()..];
                let end = after.find('"').unwrap_or(after.len());
                out.insert(after[..end].to_string());
                rest = &after[end..];
            }
        }
    }
    out
}

/// GitHub's anchor of a heading's text: links reduced to their text, lowercased, every
/// character but letters, digits, '-' and '_' dropped, spaces turned into '-'.
pub fn anchor(heading: &str) -> String {
    let mut text = String::new();
    let mut rest = heading.trim();
    // `[text](target)` → `text`.
    while let Some(open) = rest.find('[') {
        let Some(close) = rest[open..].find("](").map(|c| open + c) else {
            break;
        };
        let Some(end) = rest[close..].find(')').map(|e| close + e) else {
            break;
        };
        text.push_str(&rest[..open]);
        text.push_str(&rest[open + 1..close]);
        rest = &rest[end + 1..];
    }
    text.push_str(rest);
    text.chars()
        .flat_map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                c.to_lowercase().collect::<Vec<_>>()
            } else if c == ' ' {
                vec!['-']
            } else {
                Vec::new()
            }
        })
        .collect()
}
