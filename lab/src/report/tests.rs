//! Tests of the three report formats.

use super::plot::{self, Axis};
use super::table::{fixed, sig};
use super::*;
use std::fs;

fn row(method: &str, setting: &str, psnr: Option<f64>, wall_ms: f64) -> ReportRow {
    ReportRow {
        psnr_db: psnr,
        ssim: psnr.map(|_| 0.9876),
        depth_abs_mean: Some(0.00123),
        depth_rel_mean: None,
        coverage: Some(0.973),
        gpu_ms: Some(1.5),
        ..ReportRow::new("refocus", "builtin:demo", method, setting, wall_ms)
    }
}

fn sample() -> Report {
    Report {
        title: "Refocus <error> & \"time\" 'vs' wall".into(),
        renderer: "llvmpipe (LLVM 17.0, 256 bits)".into(),
        rows: vec![
            row("seed", "s=0.5", Some(31.25), 0.5),
            row("seed", "s=2", Some(f64::INFINITY), 3.0),
            row("k-step(3)", "a, \"quoted\"\nsetting", Some(40.0), 45.0),
            row("mesh", "no psnr", None, 12.0),
            row("mesh|pipe", "s=1", Some(28.0), 500.0),
        ],
        notes: vec!["medians of 5 runs".into(), "two\nlines".into()],
    }
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("viewsynth-report-{tag}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// RFC 4180 reader: quoted fields may hold commas, doubled quotes and line breaks.
fn parse_csv(s: &str) -> Vec<Vec<String>> {
    let mut records = Vec::new();
    let mut record = Vec::new();
    let mut field = String::new();
    let mut chars = s.chars().peekable();
    let mut quoted = false;
    while let Some(c) = chars.next() {
        if quoted {
            match c {
                '"' if chars.peek() == Some(&'"') => {
                    chars.next();
                    field.push('"');
                }
                '"' => quoted = false,
                c => field.push(c),
            }
        } else {
            match c {
                '"' => quoted = true,
                ',' => record.push(std::mem::take(&mut field)),
                '\r' => assert_eq!(chars.next(), Some('\n'), "bare CR outside quotes"),
                '\n' => panic!("bare LF outside quotes"),
                c => field.push(c),
            }
            if c == '\r' {
                record.push(std::mem::take(&mut field));
                records.push(std::mem::take(&mut record));
            }
        }
    }
    assert!(!quoted && field.is_empty() && record.is_empty(), "unterminated record");
    records
}

type Element = (String, Vec<(String, String)>);

/// Every `&` starts one of the five predefined entities and no `<` appears.
fn check_entities(s: &str) {
    assert!(!s.contains('<'), "raw '<' in {s:?}");
    for (i, _) in s.match_indices('&') {
        let ok = ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
            .iter()
            .any(|e| s[i..].starts_with(e));
        assert!(ok, "bare '&' in {s:?}");
    }
}

/// Elements in document order with their attributes, after checking that tags balance
/// and that text and attribute values are properly escaped.
fn check_xml(s: &str) -> Vec<Element> {
    let mut stack: Vec<String> = Vec::new();
    let mut elements = Vec::new();
    let mut rest = s;
    while let Some(open) = rest.find('<') {
        check_entities(&rest[..open]);
        assert!(!rest[..open].contains('>'), "stray '>' in text");
        let close = rest[open..].find('>').expect("unclosed tag") + open;
        let tag = &rest[open + 1..close];
        rest = &rest[close + 1..];
        if let Some(decl) = tag.strip_prefix('?') {
            assert!(decl.ends_with('?') && decl.starts_with("xml "));
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name.trim()), "mismatched close tag");
            continue;
        }
        let self_closing = tag.ends_with('/');
        let body = tag.trim_end_matches('/');
        let name_end = body.find(char::is_whitespace).unwrap_or(body.len());
        let name = &body[..name_end];
        assert!(
            !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-'),
            "{name:?}"
        );
        let mut attrs = Vec::new();
        let mut a = body[name_end..].trim();
        while !a.is_empty() {
            let eq = a.find("=\"").expect("attribute without =\"");
            let key = a[..eq].trim().to_string();
            assert!(!key.is_empty() && !key.contains(char::is_whitespace), "{key:?}");
            let end = a[eq + 2..].find('"').expect("unterminated attribute") + eq + 2;
            let value = a[eq + 2..end].to_string();
            check_entities(&value);
            assert!(attrs.iter().all(|(k, _)| *k != key), "duplicate attribute {key}");
            attrs.push((key, value));
            a = a[end + 1..].trim_start();
        }
        elements.push((name.to_string(), attrs));
        if !self_closing {
            stack.push(name.to_string());
        }
    }
    assert!(rest.trim().is_empty(), "text after the root element");
    assert!(stack.is_empty(), "unclosed elements {stack:?}");
    elements
}

