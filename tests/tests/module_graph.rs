//! The module graph of `curbtrace-core` and `curbtrace-host-sim` has no cycles, and every
//! import follows the flow of data (`docs/architecture.md`): a module imports only from its
//! own layer or the layers below it.
//!
//! The graph is read from the sources: every `crate::…` and `super::…` path outside the
//! test module at the bottom of a file is an edge from that file's module to the deepest
//! module the path names. Edges between a module and its own descendants (a folder's
//! `mod.rs` and its files) are part of the module's inside and are not checked; cycles
//! between sibling or cousin modules are.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module path such as `["bend", "track"]` (the crate root is `[]`).
type ModPath = Vec<String>;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every `.rs` file under `src` (except the binary's `main.rs` and `bin/`) and its module path.
fn modules(src: &Path) -> BTreeMap<ModPath, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).expect("read source dir") {
            let p = e.expect("dir entry").path();
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n == "bin") {
                    continue;
                }
                stack.push(p);
                continue;
            }
            if p.extension().is_none_or(|x| x != "rs") {
                continue;
            }
            let rel = p.strip_prefix(src).expect("under src");
            let mut parts: ModPath = rel
                .iter()
                .map(|c| c.to_string_lossy().trim_end_matches(".rs").to_string())
                .collect();
            match parts.last().map(String::as_str) {
                Some("main") if parts.len() == 1 => continue,
                Some("lib") if parts.len() == 1 => parts.clear(),
                Some("mod") => {
                    parts.pop();
                }
                _ => {}
            }
            out.insert(parts, p);
        }
    }
    out
}

/// The source without the trailing `#[cfg(test)] mod tests { … }` block.
fn product_part(text: &str) -> &str {
    let mut cut = text.len();
    let lines: Vec<(usize, &str)> = text
        .lines()
        .scan(0usize, |off, l| {
            let start = *off;
            *off += l.len() + 1;
            Some((start, l))
        })
        .collect();
    for w in lines.windows(2) {
        if w[0].1.trim() == "#[cfg(test)]" && w[1].1.trim_start().starts_with("mod tests") {
            cut = w[0].0;
            break;
        }
    }
    &text[..cut]
}

