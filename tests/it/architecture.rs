//! The module graph points one way: no import cycle between any two files of the workspace,
//! and the layers of `src/` only use layers below them.
//!
//! The layers, lowest first, are listed in [`LAYERS`] (and in the guide's architecture chapter,
//! docs/src/dev/architecture.md). An edge A → B is any path in A's code (not its comments or
//! strings) that names an item of module B: `crate::…`, `super::…` and `self::…` paths and, in a
//! module with children (a folder's `mod.rs`), paths through a child: the re-exports `pub use
//! child::…` and calls such as `child::run(…)`, so a `mod.rs` that calls into a child which uses
//! the `mod.rs` back is a loop. A path through a re-export is followed to the module that defines
//! the item, so `crate::contact::ContactPoint` is an edge to `contact::point`. `mod` declarations
//! are containment, not use, and are not edges. Inline `#[cfg(test)]` modules are tests: like the
//! files of `tests/`, they may build their fixtures with any layer, and are left out.
//!
//! No source file of the workspace is longer than [`MAX_LINES`] lines: a file that grows past
//! it is split along its responsibilities.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::support::doc_links;
use crate::support::rust_source::{
    code_only, declared_for_tests, tokens, without_test_modules, Token,
};

/// Top-level modules of `src/`, lowest layer first. A module may use the ones before it.
const LAYERS: &[&str] = &[
    "numerics", "contact", "fe", "model", "hbm", "analysis", "scene", "study", "report", "cli",
];

/// The longest a source file of `src/` or `reduction/src/` may be, in lines.
const MAX_LINES: usize = 800;

/// Files over [`MAX_LINES`] tolerated while their split is under way (none now): paths
/// relative to the workspace root; an entry no longer over the limit fails the test.
const LONG_FILES_BEING_SPLIT: &[&str] = &[];

/// Loops between a `mod.rs` and the children it calls into, which use it back, tolerated
/// while they are being removed (none now): the edges left out of the cycle search; any other
/// loop fails the test.
const KNOWN_CLI_LOOPS: &[(&str, &str)] = &[];

/// One crate's modules: path (e.g. `contact::point`, "" for the root) → source file.
struct CrateModules {
    files: BTreeMap<String, PathBuf>,
}

impl CrateModules {
    fn read(src: &Path) -> Self {
        let mut files = BTreeMap::new();
        let mut stack = vec![src.to_path_buf()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).expect("source folder is readable") {
                let path = entry.expect("folder entry").path();
                if path.is_dir() {
                    stack.push(path);
                    continue;
                }
                if path.extension().is_none_or(|e| e != "rs") {
                    continue;
                }
                let rel = path.strip_prefix(src).expect("below src");
                let mut parts: Vec<String> = rel
                    .iter()
                    .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
                    .collect();
                let last = parts.last().cloned().unwrap_or_default();
                if last == "main" && parts.len() == 1 {
                    continue; // the binary: parses and dispatches only
                }
                if last == "mod" || (last == "lib" && parts.len() == 1) {
                    parts.pop();
                }
                files.insert(parts.join("::"), path);
            }
        }
        // Test modules in files of their own (`#[cfg(test)] mod name;` in their parent) are
        // tests, like inline ones: left out.
        let test_only: Vec<String> = files
            .keys()
            .filter(|path| {
                let Some((parent, name)) = path.rsplit_once("::") else {
                    return false;
                };
                files.get(parent).is_some_and(|file| {
                    let text = std::fs::read_to_string(file).unwrap_or_default();
                    declared_for_tests(&text, name)
                })
            })
            .cloned()
            .collect();
        for path in test_only {
            files.remove(&path);
        }
        Self { files }
    }

    fn is_module(&self, path: &str) -> bool {
        self.files.contains_key(path)
    }
}

