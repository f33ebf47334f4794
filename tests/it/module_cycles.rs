//! The library's modules depend on each other one way: no cycle of `crate::`, `super::` or
//! `self::` paths between them. Each file's code outside comments and its `#[cfg(test)]`
//! part is read; a path names the deepest module it reaches; a module's own parents and
//! children do not count.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("src/ reads") {
        let p = e.expect("directory entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `crate::a::b` for `src/a/b.rs` or `src/a/b/mod.rs`.
fn module_of(src: &Path, file: &Path) -> (Vec<String>, bool) {
    let rel = file
        .strip_prefix(src)
        .expect("under src/")
        .with_extension("");
    let mut parts = vec!["crate".to_string()];
    parts.extend(rel.iter().map(|s| s.to_string_lossy().into_owned()));
    let dir = matches!(parts.last().map(String::as_str), Some("mod" | "lib"));
    if dir {
        parts.pop();
    }
    (parts, dir)
}

/// The paths in `code` that start with `crate`, `super` or `self`.
fn paths(code: &str) -> Vec<Vec<&str>> {
    let bytes = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if !code.is_char_boundary(i) {
            i += 1;
            continue;
        }
        let word_start = i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        let rest = &code[i..];
        if word_start
            && ["crate::", "super::", "self::"]
                .iter()
                .any(|p| rest.starts_with(p))
        {
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            out.push(rest[..end].split("::").filter(|s| !s.is_empty()).collect());
            i += end;
        } else {
            i += 1;
        }
    }
    out
}

/// Each module and the modules its code (outside comments and tests) names.
fn import_edges() -> BTreeMap<String, BTreeSet<String>> {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let modules: BTreeSet<String> = files
        .iter()
        .map(|f| module_of(&src, f).0.join("::"))
        .collect();
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        let (me, _) = module_of(&src, f);
        let text = std::fs::read_to_string(f).expect("source reads");
        let text = text.split("#[cfg(test)]").next().unwrap_or("");
        let code: String = text
            .lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n");
        for path in paths(&code) {
            let (mut at, rest): (Vec<String>, &[&str]) = match path[0] {
                "crate" => (vec!["crate".into()], &path[1..]),
                _ => (me.clone(), &path[..]),
            };
            let mut rest = rest;
            while let Some((first, more)) = rest.split_first() {
                match *first {
                    "super" => {
                        at.pop();
                    }
                    "self" => {}
                    _ => break,
                }
                rest = more;
            }
            let mut target = None;
            for part in rest {
                at.push(part.to_string());
                if modules.contains(&at.join("::")) {
                    target = Some(at.join("::"));
                } else {
                    break;
                }
            }
            let (Some(t), m) = (target, me.join("::")) else {
                continue;
            };
            let related =
                t == m || t.starts_with(&format!("{m}::")) || m.starts_with(&format!("{t}::"));
            if !related {
                edges.entry(m).or_default().insert(t);
            }
        }
    }
    edges
}

#[test]
fn library_modules_have_no_import_cycle() {
    let edges = import_edges();
    // A cycle: a module that reaches itself.
    let mut cycles = Vec::new();
    for start in edges.keys() {
        let mut seen = BTreeSet::new();
        let mut stack: Vec<(String, Vec<String>)> = vec![(start.clone(), vec![start.clone()])];
        while let Some((m, trail)) = stack.pop() {
            for next in edges.get(&m).into_iter().flatten() {
                if next == start {
                    cycles.push(trail.join(" -> ") + " -> " + start);
                } else if seen.insert(next.clone()) {
                    let mut t = trail.clone();
                    t.push(next.clone());
                    stack.push((next.clone(), t));
                }
            }
        }
    }
    assert!(cycles.is_empty(), "import cycles:\n{}", cycles.join("\n"));
    // The reading found the library's structure at all.
    assert!(edges
        .get("crate::render::lighting")
        .is_some_and(|e| e.contains("crate::render::visibility")));
}

#[test]
fn the_scene_builder_imports_nothing_of_the_expander() {
    // Lowering is two halves: the expander (DEF/USE, PROTO, Inline, ...) drives the scene
    // builder, never the other way round.
    let edges = import_edges();
    let builder = "crate::vrml::lower::build";
    let expander = "crate::vrml::lower::expand";
    let mut wrong = Vec::new();
    for (m, targets) in &edges {
        if m == builder || m.starts_with(&format!("{builder}::")) {
            for t in targets {
                if t == expander || t.starts_with(&format!("{expander}::")) {
                    wrong.push(format!("{m} -> {t}"));
                }
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "the builder imports the expander:\n{}",
        wrong.join("\n")
    );
    // The reading found both halves and the way between them.
    assert!(edges
        .get("crate::vrml::lower::build::fields")
        .is_some_and(|e| e.contains("crate::vrml::lower::context")));
    assert!(edges
        .get("crate::vrml::lower::expand::dispatch")
        .is_some_and(|e| e.contains("crate::vrml::lower::build")));
}
