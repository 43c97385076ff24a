//! The layout as the crates' maps state it (fog-core's and fog-sim's `lib.rs`, diagnose's
//! `mod.rs`), read from the code's own imports: no file circle in either crate, and no
//! import from a folder to one above it in its map. A circle between two files came back
//! once in a review mend (2026-12-03); this is the guard.
//!
//! An import is every `crate::`, `super::` and `self::` path outside `#[cfg(test)]` items
//! (tests may reach anywhere), resolved to the longest module path that is a file. A
//! `pub use` in a `mod.rs` of its own folder's files is the folder's face, not a
//! dependency of the folder on its files, and is left out, as are `mod` declarations.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module path of each source file of a crate (`src/a/b.rs` and `src/a/b/mod.rs` are
/// `[a, b]`; `lib.rs` is `[]`).
fn modules(src: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    walk(src, &mut files);
    files
        .into_iter()
        .filter_map(|p| {
            let rel = p.strip_prefix(src).unwrap().with_extension("");
            let mut parts: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if parts.first().is_some_and(|p| p == "bin") {
                return None;
            }
            if parts
                .last()
                .is_some_and(|l| l == "mod" || l == "lib" || l == "main")
            {
                parts.pop();
            }
            Some((parts, p))
        })
        .collect()
}

/// The source without comments and without its `#[cfg(test)]` items (the attribute and the
/// item after it: a `mod x;` line, or everything up to the brace that closes the item).
fn code_of(text: &str) -> String {
    let code: String = text
        .lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n");
    let mut out = String::with_capacity(code.len());
    let mut rest = code.as_str();
    while let Some(i) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..i]);
        let item = &rest[i + "#[cfg(test)]".len()..];
        let (semi, open) = (item.find(';'), item.find('{'));
        let end = match (semi, open) {
            (Some(s), o) if o.is_none_or(|o| s < o) => s + 1,
            (_, Some(o)) => {
                let mut depth = 0usize;
                let mut close = item.len();
                for (k, ch) in item[o..].char_indices() {
                    match ch {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                close = o + k + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                close
            }
            _ => item.len(),
        };
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}

/// Expands a use tree (`a::{b, c::{d, e}}`) into its paths.
fn expand(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        return vec![tree.split(" as ").next().unwrap().trim().to_owned()];
    };
    let prefix = &tree[..open];
    let close = tree.rfind('}').filter(|&c| c > open).unwrap_or(tree.len());
    let inner = &tree[open + 1..close];
    let (mut depth, mut start, mut out) = (0, 0, Vec::new());
    let push = |part: &str, out: &mut Vec<String>| {
        for p in expand(part) {
            if !p.is_empty() {
                out.push(if p == "self" {
                    prefix.trim_end_matches("::").to_owned()
                } else {
                    format!("{prefix}{p}")
                });
            }
        }
    };
    for (i, ch) in inner.char_indices() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                push(&inner[start..i], &mut out);
                start = i + 1;
            }
            _ => {}
        }
    }
    push(&inner[start..], &mut out);
    out
}

/// The imports of one file as (path words, is a `pub use`).
fn import_paths(code: &str) -> Vec<(Vec<String>, bool)> {
    let mut out = Vec::new();
    // `use` statements: a line that starts one, up to its `;`.
    let lines: Vec<&str> = code.lines().collect();
    let mut in_use = vec![false; lines.len()];
    for (i, line) in lines.iter().enumerate() {
        let t = line.trim_start();
        let (public, body) = if let Some(b) = t.strip_prefix("use ") {
            (false, b)
        } else if let Some(b) = t.strip_prefix("pub use ") {
            (true, b)
        } else if let Some(b) = t
            .strip_prefix("pub(crate) use ")
            .or(t.strip_prefix("pub(super) use "))
        {
            (true, b)
        } else {
            continue;
        };
        let mut stmt = body.to_owned();
        let mut k = i + 1;
        while !stmt.contains(';') && k < lines.len() {
            stmt.push_str(lines[k]);
            k += 1;
        }
        in_use[i..k].iter_mut().for_each(|u| *u = true);
        let stmt = stmt.split(';').next().unwrap_or("");
        for p in expand(stmt) {
            out.push((words(&p), public));
        }
    }
    // Paths written inline in the code (`crate::io::guard::create_dir(...)`), outside the
    // `use` statements read above (a `pub use` read again here would lose its `pub`).
    let rest: Vec<&str> = lines
        .iter()
        .zip(&in_use)
        .filter(|(_, u)| !**u)
        .map(|(l, _)| *l)
        .collect();
    let code = rest.join("\n");
    let code = code.as_str();
    let bytes = code.as_bytes();
    for root in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(k) = code[from..].find(root) {
            let s = from + k;
            from = s + root.len();
            if s > 0
                && (bytes[s - 1].is_ascii_alphanumeric()
                    || bytes[s - 1] == b'_'
                    || bytes[s - 1] == b':')
            {
                continue;
            }
            let end = code[s..]
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .map_or(code.len(), |e| s + e);
            out.push((words(&code[s..end]), false));
        }
    }
    out
}