const NUMERIC_ATTRS: [&str; 14] = [
    "x",
    "y",
    "cx",
    "cy",
    "r",
    "x1",
    "y1",
    "x2",
    "y2",
    "width",
    "height",
    "font-size",
    "stroke-width",
    "fill-opacity",
];

fn numbers_in(value: &str) -> Vec<f64> {
    value
        .split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')')
        .filter(|t| !t.is_empty() && t.chars().next().is_some_and(|c| c.is_ascii_digit() || c == '-'))
        .map(|t| {
            t.parse::<f64>()
                .unwrap_or_else(|_| panic!("not a number: {t:?} in {value:?}"))
        })
        .collect()
}

fn check_svg(svg: &str) -> Vec<Element> {
    let elements = check_xml(svg);
    let (root, root_attrs) = &elements[0];
    assert_eq!(root, "svg");
    assert!(root_attrs.contains(&("xmlns".into(), "http://www.w3.org/2000/svg".into())));
    assert!(root_attrs.contains(&("version".into(), "1.1".into())));
    for (k, v) in elements.iter().flat_map(|(_, a)| a) {
        let lower = v.to_ascii_lowercase();
        assert!(!lower.contains("inf") && !lower.contains("nan"), "{k}={v:?}");
        if NUMERIC_ATTRS.contains(&k.as_str()) {
            let x: f64 = v.parse().unwrap_or_else(|_| panic!("{k}={v:?} is not a number"));
            assert!(x.is_finite());
        }
        if ["points", "viewBox", "transform"].contains(&k.as_str()) {
            let nums = numbers_in(v);
            assert!(!nums.is_empty() && nums.iter().all(|x| x.is_finite()), "{k}={v:?}");
        }
    }
    elements
}

fn with_class<'a>(elements: &'a [Element], class: &str) -> Vec<&'a Element> {
    elements
        .iter()
        .filter(|(_, a)| a.iter().any(|(k, v)| k == "class" && v == class))
        .collect()
}

fn marker_count(elements: &[Element]) -> usize {
    with_class(elements, "marker").len()
}

#[test]
fn markdown_has_one_line_per_row() {
    let r = sample();
    let md = r.to_markdown();
    let table: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
    assert_eq!(table.len(), r.rows.len() + 2, "{md}");
    assert!(table[1].starts_with("|---|"));
    let cells = |l: &str| l.replace("\\|", "").matches('|').count() - 1;
    assert!(table.iter().all(|l| cells(l) == 11), "{md}");
    assert!(table[3].contains("| inf |"), "{}", table[3]);
    assert!(
        table[5].contains("| - |") && table[5].contains("| 12.0 |"),
        "{}",
        table[5]
    );
    assert!(
        table[2].contains("| 31.25 | 0.9876 | 0.00123 | - | 97.3% | 1.50 | 0.500 |"),
        "{}",
        table[2]
    );
    assert!(table[6].contains("mesh\\|pipe"));
    assert!(md.starts_with("# Refocus"));
    assert!(md.contains("Renderer: llvmpipe"));
    assert!(md.contains("- medians of 5 runs\n- two\n  lines\n"), "{md}");
}

#[test]
fn number_formatting() {
    assert_eq!(sig(1234.56, 3), "1235");
    assert_eq!(sig(0.0123456, 3), "0.0123");
    assert_eq!(sig(0.0, 3), "0");
    assert_eq!(sig(f64::NAN, 3), "NaN");
    assert_eq!(sig(1e-9, 3), "1.00e-9");
    assert_eq!(fixed(f64::INFINITY, 2), "inf");
    assert_eq!(fixed(-1.005, 1), "-1.0");
}

