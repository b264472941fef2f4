//! The report as a standalone SVG 1.1 scatter plot of wall time against PSNR: one panel per
//! capability (its own axes, since a refocus and a stitch run differ by orders of magnitude),
//! one colour and marker shape per method within a panel, with the panel's legend beside it and
//! a tooltip per marker naming the row.
//!
//! Written by hand rather than with `plotters`: its SVG backend has no per-element `<title>`
//! (the tooltips), no way to mark +inf PSNR at the axis top, and it would add crates to a
//! 2-core CI build for about 300 lines that the tests below hold to well-formed XML.

use super::Report;
use std::fmt::Write as _;

const WIDTH_BASE: f64 = 640.0;
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

/// The rows of one capability with a PSNR that can be placed: (row index, method index within
/// the panel), and the panel's methods in order of first appearance.
struct Panel<'a> {
    capability: &'a str,
    scenes: Vec<&'a str>,
    methods: Vec<&'a str>,
    points: Vec<(usize, usize)>,
}

/// One panel per capability in order of first appearance (one untitled panel for no rows), so
/// that error and time scales of different tasks are never mixed on one axis.
fn panels(report: &Report) -> Vec<Panel<'_>> {
    let mut panels: Vec<Panel> = Vec::new();
    for (i, r) in report.rows.iter().enumerate() {
        let at = match panels.iter().position(|p| p.capability == r.capability) {
            Some(at) => at,
            None => {
                panels.push(Panel {
                    capability: &r.capability,
                    scenes: Vec::new(),
                    methods: Vec::new(),
                    points: Vec::new(),
                });
                panels.len() - 1
            }
        };
        let panel = &mut panels[at];
        let Some(p) = r.psnr_db else { continue };
        if p.is_nan() || p == f64::NEG_INFINITY || !r.wall_ms.is_finite() || r.wall_ms < 0.0 {
            continue;
        }
        if !panel.scenes.contains(&r.scene.as_str()) {
            panel.scenes.push(&r.scene);
        }
        let m = match panel.methods.iter().position(|&m| m == r.method) {
            Some(m) => m,
            None => {
                panel.methods.push(&r.method);
                panel.methods.len() - 1
            }
        };
        panel.points.push((i, m));
    }
    if panels.is_empty() {
        panels.push(Panel {
            capability: "",
            scenes: Vec::new(),
            methods: Vec::new(),
            points: Vec::new(),
        });
    }
    panels
}

/// Vertical space of a panel: its title, the plot and its axis labels, or the legend if longer.
fn panel_height(methods: usize) -> f64 {
    (PANEL_TITLE + PLOT_H + 50.0).max(PANEL_TITLE + 20.0 * methods as f64 + 20.0)
}

/// Space above a panel's plot for its title.
const PANEL_TITLE: f64 = 28.0;

pub(super) fn render(report: &Report) -> String {
    let panels = panels(report);
    // Legend width from the longest method name (~6.5 px per character at 12 px).
    let longest = panels
        .iter()
        .flat_map(|p| p.methods.iter().map(|m| m.chars().count()))
        .max();
    let legend_w = longest.map_or(0.0, |l| 40.0 + 6.5 * l.min(60) as f64);
    let width = WIDTH_BASE + legend_w;
    let height = TOP + panels.iter().map(|p| panel_height(p.methods.len())).sum::<f64>();

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
    let mut top = TOP;
    for panel in &panels {
        render_panel(&mut s, report, panel, top);
        top += panel_height(panel.methods.len());
    }
    s.push_str("</svg>\n");
    s
}

/// One capability's scatter plot with its own axes and its own legend, `top` px from the top.
fn render_panel(s: &mut String, report: &Report, panel: &Panel, top: f64) {
    let points = &panel.points;
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
    let plot_top = top + PANEL_TITLE;
    // Inset so markers at the ends of the data range are not cut by the frame.
    let px = |v: f64| LEFT + INSET + x_axis.frac(v) * (PLOT_W - 2.0 * INSET);
    let py = |v: f64| plot_top + PLOT_H - INSET - y_axis.frac(v) * (PLOT_H - 2.0 * INSET);

    let _ = writeln!(s, "<g class=\"panel\">");
    if !panel.capability.is_empty() {
        let title = if panel.scenes.is_empty() {
            panel.capability.to_string()
        } else {
            format!("{} ({})", panel.capability, panel.scenes.join(", "))
        };
        text(
            s,
            LEFT,
            top + 18.0,
            "start",
            13.0,
            " font-weight=\"bold\" class=\"panel-title\"",
            &title,
        );
    }
    // Grid, ticks and tick labels.
    let (x0, y0, x1, y1) = (LEFT, plot_top, LEFT + PLOT_W, plot_top + PLOT_H);
    for (v, label, major) in &x_axis.ticks {
        let x = px(*v);
        line(s, x, y0, x, y1, if *major { "#dddddd" } else { "#f0f0f0" }, 1.0);
        line(s, x, y1, x, y1 + if *major { 5.0 } else { 3.0 }, "#333", 1.0);
        if !label.is_empty() {
            text(s, x, y1 + 18.0, "middle", 11.0, "", label);
        }
    }
    for (v, label, _) in &y_axis.ticks {
        let y = py(*v);
        line(s, x0, y, x1, y, "#dddddd", 1.0);
        line(s, x0 - 5.0, y, x0, y, "#333", 1.0);
        text(s, x0 - 8.0, y + 4.0, "end", 11.0, "", label);
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
    text(s, x0 + PLOT_W / 2.0, y1 + 40.0, "middle", 12.0, "", x_label);
    let (lx, ly) = (18.0, y0 + PLOT_H / 2.0);
    let rotate = format!(" transform=\"rotate(-90 {} {})\"", n(lx), n(ly));
    text(s, lx, ly, "middle", 12.0, &rotate, "PSNR (dB)");
    if points.is_empty() {
        text(
            s,
            x0 + PLOT_W / 2.0,
            y0 + PLOT_H / 2.0,
            "middle",
            13.0,
            " fill=\"#777\"",
            "no rows with PSNR",
        );
    }

    // Markers; +inf PSNR sits at the top of the axis with an "inf" label beside it.
    for &(i, m) in points {
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
            super::table::sig(r.wall_ms, 3)
        );
        marker(s, m, x, y, COLOURS[m % COLOURS.len()], "marker", Some(&tip));
        if !psnr.is_finite() {
            let fill = format!(" fill=\"{}\"", COLOURS[m % COLOURS.len()]);
            text(s, x + MARKER_R + 3.0, y + 4.0, "start", 10.0, &fill, "\u{2191}inf");
        }
    }

    // The panel's legend, one entry per method in order of first appearance.
    let lx = x1 + 20.0;
    for (m, name) in panel.methods.iter().enumerate() {
        let y = plot_top + 10.0 + 20.0 * m as f64;
        marker(
            s,
            m,
            lx + MARKER_R,
            y,
            COLOURS[m % COLOURS.len()],
            "legend-marker",
            None,
        );
        text(s, lx + 2.0 * MARKER_R + 8.0, y + 4.0, "start", 12.0, "", name);
    }
    s.push_str("</g>\n");
}
