//! `viewsynth stress`: stiff and extreme cases for every capability, GPU f32 output against the
//! f64 reference of the same inputs, as a table of max / percentile errors with the first
//! failing case.
//!
//! Every row runs one case (a family of sub-cases: scales, conventions, methods) and pools its
//! pixels. A pixel is *decided differently* when the validity differs or the depths differ by
//! more than [`Tolerance::other_surface`] (another surface or texel won: a discrete choice that
//! f32 and f64 may take apart on a tie). On the other pixels the relative depth error is pooled
//! into max / p99 / p50, and colour more than one 8-bit level off (after accepting either side of
//! an exact rounding tie) is counted. A row passes when no output value is NaN/Inf, decisions and
//! colour misses stay within their fractions, and the max depth error within the bound derived
//! for that case (written beside each case). Where precision is lost by design the bound says so
//! and the note names the cause.
//!
//! - [`camera`]: projection matrices as f32 uniforms, parallax, vergence (CPU; the f32 arithmetic
//!   of a vertex shader emulated, no readback involved).
//! - [`refocus`], [`cyclopean`], [`reproject`], [`stitch`]: the GPU passes.
//! - [`values`]: every GPU capability over the whole f32/f64 value range (depth, focal
//!   lengths), with the rule that a valid pixel has finite outputs (GPU and twin).

pub mod camera;
pub mod cyclopean;
pub mod refocus;
pub mod reproject;
pub mod stitch;
pub mod values;

use serde::Serialize;
use viewsynth::error::Result;
use viewsynth::metrics;
use viewsynth::pass::Device;

/// f32 unit roundoff (2^-24).
pub const EPS32: f64 = 5.960464477539063e-8;

/// What a row allows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Tolerance {
    /// Max relative depth error on agreeing pixels.
    pub depth_rel: f64,
    /// Fraction of pixels that may be decided differently.
    pub decisions: f64,
    /// Fraction of agreeing pixels whose colour may be more than one level off.
    pub colour: f64,
    /// Precision is lost by design here (the input format cannot hold it): the row reports the
    /// errors and fails only on NaN/Inf.
    pub by_design: bool,
}

impl Tolerance {
    /// A row's bounds: relative depth error, fraction of pixels decided differently, fraction of
    /// pixels more than one colour level off.
    pub const fn new(depth_rel: f64, decisions: f64, colour: f64) -> Self {
        Tolerance {
            depth_rel,
            decisions,
            colour,
            by_design: false,
        }
    }

    /// A lost-by-design row: `depth_rel` is the expected size of the loss, shown, not enforced.
    pub const fn lost_by_design(depth_rel: f64) -> Self {
        Tolerance {
            depth_rel,
            decisions: 1.0,
            colour: 1.0,
            by_design: true,
        }
    }

    /// Relative depth difference above which a pixel shows another surface.
    pub fn other_surface(&self) -> f64 {
        (10.0 * self.depth_rel).max(1e-2)
    }
}

/// max / p99 / p50 of a pooled error.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Stats {
    /// The largest value.
    pub max: f64,
    /// The 99th percentile.
    pub p99: f64,
    /// The median.
    pub p50: f64,
}

impl Stats {
    /// The statistics of `v`, or None when it is empty.
    pub fn of(mut v: Vec<f64>) -> Option<Stats> {
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let at = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
        Some(Stats {
            max: v[v.len() - 1],
            p99: at(0.99),
            p50: at(0.5),
        })
    }
}

/// One GPU output, per pixel: valid, depth (if the capability outputs one), 8-bit colour.
pub struct GpuPixels<'a> {
    /// Whether each pixel is valid (mask).
    pub valid: Vec<bool>,
    /// Optional per-pixel class (e.g. which eyes contributed); a different class is a decision.
    pub class: Option<&'a [u8]>,
    /// View depth per pixel, f32 as read back.
    pub depth: Option<&'a [f32]>,
    /// Colour, 8-bit RGB per pixel.
    pub rgb: &'a [u8],
}

/// The f64 reference of the same pixels.
pub struct RefPixels<'a> {
    /// Whether each pixel is valid in the reference.
    pub valid: Vec<bool>,
    /// The reference's per-pixel class, as [`GpuPixels::class`].
    pub class: Option<&'a [u8]>,
    /// Pixels whose exact answer is a tie (a sample point on an edge, within f64 rounding): a
    /// different decision there is counted as a tie, not as a disagreement.
    pub ties: Option<Vec<bool>>,
    /// View depth per pixel, f64.
    pub depth: Option<&'a [f64]>,
    /// Colour per pixel, unrounded 8-bit levels.
    pub rgb: &'a [[f64; 3]],
}

/// Pooled comparison of one case.
#[derive(Debug, Clone, Default)]
pub struct Tally {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels decided differently (valid in one only, or another class), ties excluded.
    pub decisions: usize,
    /// Decided differently on an exact tie (allowed).
    pub ties: usize,
    /// Agreeing pixels more than one colour level off.
    pub colour_off: usize,
    /// GPU depths that are NaN or infinite.
    pub non_finite: usize,
    /// Relative depth error of every agreeing pixel.
    pub depth_rel: Vec<f64>,
    /// Largest decision / colour / depth fraction seen and the sub-case where it happened.
    pub worst: Option<(f64, String)>,
}