/// Reads a path or use tree from `toks[*i]` (after a `::`), appending every full path.
fn read_tree(toks: &[Token], i: &mut usize, prefix: &[String], paths: &mut Vec<Vec<String>>) {
    match toks.get(*i) {
        Some(Token::Open) => {
            *i += 1;
            loop {
                match toks.get(*i) {
                    Some(Token::Close) => {
                        *i += 1;
                        break;
                    }
                    Some(Token::Comma) => *i += 1,
                    None => break,
                    _ => {
                        let before = *i;
                        read_tree(toks, i, prefix, paths);
                        // Skip `as name` and anything up to the next separator.
                        while !matches!(toks.get(*i), Some(Token::Comma | Token::Close) | None) {
                            *i += 1;
                        }
                        if *i == before {
                            *i += 1;
                        }
                    }
                }
            }
        }
        Some(Token::Ident(name)) => {
            let mut path = prefix.to_vec();
            path.push(name.clone());
            *i += 1;
            if toks.get(*i) == Some(&Token::PathSep) {
                *i += 1;
                read_tree(toks, i, &path, paths);
            } else {
                paths.push(path);
            }
        }
        _ => paths.push(prefix.to_vec()),
    }
}

/// The module paths a file names, as absolute segment lists (without `crate`).
fn named_paths(module: &str, code: &str, children: &BTreeSet<String>) -> Vec<Vec<String>> {
    let toks = tokens(code);
    let own: Vec<String> = if module.is_empty() {
        Vec::new()
    } else {
        module.split("::").map(str::to_string).collect()
    };
    let parent: Vec<String> = own[..own.len().saturating_sub(1)].to_vec();
    let mut paths = Vec::new();
    // Brace depths at which inline `mod name {` blocks opened (their `super` is this file).
    let mut inline_mods: Vec<usize> = Vec::new();
    let mut depth = 0usize;
    let mut i = 0;
    while i < toks.len() {
        match &toks[i] {
            Token::Open => depth += 1,
            Token::Close => {
                depth = depth.saturating_sub(1);
                if inline_mods.last() == Some(&depth) {
                    inline_mods.pop();
                }
            }
            Token::Ident(w) if w == "mod" => {
                if let (Some(Token::Ident(_)), Some(Token::Open)) =
                    (toks.get(i + 1), toks.get(i + 2))
                {
                    inline_mods.push(depth);
                }
            }
            // `child::item` in a module with that child (a call or a type through it), relative
            // to the module itself; not after `::`, where the name is inside a longer path.
            Token::Ident(w)
                if children.contains(w)
                    && toks.get(i + 1) == Some(&Token::PathSep)
                    && i.checked_sub(1).map(|k| &toks[k]) != Some(&Token::PathSep)
                    && inline_mods.is_empty() =>
            {
                let mut k = i;
                read_tree(&toks, &mut k, &own, &mut paths);
                i = k;
                continue;
            }
            Token::Ident(w)
                if (w == "crate" || w == "super" || w == "self" || (w == "use" && depth == 0))
                    && i.checked_sub(1).map(|k| &toks[k]) != Some(&Token::PathSep) =>
            {
                let base = match w.as_str() {
                    "crate" => Some(Vec::new()),
                    "super" if inline_mods.is_empty() => Some(parent.clone()),
                    "self" if inline_mods.is_empty() => Some(own.clone()),
                    "use" => {
                        // `pub use child::…` in a module with that child: relative to itself.
                        match toks.get(i + 1) {
                            Some(Token::Ident(c)) if children.contains(c) => Some(own.clone()),
                            _ => None,
                        }
                    }
                    _ => None,
                };
                if let Some(base) = base {
                    let mut k = i + 1;
                    if w != "use" {
                        if toks.get(k) != Some(&Token::PathSep) {
                            i += 1;
                            continue;
                        }
                        k += 1;
                    }
                    read_tree(&toks, &mut k, &base, &mut paths);
                    i = k;
                    continue;
                }
            }
            _ => {}
        }
        i += 1;
    }
    paths
}

