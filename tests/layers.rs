//! The workspace's layers, held by its imports (ARCHITECTURE.md, "Crates" and "Layers inside the
//! library"). The crates: the library depends on neither the lab nor the command line, the lab
//! not on the command line. Inside each crate (`src/`, `lab/src/`, `cli/src/`) no circle between
//! files; inside the library, the layer table below.
//!
//! Every `crate::`, `super::` and `self::` path in a crate's `*.rs` is resolved to the file that defines what it names,
//! following the `use` re-exports of the modules on the way, so `crate::io::DepthMap` is an
//! import of `src/io/image/types.rs`, not of `src/io/mod.rs`. A module's own `pub use` of its
//! children is its facade, not an import. Test modules (`#[cfg(test)] mod ... { }`) are left
//! out: the layers are the library's build. Two rules, each failure naming the files:
//!
//! - no circle between files;
//! - no import from a file of a lower layer (the table below, ARCHITECTURE.md's picture) to a
//!   file of a higher one. Imports within one layer are free (the circle rule still holds),
//!   but for the capabilities: no capability's folder imports another's.
//!
//! A plain text scan (comments and string literals blanked first) rather than a Rust parser:
//! the library's imports are ordinary paths and use trees, and a path the scan cannot follow
//! is attributed to the deepest module file it reaches, never dropped.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The layers, bottom first: each row lists path prefixes under `src/` (a folder ends with
/// `/`); the longest prefix that matches a file decides its layer. Kept in step with
/// ARCHITECTURE.md's picture.
const LAYERS: &[(&str, &[&str])] = &[
    ("error", &["error.rs", "field.rs", "lib.rs", "test_data.rs"]),
    ("conventions", &["convention.rs"]),
    ("files", &["io/", "alloc.rs", "cpu_time.rs"]),
    ("maths", &["camera/", "test_rng.rs"]),
    ("data", &["depth/", "metrics.rs", "ssim.rs"]),
    ("built-in scenes", &["world/"]),
    ("pass descriptions", &["pass/"]),
    ("backends", &["gpu/", "vulkan/", "vulkan_off.rs"]),
    ("view", &["view.rs", "progress.rs"]),
    ("output", &["output.rs", "output/"]),
    ("stereo and mesh", &["stereo/", "mesh/"]),
    ("capabilities", CAPABILITIES),
    ("checking", &["compare/"]),
    ("jobs", &["job/"]),
];

/// The capabilities: peers, none importing another (what two share sits below them, in the
/// stereo and mesh layer or lower).
const CAPABILITIES: &[&str] = &["refocus/", "cyclopean/", "reproject/", "stitch/", "scene/"];

fn layer_of(file: &str) -> Option<usize> {
    let mut best: Option<(usize, usize)> = None;
    for (i, (_, prefixes)) in LAYERS.iter().enumerate() {
        for p in prefixes.iter() {
            let hit = if p.ends_with('/') {
                file.starts_with(p)
            } else {
                file == *p
            };
            if hit && best.is_none_or(|(len, _)| p.len() > len) {
                best = Some((p.len(), i));
            }
        }
    }
    best.map(|(_, i)| i)
}