#[test]
fn csv_round_trips_tricky_strings() {
    let mut r = sample();
    r.rows.push(ReportRow::new(
        "cyc,lopean",
        "\"q\"",
        "",
        "line1\r\nline2\nline3 ,\"",
        7.25,
    ));
    let csv = r.to_csv();
    let parsed = parse_csv(&csv);
    assert_eq!(parsed.len(), r.rows.len() + 1);
    assert_eq!(parsed[0], CSV_HEADER.map(String::from).to_vec());
    for (rec, row) in parsed[1..].iter().zip(&r.rows) {
        assert_eq!(rec.len(), 11);
        assert_eq!(
            &rec[..4],
            &[
                row.capability.clone(),
                row.scene.clone(),
                row.method.clone(),
                row.setting.clone()
            ]
        );
        let back = |s: &str| (!s.is_empty()).then(|| s.parse::<f64>().unwrap());
        assert_eq!(back(&rec[4]), row.psnr_db);
        assert_eq!(back(&rec[5]), row.ssim);
        assert_eq!(back(&rec[6]), row.depth_abs_mean);
        assert_eq!(back(&rec[7]), row.depth_rel_mean);
        assert_eq!(back(&rec[8]), row.coverage);
        assert_eq!(back(&rec[9]), row.gpu_ms);
        assert_eq!(back(&rec[10]), Some(row.wall_ms));
    }
    assert_eq!(parsed[2][4], "inf");
}

#[test]
fn svg_is_well_formed_with_one_marker_per_psnr_row() {
    let r = sample();
    let svg = r.to_svg();
    let elements = check_svg(&svg);
    let with_psnr = r.rows.iter().filter(|r| r.psnr_db.is_some()).count();
    assert_eq!(marker_count(&elements), with_psnr);
    // One legend entry per method among plotted rows: seed, k-step(3), mesh|pipe.
    assert_eq!(with_class(&elements, "legend-marker").len(), 3);
    assert!(elements.iter().any(|(n, _)| n == "title"));
    assert!(svg.contains("Refocus &lt;error&gt; &amp; &quot;time&quot; &apos;vs&apos; wall"));
    assert!(svg.contains("\u{2191}inf</text>"));
    assert!(svg.contains("PSNR (dB)"));
}

#[test]
fn log_axis_only_when_times_span_more_than_a_decade() {
    assert!(Axis::for_times(&[0.5, 3.0, 500.0]).log);
    assert!(!Axis::for_times(&[10.0, 12.5, 20.0]).log);
    assert!(!Axis::for_times(&[0.0, 500.0]).log, "zero cannot go on a log axis");
    assert!(!Axis::for_times(&[7.0]).log);

    let mut r = sample();
    assert!(r.to_svg().contains("wall time (ms, log scale)"));
    for (row, t) in r.rows.iter_mut().zip([10.0, 12.0, 15.0, 18.0, 20.0]) {
        row.wall_ms = t;
    }
    let svg = r.to_svg();
    assert!(svg.contains(">wall time (ms)</text>"));
    check_svg(&svg);
}

#[test]
fn axis_ticks_cover_the_data() {
    let a = Axis::for_times(&[0.5, 500.0]);
    let majors: Vec<f64> = a.ticks.iter().filter(|t| t.2).map(|t| t.0).collect();
    assert_eq!(majors, vec![0.1, 1.0, 10.0, 100.0, 1000.0]);
    assert!(a.frac(0.1).abs() < 1e-12 && (a.frac(1000.0) - 1.0).abs() < 1e-12);
    assert!((a.frac(10.0) - 0.5).abs() < 1e-12);
    let l = Axis::linear(10.0, 20.0, 1.0);
    assert!(l.ticks.first().unwrap().0 <= 10.0 && l.ticks.last().unwrap().0 >= 20.0);
    assert!(l.ticks.len() >= 3 && l.ticks.len() <= 12);
    let mut e = Axis::linear(25.0, 40.0, 1.0);
    e.extend_top();
    assert_eq!(e.ticks.last().unwrap().1, "45");
    assert!(e.frac(40.0) < 1.0 && e.frac(45.0) == 1.0);
    let flat = Axis::linear(30.0, 30.0, 1.0);
    assert!(flat.frac(30.0) > 0.0 && flat.frac(30.0) < 1.0);
    assert_eq!(
        (
            flat.frac(f64::INFINITY),
            flat.frac(f64::NEG_INFINITY),
            flat.frac(f64::NAN)
        ),
        (1.0, 0.0, 0.0)
    );
}