/// Paths through module aliases: `alias::rest` where `alias` names an imported module.
fn alias_paths(code: &str, aliases: &BTreeMap<String, Vec<String>>) -> Vec<Vec<String>> {
    let toks = tokens(code);
    let mut paths = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        if let Token::Ident(name) = &toks[i] {
            let after_sep = i.checked_sub(1).map(|k| &toks[k]) == Some(&Token::PathSep);
            if let (Some(base), false, Some(Token::PathSep)) =
                (aliases.get(name), after_sep, toks.get(i + 1))
            {
                let mut k = i + 2;
                read_tree(&toks, &mut k, base, &mut paths);
                i = k;
                continue;
            }
        }
        i += 1;
    }
    paths
}

/// Re-exports of a module: item name → absolute path of its source.
type Reexports = BTreeMap<String, BTreeMap<String, Vec<String>>>;

/// The module that defines the item a path names (following re-exports).
fn resolve(modules: &CrateModules, reexports: &Reexports, path: &[String]) -> String {
    let mut module = String::new();
    for seg in path {
        let next = if module.is_empty() {
            seg.clone()
        } else {
            format!("{module}::{seg}")
        };
        if modules.is_module(&next) {
            module = next;
            continue;
        }
        if let Some(source) = reexports.get(&module).and_then(|r| r.get(seg)) {
            return resolve(modules, reexports, source);
        }
        break;
    }
    module
}

/// Edges between the files (modules) of one crate.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let modules = CrateModules::read(src);
    let mut raw: BTreeMap<String, Vec<Vec<String>>> = BTreeMap::new();
    let mut reexports: Reexports = BTreeMap::new();
    for (module, file) in &modules.files {
        let text = std::fs::read_to_string(file).expect("source is readable");
        let code = without_test_modules(&code_only(&text));
        let children: BTreeSet<String> = modules
            .files
            .keys()
            .filter_map(|m| {
                let rest = if module.is_empty() {
                    Some(m.as_str())
                } else {
                    m.strip_prefix(module.as_str())?.strip_prefix("::")
                };
                rest.filter(|r| !r.is_empty() && !r.contains("::"))
                    .map(str::to_string)
            })
            .collect();
        let mut paths = named_paths(module, &code, &children);
        // A module brought in by name (`use crate::hbm::{self, …}`, `use crate::model::reduce`)
        // is used through `name::item` paths: follow those instead of the import itself.
        let mut aliases: BTreeMap<String, Vec<String>> = BTreeMap::new();
        paths.retain(|p| {
            let p_mod: Vec<String> = match p.last().map(String::as_str) {
                Some("self") => p[..p.len() - 1].to_vec(),
                _ => p.clone(),
            };
            if !p_mod.is_empty() && modules.is_module(&p_mod.join("::")) {
                aliases.insert(p_mod.last().cloned().unwrap_or_default(), p_mod);
                return false;
            }
            true
        });
        paths.extend(alias_paths(&code, &aliases));
        // `pub use` items of this module define re-exports.
        let toks = tokens(&code);
        let own: Vec<String> = module
            .split("::")
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        for k in 0..toks.len().saturating_sub(1) {
            if toks[k] != Token::Ident("pub".into()) || toks[k + 1] != Token::Ident("use".into()) {
                continue;
            }
            let mut j = k + 2;
            let base = match toks.get(j) {
                Some(Token::Ident(c)) if c == "crate" => {
                    j += 2;
                    Vec::new()
                }
                Some(Token::Ident(c)) if c == "self" => {
                    j += 2;
                    own.clone()
                }
                _ => own.clone(),
            };
            let mut found = Vec::new();
            read_tree(&toks, &mut j, &base, &mut found);
            for p in found {
                if let Some(name) = p.last() {
                    reexports
                        .entry(module.clone())
                        .or_default()
                        .insert(name.clone(), p.clone());
                }
            }
        }
        raw.insert(module.clone(), paths);
    }
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (module, paths) in raw {
        let targets = graph.entry(module.clone()).or_default();
        for p in paths {
            let target = resolve(&modules, &reexports, &p);
            if !target.is_empty() && target != module {
                targets.insert(target);
            }
        }
    }
    graph
}

