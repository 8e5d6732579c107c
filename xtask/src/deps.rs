//! `cargo xtask deps [--crate DIR]`: the module graph of a crate, read from its sources,
//! printed in layers; exits 1 when the graph has an import cycle.
//!
//! A node is a top-level module of the crate (`src/x.rs` or `src/x/`; the files of a
//! directory module all count as that module). An edge `x -> y` is a path `crate::y…` (or
//! `super::…` reaching the crate root, then `y`) in the code of `x`'s files, tests
//! included; `use crate::{a, b::c}` names `a` and `b`. Comments (doc comments too), string
//! and character literals are removed first, so a doc link or a message naming a module is
//! no dependency. Items re-exported by the crate root (`crate::Result`) are not modules and
//! make no edge.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Options of `cargo xtask deps`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The crate's directory (holding `src/`), relative to the workspace root.
    #[arg(long = "crate", value_name = "DIR", default_value = "crates/harness")]
    krate: PathBuf,
}

/// Prints the module graph of the crate in layers (a module uses only modules of earlier
/// layers); exit code 1 and the cycle when there is one.
pub fn run(args: Args, workspace: &Path) -> anyhow::Result<ExitCode> {
    let src = workspace.join(&args.krate).join("src");
    let graph = module_graph(&src).map_err(|e| anyhow::anyhow!("{}: {e}", src.display()))?;
    println!("module graph of {} ({} modules)", src.display(), graph.len());
    if let Some(cycle) = find_cycle(&graph) {
        for (module, uses) in &graph {
            println!("  {module} -> {}", join(uses));
        }
        println!("import cycle: {}", cycle.join(" -> "));
        return Ok(ExitCode::FAILURE);
    }
    for (i, layer) in layers(&graph).iter().enumerate() {
        println!("layer {i}:");
        for module in layer {
            println!("  {module} -> {}", join(&graph[module]));
        }
    }
    println!("no import cycle");
    Ok(ExitCode::SUCCESS)
}

fn join(names: &BTreeSet<String>) -> String {
    if names.is_empty() { "(nothing)".into() } else { names.iter().cloned().collect::<Vec<_>>().join(", ") }
}

/// Top-level module → the top-level modules its code names (never itself).
pub type Graph = BTreeMap<String, BTreeSet<String>>;

/// The module graph of the crate whose sources are in `src` (see the module documentation).
pub fn module_graph(src: &Path) -> std::io::Result<Graph> {
    let mut files = Vec::new();
    rust_files(src, &mut files)?;
    let modules: Vec<(PathBuf, Vec<String>)> =
        files.into_iter().filter_map(|f| module_path(src, &f).map(|m| (f, m))).collect();
    let mut graph = Graph::new();
    for (_, m) in &modules {
        if let Some(top) = m.first() {
            graph.entry(top.clone()).or_default();
        }
    }
    for (file, m) in &modules {
        let Some(top) = m.first() else { continue };
        let code = strip_comments_and_literals(&std::fs::read_to_string(file)?);
        let used: BTreeSet<String> =
            references(&code, m).into_iter().filter(|name| name != top && graph.contains_key(name)).collect();
        graph.entry(top.clone()).or_default().extend(used);
    }
    Ok(graph)
}

/// Every `.rs` file below `dir`, sorted.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    let mut entries: Vec<PathBuf> =
        std::fs::read_dir(dir)?.map(|e| e.map(|e| e.path())).collect::<Result<_, _>>()?;
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out)?;
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    Ok(())
}

/// The module path of `file` (`src/a/b.rs` → `[a, b]`, `src/a/mod.rs` → `[a]`); empty for
/// the crate root (`lib.rs`, `main.rs`); `None` for a file of no module (`src/bin/`).
fn module_path(src: &Path, file: &Path) -> Option<Vec<String>> {
    let rel = file.strip_prefix(src).ok()?;
    let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if parts.first().is_some_and(|p| p == "bin") {
        return None;
    }
    let last = parts.pop()?;
    let stem = last.strip_suffix(".rs")?;
    if parts.is_empty() && (stem == "lib" || stem == "main") {
        return Some(Vec::new());
    }
    if stem != "mod" {
        parts.push(stem.to_string());
    }
    Some(parts)
}

