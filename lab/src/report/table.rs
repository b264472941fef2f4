//! The report as Markdown: title, renderer, one table line per row, the notes as a list; and
//! the number formatting the table and the plot share.

use super::Report;
use std::fmt::Write as _;

pub(super) fn markdown(report: &Report) -> String {
    let mut s = format!(
        "# {}\n\nRenderer: {}\n\n",
        md_inline(&report.title),
        md_inline(&report.renderer)
    );
    s.push_str(
        "| capability | scene | method | setting | PSNR (dB) | SSIM | depth abs (m) | depth rel | coverage \
             | GPU ms | wall ms |\n|---|---|---|---|--:|--:|--:|--:|--:|--:|--:|\n",
    );
    for r in &report.rows {
        let cells = [
            md_cell(&r.capability),
            md_cell(&r.scene),
            md_cell(&r.method),
            md_cell(&r.setting),
            opt(r.psnr_db, |v| fixed(v, 2)),
            opt(r.ssim, |v| fixed(v, 4)),
            opt(r.depth_abs_mean, |v| sig(v, 3)),
            opt(r.depth_rel_mean, |v| sig(v, 3)),
            opt(r.coverage, |v| {
                if v.is_finite() {
                    format!("{:.1}%", v * 100.0)
                } else {
                    fixed(v, 0)
                }
            }),
            opt(r.gpu_ms, |v| sig(v, 3)),
            // NaN: not timed (a peer that ran outside viewsynth).
            opt(Some(r.wall_ms).filter(|w| !w.is_nan()), |v| sig(v, 3)),
        ];
        let _ = writeln!(s, "| {} |", cells.join(" | "));
    }
    if !report.notes.is_empty() {
        s.push('\n');
        for n in &report.notes {
            // Continuation lines indented so a multi-line note stays one list item.
            let _ = writeln!(s, "- {}", n.lines().collect::<Vec<_>>().join("\n  "));
        }
    }
    s
}

pub(super) fn opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map(f).unwrap_or_else(|| "-".to_string())
}

fn non_finite(v: f64) -> Option<String> {
    if v.is_nan() {
        Some("NaN".into())
    } else if v.is_infinite() {
        Some(if v > 0.0 { "inf" } else { "-inf" }.into())
    } else {
        None
    }
}

pub(super) fn fixed(v: f64, decimals: usize) -> String {
    non_finite(v).unwrap_or_else(|| format!("{v:.decimals$}"))
}

/// `digits` significant digits without exponent for ordinary magnitudes (times, depths).
pub(super) fn sig(v: f64, digits: i32) -> String {
    if let Some(s) = non_finite(v) {
        return s;
    }
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    if !(-6..=12).contains(&mag) {
        return format!("{:.*e}", (digits - 1) as usize, v);
    }
    format!("{:.*}", (digits - 1 - mag).max(0) as usize, v)
}

/// Text for a Markdown line outside the table: line breaks become spaces.
pub(super) fn md_inline(s: &str) -> String {
    s.replace("\r\n", " ").replace(['\n', '\r'], " ")
}

pub(super) fn md_cell(s: &str) -> String {
    md_inline(s).replace('|', "\\|")
}