impl Tally {
    /// Add one sub-case (labelled `tag`).
    pub fn add(&mut self, tag: &str, gpu: &GpuPixels, reference: &RefPixels, tol: &Tolerance) {
        let n = reference.valid.len();
        let (mut decisions, mut colour, mut worst_rel) = (0usize, 0usize, 0f64);
        for i in 0..n {
            if let Some(z) = gpu.depth {
                self.non_finite += (!z[i].is_finite()) as usize;
            }
            let class_differs = matches!((gpu.class, reference.class), (Some(a), Some(b)) if a[i] != b[i]);
            if gpu.valid[i] != reference.valid[i] || class_differs {
                if reference.ties.as_ref().is_some_and(|t| t[i]) {
                    self.ties += 1;
                } else {
                    decisions += 1;
                }
                continue;
            }
            if !reference.valid[i] {
                continue;
            }
            if let (Some(zg), Some(zr)) = (gpu.depth, reference.depth) {
                let rel = (zg[i] as f64 - zr[i]).abs() / zr[i].abs().max(f64::MIN_POSITIVE);
                // NaN (a non-finite GPU depth) counts as another surface too.
                if rel.is_nan() || rel > tol.other_surface() {
                    decisions += 1;
                    continue;
                }
                worst_rel = worst_rel.max(rel);
                self.depth_rel.push(rel);
            }
            let e = (0..3)
                .map(|c| metrics::quantization_error(gpu.rgb[i * 3 + c], reference.rgb[i][c]))
                .max()
                .unwrap_or(0);
            colour += (e > 1) as usize;
        }
        self.pixels += n;
        self.decisions += decisions;
        self.colour_off += colour;
        let nf = n.max(1) as f64;
        let badness = (decisions as f64 / nf / tol.decisions.max(1e-12))
            .max(colour as f64 / nf / tol.colour.max(1e-12))
            .max(worst_rel / tol.depth_rel);
        if self.worst.as_ref().is_none_or(|(b, _)| badness > *b) {
            self.worst = Some((badness, tag.to_string()));
        }
    }
}

/// One line of the stress table.
#[derive(Debug, Clone, Serialize)]
pub struct StressRow {
    /// The capability (a name of [`CAPABILITIES`]).
    pub capability: &'static str,
    /// The case, e.g. "focal scale 0.05".
    pub case: String,
    /// Pixels compared over all sub-cases.
    pub pixels: usize,
    /// Pixels decided differently, ties excluded.
    pub decisions: usize,
    /// Pixels decided differently on an exact tie (allowed).
    pub ties: usize,
    /// Agreeing pixels more than one colour level off.
    pub colour_off: usize,
    /// Relative depth error statistics, where the capability outputs depth.
    pub depth_rel: Option<Stats>,
    /// GPU depths that are NaN or infinite.
    pub non_finite: usize,
    /// The bounds the row is held to.
    pub tolerance: Tolerance,
    /// The sub-case closest to (or past) its tolerance.
    pub worst: String,
    /// Whether the row is within its bounds.
    pub pass: bool,
    /// Why the bound is what it is, or why precision is lost by design.
    pub note: String,
}

impl StressRow {
    /// The row of a pooled tally under its tolerance.
    pub fn from_tally(capability: &'static str, case: impl Into<String>, t: Tally, tol: Tolerance, note: &str) -> Self {
        let stats = Stats::of(t.depth_rel);
        let n = t.pixels.max(1) as f64;
        let pass = t.non_finite == 0
            && (tol.by_design
                || t.decisions as f64 <= tol.decisions * n
                    && t.colour_off as f64 <= tol.colour * n
                    && stats.is_none_or(|s| s.max <= tol.depth_rel));
        StressRow {
            capability,
            case: case.into(),
            pixels: t.pixels,
            decisions: t.decisions,
            ties: t.ties,
            colour_off: t.colour_off,
            depth_rel: stats,
            non_finite: t.non_finite,
            tolerance: tol,
            worst: t.worst.map(|(_, s)| s).unwrap_or_default(),
            pass,
            note: note.to_string(),
        }
    }

    /// A row whose check is a rule (an expected error, a finite fallback), not a pixel comparison.
    pub fn rule(capability: &'static str, case: impl Into<String>, pass: bool, note: impl Into<String>) -> Self {
        StressRow {
            capability,
            case: case.into(),
            pixels: 0,
            decisions: 0,
            ties: 0,
            colour_off: 0,
            depth_rel: None,
            non_finite: 0,
            tolerance: Tolerance::new(0.0, 0.0, 0.0),
            worst: String::new(),
            pass,
            note: note.into(),
        }
    }
}

/// How big the sweep is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StressOptions {
    /// Smaller images and fewer sub-cases (the test suite's setting).
    pub quick: bool,
}

/// Which capabilities to sweep.
pub const CAPABILITIES: [&str; 5] = ["camera", "refocus", "cyclopean", "reproject", "stitch"];

