//! `viewsynth stress`: the table, the JSON, an unknown capability refused (the sweep itself is
//! `viewsynth_tests`' `stress`).

#[test]
fn cli_prints_the_table_writes_json_and_refuses_an_unknown_capability() {
    let dir = crate::cli::scratch("stress_cli");
    let json = dir.join("rows.json");
    let o = crate::cli::bin()
        .args(["stress", "--quick", "--only", "camera", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        out.contains("first failing case: none") && out.contains("lost by design"),
        "{out}"
    );
    // Progress off a terminal: one line per capability swept, as stages.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("[1/1] stress: camera"), "{err}");
    let rows: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(rows.as_array().is_some_and(|a| a.len() >= 10));
    let o = crate::cli::bin()
        .args(["stress", "--only", "camera,warp"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--only 'warp'") && !err.contains("panicked"), "{err}");
}