/// Strongly connected components with more than one module (Tarjan).
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'g> {
        graph: &'g BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        stack: Vec<&'g str>,
        on_stack: BTreeSet<&'g str>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit<'g>(s: &mut State<'g>, v: &'g str) {
        s.index.insert(v, s.next);
        s.low.insert(v, s.next);
        s.next += 1;
        s.stack.push(v);
        s.on_stack.insert(v);
        let graph = s.graph;
        for w in graph.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !graph.contains_key(w) {
                continue;
            }
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low[v];
                s.low.insert(v, lv.min(lw));
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low[v];
                s.low.insert(v, lv.min(iw));
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                s.out.push(component);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.out
}

fn describe(graph: &BTreeMap<String, BTreeSet<String>>, component: &[String]) -> String {
    let members: BTreeSet<&String> = component.iter().collect();
    let edges: Vec<String> = component
        .iter()
        .flat_map(|a| {
            graph[a]
                .iter()
                .filter(|b| members.contains(b))
                .map(move |b| format!("{a} → {b}"))
        })
        .collect();
    format!("{{{}}}: {}", component.join(", "), edges.join("; "))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `graph` without the edges of [`KNOWN_CLI_LOOPS`].
fn without_known_loops(
    mut graph: BTreeMap<String, BTreeSet<String>>,
) -> BTreeMap<String, BTreeSet<String>> {
    for (from, to) in KNOWN_CLI_LOOPS {
        if let Some(targets) = graph.get_mut(*from) {
            targets.remove(*to);
        }
    }
    graph
}

#[test]
fn no_import_cycle_between_files_of_fricbound() {
    let graph = without_known_loops(module_graph(&root().join("src")));
    assert!(graph.len() > 40, "read {} modules", graph.len());
    let found: Vec<String> = cycles(&graph).iter().map(|c| describe(&graph, c)).collect();
    assert!(found.is_empty(), "import cycles:\n{}", found.join("\n"));
}

/// Every `.rs` file below `dir`, with its number of lines.
fn line_counts(dir: &Path) -> Vec<(PathBuf, usize)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("source folder is readable") {
            let path = entry.expect("folder entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).expect("source is readable");
                out.push((path, text.lines().count()));
            }
        }
    }
    out
}

/// The files of `counts` over [`MAX_LINES`] and not in `allowed` (paths relative to `root`),
/// as "path: N lines".
fn too_long(root: &Path, counts: &[(PathBuf, usize)], allowed: &[&str]) -> Vec<String> {
    let mut out: Vec<String> = counts
        .iter()
        .filter(|(_, n)| *n > MAX_LINES)
        .map(|(p, n)| {
            let rel = p.strip_prefix(root).unwrap_or(p);
            (rel.to_string_lossy().replace('\\', "/"), *n)
        })
        .filter(|(rel, _)| !allowed.contains(&rel.as_str()))
        .map(|(rel, n)| format!("{rel}: {n} lines"))
        .collect();
    out.sort();
    out
}

#[test]
fn no_source_file_is_longer_than_the_limit() {
    let root = root();
    let mut counts = line_counts(&root.join("src"));
    counts.extend(line_counts(&root.join("reduction/src")));
    assert!(counts.len() > 40, "read {} files", counts.len());
    let long = too_long(&root, &counts, LONG_FILES_BEING_SPLIT);
    assert!(
        long.is_empty(),
        "source files over {MAX_LINES} lines (split them along their responsibilities):\n{}",
        long.join("\n")
    );
    // An entry whose file got split (or shrank) is stale: delete it with the split.
    let stale: Vec<&&str> = LONG_FILES_BEING_SPLIT
        .iter()
        .filter(|f| {
            !counts.iter().any(|(p, n)| {
                p.strip_prefix(&root).is_ok_and(|r| r == Path::new(f)) && *n > MAX_LINES
            })
        })
        .collect();
    assert!(
        stale.is_empty(),
        "files no longer over {MAX_LINES} lines in LONG_FILES_BEING_SPLIT: {stale:?}"
    );
}