/// Blanks comments, string and char literals (keeping line breaks), so paths in docs or
/// messages are not imports.
fn strip(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    if b[i] == b'\n' {
                        out.push('\n');
                    }
                    i += 1;
                }
            }
        } else if b[i] == b'r' && (b[i..].starts_with(b"r\"") || b[i..].starts_with(b"r#")) && !ident_byte_before(b, i)
        {
            let mut j = i + 1;
            let mut hashes = 0;
            while j < b.len() && b[j] == b'#' {
                hashes += 1;
                j += 1;
            }
            if j < b.len() && b[j] == b'"' {
                let close: Vec<u8> = std::iter::once(b'"').chain(std::iter::repeat_n(b'#', hashes)).collect();
                j += 1;
                while j < b.len() && !b[j..].starts_with(&close) {
                    if b[j] == b'\n' {
                        out.push('\n');
                    }
                    j += 1;
                }
                i = j + close.len();
                out.push_str("\"\"");
            } else {
                out.push(b[i] as char);
                i += 1;
            }
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                if i < b.len() && b[i] == b'\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' {
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a): only the former is blanked.
            let rest = &b[i + 1..];
            let len = if rest.first() == Some(&b'\\') {
                rest.iter().position(|&c| c == b'\'').map(|p| p + 1)
            } else if rest.len() > 1 && rest[1] == b'\'' {
                Some(2)
            } else {
                let ch = src[i + 1..].chars().next().map_or(0, char::len_utf8);
                (rest.get(ch) == Some(&b'\'')).then_some(ch + 1)
            };
            match len {
                Some(n) => {
                    out.push_str("' '");
                    i += 1 + n;
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            let ch = src[i..].chars().next().unwrap();
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

fn ident_byte_before(b: &[u8], i: usize) -> bool {
    i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')
}

/// A source file: its module path and the paths it names, each with the module it is written
/// in (inline modules change what `super` and `self` mean).
struct File {
    rel: String,
    module: Vec<String>,
    /// (module written in, path segments as written, is part of a `pub use`).
    paths: Vec<(Vec<String>, Vec<String>, bool)>,
    /// Names a `use` brings into a module: (module, name) -> absolute path.
    uses: Vec<(Vec<String>, String, Vec<String>)>,
    /// Child modules declared `#[cfg(test)] mod name;` (a file of tests, left out like an inline
    /// test module).
    test_children: Vec<Vec<String>>,
}

fn module_of(rel: &str) -> Vec<String> {
    let no_ext = rel.strip_suffix(".rs").unwrap();
    let mut parts: Vec<String> = no_ext.split('/').map(str::to_string).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Expands a use tree (`a::{b, c::d as e, f::*}`) into (full path, name it binds).
fn expand_use(tree: &str, prefix: &[String], out: &mut Vec<(Vec<String>, Option<String>)>) {
    let tree = tree.trim();
    if tree.is_empty() {
        return;
    }
    if let Some(open) = tree.find('{') {
        let head = tree[..open].trim().trim_end_matches("::");
        let mut base = prefix.to_vec();
        base.extend(head.split("::").map(|s| s.trim().to_string()).filter(|s| !s.is_empty()));
        let close = tree.rfind('}').unwrap();
        let inner = &tree[open + 1..close];
        let mut depth = 0;
        let mut start = 0;
        for (i, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand_use(&inner[start..i], &base, out);
                    start = i + 1;
                }
                _ => {}
            }
        }
        expand_use(&inner[start..], &base, out);
        return;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((p, a)) => (p.trim(), Some(a.trim().to_string())),
        None => (tree, None),
    };
    let mut full = prefix.to_vec();
    full.extend(path.split("::").map(|s| s.trim().to_string()).filter(|s| !s.is_empty()));
    let name = match full.last().map(String::as_str) {
        Some("*") => None,
        Some("self") => {
            full.pop();
            alias.or_else(|| full.last().cloned())
        }
        _ => alias.or_else(|| full.last().cloned()),
    };
    out.push((full, name));
}

fn parse(rel: &str, text: &str) -> File {
    let module = module_of(rel);
    let src = strip(text);
    let mut paths = Vec::new();
    let mut uses = Vec::new();
    // The stack of inline modules: (name, brace depth at which it closes, is a test module).
    let mut stack: Vec<(String, usize, bool)> = Vec::new();
    let mut depth = 0usize;
    let mut cfg_test_pending = false;
    let mut test_children = Vec::new();
    let chars: Vec<(usize, char)> = src.char_indices().collect();
    let mut k = 0;
    while k < chars.len() {
        let (i, c) = chars[k];
        let in_test = stack.iter().any(|s| s.2);
        let here = || {
            let mut m = module.clone();
            m.extend(stack.iter().map(|s| s.0.clone()));
            m
        };
        if c == '{' {
            depth += 1;
        } else if c == '}' {
            if stack.last().is_some_and(|s| s.1 == depth) {
                stack.pop();
            }
            depth = depth.saturating_sub(1);
        } else if c == '#' && src[i..].starts_with("#[cfg(test)]") {
            cfg_test_pending = true;
        } else if is_ident(c) && (i == 0 || !is_ident(src[..i].chars().next_back().unwrap())) {
            let end = src[i..].find(|ch: char| !is_ident(ch)).map_or(src.len(), |e| i + e);
            let word = &src[i..end];
            let rest = &src[end..];
            if word == "mod" {
                let after = rest.trim_start();
                let name_end = after.find(|ch: char| !is_ident(ch)).unwrap_or(after.len());
                let name = &after[..name_end];
                if after[name_end..].trim_start().starts_with('{') {
                    stack.push((name.to_string(), depth + 1, cfg_test_pending));
                } else if cfg_test_pending || in_test {
                    let mut child = here();
                    child.push(name.to_string());
                    test_children.push(child);
                }
                cfg_test_pending = false;
            } else if word == "use" && !in_test {
                let stmt_end = rest.find(';').map_or(src.len(), |e| end + e);
                let before = src[..i].trim_end();
                let is_pub = before.ends_with("pub") || before.ends_with(')') && before.contains("pub(");
                let tree = src[end..stmt_end].trim().trim_start_matches("::");
                let mut expanded = Vec::new();
                expand_use(tree, &[], &mut expanded);
                let m = here();
                for (full, name) in expanded {
                    if matches!(full.first().map(String::as_str), Some("crate" | "super" | "self")) {
                        let abs = absolute(&m, &full);
                        if let Some(name) = name {
                            uses.push((m.clone(), name, abs.clone()));
                        }
                        paths.push((m.clone(), full, is_pub));
                    } else if let Some(name) = name {
                        // `use child::Item` inside a module: a relative path (2018 edition),
                        // kept when its first segment is a child module (checked at resolve).
                        let mut rel_full = vec!["self".to_string()];
                        rel_full.extend(full.iter().cloned());
                        uses.push((m.clone(), name, absolute(&m, &rel_full)));
                        paths.push((m.clone(), rel_full, is_pub));
                    }
                }
                let skip_to = stmt_end;
                while k < chars.len() && chars[k].0 < skip_to {
                    k += 1;
                }
                cfg_test_pending = false;
                continue;
            } else if matches!(word, "crate" | "super" | "self") && rest.starts_with("::") && !in_test {
                let mut j = end;
                let mut segs = vec![word.to_string()];
                while src[j..].starts_with("::") {
                    let s = j + 2;
                    let e = src[s..].find(|ch: char| !is_ident(ch)).map_or(src.len(), |x| s + x);
                    if e == s {
                        break;
                    }
                    segs.push(src[s..e].to_string());
                    j = e;
                }
                paths.push((here(), segs, false));
                while k < chars.len() && chars[k].0 < j {
                    k += 1;
                }
                continue;
            } else if !matches!(word, "pub" | "cfg" | "test" | "allow" | "expect") {
                cfg_test_pending = cfg_test_pending && matches!(word, "mod");
            }
            while k < chars.len() && chars[k].0 < end {
                k += 1;
            }
            continue;
        }
        k += 1;
    }
    File {
        rel: rel.to_string(),
        module,
        paths,
        uses,
        test_children,
    }
}

/// `crate::a::b` / `super::x` / `self::y` written in module `m` -> absolute segments.
fn absolute(m: &[String], path: &[String]) -> Vec<String> {
    let mut base: Vec<String> = m.to_vec();
    let mut segs = path.iter().peekable();
    match segs.peek().map(|s| s.as_str()) {
        Some("crate") => {
            base.clear();
            segs.next();
        }
        Some("self") => {
            segs.next();
        }
        _ => {}
    }
    while segs.peek().map(|s| s.as_str()) == Some("super") {
        base.pop();
        segs.next();
    }
    base.extend(segs.cloned());
    base
}

struct Crate {
    /// module path -> file
    modules: BTreeMap<Vec<String>, String>,
    /// (module, name) -> absolute path the name stands for
    uses: BTreeMap<(Vec<String>, String), Vec<String>>,
}

impl Crate {
    fn module_of_file(&self, file: &str) -> Option<&Vec<String>> {
        self.modules.iter().find(|(_, f)| f.as_str() == file).map(|(m, _)| m)
    }

    /// The file that defines what `abs` names, following re-exports (bounded, against loops).
    fn resolve(&self, abs: &[String], hops: usize) -> Option<String> {
        let mut m: Vec<String> = Vec::new();
        for (i, seg) in abs.iter().enumerate() {
            let mut child = m.clone();
            child.push(seg.clone());
            if self.modules.contains_key(&child) {
                m = child;
                continue;
            }
            if hops < 16 {
                if let Some(target) = self.uses.get(&(m.clone(), seg.clone())) {
                    let mut next = target.clone();
                    next.extend(abs[i + 1..].iter().cloned());
                    if next != abs {
                        return self.resolve(&next, hops + 1);
                    }
                }
            }
            break;
        }
        // An item of module `m`, or of an inline module inside its file.
        let mut probe = m;
        loop {
            if let Some(f) = self.modules.get(&probe) {
                return Some(f.clone());
            }
            probe.pop()?;
        }
    }
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The file -> file import graph of the library.
fn import_graph() -> BTreeMap<String, BTreeSet<String>> {
    crate_graph("src")
}

/// The file -> file import graph of the crate whose sources are `dir` (from the repository
/// root): the library's `src`, the lab's `lab/src`, the command line's `cli/src`.
fn crate_graph(dir: &str) -> BTreeMap<String, BTreeSet<String>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut found = Vec::new();
    rust_files(&root, &mut found);
    let mut files = Vec::new();
    for p in found {
        let rel = p.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/");
        let text = fs::read_to_string(&p).unwrap();
        files.push(parse(&rel, &text));
    }
    // Files of tests (`#[cfg(test)] mod name;` and what lies below) are not the library's build.
    let test_modules: Vec<Vec<String>> = files.iter().flat_map(|f| f.test_children.clone()).collect();
    files.retain(|f| !test_modules.iter().any(|t| f.module.starts_with(t)));
    let mut krate = Crate {
        modules: BTreeMap::new(),
        uses: BTreeMap::new(),
    };
    // Files that `#[path]` brings in under another name are their own modules only through
    // that attribute; the others are where their path says.
    for f in &files {
        krate.modules.insert(f.module.clone(), f.rel.clone());
    }
    for f in &files {
        for (m, name, abs) in &f.uses {
            krate
                .uses
                .entry((m.clone(), name.clone()))
                .or_insert_with(|| abs.clone());
        }
    }
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        let edges = graph.entry(f.rel.clone()).or_default();
        for (m, path, is_pub) in &f.paths {
            let abs = absolute(m, path);
            let Some(target) = krate.resolve(&abs, 0) else { continue };
            // A module's `pub use` of what lies inside it is its facade, not an import.
            let inside = krate.module_of_file(&target).is_some_and(|t| t.starts_with(&f.module));
            if target != f.rel && !(*is_pub && inside) && f.rel != "lib.rs" {
                edges.insert(target);
            }
        }
    }
    graph
}

/// Every circle of the graph, as the strongly connected components with more than one file
/// (Tarjan).
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        t.index.insert(v, t.next);
        t.low.insert(v, t.next);
        t.next += 1;
        t.stack.push(v);
        t.on.insert(v);
        if let Some(ws) = t.g.get(v) {
            for w in ws {
                let w = w.as_str();
                if !t.index.contains_key(w) {
                    visit(t, w);
                    let lw = t.low[w];
                    let lv = t.low[v];
                    t.low.insert(v, lv.min(lw));
                } else if t.on.contains(w) {
                    let iw = t.index[w];
                    let lv = t.low[v];
                    t.low.insert(v, lv.min(iw));
                }
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on.remove(w);
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g: graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v.as_str());
        }
    }
    t.out
}