/// Strips `//` comments (doc comments mention paths that are not imports).
fn code_only(text: &str) -> String {
    text.lines()
        .map(|l| match l.find("//") {
            Some(k) => &l[..k],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Expands a `use` tree (`a::{b, c::{d, e}}`) into full paths.
fn expand_use(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let Some(open) = tree.find('{') else {
        return vec![tree.split(" as ").next().unwrap_or(&tree).to_string()];
    };
    let prefix = &tree[..open];
    let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
    let mut parts = Vec::new();
    let (mut depth, mut start) = (0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .filter(|p| !p.is_empty())
        .flat_map(|p| {
            if p == "self" {
                vec![prefix.trim_end_matches("::").to_string()]
            } else {
                expand_use(&format!("{prefix}{p}"))
            }
        })
        .collect()
}

/// Every `crate::`/`super::` path in the code: from `use` trees and from paths in
/// expressions and types.
fn paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(k) = rest.find("use ") {
        let before_ok = k == 0 || !rest.as_bytes()[k - 1].is_ascii_alphanumeric();
        let after = &rest[k + 4..];
        if before_ok {
            if let Some(end) = after.find(';') {
                let tree = &after[..end];
                if tree.trim_start().starts_with("crate::")
                    || tree.trim_start().starts_with("super::")
                {
                    out.extend(expand_use(tree));
                }
            }
        }
        rest = after;
    }
    for start in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(k) = code[from..].find(start) {
            let at = from + k;
            from = at + start.len();
            if at > 0 {
                let b = code.as_bytes()[at - 1];
                if b.is_ascii_alphanumeric() || b == b'_' || b == b':' {
                    continue;
                }
            }
            let path: String = code[at..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            out.push(path);
        }
    }
    out
}

/// The module a path names, resolved against the module `from` (file `is_dir_mod` when it
/// is a folder's `mod.rs` or the crate root): the deepest existing module on the path.
fn resolve(
    path: &str,
    from: &ModPath,
    is_dir_mod: bool,
    known: &BTreeMap<ModPath, PathBuf>,
) -> Option<ModPath> {
    let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let mut base: ModPath;
    let mut i = 0;
    if segs.first() == Some(&"crate") {
        base = Vec::new();
        i = 1;
    } else {
        // `super` in a file module is its parent; in a folder's mod.rs the folder's parent.
        base = from.clone();
        let _ = is_dir_mod;
        while segs.get(i) == Some(&"super") {
            base.pop()?;
            i += 1;
        }
    }
    for s in &segs[i..] {
        let mut next = base.clone();
        next.push((*s).to_string());
        if known.contains_key(&next) {
            base = next;
        } else {
            break;
        }
    }
    Some(base)
}

fn is_prefix(a: &ModPath, b: &ModPath) -> bool {
    a.len() <= b.len() && a[..] == b[..a.len()]
}

/// Edges between modules that are not ancestor and descendant of each other.
fn graph(src: &Path) -> BTreeMap<ModPath, BTreeSet<ModPath>> {
    let known = modules(src);
    let mut g: BTreeMap<ModPath, BTreeSet<ModPath>> = BTreeMap::new();
    for (m, file) in &known {
        let text = std::fs::read_to_string(file).expect("read source");
        let code = code_only(product_part(&text));
        let dir_mod = file
            .file_name()
            .is_some_and(|n| n == "mod.rs" || n == "lib.rs");
        let entry = g.entry(m.clone()).or_default();
        for p in paths(&code) {
            if let Some(t) = resolve(&p, m, dir_mod, &known) {
                if !is_prefix(&t, m) && !is_prefix(m, &t) {
                    entry.insert(t);
                }
            }
        }
    }
    g
}

/// The strongly connected components with more than one module (Tarjan).
fn cycles(g: &BTreeMap<ModPath, BTreeSet<ModPath>>) -> Vec<Vec<ModPath>> {
    struct T<'a> {
        g: &'a BTreeMap<ModPath, BTreeSet<ModPath>>,
        index: BTreeMap<&'a ModPath, usize>,
        low: BTreeMap<&'a ModPath, usize>,
        stack: Vec<&'a ModPath>,
        on: BTreeSet<&'a ModPath>,
        next: usize,
        out: Vec<Vec<ModPath>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a ModPath) {
        t.index.insert(v, t.next);
        t.low.insert(v, t.next);
        t.next += 1;
        t.stack.push(v);
        t.on.insert(v);
        if let Some(ws) = t.g.get(v) {
            for w in ws {
                let Some((w, _)) = t.g.get_key_value(w) else {
                    continue;
                };
                if !t.index.contains_key(w) {
                    visit(t, w);
                    let l = t.low[v].min(t.low[w]);
                    t.low.insert(v, l);
                } else if t.on.contains(w) {
                    let l = t.low[v].min(t.index[w]);
                    t.low.insert(v, l);
                }
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                comp.push(w.clone());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v) {
            visit(&mut t, v);
        }
    }
    t.out
}

fn show(m: &ModPath) -> String {
    if m.is_empty() {
        "crate".into()
    } else {
        m.join("::")
    }
}

/// Checks the crate under `src` against `layers` (top-level module → layer number; a module
/// may import from layers up to its own). Top-level modules missing from the table fail the
/// test, so a new module is placed consciously.
fn check(src: &str, layers: &[(&str, u32)]) {
    let src = root().join(src);
    let g = graph(&src);
    let mut problems = Vec::new();
    for c in cycles(&g) {
        let names: Vec<String> = c.iter().map(show).collect();
        problems.push(format!("import cycle: {}", names.join(" <-> ")));
    }
    let layer = |m: &ModPath| -> Option<u32> {
        let top = m.first()?;
        layers.iter().find(|(n, _)| n == top).map(|&(_, l)| l)
    };
    for m in g.keys() {
        if !m.is_empty() && layer(m).is_none() {
            problems.push(format!("module {} is not in the layer table", show(m)));
        }
    }
    for (from, tos) in &g {
        let Some(lf) = layer(from) else { continue };
        for to in tos {
            if let Some(lt) = layer(to) {
                if lt > lf {
                    problems.push(format!(
                        "{} (layer {lf}) imports {} (layer {lt}): against the flow of data",
                        show(from),
                        show(to)
                    ));
                }
            }
        }
    }
    assert!(
        problems.is_empty(),
        "{}:\n{}",
        src.display(),
        problems.join("\n")
    );
}

#[test]
fn the_core_has_no_cycle_and_imports_downwards() {
    check(
        "core/src",
        &[
            ("math", 0),
            ("wire", 1),
            ("scanline", 2),
            ("kernel", 3),
            ("pipeline", 4),
        ],
    );
}

#[test]
fn the_host_has_no_cycle_and_imports_downwards() {
    check(
        "host-sim/src",
        &[
            ("model", 0),
            ("proc_stats", 0),
            ("io", 1),
            ("source", 1),
            ("replay", 2),
            ("rings", 2),
            ("mounts", 2),
            ("bend", 3),
            ("frame", 3),
            ("qiu", 3),
            ("curb", 4),
            ("config", 4),
            ("output", 4),
            ("pipeline", 5),
            ("stream", 5),
            ("simulate", 6),
            ("plot", 6),
            ("eval", 7),
            ("cli", 8),
        ],
    );
}

#[test]
fn the_check_finds_a_cycle_and_a_back_arrow() {
    let dir = tempfile::tempdir().expect("tempdir");
    let src = dir.path();
    std::fs::create_dir_all(src.join("a")).expect("mkdir");
    std::fs::write(src.join("lib.rs"), "pub mod a;\npub mod b;\n").expect("write");
    std::fs::write(src.join("a/mod.rs"), "pub mod x;\npub mod y;\n").expect("write");
    std::fs::write(src.join("a/x.rs"), "use super::y::Y;\npub struct X;\n").expect("write");
    std::fs::write(src.join("a/y.rs"), "use crate::a::x::X;\npub struct Y;\n").expect("write");
    std::fs::write(src.join("b.rs"), "pub fn f() { crate::a::x::X; }\n").expect("write");
    let g = graph(src);
    let c = cycles(&g);
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(c[0].len(), 2);
    assert!(g[&vec!["b".to_string()]].contains(&vec!["a".to_string(), "x".to_string()]));
    // The same path inside the test module at the bottom is not an edge.
    std::fs::write(
        src.join("b.rs"),
        "pub fn f() {}\n#[cfg(test)]\nmod tests {\n    use crate::a::x::X;\n}\n",
    )
    .expect("write");
    assert!(graph(src)[&vec!["b".to_string()]].is_empty());
}