#[test]
fn the_line_limit_names_each_long_file_and_its_count() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let src = dir.path().join("src");
    std::fs::create_dir_all(src.join("cli")).expect("folder");
    let lines = |n: usize| "fn f() {}\n".repeat(n);
    std::fs::write(src.join("short.rs"), lines(MAX_LINES)).expect("write");
    std::fs::write(src.join("long.rs"), lines(MAX_LINES + 1)).expect("write");
    std::fs::write(src.join("cli/mod.rs"), lines(MAX_LINES + 7)).expect("write");
    let counts = line_counts(&src);
    assert_eq!(
        too_long(dir.path(), &counts, &[]),
        vec![
            format!("src/cli/mod.rs: {} lines", MAX_LINES + 7),
            format!("src/long.rs: {} lines", MAX_LINES + 1),
        ]
    );
    assert_eq!(
        too_long(dir.path(), &counts, &["src/cli/mod.rs"]),
        vec![format!("src/long.rs: {} lines", MAX_LINES + 1)]
    );
}

#[test]
fn no_import_cycle_between_files_of_the_reduction_crate() {
    let graph = module_graph(&root().join("reduction/src"));
    assert!(graph.len() > 5, "read {} modules", graph.len());
    let found: Vec<String> = cycles(&graph).iter().map(|c| describe(&graph, c)).collect();
    assert!(found.is_empty(), "import cycles:\n{}", found.join("\n"));
}

#[test]
fn layers_use_only_layers_below_them() {
    let graph = module_graph(&root().join("src"));
    let layer = |m: &str| m.split("::").next().unwrap_or("").to_string();
    let rank = |l: &str| LAYERS.iter().position(|x| *x == l);
    let mut upward = Vec::new();
    for (from, targets) in &graph {
        let Some(rf) = rank(&layer(from)) else {
            assert!(from.is_empty(), "module `{from}` is in no layer of LAYERS");
            continue;
        };
        for to in targets {
            let rt = rank(&layer(to)).unwrap_or(usize::MAX);
            if rt > rf {
                upward.push(format!("{from} → {to}"));
            }
        }
    }
    assert!(
        upward.is_empty(),
        "imports pointing up a layer:\n{}",
        upward.join("\n")
    );
}

#[test]
fn the_checker_sees_cycles_and_re_exports() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let src = dir.path();
    std::fs::create_dir_all(src.join("low")).expect("folder");
    let write = |p: &str, s: &str| std::fs::write(src.join(p), s).expect("write");
    write("lib.rs", "pub mod low;\npub mod high;\n");
    write(
        "low/mod.rs",
        "//! crate::high in a comment is no edge\npub mod item;\npub use item::Thing;\n",
    );
    write(
        "low/item.rs",
        "pub struct Thing;\nconst S: &str = \"crate::high::Other\";\n",
    );
    write(
        "high.rs",
        "use crate::low::Thing;\npub struct Other(Thing);\n",
    );
    let graph = module_graph(src);
    assert_eq!(graph["high"], BTreeSet::from(["low::item".to_string()]));
    assert_eq!(graph["low"], BTreeSet::from(["low::item".to_string()]));
    assert!(graph["low::item"].is_empty());
    assert!(cycles(&graph).is_empty());
    // A use back up closes a cycle.
    write(
        "low/item.rs",
        "pub struct Thing;\nfn f() { let _ = crate::high::Other; }\n",
    );
    let graph = module_graph(src);
    assert_eq!(
        cycles(&graph),
        vec![vec!["high".to_string(), "low::item".to_string()]]
    );
    // `super::` at file level names the parent; inside an inline test module, the file itself.
    write(
        "low/item.rs",
        "pub struct Thing;\nuse super::Thing as T;\n#[cfg(test)]\nmod tests { use super::*; }\n",
    );
    let graph = module_graph(src);
    assert_eq!(
        graph["low::item"],
        BTreeSet::from([]),
        "re-export resolves to itself"
    );
}

