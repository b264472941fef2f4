//! The field table (`src/field.rs`) against tests/data/front_ends.json, the table of each
//! command's request fields with the option and keyword that fill each: a field both name has
//! the same option and the same keyword in both, so the spellings cannot drift apart.

use serde_json::Value;
use std::collections::BTreeMap;
use viewsynth::Field;

/// Every command's request fields in front_ends.json: command -> field key -> entry.
fn front_ends() -> BTreeMap<String, BTreeMap<String, Value>> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/front_ends.json");
    let json: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    json.as_object()
        .unwrap()
        .iter()
        .filter_map(|(command, v)| {
            let fields = v.get("fields")?.as_object()?;
            Some((
                command.clone(),
                fields.iter().map(|(k, e)| (k.clone(), e.clone())).collect(),
            ))
        })
        .collect()
}

/// The options an entry's command line gives (its `cli` words that are options).
fn options(entry: &Value) -> Vec<&str> {
    entry["cli"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(Value::as_str)
        .filter(|w| w.starts_with("--"))
        .collect()
}

#[test]
fn each_field_is_spelled_as_front_ends_json_spells_it() {
    let commands = front_ends();
    let mut checked = 0;
    for &field in Field::ALL {
        for (command, fields) in &commands {
            let Some(entry) = fields.get(field.key()) else { continue };
            checked += 1;
            assert!(
                options(entry).contains(&field.cli()),
                "{command}.{}: front_ends.json fills it with {:?}, the field table with {}",
                field.key(),
                entry["cli"],
                field.cli()
            );
            if let Some(keyword) = entry["python"].as_str() {
                assert_eq!(
                    keyword,
                    field.python(),
                    "{command}.{}: front_ends.json's keyword against the field table's",
                    field.key()
                );
            }
        }
    }
    // Most of the table is there: a renamed key would silently skip its row.
    assert!(checked >= 60, "only {checked} (command, field) pairs checked");
}

#[test]
fn each_option_of_front_ends_json_has_its_fields_key() {
    // The other way round: the option that fills a field in front_ends.json (the first of
    // its command line; the others are partners, as `--baseline` with `--focal`) is in the
    // table, filling that same field (`--zoom-range` is `scales`'s).
    for (command, fields) in front_ends() {
        for (key, entry) in &fields {
            let option = options(entry)[0];
            let field = Field::ALL.iter().find(|f| f.cli() == option);
            let field = field.unwrap_or_else(|| panic!("{command}.{key}: the field table lacks {option}"));
            assert_eq!(field.key(), key, "{command}: {option} fills {key} in front_ends.json");
        }
    }
}

#[test]
fn no_two_fields_are_one_option() {
    for (i, a) in Field::ALL.iter().enumerate() {
        for b in &Field::ALL[i + 1..] {
            assert_ne!(a.cli(), b.cli(), "two fields are one option");
        }
    }
}

/// The string literals of `src` (not comments, not doc comments), each with its line.
fn string_literals(src: &str) -> Vec<(usize, String)> {
    let b = src.as_bytes();
    let (mut i, mut line, mut out) = (0, 1, Vec::new());
    let skip_to = |from: usize, end: &[u8]| {
        b[from..]
            .windows(end.len())
            .position(|w| w == end)
            .map_or(b.len(), |p| from + p + end.len())
    };
    while i < b.len() {
        let start = i;
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => i = skip_to(i, b"\n") - 1,
            b'/' if b.get(i + 1) == Some(&b'*') => i = skip_to(i, b"*/"),
            b'\'' => {
                // A char literal ('x', '\n', '"'), else a lifetime.
                let close = if b.get(i + 1) == Some(&b'\\') {
                    b[i + 2..].iter().position(|&c| c == b'\'').map(|p| i + 2 + p)
                } else {
                    src[i + 1..]
                        .chars()
                        .next()
                        .map(|c| i + 1 + c.len_utf8())
                        .filter(|&j| b.get(j) == Some(&b'\''))
                };
                i = close.map_or(i + 1, |j| j + 1);
            }
            b'r' | b'b' if !b[..i].last().is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_') => {
                let mut j = i + 1;
                if b[i] == b'b' && b.get(j) == Some(&b'r') {
                    j += 1;
                }
                let hashes = b[j..].iter().take_while(|&&c| c == b'#').count();
                if b.get(j + hashes) == Some(&b'"') && (b[i] == b'r' || j > i + 1 || hashes == 0) {
                    let mut end = vec![b'"'];
                    end.extend(std::iter::repeat_n(b'#', hashes));
                    let body = j + hashes + 1;
                    i = skip_to(body, &end);
                    if b[start] == b'r' {
                        out.push((line, src[body..i - end.len()].to_string()));
                    }
                } else {
                    i += 1;
                }
            }
            b'"' => {
                let mut j = i + 1;
                while b[j] != b'"' {
                    j += if b[j] == b'\\' { 2 } else { 1 };
                }
                out.push((line, src[i + 1..j].to_string()));
                i = j + 1;
            }
            _ => i += 1,
        }
        line += b[start..i.max(start + 1)].iter().filter(|&&c| c == b'\n').count();
    }
    out
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Literals that spell `--` before a lowercase letter and stay text: (file under src/, text
/// the literal holds, why). Each is a genuine non-option use, or an error that names a file,
/// whose message stays plain text (its path is the subject; the front ends print it as is).
const NOT_FIELDS: &[(&str, &str, &str)] = &[
    (
        "job/host.rs",
        "`viewsynth info --backend vulkan`",
        "a shell command to run",
    ),
    (
        "refocus/batch/index.rs",
        "run refocus --batch into it",
        "a shell command to run",
    ),
    ("gpu/policy.rs", "--gpus all", "Docker's option"),
    ("vulkan/devices.rs", "--gpus all", "Docker's option"),
    ("vulkan_off.rs", "--no-default-features", "cargo's option"),
    (
        "io/depth/file.rs",
        "with --depth-scale",
        "a depth file's error (Error::Decode)",
    ),
    (
        "io/depth/file.rs",
        "depth needs --depth-scale",
        "a depth file's error (Error::Decode)",
    ),
    (
        "io/files/input.rs",
        "(--max-pixels; refused",
        "an input file's error (Error::Decode)",
    ),
    (
        "io/files/out_dir.rs",
        "another --out-dir",
        "the output folder's error (Error::Io)",
    ),
    (
        "io/files/out_dir.rs",
        "inside --out-dir",
        "the output folder's error (Error::Io)",
    ),
    (
        "io/formats/decode.rs",
        "--max-pixels",
        "an image file's error (Error::Decode)",
    ),
    (
        "io/formats/exr.rs",
        "--max-pixels",
        "an EXR file's error (Error::Decode)",
    ),
    (
        "io/formats/npy.rs",
        "--max-pixels",
        "an NPY file's error (Error::Decode)",
    ),
    ("io/formats/npz.rs", "--npz-key", "an NPZ file's error (Error::Decode)"),
    (
        "refocus/batch/manifest.rs",
        "--fx/--fy/--cx/--cy",
        "the manifest file's error (Error::Decode)",
    ),
    (
        "refocus/batch/manifest.rs",
        "or --intrinsics)",
        "the manifest file's error (Error::Decode)",
    ),
    (
        "camera/intrinsics_file.rs",
        "give --fx/--fy/--cx/--cy",
        "the intrinsics file's error (Error::Decode)",
    ),
    (
        "refocus/batch/manifest.rs",
        "--shard runs",
        "the manifest file's error (Error::Decode)",
    ),
    (
        "job/reproject/mod.rs",
        "(check --depth-kind, --depth-scale",
        "how the depth file was read, for its Error::Decode",
    ),
    // Not converted yet: the Vulkan backend's errors are text (Error::Vulkan(String)).
    ("gpu/devices.rs", "--gpus all", "Docker's option"),
    (
        "vulkan/pipeline.rs",
        "--ndc vulkan",
        "not converted yet: Error::Vulkan holds text",
    ),
];

/// A library message that spells an option literally (`"--tau-rel"`) instead of naming its
/// [`Field`]: the command line would show it, and Python would show a flag it has no keyword
/// for. Test code (`#[cfg(test)]` modules at a file's end, `*_tests.rs`) checks the command
/// line's text and is left out.
#[test]
fn no_library_message_spells_an_option() {
    // Another tree's src/ may be scanned instead (VIEWSYNTH_SCAN_SRC), to compare before/after.
    let root = std::env::var_os("VIEWSYNTH_SCAN_SRC")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/src").into());
    let root = root.as_path();
    let mut files = Vec::new();
    rust_files(root, &mut files);
    files.sort();
    let flag = |text: &str| {
        text.match_indices("--")
            .any(|(at, _)| text[at + 2..].starts_with(|c: char| c.is_ascii_lowercase()))
    };
    let mut found = Vec::new();
    for path in files {
        let rel = path.strip_prefix(root).unwrap().to_string_lossy().to_string();
        if rel == "field.rs" || rel.ends_with("_tests.rs") || rel.contains("/tests/") {
            continue;
        }
        let src = std::fs::read_to_string(&path).unwrap();
        let code = src.split("#[cfg(test)]\nmod ").next().unwrap();
        for (line, text) in string_literals(code) {
            let allowed = NOT_FIELDS
                .iter()
                .any(|(file, holds, _)| *file == rel && text.contains(holds));
            if flag(&text) && !allowed {
                found.push(format!("src/{rel}:{line}: \"{text}\""));
            }
        }
    }
    assert!(
        found.is_empty(),
        "{} literals spell an option; name it by its viewsynth::Field instead (msg![...]):\n{}",
        found.len(),
        found.join("\n")
    );
}

#[test]
fn the_scan_sees_literals_and_not_comments() {
    let src = "// \"--a\"\n/// `--b`\nlet s = \"--c\"; let c = '\"'; let r = r#\"--d\"#;\n/* \"--e\" */ f(\"x\\\"--g\");\nfn f<'a>(x: &'a str) -> &'a str { \"--h\" }";
    let texts: Vec<_> = string_literals(src).into_iter().collect();
    assert_eq!(
        texts,
        [
            (3, "--c".to_string()),
            (3, "--d".to_string()),
            (4, "x\\\"--g".to_string()),
            (5, "--h".to_string())
        ]
    );
}
