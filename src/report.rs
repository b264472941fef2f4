//! Error against run time for any capability, as a Markdown table, a CSV file and an SVG
//! scatter plot (wall time against PSNR, one colour and marker per method).

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::io::atomic_write;

/// One measured configuration.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ReportRow {
    /// "refocus", "cyclopean", ...
    pub capability: String,
    /// "builtin:demo", "teddy", ...
    pub scene: String,
    /// "seed", "k-step(3)", "mesh", ...
    pub method: String,
    /// Free text, e.g. "s=0.5", "gl-std-bu".
    pub setting: String,
    pub psnr_db: Option<f64>,
    pub ssim: Option<f64>,
    /// Mean absolute depth error in metres.
    pub depth_abs_mean: Option<f64>,
    /// Mean relative depth error.
    pub depth_rel_mean: Option<f64>,
    /// Fraction of pixels covered, 0..1.
    pub coverage: Option<f64>,
    /// Only where GPU timers are meaningful.
    pub gpu_ms: Option<f64>,
    pub wall_ms: f64,
}

impl ReportRow {
    /// A row with every optional measure absent.
    pub fn new(
        capability: impl Into<String>,
        scene: impl Into<String>,
        method: impl Into<String>,
        setting: impl Into<String>,
        wall_ms: f64,
    ) -> Self {
        ReportRow {
            capability: capability.into(),
            scene: scene.into(),
            method: method.into(),
            setting: setting.into(),
            psnr_db: None,
            ssim: None,
            depth_abs_mean: None,
            depth_rel_mean: None,
            coverage: None,
            gpu_ms: None,
            wall_ms,
        }
    }
}

/// A titled set of rows with the renderer they ran on and free-form notes.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Report {
    pub title: String,
    /// GL renderer string (or "cpu"), so numbers are never read without their machine.
    pub renderer: String,
    pub rows: Vec<ReportRow>,
    pub notes: Vec<String>,
}

const CSV_HEADER: [&str; 11] = [
    "capability",
    "scene",
    "method",
    "setting",
    "psnr_db",
    "ssim",
    "depth_abs_mean_m",
    "depth_rel_mean",
    "coverage",
    "gpu_ms",
    "wall_ms",
];

impl Report {
    /// Title, renderer, one table line per row, then the notes as a list. Absent values are
    /// "-", +inf PSNR (identical images) is "inf"; `|` and line breaks in text are escaped so
    /// every row stays one table line.
    pub fn to_markdown(&self) -> String {
        let mut s = format!(
            "# {}\n\nRenderer: {}\n\n",
            md_inline(&self.title),
            md_inline(&self.renderer)
        );
        s.push_str(
            "| capability | scene | method | setting | PSNR (dB) | SSIM | depth abs (m) | depth rel | coverage \
             | GPU ms | wall ms |\n|---|---|---|---|--:|--:|--:|--:|--:|--:|--:|\n",
        );
        for r in &self.rows {
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
                sig(r.wall_ms, 3),
            ];
            let _ = writeln!(s, "| {} |", cells.join(" | "));
        }
        if !self.notes.is_empty() {
            s.push('\n');
            for n in &self.notes {
                // Continuation lines indented so a multi-line note stays one list item.
                let _ = writeln!(s, "- {}", n.lines().collect::<Vec<_>>().join("\n  "));
            }
        }
        s
    }

    /// Header row plus one record per row, RFC 4180: CRLF line ends, fields containing `,`,
    /// `"`, CR or LF quoted with `"` doubled. Numbers at full precision (shortest round-trip
    /// form; "inf" for +inf), empty cells for absent values. Title and notes are not included.
    pub fn to_csv(&self) -> String {
        let mut s = CSV_HEADER.join(",");
        s.push_str("\r\n");
        let num = |v: Option<f64>| v.map(|v| v.to_string()).unwrap_or_default();
        for r in &self.rows {
            let fields = [
                csv_field(&r.capability),
                csv_field(&r.scene),
                csv_field(&r.method),
                csv_field(&r.setting),
                num(r.psnr_db),
                num(r.ssim),
                num(r.depth_abs_mean),
                num(r.depth_rel_mean),
                num(r.coverage),
                num(r.gpu_ms),
                num(Some(r.wall_ms)),
            ];
            s.push_str(&fields.join(","));
            s.push_str("\r\n");
        }
        s
    }

    /// Standalone SVG 1.1 scatter plot: x = wall ms (log10 axis when the plotted times span
    /// more than a decade, linear otherwise), y = PSNR dB. Rows without a PSNR, with a NaN or
    /// -inf PSNR, or with a negative or non-finite wall time are not plotted. +inf PSNR is drawn
    /// at the top of the axis with an "inf" label. Each marker has a tooltip naming the row.
    pub fn to_svg(&self) -> String {
        svg::render(self)
    }

    /// Writes `{stem}.md`, `{stem}.csv` and `{stem}.svg` into `dir`, each atomically, and
    /// returns their paths. `dir` must exist. If any write fails, the files this call already
    /// wrote are removed, so a failed call never leaves a partial set.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<Vec<PathBuf>> {
        if stem.is_empty() || stem.contains(['/', '\\']) || stem == "." || stem == ".." {
            return Err(Error::param(
                "report stem",
                format!("{stem:?} must be a plain file name stem"),
            ));
        }
        let outputs = [
            ("md", self.to_markdown()),
            ("csv", self.to_csv()),
            ("svg", self.to_svg()),
        ];
        let mut written = Vec::with_capacity(outputs.len());
        for (ext, text) in &outputs {
            let path = dir.join(format!("{stem}.{ext}"));
            let result = atomic_write(&path, |w| w.write_all(text.as_bytes()).map_err(|e| Error::io(&path, e)));
            if let Err(e) = result {
                for p in &written {
                    let _ = std::fs::remove_file(p);
                }
                return Err(e);
            }
            written.push(path);
        }
        Ok(written)
    }
}

