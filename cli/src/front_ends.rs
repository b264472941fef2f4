//! The CLI half of the front-end mapping test (the Python half: python/tests/test_front_ends.py).
//! Both read tests/data/front_ends.json, which names, for each command with a library request,
//! the option and keyword argument that fill each request field, and every option or argument
//! that exists on one side only with its reason. Here: each option of the command is a request
//! field or listed CLI-only; parsing no options gives the library's defaults; each listed
//! option changes exactly its own field (and those it needs) to the value expected.

use crate::{Cli, Command};
use clap::{CommandFactory, Parser};
use serde_json::Value;

/// The options every run of `command` needs, none of them a request field.
fn required(command: &str) -> &'static [&'static str] {
    match command {
        "cyclopean" => &["--left-rgb", "l.png", "--right-rgb", "r.png", "--out-dir", "o"],
        "reproject" => &["--color", "c.png", "--depth", "d.exr", "--out-dir", "o"],
        "stitch" => &["--faces", "faces", "--out-dir", "o"],
        "refocus" => &["--rgb", "c.png", "--depth", "d.exr", "--out-dir", "o"],
        _ => panic!("{command}: no required options listed"),
    }
}

/// The request `viewsynth <command> <required> <extra>` fills, as JSON.
fn request_of(command: &str, extra: &[&str]) -> Value {
    let argv = ["viewsynth", command]
        .into_iter()
        .chain(required(command).iter().copied())
        .chain(extra.iter().copied());
    let cli = Cli::try_parse_from(argv).unwrap_or_else(|e| panic!("{command} {extra:?}: {e}"));
    let request = match cli.command {
        Command::Cyclopean(a) => a.request().map(|r| serde_json::to_value(r).unwrap()),
        Command::Reproject(a) => a.request().map(|r| serde_json::to_value(r).unwrap()),
        Command::Stitch(a) => a.request().map(|r| serde_json::to_value(r).unwrap()),
        Command::Refocus(a) => a.request().map(|r| serde_json::to_value(r).unwrap()),
        _ => panic!("{command}: no request conversion"),
    };
    request.unwrap_or_else(|e| panic!("{command} {extra:?}: {e}"))
}

fn table() -> Value {
    serde_json::from_str(include_str!("../../tests/data/front_ends.json")).expect("front_ends.json parses")
}

#[test]
fn every_request_command_is_in_the_table() {
    let table = table();
    for command in viewsynth::job::REQUEST_COMMANDS {
        assert!(
            table.get(command).is_some(),
            "{command}: missing from tests/data/front_ends.json"
        );
    }
}

#[test]
fn cli_options_map_to_request_fields_with_the_library_defaults() {
    let table = table();
    for command in viewsynth::job::REQUEST_COMMANDS {
        let entry = &table[command];
        let fields = entry["fields"].as_object().unwrap();
        let cli_only = entry["cli_only"].as_object().unwrap();
        let defaults = viewsynth::job::request_defaults(command).unwrap();
        let request_keys: Vec<&String> = defaults.as_object().unwrap().keys().collect();
        let table_keys: Vec<&String> = fields.keys().collect();
        let mut sorted = (request_keys.clone(), table_keys.clone());
        sorted.0.sort();
        sorted.1.sort();
        assert_eq!(
            sorted.0, sorted.1,
            "{command}: the request's fields and the table's differ"
        );

        // No option given: the library's defaults, field for field.
        assert_eq!(
            request_of(command, &[]),
            defaults,
            "{command}: CLI defaults differ from the request's"
        );

        // Each field's option changes that field (and the partners it needs) and nothing else.
        for (field, spec) in fields {
            let Some(cli) = spec["cli"].as_array() else {
                assert!(
                    spec["why"].as_str().is_some_and(|w| !w.is_empty()),
                    "{command}.{field}: no CLI option and no reason"
                );
                continue;
            };
            let args: Vec<&str> = cli.iter().map(|a| a.as_str().unwrap()).collect();
            let got = request_of(command, &args);
            let mut want = defaults.clone();
            want[field.as_str()] = spec["expect"].clone();
            if let Some(also) = spec.get("also").and_then(Value::as_object) {
                for (k, v) in also {
                    want[k.as_str()] = v.clone();
                }
            }
            assert_eq!(got, want, "{command}: {args:?} should set {field} only");
        }

        // Every option of the command is a field's or listed CLI-only with a reason.
        let cmd = Cli::command();
        let sub = cmd.find_subcommand(command).unwrap();
        // Every option a field's arguments name (a field may take two, e.g. --width-out/--height-out).
        let field_options: Vec<&str> = fields
            .values()
            .filter_map(|s| s["cli"].as_array())
            .flatten()
            .filter_map(Value::as_str)
            .filter(|a| a.starts_with("--"))
            .collect();
        let mut options: Vec<String> = sub
            .get_arguments()
            .filter_map(|a| a.get_long().map(|l| format!("--{l}")))
            .collect();
        options.extend(
            cmd.get_arguments()
                .filter_map(|a| a.get_long().map(|l| format!("--{l}"))),
        );
        options.push("--help".into());
        for option in &options {
            let listed = cli_only
                .get(option)
                .and_then(Value::as_str)
                .is_some_and(|w| !w.is_empty());
            assert!(
                field_options.contains(&option.as_str()) || listed,
                "{command} {option}: neither a request field's option nor listed CLI-only with a reason"
            );
        }
        for option in field_options.iter().copied().chain(cli_only.keys().map(String::as_str)) {
            assert!(
                options.iter().any(|o| o == option),
                "{command}: the table names {option}, which the CLI lacks"
            );
        }
    }
}