#[test]
fn the_checker_sees_a_mod_rs_calling_into_a_child_that_uses_it_back() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let src = dir.path();
    std::fs::create_dir_all(src.join("cli")).expect("folder");
    std::fs::create_dir_all(src.join("app")).expect("folder");
    let write = |p: &str, s: &str| std::fs::write(src.join(p), s).expect("write");
    write("lib.rs", "pub mod app;\npub mod cli;\n");
    // `app/mod.rs` calls its child `run`, which uses `app/mod.rs` back: a loop the re-export
    // rule alone does not see.
    write(
        "app/mod.rs",
        "mod run;\npub struct Context;\npub fn main() { run::go(Context); }\n",
    );
    write(
        "app/run.rs",
        "use super::Context;\npub fn go(_: Context) { self::helper(); }\nfn helper() {}\n",
    );
    // The known cli loops, and one that is not known.
    write(
        "cli/mod.rs",
        "mod limits_run;\nmod sweep_run;\nmod modes;\nmod other;\npub struct Ctx;\n\
         pub fn run() {\n    limits_run::run_limits();\n    sweep_run::run_sweep();\n    \
         let _ = modes::boundary_check_lines();\n    other::go();\n}\n",
    );
    write(
        "cli/limits_run.rs",
        "use super::Ctx;\npub fn run_limits() { let _ = Ctx; }\n",
    );
    write(
        "cli/sweep_run.rs",
        "pub fn run_sweep() { let _ = super::Ctx; }\n",
    );
    write(
        "cli/modes.rs",
        "use crate::cli::Ctx;\npub fn boundary_check_lines() -> Ctx { Ctx }\n",
    );
    write("cli/other.rs", "pub fn go() { let _ = super::Ctx; }\n");
    let graph = module_graph(src);
    assert_eq!(
        graph["app"],
        BTreeSet::from(["app::run".to_string()]),
        "a call into a child is an edge"
    );
    assert_eq!(
        graph["app::run"],
        BTreeSet::from(["app".to_string()]),
        "`self::` names the module itself"
    );
    let found = cycles(&graph);
    assert!(found.contains(&vec!["app".to_string(), "app::run".to_string()]));
    // No loop is tolerated: the app loop and every cli loop remain.
    let found: BTreeSet<Vec<String>> = cycles(&without_known_loops(graph)).into_iter().collect();
    assert_eq!(
        found,
        BTreeSet::from([
            vec!["app".to_string(), "app::run".to_string()],
            vec![
                "cli".to_string(),
                "cli::limits_run".to_string(),
                "cli::modes".to_string(),
                "cli::other".to_string(),
                "cli::sweep_run".to_string(),
            ],
        ])
    );
}

#[test]
fn every_relative_link_and_anchor_of_the_documentation_resolves() {
    let root = root();
    let files = doc_links::documentation_files(&root);
    assert!(files.len() > 10, "the guide's pages are found: {files:?}");
    let broken = doc_links::broken_links(&root, &files);
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_link_checker_sees_missing_files_and_headings() {
    assert_eq!(
        doc_links::anchor("2D friction law (`jenkins-2d`)".replace('`', "").as_str()),
        "2d-friction-law-jenkins-2d"
    );
    assert_eq!(doc_links::anchor("The 5 % bound"), "the-5--bound");
    assert_eq!(doc_links::anchor("See [Outputs](x.md)"), "see-outputs");
    let dir = std::env::temp_dir().join(format!("fricbound-doc-links-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let page = dir.join("page.md");
    std::fs::write(&page, "# Title\n\n## Title\n\n```\n[not](a-link.md)\n```\n").unwrap();
    let index = dir.join("index.md");
    let links = "[a](page.md#title-1) [b](page.md#title-2) [c](gone.md) `[d](gone.md)` \
                 [e](https://example.org/x) [f](#here)\n\n# Here\n";
    std::fs::write(&index, links).unwrap();
    let broken = doc_links::broken_links(&dir, &[index, page]);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(broken.len(), 2, "{broken:?}");
    assert!(
        broken[0].contains("page.md#title-2: no such heading"),
        "{broken:?}"
    );
    assert!(broken[1].contains("gone.md: no such file"), "{broken:?}");
}
