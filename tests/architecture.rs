//! The shape of the tree, checked so it cannot drift back: the library's folders depend on each
//! other in one direction only (no folder cycle such as estimate ↔ report), the files of
//! `src/io/` form no import cycle (readers stand on a leaf sample-source trait; the stream
//! dispatches to them, never the reverse), `src/cli/` holds no file over 400 lines, and no
//! function outside generated code and tests is over 150 lines.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// The text of a source file without its `#[cfg(test)]` part and without comment lines.
fn code_of(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The names `crate::NAME` (or `crate::io::NAME` with `prefix` = "io::") refers to in `code`.
fn referenced(code: &str, prefix: &str) -> BTreeSet<String> {
    let pat = format!("crate::{prefix}");
    let mut out = BTreeSet::new();
    let mut rest = code;
    while let Some(i) = rest.find(&pat) {
        rest = &rest[i + pat.len()..];
        let name: String = rest
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        if !name.is_empty() {
            out.insert(name);
        }
    }
    out
}

/// A cycle of `graph`, if it has one (depth-first search).
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == n) {
            let mut c = path[i..].to_vec();
            c.push(n.to_string());
            return Some(c);
        }
        if done.contains(n) {
            return None;
        }
        path.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            if let Some(c) = visit(m, g, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    for n in graph.keys() {
        if let Some(c) = visit(n, graph, &mut Vec::new(), &mut done) {
            return Some(c);
        }
    }
    None
}

/// The folder (first component under `src/`) of a source file; None for files at the top.
fn folder(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let mut parts = rel.components();
    let first = parts.next()?.as_os_str().to_string_lossy().into_owned();
    parts.next().map(|_| first)
}

#[test]
fn the_library_folders_form_no_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in rust_files(&src) {
        let Some(top) = folder(&src, &f) else {
            continue;
        };
        if top == "cli" {
            continue;
        }
        let refs = referenced(&code_of(&f), "");
        let entry = graph.entry(top.clone()).or_default();
        entry.extend(refs.into_iter().filter(|r| *r != top));
    }
    assert!(graph.len() >= 8, "folders found: {graph:?}");
    if let Some(c) = find_cycle(&graph) {
        panic!("folder cycle in src/: {}", c.join(" → "));
    }
}

#[test]
fn the_io_files_form_no_import_cycle() {
    let io = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/io");
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in rust_files(&io) {
        let rel = f.strip_prefix(&io).unwrap().with_extension("");
        let rel = rel.to_string_lossy().replace('/', "::");
        let name = rel.trim_end_matches("::mod").to_string();
        let code = code_of(&f);
        let mut refs = referenced(&code, "io::");
        // readers::X names a reader file
        for r in referenced(&code, "io::readers::") {
            refs.insert(format!("readers::{r}"));
        }
        refs.retain(|r| *r != name && *r != "readers");
        graph.entry(name).or_default().extend(refs);
    }
    assert!(graph.contains_key("imu_stream") && graph.contains_key("readers::psins"));
    if let Some(c) = find_cycle(&graph) {
        panic!("import cycle in src/io: {}", c.join(" → "));
    }
}

#[test]
fn the_command_line_files_stay_thin() {
    let cli = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/cli");
    let files = rust_files(&cli);
    assert!(files.len() >= 10, "cli files found: {files:?}");
    let fat: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let n = std::fs::read_to_string(f).unwrap().lines().count();
            (n > 400).then(|| format!("{} ({n} lines)", f.display()))
        })
        .collect();
    assert!(fat.is_empty(), "src/cli is argument handling and printing only; move computation into the library: {fat:?}");
}

/// The length in lines of each function in `text` (before any `#[cfg(test)]`), with its name
/// and first line, found by matching braces outside strings, characters and comments.
fn function_lengths(text: &str) -> Vec<(usize, usize, String)> {
    let lines: Vec<&str> = text
        .split("#[cfg(test)]")
        .next()
        .unwrap_or("")
        .lines()
        .collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let Some(name) = fn_name(lines[i]) else {
            i += 1;
            continue;
        };
        let (mut depth, mut started, mut j) = (0i64, false, i);
        while j < lines.len() {
            let code = strip_literals(lines[j]);
            for ch in code.chars() {
                match ch {
                    '{' => {
                        depth += 1;
                        started = true;
                    }
                    '}' => depth -= 1,
                    _ => {}
                }
            }
            if (started && depth == 0) || (!started && code.trim_end().ends_with(';')) {
                break;
            }
            j += 1;
        }
        if started {
            out.push((j - i + 1, i + 1, name));
            i = j + 1;
        } else {
            i += 1;
        }
    }
    out
}

/// The name of the function a line opens (`fn NAME`, with any `pub`, `const`, `unsafe`), if any.
fn fn_name(line: &str) -> Option<String> {
    let mut words = line.split_whitespace().peekable();
    while let Some(w) = words.next() {
        if w == "fn" {
            let name: String = words
                .next()?
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            return (!name.is_empty()).then_some(name);
        }
        let qualifier = w.starts_with("pub") || matches!(w, "const" | "async" | "unsafe");
        if !qualifier {
            return None;
        }
    }
    None
}

/// A line with string and character literals emptied and any `//` comment removed.
fn strip_literals(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                while let Some(d) = chars.next() {
                    if d == '\\' {
                        chars.next();
                    } else if d == '"' {
                        break;
                    }
                }
            }
            '\'' => {
                // a char literal ('x', '\n', '{'), not a lifetime ('a)
                let rest: String = chars.clone().take(3).collect();
                let mut r = rest.chars();
                match (r.next(), r.next(), r.next()) {
                    (Some('\\'), _, _) => {
                        chars.next();
                        chars.next();
                        for d in chars.by_ref() {
                            if d == '\'' {
                                break;
                            }
                        }
                    }
                    (Some(_), Some('\''), _) => {
                        chars.next();
                        chars.next();
                    }
                    _ => {}
                }
            }
            '/' if chars.peek() == Some(&'/') => break,
            _ => out.push(c),
        }
    }
    out
}

#[test]
fn the_function_length_check_measures_what_it_says() {
    let text = "pub fn a() {\n    let s = \"{\";\n    let c = '}';\n}\nfn b<'x>(v: &'x str) {\n    // {\n}\n";
    let got = function_lengths(text);
    assert_eq!(got, vec![(4, 1, "a".to_string()), (3, 5, "b".to_string())]);
}

#[test]
fn no_function_is_over_150_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut long = Vec::new();
    let mut seen = 0;
    for dir in ["src", "codegen/src"] {
        for f in rust_files(&root.join(dir)) {
            if f.components().any(|c| c.as_os_str() == "generated") {
                continue;
            }
            for (n, line, name) in function_lengths(&std::fs::read_to_string(&f).unwrap()) {
                seen += 1;
                if n > 150 {
                    long.push(format!("{}:{line} {name} ({n} lines)", f.display()));
                }
            }
        }
    }
    assert!(
        seen > 500,
        "only {seen} functions found: the scanner is broken"
    );
    assert!(long.is_empty(), "split these functions: {long:?}");
}