#[test]
fn no_circle_between_the_files_of_any_crate() {
    let mut all = Vec::new();
    for dir in ["src", "lab/src", "cli/src"] {
        let shown = circles_shown(&crate_graph(dir));
        if !shown.is_empty() {
            all.push(format!(
                "{} circle(s) between files under {dir}/:\n{}",
                shown.len(),
                shown.join("\n")
            ));
        }
    }
    assert!(all.is_empty(), "{}", all.join("\n"));
}

/// The crates are layers too: the library depends on neither the lab nor the command line, the
/// lab not on the command line (Cargo refuses a circle of crates, not a dependency that runs
/// up, e.g. a dev-dependency).
#[test]
fn no_crate_depends_on_one_above_it() {
    let manifest =
        |dir: &str| fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(dir).join("Cargo.toml")).unwrap();
    // A dependency on a crate above is a `name = ...` line or a path to its folder.
    let names_above = |text: &str, above: &[&str]| -> Vec<String> {
        text.lines()
            .filter(|l| {
                let l = l.trim();
                !l.starts_with('#')
                    && above.iter().any(|a| {
                        let folder = a.trim_start_matches("viewsynth-");
                        l.starts_with(&format!("{a} ="))
                            || l.contains(&format!("path = \"{folder}\""))
                            || l.contains(&format!("path = \"../{folder}\""))
                    })
            })
            .map(str::to_string)
            .collect()
    };
    assert_eq!(
        names_above(&manifest("."), &["viewsynth-lab", "viewsynth-cli"]),
        Vec::<String>::new(),
        "the library's Cargo.toml"
    );
    assert_eq!(
        names_above(&manifest("lab"), &["viewsynth-cli"]),
        Vec::<String>::new(),
        "the lab's Cargo.toml"
    );
}

