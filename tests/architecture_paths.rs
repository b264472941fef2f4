//! ARCHITECTURE.md names the tree as it is: every file or folder path it spells exists.
//!
//! A path is a token of the document with a file extension (`.rs`, `.glsl`, shader stages,
//! `.md`, `.sh`, `.py`, `.toml`, ...), a folder ending in `/`, or a code span with a `/` in it
//! (prose such as "near/far" is not a path). The document writes paths from wherever its
//! sentence stands (`refocus/grid.rs` under "src/", `egl.rs` under "src/gpu/"), so a path must
//! name the end of some path of the tree. `{a,b}` expands to each choice; `<name>` stands for any
//! text within one segment, and then at least one match must exist. Paths made at run time or
//! outside the repository are listed below.

use std::path::{Path, PathBuf};

/// Tokens that are not paths of this repository: made at run time, or elsewhere.
const NOT_OURS: &[&str] = &[
    "target/",
    "../shared/",
    "out/",
    "/tmp",
    "http",
    "~/",
    "/usr/",
    "/opt/",
    "/dev/",
];

const EXTENSIONS: &[&str] = &[".rs", ".glsl", ".frag", ".vert", ".comp", ".md", ".sh", ".py", ".toml"];

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The path-like tokens of `text`.
fn tokens(text: &str) -> Vec<String> {
    let path_char = |c: char| c.is_ascii_alphanumeric() || "_-./{},<>*".contains(c);
    // Inside a code span a `/` is enough; elsewhere an extension or a closing `/` is needed. A
    // token is a slice of `text`: its byte offset tells how many backticks precede it (counted
    // once, as the tokens come in order), and an odd count puts it in a code span.
    let mut out = Vec::new();
    let (mut counted, mut backticks) = (0, 0);
    for raw in text.split(|c: char| !path_char(c)) {
        let start = raw.as_ptr() as usize - text.as_ptr() as usize;
        backticks += text[counted..start].matches('`').count();
        counted = start;
        let coded = backticks % 2 == 1;
        // Trailing sentence punctuation and list commas are not part of a path.
        let t = raw.trim_end_matches(['.', ',']).trim_start_matches(',');
        let t = t.strip_prefix("./").unwrap_or(t);
        if t.is_empty() || t.starts_with('-') || t.contains("..") && !t.starts_with("../") {
            continue;
        }
        let has_ext = EXTENSIONS.iter().any(|e| t.ends_with(e));
        let has_dir = t.contains('/') && t.chars().any(|c| c.is_ascii_alphabetic()) && (coded || t.ends_with('/'));
        if !(has_ext || has_dir) || t.contains("::") || t.starts_with('/') && !t.starts_with("/tmp") {
            continue;
        }
        // Maths and lists of names (`1/Z`, `K/N`, `PNG/JPEG`): a path's segments are words in
        // lower case (or a file name with its extension).
        let wordlike = |seg: &str| {
            seg.is_empty() || seg.len() >= 2 && (seg.contains('.') || !seg.chars().any(|c| c.is_ascii_uppercase()))
        };
        if !t.split('/').all(wordlike) {
            continue;
        }
        // Braces must balance in a path (a `{` left open is prose or code, not a path).
        if t.matches('{').count() != t.matches('}').count() || t.matches('<').count() != t.matches('>').count() {
            continue;
        }
        out.push(t.to_string());
    }
    out
}

/// `a/{b,c}.rs` -> `a/b.rs`, `a/c.rs`.
fn expand(t: &str) -> Vec<String> {
    let Some(open) = t.find('{') else {
        return vec![t.to_string()];
    };
    let close = open + t[open..].find('}').unwrap();
    t[open + 1..close]
        .split(',')
        .flat_map(|choice| expand(&format!("{}{}{}", &t[..open], choice.trim(), &t[close + 1..])))
        .collect()
}

