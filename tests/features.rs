//! The library's cargo features as its other workspaces select them: `compare` (and with it
//! nv-flip's C++) builds into the command line only, never into the Python extension or the
//! fuzz targets (issue 45).
//!
//! A read of the manifests rather than `cargo tree` on them: the Python and fuzz workspaces'
//! own dependencies (pyo3, libfuzzer-sys) need not be downloaded where the library is tested.
//! `ci/python-tests.sh` also asks `cargo tree` of the Python extension once they are.

use std::collections::BTreeSet;
use std::path::Path;

fn manifest(relative: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(relative);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The lines of `[section]` (up to the next section header).
fn section<'a>(toml: &'a str, name: &str) -> Vec<&'a str> {
    let header = format!("[{name}]");
    toml.lines()
        .skip_while(|l| l.trim() != header)
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with('['))
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .collect()
}

/// The quoted names of a `[...]` list in `line` (after `key`).
fn list_after(line: &str, key: &str) -> Vec<String> {
    let Some(at) = line.find(key) else { return Vec::new() };
    let rest = &line[at..];
    let (Some(open), Some(close)) = (rest.find('['), rest.find(']')) else {
        return Vec::new();
    };
    rest[open + 1..close]
        .split(',')
        .map(|n| n.trim().trim_matches('"').to_string())
        .filter(|n| !n.is_empty())
        .collect()
}

/// The library's features a dependent's manifest turns on.
fn features_of_dependent(dependent: &str) -> BTreeSet<String> {
    let text = manifest(dependent);
    let line = section(&text, "dependencies")
        .into_iter()
        .find(|l| l.trim_start().starts_with("viewsynth "))
        .unwrap_or_else(|| panic!("{dependent}: no viewsynth dependency"));
    features_of(line)
}

/// The library's features a `viewsynth = { ... }` dependency line turns on, each feature's own
/// list followed (the root manifest's `[features]` table).
fn features_of(line: &str) -> BTreeSet<String> {
    let root = manifest("Cargo.toml");
    let table = section(&root, "features");
    let own = |feature: &str| -> Vec<String> {
        table
            .iter()
            .find(|l| l.split('=').next().map(str::trim) == Some(feature))
            .map(|l| list_after(l, "="))
            .unwrap_or_default()
    };
    let mut todo = list_after(line, "features");
    if !line.replace(' ', "").contains("default-features=false") {
        todo.push("default".to_string());
    }
    let mut on = BTreeSet::new();
    while let Some(f) = todo.pop() {
        if on.insert(f.clone()) {
            todo.extend(own(&f));
        }
    }
    on
}

#[test]
fn nv_flip_comes_with_the_compare_feature_only() {
    let root = manifest("Cargo.toml");
    let deps = section(&root, "dependencies");
    let flip = deps
        .iter()
        .find(|l| l.trim_start().starts_with("nv-flip"))
        .expect("nv-flip");
    assert!(
        flip.replace(' ', "").contains("optional=true"),
        "nv-flip must stay optional: {flip}"
    );
    let features = section(&root, "features");
    let pulling: Vec<&str> = features.into_iter().filter(|l| l.contains("dep:nv-flip")).collect();
    assert_eq!(pulling.len(), 1, "{pulling:?}");
    assert!(pulling[0].trim_start().starts_with("compare "), "{pulling:?}");
}

#[test]
fn the_command_line_has_compare_and_python_and_fuzz_do_not() {
    assert!(features_of_dependent("cli/Cargo.toml").contains("compare"));
    for dependent in ["python/Cargo.toml", "fuzz/Cargo.toml"] {
        let on = features_of_dependent(dependent);
        assert!(
            !on.contains("compare"),
            "{dependent} builds `compare` (nv-flip's C++) in: {on:?}"
        );
        // They keep the Vulkan backend they had through the default.
        assert!(on.contains("vulkan"), "{dependent}: {on:?}");
    }
}

#[test]
fn the_manifest_reading_sees_compare_come_back() {
    // What the test above sees if a dependent goes back to the plain dependency, or asks for it.
    assert!(features_of(r#"viewsynth = { path = ".." }"#).contains("compare"));
    let asked = r#"viewsynth = { path = "..", default-features = false, features = ["vulkan", "compare"] }"#;
    assert!(features_of(asked).contains("compare"));
    let without = r#"viewsynth = { path = "..", default-features = false, features = ["vulkan"] }"#;
    assert!(!features_of(without).contains("compare"));
}
