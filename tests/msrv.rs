//! The declared MSRV is what the lock file needs: every workspace crate's `rust-version` equals
//! the largest `rust-version` of a locked dependency (a dependency update that raises it fails
//! here, naming the dependency, instead of breaking users of the older toolchain; a declared
//! version above it is a promise nobody checks). `ci/msrv.sh` then builds the workspace with
//! that toolchain. The Python package's manifest declares the same version.

use serde_json::Value;

/// "1.88" and "1.88.0" alike, as [1, 88, 0].
fn version(text: &str) -> Vec<u64> {
    let mut v: Vec<u64> = text.split('.').map(|p| p.parse().expect("rust-version part")).collect();
    v.resize(3, 0);
    v
}

#[test]
fn declared_rust_version_is_the_largest_a_locked_dependency_needs() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let root = env!("CARGO_MANIFEST_DIR");
    // Offline first; a cargo home that holds only this platform's crates (a fresh machine: the
    // build fetched no Windows-only dependency) lacks some manifests, so then fetch them.
    let metadata = |offline: bool| {
        let mut c = std::process::Command::new(&cargo);
        c.args(["metadata", "--format-version", "1", "--locked"]);
        if offline {
            c.arg("--offline");
        }
        c.arg("--manifest-path")
            .arg(format!("{root}/Cargo.toml"))
            .output()
            .expect("cargo metadata runs")
    };
    let mut out = metadata(true);
    if !out.status.success() {
        out = metadata(false);
    }
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let meta: Value = serde_json::from_slice(&out.stdout).expect("cargo metadata is JSON");
    let members: Vec<&str> = meta["workspace_members"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m.as_str().unwrap())
        .collect();
    let (mut ours, mut needed) = (Vec::new(), (Vec::new(), String::new()));
    for p in meta["packages"].as_array().unwrap() {
        let Some(rv) = p["rust_version"].as_str() else { continue };
        let name = format!("{} {}", p["name"].as_str().unwrap(), p["version"].as_str().unwrap());
        if members.contains(&p["id"].as_str().unwrap()) {
            ours.push((name, version(rv)));
        } else if version(rv) > needed.0 {
            needed = (version(rv), name);
        }
    }
    assert_eq!(
        ours.len(),
        4,
        "the library, its tests, the lab and the command line declare one: {ours:?}"
    );
    for (name, v) in &ours {
        assert_eq!(
            v, &needed.0,
            "{name} declares {v:?}; the lock needs {:?} ({})",
            needed.0, needed.1
        );
    }
    let python = std::fs::read_to_string(format!("{root}/python/Cargo.toml")).unwrap();
    let python = python
        .lines()
        .find_map(|l| l.strip_prefix("rust-version = \""))
        .and_then(|v| v.strip_suffix('"'))
        .expect("python/Cargo.toml declares a rust-version");
    assert_eq!(version(python), needed.0, "python/Cargo.toml's rust-version");
}