fn opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
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

fn fixed(v: f64, decimals: usize) -> String {
    non_finite(v).unwrap_or_else(|| format!("{v:.decimals$}"))
}

/// `digits` significant digits without exponent for ordinary magnitudes (times, depths).
fn sig(v: f64, digits: i32) -> String {
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
fn md_inline(s: &str) -> String {
    s.replace("\r\n", " ").replace(['\n', '\r'], " ")
}

fn md_cell(s: &str) -> String {
    md_inline(s).replace('|', "\\|")
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

mod svg {
    use super::Report;
    use std::fmt::Write as _;

    const WIDTH_BASE: f64 = 640.0;
    const HEIGHT: f64 = 420.0;
    const LEFT: f64 = 70.0;
    const TOP: f64 = 60.0;
    const PLOT_W: f64 = 500.0;
    const PLOT_H: f64 = 290.0;
    const MARKER_R: f64 = 5.0;
    const INSET: f64 = 10.0;
    /// Okabe-Ito colour-blind-safe palette, yellow last as it is weakest on white.
    const COLOURS: [&str; 8] = [
        "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442",
    ];
    const SHAPES: usize = 6;

    /// Axis mapping from data to 0..1 plus its ticks (value, label, major).
    #[derive(Debug)]
    pub(super) struct Axis {
        pub log: bool,
        lo: f64,
        hi: f64,
        pub ticks: Vec<(f64, String, bool)>,
    }

    impl Axis {
        /// Log10 when every value is positive and max/min exceeds 10, linear otherwise.
        pub fn for_times(values: &[f64]) -> Axis {
            let (min, max) = min_max(values).unwrap_or((1.0, 10.0));
            if min > 0.0 && max / min > 10.0 {
                Axis::log10(min, max)
            } else {
                Axis::linear(min, max, min.abs().max(max.abs()) * 0.1)
            }
        }

        pub fn linear(min: f64, max: f64, pad_if_flat: f64) -> Axis {
            let (mut min, mut max) = (min, max);
            if max - min <= f64::EPSILON * max.abs().max(1.0) {
                let pad = if pad_if_flat > 0.0 { pad_if_flat } else { 1.0 };
                min -= pad;
                max += pad;
            }
            let step = nice_step((max - min) / 5.0);
            let lo = (min / step).floor() * step;
            let hi = (max / step).ceil() * step;
            let n = ((hi - lo) / step).round().clamp(1.0, 40.0) as usize;
            let decimals = (-step.log10().floor()).clamp(0.0, 12.0) as usize;
            let ticks = (0..=n)
                .map(|i| {
                    let v = lo + i as f64 * step;
                    // Avoid "-0" labels from rounding.
                    let v = if v.abs() < step * 1e-9 { 0.0 } else { v };
                    (v, format!("{v:.decimals$}"), true)
                })
                .collect();
            Axis {
                log: false,
                lo,
                hi,
                ticks,
            }
        }

        fn log10(min: f64, max: f64) -> Axis {
            let lo = min.log10().floor();
            let mut hi = max.log10().ceil();
            if hi <= lo {
                hi = lo + 1.0;
            }
            let decades = (hi - lo) as i32;
            let mut ticks = Vec::new();
            for d in lo as i32..=hi as i32 {
                let v = 10f64.powi(d);
                let label = if (-4..=5).contains(&d) {
                    format!("{:.*}", (-d).max(0) as usize, v)
                } else {
                    format!("1e{d}")
                };
                ticks.push((v, label, true));
                if d < hi as i32 && decades <= 6 {
                    for m in [2.0, 5.0] {
                        ticks.push((m * v, String::new(), false));
                    }
                }
            }
            Axis {
                log: true,
                lo,
                hi,
                ticks,
            }
        }

        /// Adds one more tick step above a linear axis.
        pub fn extend_top(&mut self) {
            if let [.., (a, _, _), (b, label, _)] = self.ticks.as_slice() {
                let step = b - a;
                let decimals = label.split_once('.').map_or(0, |(_, d)| d.len());
                let v = b + step;
                self.ticks.push((v, format!("{v:.decimals$}"), true));
                self.hi = v;
            }
        }

        /// Position of `v` on the axis in 0..1: clamped, so outliers (and +inf) stay on the plot
        /// edge; NaN maps to 0.
        pub fn frac(&self, v: f64) -> f64 {
            let t = if self.log { v.log10() } else { v };
            let f = (t - self.lo) / (self.hi - self.lo);
            if f.is_nan() {
                0.0
            } else {
                f.clamp(0.0, 1.0)
            }
        }
    }

    fn min_max(values: &[f64]) -> Option<(f64, f64)> {
        values.iter().fold(None, |acc, &v| match acc {
            None => Some((v, v)),
            Some((a, b)) => Some((a.min(v), b.max(v))),
        })
    }

    /// 1, 2 or 5 times a power of ten, at least `raw`.
    fn nice_step(raw: f64) -> f64 {
        let raw = if raw.is_finite() && raw > 0.0 { raw } else { 1.0 };
        let mag = 10f64.powf(raw.log10().floor());
        let f = raw / mag;
        let m = if f <= 1.0 {
            1.0
        } else if f <= 2.0 {
            2.0
        } else if f <= 5.0 {
            5.0
        } else {
            10.0
        };
        m * mag
    }

    /// A coordinate or length; never NaN or inf in the output whatever the input.
    fn n(v: f64) -> String {
        let v = if v.is_finite() { v } else { 0.0 };
        let s = format!("{v:.2}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.to_string()
        }
    }

    /// XML text and attribute escaping; drops characters XML 1.0 forbids.
    pub(super) fn esc(s: &str) -> String {
        let mut out = String::with_capacity(s.len());
        for c in s.chars() {
            match c {
                '&' => out.push_str("&amp;"),
                '<' => out.push_str("&lt;"),
                '>' => out.push_str("&gt;"),
                '"' => out.push_str("&quot;"),
                '\'' => out.push_str("&apos;"),
                '\t' | '\n' | '\r' => out.push(' '),
                c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => {}
                c => out.push(c),
            }
        }
        out
    }

    /// Marker `shape` centred at (x, y); `class` distinguishes plot from legend markers.
    fn marker(out: &mut String, shape: usize, x: f64, y: f64, colour: &str, class: &str, tooltip: Option<&str>) {
        let r = MARKER_R;
        let style =
            format!("class=\"{class}\" fill=\"{colour}\" fill-opacity=\"0.85\" stroke=\"#222\" stroke-width=\"0.7\"");
        let poly = |pts: &[(f64, f64)]| {
            let p: Vec<String> = pts
                .iter()
                .map(|(dx, dy)| format!("{},{}", n(x + dx * r), n(y + dy * r)))
                .collect();
            format!("<polygon {style} points=\"{}\"", p.join(" "))
        };
        let open = match shape % SHAPES {
            0 => format!("<circle {style} cx=\"{}\" cy=\"{}\" r=\"{}\"", n(x), n(y), n(r)),
            1 => format!(
                "<rect {style} x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"",
                n(x - 0.9 * r),
                n(y - 0.9 * r),
                n(1.8 * r),
                n(1.8 * r)
            ),
            2 => poly(&[(0.0, -1.2), (1.1, 0.8), (-1.1, 0.8)]),
            3 => poly(&[(0.0, -1.25), (1.0, 0.0), (0.0, 1.25), (-1.0, 0.0)]),
            4 => poly(&[(0.0, 1.2), (1.1, -0.8), (-1.1, -0.8)]),
            _ => {
                let (a, b) = (0.35, 1.1);
                poly(&[
                    (-a, -b),
                    (a, -b),
                    (a, -a),
                    (b, -a),
                    (b, a),
                    (a, a),
                    (a, b),
                    (-a, b),
                    (-a, a),
                    (-b, a),
                    (-b, -a),
                    (-a, -a),
                ])
            }
        };
        match tooltip {
            Some(t) => {
                let _ = writeln!(out, "{open}><title>{}</title></{}>", esc(t), element_name(&open));
            }
            None => {
                let _ = writeln!(out, "{open}/>");
            }
        }
    }

    fn element_name(open: &str) -> &str {
        open[1..].split(' ').next().unwrap_or("g")
    }

    fn text(out: &mut String, x: f64, y: f64, anchor: &str, size: f64, extra: &str, content: &str) {
        let _ = writeln!(
            out,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"{anchor}\" font-size=\"{}\"{extra}>{}</text>",
            n(x),
            n(y),
            n(size),
            esc(content)
        );
    }

    fn line(out: &mut String, x1: f64, y1: f64, x2: f64, y2: f64, stroke: &str, width: f64) {
        let _ = writeln!(
            out,
            "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{stroke}\" stroke-width=\"{}\"/>",
            n(x1),
            n(y1),
            n(x2),
            n(y2),
            n(width)
        );
    }

    fn fmt_value(v: f64) -> String {
        if v == f64::INFINITY {
            "inf".into()
        } else {
            format!("{v:.2}")
        }
    }

    pub(super) fn render(report: &Report) -> String {
        // Plotted rows: (row index, method index).
        let mut methods: Vec<&str> = Vec::new();
        let mut points = Vec::new();
        for (i, r) in report.rows.iter().enumerate() {
            let Some(p) = r.psnr_db else { continue };
            if p.is_nan() || p == f64::NEG_INFINITY || !r.wall_ms.is_finite() || r.wall_ms < 0.0 {
                continue;
            }
            let m = match methods.iter().position(|&m| m == r.method) {
                Some(m) => m,
                None => {
                    methods.push(&r.method);
                    methods.len() - 1
                }
            };
            points.push((i, m));
        }
        let times: Vec<f64> = points.iter().map(|&(i, _)| report.rows[i].wall_ms).collect();
        let finite_psnr: Vec<f64> = points
            .iter()
            .filter_map(|&(i, _)| report.rows[i].psnr_db.filter(|p| p.is_finite()))
            .collect();
        let x_axis = Axis::for_times(&times);
        let mut y_axis = match min_max(&finite_psnr) {
            Some((lo, hi)) => Axis::linear(lo, hi, 1.0),
            None => Axis::linear(0.0, 50.0, 1.0),
        };
        if finite_psnr.len() < points.len() {
            // One step of headroom so +inf points on the top edge are not confused with the
            // best finite ones.
            y_axis.extend_top();
        }

        // Legend width from the longest method name (~6.5 px per character at 12 px).
        let longest = methods.iter().map(|m| m.chars().count()).max().unwrap_or(0);
        let legend_w = if methods.is_empty() {
            0.0
        } else {
            40.0 + 6.5 * longest.min(60) as f64
        };
        let width = WIDTH_BASE + legend_w;
        let height = HEIGHT.max(TOP + 20.0 * methods.len() as f64 + 20.0);
        // Inset so markers at the ends of the data range are not cut by the frame.
        let px = |v: f64| LEFT + INSET + x_axis.frac(v) * (PLOT_W - 2.0 * INSET);
        let py = |v: f64| TOP + PLOT_H - INSET - y_axis.frac(v) * (PLOT_H - 2.0 * INSET);

        let mut s = String::new();
        s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n");
        let _ = writeln!(
            s,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{}\" height=\"{}\" \
             viewBox=\"0 0 {} {}\" font-family=\"sans-serif\">",
            n(width),
            n(height),
            n(width),
            n(height)
        );
        let _ = writeln!(s, "<title>{}</title>", esc(&report.title));
        let _ = writeln!(
            s,
            "<rect x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"#ffffff\"/>",
            n(width),
            n(height)
        );
        text(
            &mut s,
            width / 2.0,
            24.0,
            "middle",
            16.0,
            " font-weight=\"bold\"",
            &report.title,
        );
        text(
            &mut s,
            width / 2.0,
            42.0,
            "middle",
            11.0,
            " fill=\"#555\"",
            &report.renderer,
        );

        // Grid, ticks and tick labels.
        let (x0, y0, x1, y1) = (LEFT, TOP, LEFT + PLOT_W, TOP + PLOT_H);
        for (v, label, major) in &x_axis.ticks {
            let x = px(*v);
            line(&mut s, x, y0, x, y1, if *major { "#dddddd" } else { "#f0f0f0" }, 1.0);
            line(&mut s, x, y1, x, y1 + if *major { 5.0 } else { 3.0 }, "#333", 1.0);
            if !label.is_empty() {
                text(&mut s, x, y1 + 18.0, "middle", 11.0, "", label);
            }
        }
        for (v, label, _) in &y_axis.ticks {
            let y = py(*v);
            line(&mut s, x0, y, x1, y, "#dddddd", 1.0);
            line(&mut s, x0 - 5.0, y, x0, y, "#333", 1.0);
            text(&mut s, x0 - 8.0, y + 4.0, "end", 11.0, "", label);
        }
        let _ = writeln!(
            s,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\" stroke-width=\"1\"/>",
            n(x0),
            n(y0),
            n(PLOT_W),
            n(PLOT_H)
        );
        let x_label = if x_axis.log {
            "wall time (ms, log scale)"
        } else {
            "wall time (ms)"
        };
        text(&mut s, x0 + PLOT_W / 2.0, y1 + 40.0, "middle", 12.0, "", x_label);
        let (lx, ly) = (18.0, y0 + PLOT_H / 2.0);
        let rotate = format!(" transform=\"rotate(-90 {} {})\"", n(lx), n(ly));
        text(&mut s, lx, ly, "middle", 12.0, &rotate, "PSNR (dB)");
        if points.is_empty() {
            text(
                &mut s,
                x0 + PLOT_W / 2.0,
                y0 + PLOT_H / 2.0,
                "middle",
                13.0,
                " fill=\"#777\"",
                "no rows with PSNR",
            );
        }

        // Markers; +inf PSNR sits at the top of the axis with an "inf" label beside it.
        for &(i, m) in &points {
            let r = &report.rows[i];
            let psnr = r.psnr_db.unwrap_or(0.0);
            let (x, y) = (
                px(r.wall_ms),
                if psnr.is_finite() { py(psnr) } else { py(f64::INFINITY) },
            );
            let tip = format!(
                "{} / {} / {} / {}: {} dB, {} ms",
                r.capability,
                r.scene,
                r.method,
                r.setting,
                fmt_value(psnr),
                super::sig(r.wall_ms, 3)
            );
            marker(&mut s, m, x, y, COLOURS[m % COLOURS.len()], "marker", Some(&tip));
            if !psnr.is_finite() {
                let fill = format!(" fill=\"{}\"", COLOURS[m % COLOURS.len()]);
                text(&mut s, x + MARKER_R + 3.0, y + 4.0, "start", 10.0, &fill, "\u{2191}inf");
            }
        }

        // Legend, one entry per method in order of first appearance.
        let lx = x1 + 20.0;
        for (m, name) in methods.iter().enumerate() {
            let y = TOP + 10.0 + 20.0 * m as f64;
            marker(
                &mut s,
                m,
                lx + MARKER_R,
                y,
                COLOURS[m % COLOURS.len()],
                "legend-marker",
                None,
            );
            text(&mut s, lx + 2.0 * MARKER_R + 8.0, y + 4.0, "start", 12.0, "", name);
        }
        s.push_str("</svg>\n");
        s
    }
}

#[cfg(test)]
mod tests {
    use super::svg::Axis;
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
        assert_eq!(svg::esc("a\u{1}b\u{FFFF}<"), "ab&lt;");
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
}