/// Every file and folder of the repository (`target/` and `.git` left out), as path segments.
fn tree() -> Vec<Vec<String>> {
    fn walk(dir: &Path, prefix: &[String], out: &mut Vec<Vec<String>>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if prefix.is_empty() && (name == "target" || name == ".git") {
                continue;
            }
            let mut p = prefix.to_vec();
            p.push(name);
            if e.path().is_dir() {
                walk(&e.path(), &p, out);
            }
            out.push(p);
        }
    }
    let mut out = Vec::new();
    walk(&repo(), &[], &mut out);
    out
}

/// Whether `rel` names the end of some path of the tree (so `refocus/grid.rs` is
/// `src/refocus/grid.rs`); `<name>` and `*` match within one segment.
fn exists(tree: &[Vec<String>], rel: &str) -> bool {
    let want: Vec<&str> = rel.trim_end_matches('/').split('/').collect();
    tree.iter().any(|p| {
        p.len() >= want.len()
            && p[p.len() - want.len()..]
                .iter()
                .zip(&want)
                .all(|(have, w)| segment_matches(w, have))
    })
}

/// `<capability>.rs` against `refocus.rs`: literal parts in order, placeholders anything.
fn segment_matches(pattern: &str, name: &str) -> bool {
    let mut literal = String::new();
    let mut parts = Vec::new();
    let mut in_placeholder = false;
    for c in pattern.chars() {
        match c {
            '<' | '*' if !in_placeholder => {
                parts.push(std::mem::take(&mut literal));
                in_placeholder = c == '<';
            }
            '>' if in_placeholder => in_placeholder = false,
            _ if in_placeholder => {}
            _ => literal.push(c),
        }
    }
    parts.push(literal);
    let mut at = 0;
    for (i, p) in parts.iter().enumerate() {
        if i == 0 {
            if !name.starts_with(p.as_str()) {
                return false;
            }
            at = p.len();
        } else if i == parts.len() - 1 {
            return name.len() >= at + p.len() && name.ends_with(p.as_str());
        } else if let Some(found) = name[at..].find(p.as_str()) {
            at += found + p.len();
        } else {
            return false;
        }
    }
    at == name.len()
}

/// The paths of `text` that name nothing in the tree.
fn missing(text: &str) -> Vec<String> {
    let tree = tree();
    let mut out = Vec::new();
    for t in tokens(text) {
        if NOT_OURS.iter().any(|n| t.starts_with(n) || t.contains(n)) {
            continue;
        }
        for p in expand(&t) {
            if !exists(&tree, &p) {
                out.push(p);
            }
        }
    }
    out.sort();
    out.dedup();
    out
}

#[test]
fn every_path_architecture_md_names_exists() {
    let text = std::fs::read_to_string(repo().join("ARCHITECTURE.md")).unwrap();
    let gone = missing(&text);
    assert!(
        gone.is_empty(),
        "ARCHITECTURE.md names {} paths that are not in the tree:\n{}",
        gone.len(),
        gone.join("\n")
    );
}

/// The scan itself: it finds paths in prose and code spans, expands braces, matches
/// placeholders, and a path that is not there is reported.
#[test]
fn the_scan_finds_expands_and_reports() {
    assert_eq!(
        tokens("see `src/refocus/grid.rs`, and io/{a,b}.rs. Not a::b, 1.5, `1/Z`, near/far or `K/N`."),
        vec!["src/refocus/grid.rs", "io/{a,b}.rs"]
    );
    assert_eq!(expand("io/{a,b}.rs"), vec!["io/a.rs", "io/b.rs"]);
    assert!(segment_matches("<capability>.rs", "refocus.rs"));
    assert!(!segment_matches("<capability>.rs", "refocus.glsl"));
    assert!(missing("`src/lib.rs` and `refocus/` and `shaders/<capability>/`").is_empty());
    assert_eq!(missing("`src/no_such_file.rs`"), vec!["src/no_such_file.rs"]);
}