/// Each circle of `graph` as its edges, "a -> b" within the circle.
fn circles_shown(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    let found = circles(graph);
    let shown: Vec<String> = found
        .iter()
        .map(|c| {
            let edges: Vec<String> = c
                .iter()
                .flat_map(|a| {
                    graph[a]
                        .iter()
                        .filter(|b| c.contains(b))
                        .map(move |b| format!("{a} -> {b}"))
                })
                .collect();
            format!("[{}]", edges.join(", "))
        })
        .collect();
    shown
}

#[test]
fn no_import_runs_from_a_lower_layer_to_a_higher_one() {
    let graph = import_graph();
    let mut unplaced = Vec::new();
    let mut upward = Vec::new();
    for (from, tos) in &graph {
        let Some(lf) = layer_of(from) else {
            unplaced.push(from.clone());
            continue;
        };
        for to in tos {
            let Some(lt) = layer_of(to) else { continue };
            if lt > lf {
                upward.push(format!("{from} ({}) -> {to} ({})", LAYERS[lf].0, LAYERS[lt].0));
            }
        }
    }
    assert!(
        unplaced.is_empty(),
        "files under src/ in no layer of the table: {unplaced:?}"
    );
    assert!(
        upward.is_empty(),
        "{} import(s) run up the layers:\n{}",
        upward.len(),
        upward.join("\n")
    );
}