#[test]
fn infinite_and_degenerate_values_never_reach_attributes() {
    let rows = vec![
        row("seed", "inf only", Some(f64::INFINITY), 5.0),
        row("seed", "inf again", Some(f64::INFINITY), 5.0),
        row("mesh", "nan psnr", Some(f64::NAN), 5.0),
        row("mesh", "nan wall", Some(20.0), f64::NAN),
        row("mesh", "inf wall", Some(20.0), f64::INFINITY),
        row("mesh", "neg inf psnr", Some(f64::NEG_INFINITY), 1.0),
    ];
    let r = Report {
        title: "degenerate".into(),
        renderer: "cpu".into(),
        rows,
        notes: vec![],
    };
    assert_eq!(marker_count(&check_svg(&r.to_svg())), 2);
    let empty = Report::default();
    let svg = empty.to_svg();
    assert_eq!(marker_count(&check_svg(&svg)), 0);
    assert!(svg.contains("no rows with PSNR"));
    // Control characters XML forbids are dropped, not written.
    assert_eq!(plot::esc("a\u{1}b\u{FFFF}<"), "ab&lt;");
}

#[test]
fn many_methods_get_distinct_styles() {
    let rows: Vec<ReportRow> = (0..24)
        .map(|i| row(&format!("method-{i}"), "", Some(20.0 + i as f64), 1.0 + i as f64))
        .collect();
    let r = Report {
        title: "many".into(),
        renderer: "cpu".into(),
        rows,
        notes: vec![],
    };
    let elements = check_svg(&r.to_svg());
    assert_eq!(marker_count(&elements), 24);
    // Legend markers: element kind, fill and geometry relative to the centre identify a style.
    let mut styles: Vec<String> = with_class(&elements, "legend-marker")
        .iter()
        .map(|(name, attrs)| {
            let get = |key: &str| {
                attrs
                    .iter()
                    .find(|(k, _)| k == key)
                    .map(|(_, v)| v.clone())
                    .unwrap_or_default()
            };
            let shape = match name.as_str() {
                "polygon" => {
                    let p = numbers_in(&get("points"));
                    // Vertex count and whether the first vertex is above the rest.
                    format!("polygon{}-{}", p.len() / 2, p[1] < p[3])
                }
                other => other.to_string(),
            };
            format!("{shape}/{}", get("fill"))
        })
        .collect();
    assert_eq!(styles.len(), 24);
    styles.sort();
    styles.dedup();
    assert_eq!(styles.len(), 24, "{styles:?}");
}