/// Run the sweep over `capabilities` (names of [`CAPABILITIES`]).
pub fn run_stress(device: &Device, capabilities: &[&str], opts: StressOptions) -> Result<Vec<StressRow>> {
    let mut rows = Vec::new();
    for cap in capabilities {
        match *cap {
            "camera" => rows.extend(camera::rows(opts)?),
            "refocus" => rows.extend(refocus::rows(device, opts)?),
            "cyclopean" => rows.extend(cyclopean::rows(device, opts)?),
            "reproject" => rows.extend(reproject::rows(device, opts)?),
            "stitch" => rows.extend(stitch::rows(device, opts)?),
            other => {
                return Err(viewsynth::Error::param(
                    "capability",
                    format!("'{other}': expected one of {}", CAPABILITIES.join(", ")),
                ))
            }
        }
        rows.extend(values::rows(device, cap, opts)?);
    }
    Ok(rows)
}

/// The first row that failed, if any.
pub fn first_failure(rows: &[StressRow]) -> Option<&StressRow> {
    rows.iter().find(|r| !r.pass)
}

fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.1e}")
    }
}

/// Markdown table of the rows, then the first failing case (or "none").
pub fn table(rows: &[StressRow]) -> String {
    let mut s = String::from(
        "| capability | case | pixels | decided differently | colour >1 level | depth rel max | p99 | p50 | \
         bound | NaN/Inf | worst sub-case | result | note |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let (max, p99, p50) = r.depth_rel.map_or(("-".into(), "-".into(), "-".into()), |st| {
            (sci(st.max), sci(st.p99), sci(st.p50))
        });
        let decided = if r.ties > 0 {
            format!("{} (+{} on exact ties)", r.decisions, r.ties)
        } else {
            r.decisions.to_string()
        };
        let bound = if r.pixels == 0 {
            "-".to_string()
        } else if r.tolerance.by_design {
            format!("~{} expected (not enforced)", sci(r.tolerance.depth_rel))
        } else {
            format!(
                "{} / {:.2}% / {:.2}%",
                sci(r.tolerance.depth_rel),
                100.0 * r.tolerance.decisions,
                100.0 * r.tolerance.colour
            )
        };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.capability,
            r.case,
            r.pixels,
            decided,
            r.colour_off,
            max,
            p99,
            p50,
            bound,
            r.non_finite,
            r.worst,
            match (r.pass, r.tolerance.by_design) {
                (false, _) => "FAIL",
                (true, true) => "lost by design",
                (true, false) => "ok",
            },
            r.note
        ));
    }
    match first_failure(rows) {
        Some(r) => s.push_str(&format!(
            "\nfirst failing case: {} / {} (worst sub-case: {})\n",
            r.capability, r.case, r.worst
        )),
        None => s.push_str(&format!("\nfirst failing case: none ({} rows)\n", rows.len())),
    }
    s
}

/// A deterministic texture: colour varies per pixel so misplaced samples show.
pub(crate) fn test_texture(w: u32, h: u32) -> Vec<u8> {
    let mut v = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            v.extend([
                ((x * 7 + y * 3) % 256) as u8,
                ((x * 2 + y * 11 + 40) % 256) as u8,
                (((x ^ y) * 5 + 90) % 256) as u8,
            ]);
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_pick_the_right_order_statistics() {
        let s = Stats::of((0..101).map(f64::from).collect()).unwrap();
        assert_eq!((s.max, s.p99, s.p50), (100.0, 99.0, 50.0));
        assert!(Stats::of(vec![]).is_none());
    }

    #[test]
    fn a_nan_depth_or_too_many_decisions_fail_the_row() {
        let tol = Tolerance::new(1e-6, 0.0, 0.0);
        let rgb = [0u8; 6];
        let rrgb = [[0.0; 3]; 2];
        let zr = [1.0, 2.0];
        let mut t = Tally::default();
        let zg = [1.0f32, f32::NAN];
        t.add(
            "nan",
            &GpuPixels {
                valid: vec![true, false],
                class: None,
                depth: Some(&zg),
                rgb: &rgb,
            },
            &RefPixels {
                valid: vec![true, false],
                class: None,
                ties: None,
                depth: Some(&zr),
                rgb: &rrgb,
            },
            &tol,
        );
        let row = StressRow::from_tally("x", "nan", t, tol, "");
        assert!(!row.pass && row.non_finite == 1);
        let mut t = Tally::default();
        let zg = [1.0f32, 2.0];
        t.add(
            "mask",
            &GpuPixels {
                valid: vec![true, true],
                class: None,
                depth: Some(&zg),
                rgb: &rgb,
            },
            &RefPixels {
                valid: vec![true, false],
                class: None,
                ties: None,
                depth: Some(&zr),
                rgb: &rrgb,
            },
            &tol,
        );
        let row = StressRow::from_tally("x", "mask", t, tol, "");
        assert!(!row.pass && row.decisions == 1, "{row:?}");
        assert!(table(&[row]).contains("first failing case: x / mask"));
    }
}