/// The capabilities are peers: no file of one capability's folder imports a file of another's
/// (what they share sits below them: `stereo/`, `mesh/`, `world/`, `camera/`).
#[test]
fn no_capability_imports_another() {
    let graph = import_graph();
    let capability = |f: &str| CAPABILITIES.iter().copied().find(|c| f.starts_with(c));
    let mut across = Vec::new();
    for (from, tos) in &graph {
        for to in tos {
            if let (Some(cf), Some(ct)) = (capability(from), capability(to)) {
                if cf != ct {
                    across.push(format!("{from} -> {to}"));
                }
            }
        }
    }
    assert!(
        across.is_empty(),
        "{} import(s) from one capability to another:\n{}",
        across.len(),
        across.join("\n")
    );
}

/// The two backends are mirror images over `pass/`: each holds its API and its executor,
/// neither imports the other, and `pass/` (below both) imports neither.
#[test]
fn the_backends_are_mirror_images_over_the_pass_layer() {
    let graph = import_graph();
    let backend = |f: &str| {
        if f.starts_with("gpu/") {
            Some("gpu")
        } else if f.starts_with("vulkan/") || f == "vulkan_off.rs" {
            Some("vulkan")
        } else {
            None
        }
    };
    let mut crossing = Vec::new();
    for (from, tos) in &graph {
        for to in tos {
            let (bf, bt) = (backend(from), backend(to));
            let across = bf.is_some() && bt.is_some() && bf != bt;
            if across || (from.starts_with("pass/") && bt.is_some()) {
                crossing.push(format!("{from} -> {to}"));
            }
        }
    }
    assert!(
        crossing.is_empty(),
        "imports across the backends:\n{}",
        crossing.join("\n")
    );
    for executor in ["gpu/executor.rs", "vulkan/executor.rs"] {
        assert!(
            graph.contains_key(executor),
            "{executor} is gone: the executors sit beside their APIs"
        );
    }
}