#[test]
fn write_produces_three_files() {
    let dir = scratch("write");
    let r = sample();
    let paths = r.write(&dir, "refocus-report").unwrap();
    let names: Vec<String> = paths
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["refocus-report.md", "refocus-report.csv", "refocus-report.svg"]);
    let mut listed: Vec<String> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    listed.sort();
    assert_eq!(
        listed,
        ["refocus-report.csv", "refocus-report.md", "refocus-report.svg"]
    );
    assert_eq!(fs::read_to_string(&paths[0]).unwrap(), r.to_markdown());
    assert_eq!(fs::read_to_string(&paths[1]).unwrap(), r.to_csv());
    assert_eq!(fs::read_to_string(&paths[2]).unwrap(), r.to_svg());
    // Rewriting replaces in place.
    assert_eq!(r.write(&dir, "refocus-report").unwrap().len(), 3);
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 3);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_into_missing_directory_fails_and_leaves_nothing() {
    let base = scratch("missing");
    let dir = base.join("no-such-dir");
    let err = sample().write(&dir, "r").unwrap_err();
    assert!(matches!(err, Error::Io { .. }));
    assert!(err.to_string().contains(&dir.display().to_string()), "{err}");
    assert!(!dir.exists());
    assert_eq!(fs::read_dir(&base).unwrap().count(), 0);
    assert!(matches!(
        sample().write(&base, "a/b"),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(sample().write(&base, ""), Err(Error::InvalidParameter { .. })));
    fs::remove_dir_all(&base).unwrap();
}

#[test]
fn failed_later_write_removes_earlier_files() {
    let dir = scratch("partial");
    // A directory where the CSV must go makes the second write fail after the first.
    fs::create_dir(dir.join("r.csv")).unwrap();
    let err = sample().write(&dir, "r").unwrap_err();
    assert!(err.to_string().contains("r.csv"), "{err}");
    let listed: Vec<String> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(listed, ["r.csv"]);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn one_panel_per_capability_with_its_own_legend() {
    let mut rows = sample().rows;
    let mut stitch = row("seam-blend", "1024x512", Some(35.0), 80.0);
    stitch.capability = "stitch".into();
    stitch.scene = "builtin:ods".into();
    rows.insert(1, stitch);
    let mut second = row("seed", "teddy", Some(25.0), 2.0);
    second.capability = "stitch".into();
    rows.push(second);
    let r = Report {
        title: "panels".into(),
        renderer: "cpu".into(),
        rows,
        notes: vec![],
    };
    let svg = r.to_svg();
    let elements = check_svg(&svg);
    assert_eq!(with_class(&elements, "panel").len(), 2);
    // Titles in order of first appearance, with the scenes plotted in each.
    let refocus = svg.find(">refocus (builtin:demo)</text>").expect("refocus panel title");
    let stitch = svg
        .find(">stitch (builtin:ods, builtin:demo)</text>")
        .expect("stitch panel title");
    assert!(refocus < stitch);
    // Legends per panel: seed, k-step(3), mesh|pipe; then seam-blend and seed again.
    assert_eq!(with_class(&elements, "legend-marker").len(), 5);
    assert_eq!(marker_count(&elements), 6);
    // Each panel's markers lie inside its own frame: the stitch markers below the first panel.
    let panel_of = |tip: &str| svg[..svg.find(tip).unwrap()].matches("<g class=\"panel\">").count();
    assert_eq!(panel_of("refocus / builtin:demo / k-step(3)"), 1);
    assert_eq!(panel_of("stitch / builtin:ods / seam-blend"), 2);
    assert_eq!(panel_of("stitch / builtin:demo / seed / teddy"), 2);
}

#[test]
fn csv_bytes_are_the_rfc_4180_form() {
    // The exact bytes the hand-written writer produced before the `csv` crate took over.
    let mut r = Report {
        rows: vec![row("k-step(3)", "a, \"quoted\"\nsetting", Some(40.0), 45.0)],
        ..Report::default()
    };
    r.rows[0].depth_abs_mean = Some(1e-9);
    assert_eq!(
        r.to_csv(),
        "capability,scene,method,setting,psnr_db,ssim,depth_abs_mean_m,depth_rel_mean,coverage,gpu_ms,wall_ms\r\n\
         refocus,builtin:demo,k-step(3),\"a, \"\"quoted\"\"\nsetting\",40,0.9876,0.000000001,,0.973,1.5,45\r\n"
    );
    assert_eq!(Report::default().to_csv(), format!("{}\r\n", CSV_HEADER.join(",")));
}

#[test]
fn summary_has_one_line_per_method_with_medians() {
    let mut r = sample();
    r.rows.push(row("seed", "s=1", Some(35.0), 2.0));
    r.rows.push(row("seed", "s=4", Some(f64::NAN), 100.0));
    let s = r.summary();
    let lines: Vec<&str> = s.lines().collect();
    // Title line, header, then seed, k-step(3), mesh, mesh|pipe in table order.
    assert_eq!(lines.len(), 6, "{s}");
    assert!(lines[0].contains("llvmpipe (LLVM 17.0, 256 bits)"), "{s}");
    let cells = |l: &str| l.split_whitespace().map(str::to_string).collect::<Vec<_>>();
    // seed: 4 rows; PSNRs 31.25, 35, inf (NaN skipped): median 35; walls 0.5, 2, 3, 100: 2.5.
    assert_eq!(
        cells(lines[2]),
        ["refocus", "seed", "4", "35.00", "dB", "2.50", "ms"],
        "{s}"
    );
    assert_eq!(cells(lines[3])[1..4], ["k-step(3)", "1", "40.00"], "{s}");
    assert_eq!(cells(lines[4])[1..4], ["mesh", "1", "-"], "{s}");
    assert_eq!(cells(lines[5])[1], "mesh|pipe", "{s}");
}