fn words(path: &str) -> Vec<String> {
    path.split("::")
        .map(|w| w.trim().to_owned())
        .filter(|w| !w.is_empty())
        .collect()
}

/// The file an import path leads to: the longest module prefix that is a file.
fn resolve(
    from: &[String],
    path: &[String],
    files: &BTreeMap<Vec<String>, PathBuf>,
) -> Option<Vec<String>> {
    // The module the path starts from.
    let mut base: Vec<String> = from.to_vec();
    let mut rest = path;
    match rest.first().map(String::as_str) {
        Some("crate") => {
            base.clear();
            rest = &rest[1..];
        }
        Some("super") | Some("self") => {
            // `self` in a.rs is module a, `super` its parent (a mod.rs is its folder's
            // module, so the same rule holds for it).
            while let Some(w) = rest.first() {
                match w.as_str() {
                    "super" => {
                        base.pop()?;
                    }
                    "self" => {}
                    _ => break,
                }
                rest = &rest[1..];
            }
        }
        _ => return None,
    }
    let mut full = base;
    full.extend(rest.iter().cloned());
    (0..=full.len())
        .rev()
        .map(|n| full[..n].to_vec())
        .find(|m| files.contains_key(m))
}

/// The file-to-file imports of a crate.
fn graph(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let files = modules(src);
    let mut g = BTreeMap::new();
    for (module, path) in &files {
        let is_mod = path.file_name().is_some_and(|n| n == "mod.rs");
        let code = code_of(&std::fs::read_to_string(path).unwrap());
        let mut to = BTreeSet::new();
        for (p, public) in import_paths(&code) {
            let Some(target) = resolve(module, &p, &files) else {
                continue;
            };
            let facade = public && is_mod && target.starts_with(module);
            if target != *module && !facade && !target.is_empty() {
                to.insert(target);
            }
        }
        g.insert(module.clone(), to);
    }
    g
}