/// The scan itself: a use tree, a re-export followed to its file, a test module left out.
#[test]
fn the_scan_resolves_use_trees_and_re_exports() {
    let f = parse(
        "io/outputs.rs",
        "//! crate::job::x in a comment\nuse super::{Encoding, file_set::{FileSet as Set}};\n\
         use crate::view::ViewOutput;\nfn f() { let s = \"crate::job::y\"; crate::depth::g(); }\n\
         #[cfg(test)]\nmod tests { use crate::job::z; }\n",
    );
    let written: Vec<Vec<String>> = f.paths.iter().map(|(m, p, _)| absolute(m, p)).collect();
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    assert_eq!(
        written,
        vec![
            s(&["io", "Encoding"]),
            s(&["io", "file_set", "FileSet"]),
            s(&["view", "ViewOutput"]),
            s(&["depth", "g"]),
        ]
    );
    let mut krate = Crate {
        modules: BTreeMap::new(),
        uses: BTreeMap::new(),
    };
    for (m, file) in [
        (vec![], "lib.rs"),
        (s(&["io"]), "io/mod.rs"),
        (s(&["io", "encoding"]), "io/encoding.rs"),
    ] {
        krate.modules.insert(m, file.to_string());
    }
    krate
        .uses
        .insert((s(&["io"]), "Encoding".into()), s(&["io", "encoding", "Encoding"]));
    assert_eq!(
        krate.resolve(&s(&["io", "Encoding"]), 0).as_deref(),
        Some("io/encoding.rs")
    );
    assert_eq!(krate.resolve(&s(&["io", "load"]), 0).as_deref(), Some("io/mod.rs"));
    // A file of tests (`#[cfg(test)] mod tests;`) is named as a test module, so it is left out;
    // a plain child module is not.
    let g = parse("gpu/mod.rs", "mod buffer;\n#[cfg(test)]\nmod tests;\n");
    assert_eq!(g.test_children, vec![s(&["gpu", "tests"])]);
}

/// Most lines a file under `src/io/` may have (issue 45): past it a file holds more than one
/// concern and is split by concern, as `files/` (out-dir, file set, staging, paths) was.
const MAX_IO_FILE_LINES: usize = 600;

/// The `src/io/` files longer than [`MAX_IO_FILE_LINES`], with their lengths.
fn io_files_over_limit(dir: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(dir, &mut files);
    files.sort();
    files
        .iter()
        .filter_map(|p| {
            let lines = fs::read_to_string(p).unwrap().lines().count();
            (lines > MAX_IO_FILE_LINES).then(|| format!("{} ({lines} lines)", p.display()))
        })
        .collect()
}

#[test]
fn no_file_under_src_io_exceeds_600_lines() {
    let over = io_files_over_limit(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src/io"));
    assert!(
        over.is_empty(),
        "files under src/io over {MAX_IO_FILE_LINES} lines (split them by concern): {}",
        over.join(", ")
    );
}
