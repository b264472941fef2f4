//! Help that is true and findable: `-h` a line per option, `--help` the detail and examples
//! (ci/readme-examples.sh runs every example line of every command's `--help`), and the
//! statements that were false stay gone.

use crate::cli::bin;

fn help(args: &[&str]) -> String {
    let o = bin().args(args).output().unwrap();
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn every_command_has_a_short_h_and_a_detailed_help_with_examples() {
    let top = help(&["--help"]);
    let listed = top.split("Commands:").nth(1).unwrap().split("Options:").next().unwrap();
    let commands: Vec<&str> = listed
        .lines()
        .filter_map(|l| l.strip_prefix("  ")?.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 11, "{commands:?}");
    for c in commands {
        let (short, long) = (help(&[c, "-h"]), help(&[c, "--help"]));
        assert!(long.contains("\nExamples:\n  "), "{c} --help has no examples");
        assert!(
            !short.contains("Examples:") && short.contains("--help"),
            "{c} -h: {short}"
        );
        assert!(short.len() < long.len(), "{c}: -h is not shorter");
        assert!(
            long.lines()
                .any(|l| l.trim_start().starts_with(&format!("viewsynth {c}"))),
            "{c}"
        );
    }
}

#[test]
fn the_statements_that_were_false_are_gone() {
    // --backend works with --batch; reproject writes no s{tag} files and no manifest.
    assert!(!help(&["refocus", "--help"]).contains("not --batch"));
    let reproject = help(&["reproject", "--help"]);
    assert!(
        !reproject.contains("s{tag}") && !reproject.contains("s{s}"),
        "{reproject}"
    );
}