/// Every file circle (as one file in it and the path back to it).
fn circles(g: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<String> {
    let mut found = Vec::new();
    for start in g.keys() {
        // Depth-first search from `start` for a path back to `start`.
        let mut stack = vec![(start.clone(), vec![start.join("/")])];
        let mut seen = BTreeSet::new();
        while let Some((node, trail)) = stack.pop() {
            for next in g.get(&node).into_iter().flatten() {
                if next == start {
                    found.push(format!("{} -> {}", trail.join(" -> "), start.join("/")));
                } else if seen.insert(next.clone()) {
                    let mut t = trail.clone();
                    t.push(next.join("/"));
                    stack.push((next.clone(), t));
                }
            }
        }
    }
    found
}

/// Imports from a module to one ranked above it: `ranks` maps a module prefix to its floor.
fn imports_up(
    g: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
    within: &[&str],
    ranks: &[(&str, u32)],
) -> Vec<String> {
    let rank = |m: &[String]| -> Option<u32> {
        let m = m.strip_prefix(&within.iter().map(|s| s.to_string()).collect::<Vec<_>>()[..])?;
        let first = m.first()?;
        ranks.iter().find(|(n, _)| n == first).map(|(_, r)| *r)
    };
    let mut up = Vec::new();
    for (from, tos) in g {
        let Some(rf) = rank(from) else { continue };
        for to in tos {
            if let Some(rt) = rank(to) {
                if rt > rf {
                    up.push(format!("{} -> {}", from.join("/"), to.join("/")));
                }
            }
        }
    }
    up
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

#[test]
fn no_file_circle_in_either_crate() {
    for krate in ["core/src", "host-sim/src"] {
        let g = graph(&root().join(krate));
        assert!(g.len() > 20, "{krate}: only {} files read", g.len());
        let c = circles(&g);
        assert!(c.is_empty(), "{krate}: file circles:\n{}", c.join("\n"));
    }
}

/// fog-core's map (core/src/lib.rs): root files, model, compensation, seeking, links.
const CORE_FLOORS: &[(&str, u32)] = &[
    ("hal", 0),
    ("consts", 0),
    ("numeric", 0),
    ("model", 1),
    ("compensation", 2),
    ("seeking", 3),
    ("link", 4),
    ("sensor_link", 4),
];
/// fog-sim's map (host-sim/src/lib.rs).
const SIM_FLOORS: &[(&str, u32)] = &[
    ("stats", 0),
    ("seed", 0),
    ("fanout", 0),
    ("io", 1),
    ("output", 2),
    ("registry", 3),
    ("sim", 4),
    ("train", 4),
    ("diagnose", 4),
    ("device", 5),
    ("pipeline", 6),
    ("cmd", 7),
];
/// diagnose's chain of stages (host-sim/src/diagnose/mod.rs).
const DIAGNOSE_FLOORS: &[(&str, u32)] = &[
    ("error", 0),
    ("linalg", 0),
    ("validation", 1),
    ("input", 2),
    ("baseline", 3),
    ("candidates", 4),
    ("selection", 5),
    ("between_runs", 6),
    ("sim_fit", 7),
    ("uncertainty", 8),
    ("report", 9),
];

#[test]
fn no_import_runs_up_a_layer() {
    let core = graph(&root().join("core/src"));
    let sim = graph(&root().join("host-sim/src"));
    for (what, g, within, floors) in [
        ("fog-core", &core, &[][..], CORE_FLOORS),
        ("fog-sim", &sim, &[][..], SIM_FLOORS),
        ("diagnose", &sim, &["diagnose"][..], DIAGNOSE_FLOORS),
    ] {
        let up = imports_up(g, within, floors);
        assert!(
            up.is_empty(),
            "{what} imports up a layer:\n{}",
            up.join("\n")
        );
    }
}

#[test]
fn the_reader_sees_a_planted_circle_and_an_import_up() {
    // The guard's own check: a circle and an upward import written into a scratch crate.
    let dir = std::env::temp_dir().join(format!("fog-layout-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("low")).unwrap();
    std::fs::create_dir_all(dir.join("high")).unwrap();
    std::fs::write(dir.join("lib.rs"), "pub mod low;\npub mod high;\n").unwrap();
    std::fs::write(
        dir.join("low/mod.rs"),
        "pub mod a;\npub mod b;\npub use a::A;\npub use crate::low::b::B;\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("low/a.rs"),
        "use super::b::{B, other::{X as Y}};\npub struct A;\n#[cfg(test)]\nmod tests { use crate::high::H; }\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("low/b.rs"),
        "pub struct B;\n#[cfg(test)]\nfn only_in_tests() { let _ = crate::high::H; }\nfn f() { let _ = crate::low::a::A; let _ = crate::high::h::H; let _ = crate::low::A; }\n",
    )
    .unwrap();
    std::fs::write(dir.join("high/mod.rs"), "pub mod h;\n").unwrap();
    std::fs::write(dir.join("high/h.rs"), "use crate::low::A;\npub struct H;\n").unwrap();
    let g = graph(&dir);
    let c = circles(&g);
    assert!(
        c.iter().any(|c| c.contains("low/a") && c.contains("low/b")),
        "{c:?}"
    );
    // `low/mod.rs` re-exports `b` (a facade), and `b` uses the facade: no circle.
    assert!(!c.iter().any(|c| c.starts_with("low ->")), "{c:?}");
    let up = imports_up(&g, &[], &[("low", 0), ("high", 1)]);
    assert_eq!(up, ["low/b -> high/h"], "{g:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
