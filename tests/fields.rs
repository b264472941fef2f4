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
