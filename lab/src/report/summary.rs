//! The report's short form for a terminal: one line per capability and method.

use super::table::{fixed, md_inline, sig};
use super::Report;
use crate::stats::median;
use std::fmt::Write as _;

/// One summary line's rows: (capability, method), their PSNRs and their wall times.
type Group<'a> = ((&'a str, &'a str), Vec<f64>, Vec<f64>);

pub(super) fn summary(report: &Report) -> String {
    // (capability, method) in first-seen order.
    let mut groups: Vec<Group<'_>> = Vec::new();
    for r in &report.rows {
        let key = (r.capability.as_str(), r.method.as_str());
        let i = match groups.iter().position(|g| g.0 == key) {
            Some(i) => i,
            None => {
                groups.push((key, Vec::new(), Vec::new()));
                groups.len() - 1
            }
        };
        // NaN and -inf PSNRs are not scores (the plot skips them too); +inf (identical) is.
        if let Some(p) = r.psnr_db.filter(|p| !p.is_nan() && *p != f64::NEG_INFINITY) {
            groups[i].1.push(p);
        }
        // NaN: not timed (a peer that ran outside viewsynth).
        if !r.wall_ms.is_nan() {
            groups[i].2.push(r.wall_ms);
        }
    }
    let cap_w = groups.iter().map(|g| g.0 .0.chars().count()).max().unwrap_or(0).max(10);
    let method_w = groups.iter().map(|g| g.0 .1.chars().count()).max().unwrap_or(0).max(6);
    let mut s = format!("{} on {}\n", md_inline(&report.title), md_inline(&report.renderer));
    let _ = writeln!(
        s,
        "{:cap_w$}  {:method_w$}  {:>4}  {:>11}  {:>11}",
        "capability", "method", "rows", "median PSNR", "median wall"
    );
    for ((capability, method), psnr, wall) in &groups {
        let rows = report
            .rows
            .iter()
            .filter(|r| (r.capability.as_str(), r.method.as_str()) == (*capability, *method))
            .count();
        let psnr = if psnr.is_empty() {
            "-".to_string()
        } else {
            format!("{} dB", fixed(median(psnr), 2))
        };
        let _ = writeln!(
            s,
            "{:cap_w$}  {:method_w$}  {:>4}  {:>11}  {:>11}",
            md_inline(capability),
            md_inline(method),
            rows,
            psnr,
            if wall.is_empty() {
                "-".to_string()
            } else {
                format!("{} ms", sig(median(wall), 3))
            }
        );
    }
    s
}