/// `text` with comments removed and every string, byte-string, raw-string and character
/// literal replaced by an empty one; lifetimes and labels are kept.
pub fn strip_comments_and_literals(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let ident = |ch: char| ch.is_alphanumeric() || ch == '_';
    let mut i = 0;
    while i < c.len() {
        let at = |k: usize| c.get(i + k).copied();
        let starts_token = i == 0 || !ident(c[i - 1]);
        if at(0) == Some('/') && at(1) == Some('/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if at(0) == Some('/') && at(1) == Some('*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if let Some(end) = starts_token.then(|| raw_string_end(&c, i)).flatten() {
            out.push_str("\"\"");
            i = end;
        } else if at(0) == Some('"') {
            i += 1;
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            out.push_str("\"\"");
            i += 1;
        } else if at(0) == Some('\'') && at(1) == Some('\\') {
            // An escaped character literal: '\n', '\'', '\u{1F600}'.
            i += 3;
            while i < c.len() && c[i] != '\'' {
                i += 1;
            }
            out.push_str("' '");
            i += 1;
        } else if at(0) == Some('\'') && at(2) == Some('\'') {
            out.push_str("' '");
            i += 3;
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// The index after a raw string literal (`r"…"`, `r#"…"#`, `br#"…"#`, `cr"…"`) starting at
/// `i`, if one starts there.
fn raw_string_end(c: &[char], i: usize) -> Option<usize> {
    let mut j = i;
    if matches!(c.get(j), Some('b' | 'c')) {
        j += 1;
    }
    if c.get(j) != Some(&'r') {
        return None;
    }
    j += 1;
    let hashes = c[j..].iter().take_while(|&&ch| ch == '#').count();
    j += hashes;
    if c.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < c.len() {
        if c[j] == '"' && c[j + 1..].iter().take(hashes).filter(|&&ch| ch == '#').count() == hashes {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(c.len())
}

/// A token of stripped code: an identifier (`$crate` included), `::`, or one other
/// character.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Token {
    Ident(String),
    PathSep,
    Punct(char),
}

fn tokens(code: &str) -> Vec<Token> {
    let c: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        let ch = c[i];
        if ch.is_alphanumeric() || ch == '_' || (ch == '$' && c.get(i + 1).is_some_and(|n| n.is_alphabetic()))
        {
            let start = i;
            i += 1;
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                i += 1;
            }
            let word: String = c[start..i].iter().collect();
            // A raw identifier `r#type` is the identifier `type`.
            if word == "r" && c.get(i) == Some(&'#') && c.get(i + 1).is_some_and(|n| n.is_alphabetic()) {
                i += 1;
                continue;
            }
            out.push(Token::Ident(word));
        } else if ch == ':' && c.get(i + 1) == Some(&':') {
            out.push(Token::PathSep);
            i += 2;
        } else {
            if !ch.is_whitespace() {
                out.push(Token::Punct(ch));
            }
            i += 1;
        }
    }
    out
}

/// The names that the paths of `code` (stripped) reach at the crate root: after `crate::`,
/// or after as many `super::` as climb from `module` (the file's module path, extended by
/// the inline `mod x { … }` blocks around the path) to the root.
fn references(code: &str, module: &[String]) -> BTreeSet<String> {
    let t = tokens(code);
    let ident = |k: usize| match t.get(k) {
        Some(Token::Ident(s)) => Some(s.as_str()),
        _ => None,
    };
    let mut found = BTreeSet::new();
    // Inline modules: (name, brace depth inside it).
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut depth = 0usize;
    let mut k = 0;
    while k < t.len() {
        match &t[k] {
            Token::Punct('{') => {
                depth += 1;
                if k >= 2
                    && ident(k - 2) == Some("mod")
                    && let Some(name) = ident(k - 1)
                {
                    inline.push((name.to_string(), depth));
                }
            }
            Token::Punct('}') => {
                if inline.last().is_some_and(|(_, d)| *d == depth) {
                    inline.pop();
                }
                depth = depth.saturating_sub(1);
            }
            Token::Ident(w) if (w == "crate" || w == "super") && t.get(k + 1) == Some(&Token::PathSep) => {
                // Only the start of a path (not `a::super`, not `$crate`).
                let continues = k > 0 && t[k - 1] == Token::PathSep;
                if !continues {
                    let mut j = k;
                    let at_root = if w == "crate" {
                        j += 2;
                        true
                    } else {
                        let mut supers = 0;
                        while ident(j) == Some("super") && t.get(j + 1) == Some(&Token::PathSep) {
                            supers += 1;
                            j += 2;
                        }
                        supers == module.len() + inline.len()
                    };
                    if at_root {
                        found.extend(first_segments(&t, j));
                    }
                    k = j;
                    continue;
                }
            }
            _ => {}
        }
        k += 1;
    }
    found
}

/// The first segment of the path (or of each path of the `{…}` group) starting at token `k`.
fn first_segments(t: &[Token], k: usize) -> Vec<String> {
    match t.get(k) {
        Some(Token::Ident(s)) => vec![s.clone()],
        Some(Token::Punct('{')) => {
            let mut out = Vec::new();
            let mut depth = 0;
            let mut expect = true;
            for tok in &t[k..] {
                match tok {
                    Token::Punct('{') => {
                        depth += 1;
                        continue;
                    }
                    Token::Punct('}') => {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    Token::Punct(',') if depth == 1 => {
                        expect = true;
                        continue;
                    }
                    Token::Ident(s) if depth == 1 && expect => out.push(s.clone()),
                    _ => {}
                }
                expect = false;
            }
            out
        }
        _ => Vec::new(),
    }
}

/// A cycle of `graph` (`[a, b, …, a]`), the first found visiting modules in name order;
/// `None` when the graph is acyclic.
pub fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        New,
        Open,
        Done,
    }
    fn visit<'a>(
        node: &'a str,
        graph: &'a Graph,
        state: &mut BTreeMap<&'a str, State>,
        stack: &mut Vec<&'a str>,
    ) -> Option<Vec<String>> {
        state.insert(node, State::Open);
        stack.push(node);
        for next in graph.get(node).into_iter().flatten() {
            match state.get(next.as_str()).copied().unwrap_or(State::New) {
                State::Open => {
                    let from = stack.iter().position(|n| *n == next.as_str()).unwrap_or(0);
                    let mut cycle: Vec<String> = stack[from..].iter().map(|s| s.to_string()).collect();
                    cycle.push(next.clone());
                    return Some(cycle);
                }
                State::New => {
                    if let Some(c) = visit(next, graph, state, stack) {
                        return Some(c);
                    }
                }
                State::Done => {}
            }
        }
        stack.pop();
        state.insert(node, State::Done);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if state.get(node.as_str()).copied().unwrap_or(State::New) == State::New
            && let Some(c) = visit(node, graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

/// The modules in layers: layer 0 uses no other module, layer n only modules of earlier
/// layers. A module on a cycle (and whatever uses it) is in no layer.
pub fn layers(graph: &Graph) -> Vec<Vec<String>> {
    let mut placed: BTreeSet<&str> = BTreeSet::new();
    let mut out = Vec::new();
    loop {
        let layer: Vec<String> = graph
            .iter()
            .filter(|(m, uses)| {
                !placed.contains(m.as_str()) && uses.iter().all(|u| placed.contains(u.as_str()))
            })
            .map(|(m, _)| m.clone())
            .collect();
        if layer.is_empty() {
            return out;
        }
        placed.extend(graph.keys().filter(|k| layer.contains(k)).map(String::as_str));
        out.push(layer);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn graph(edges: &[(&str, &[&str])]) -> Graph {
        edges.iter().map(|(m, uses)| (m.to_string(), uses.iter().map(|u| u.to_string()).collect())).collect()
    }

    #[test]
    fn finds_a_cycle_and_names_it() {
        let g = graph(&[("a", &["b"]), ("b", &["c"]), ("c", &["a", "d"]), ("d", &[])]);
        assert_eq!(find_cycle(&g), Some(vec!["a".into(), "b".into(), "c".into(), "a".into()]));
        let g = graph(&[("a", &["b"]), ("b", &["a"])]);
        assert_eq!(find_cycle(&g), Some(vec!["a".into(), "b".into(), "a".into()]));
    }

    #[test]
    fn an_acyclic_graph_has_layers() {
        let g = graph(&[("a", &["b", "c"]), ("b", &["c"]), ("c", &[]), ("d", &[])]);
        assert_eq!(find_cycle(&g), None);
        assert_eq!(layers(&g), [vec!["c".to_string(), "d".into()], vec!["b".into()], vec!["a".into()]]);
        let cyclic = graph(&[("a", &["b"]), ("b", &["a"]), ("c", &[])]);
        assert_eq!(layers(&cyclic), [vec!["c".to_string()]]);
    }

    #[test]
    fn comments_and_literals_are_no_code() {
        let code = strip_comments_and_literals(
            "/// [`crate::a`]\nlet s = \"crate::b\"; /* crate::c /* nested */ crate::d */ let r = r#\"crate::e \"quoted\"\"#;\n\
             let q = '\"'; let l: &'static str = \"x\"; crate::f::g(); // crate::h\nlet e = '\\''; crate::i",
        );
        let found = references(&code, &["m".to_string()]);
        assert_eq!(found, ["f", "i"].iter().map(|s| s.to_string()).collect());
    }

    #[test]
    fn groups_super_and_inline_modules() {
        let code = "use crate::{a, b::{c, d}, e::*};\nuse super::f;\nuse super::super::g;\n\
                    pub(crate) fn x() {}\nmod tests { use super::super::h; use super::i; }\n$crate::j";
        let code = strip_comments_and_literals(code);
        // In module `m::n`: `super::f` is `m::f`, `super::super::g` the root's `g`; inside
        // `mod tests`, one more `super` is needed.
        let found = references(&code, &["m".to_string(), "n".to_string()]);
        assert_eq!(found, ["a", "b", "e", "g"].iter().map(|s| s.to_string()).collect());
        let top = references(
            &strip_comments_and_literals("use super::k; mod t { use super::super::l; }"),
            &["m".to_string()],
        );
        assert_eq!(top, ["k", "l"].iter().map(|s| s.to_string()).collect());
    }

    #[test]
    fn files_map_to_modules() {
        let src = Path::new("/x/src");
        let m = |f: &str| module_path(src, &src.join(f));
        assert_eq!(m("lib.rs"), Some(vec![]));
        assert_eq!(m("a.rs"), Some(vec!["a".to_string()]));
        assert_eq!(m("a/mod.rs"), Some(vec!["a".to_string()]));
        assert_eq!(m("a/b.rs"), Some(vec!["a".to_string(), "b".to_string()]));
        assert_eq!(m("bin/tool.rs"), None);
    }
}
