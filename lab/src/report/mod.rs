//! Error against run time for any capability, as a Markdown table (`table`), a CSV file
//! (`csv_file`) and an SVG scatter plot (`plot`: wall time against PSNR, one panel per
//! capability, one colour and marker per method).

mod csv_file;
mod plot;
mod summary;
mod table;
#[cfg(test)]
mod tests;

use std::io::Write as _;
use std::path::{Path, PathBuf};

use viewsynth::error::{Error, Result};
use viewsynth::io::atomic_write;

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
    /// Colour PSNR against the truth, dB; None where no truth colour exists.
    pub psnr_db: Option<f64>,
    /// SSIM (BT.601 luma) against the truth; None where not measured.
    pub ssim: Option<f64>,
    /// Mean absolute depth error in metres.
    pub depth_abs_mean: Option<f64>,
    /// Mean relative depth error.
    pub depth_rel_mean: Option<f64>,
    /// Fraction of pixels covered, 0..1.
    pub coverage: Option<f64>,
    /// Only where GPU timers are meaningful.
    pub gpu_ms: Option<f64>,
    /// Wall-clock time per run, milliseconds; NaN where not timed (a peer that ran outside
    /// viewsynth): "-" in the table and the summary, not plotted.
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

/// A report and the files [`Report::write`] made of it.
#[derive(Debug, Clone)]
pub struct WrittenReport {
    /// The measured rows (its [`Report::summary`] is the terminal's short form).
    pub report: Report,
    /// The files written: `{stem}.md`, `{stem}.csv`, `{stem}.svg` (and any a caller adds).
    pub files: Vec<PathBuf>,
}

impl WrittenReport {
    /// The Markdown file among [`WrittenReport::files`] (the first, where a caller added one).
    pub fn markdown(&self) -> Option<&Path> {
        self.files
            .iter()
            .find(|p| p.extension().is_some_and(|e| e == "md"))
            .map(PathBuf::as_path)
    }
}

/// A titled set of rows with the renderer they ran on and free-form notes.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Report {
    /// Heading of the report.
    pub title: String,
    /// GL renderer string (or "cpu"), so numbers are never read without their machine.
    pub renderer: String,
    /// Measured configurations, in table order.
    pub rows: Vec<ReportRow>,
    /// Free-form remarks printed under the table.
    pub notes: Vec<String>,
}

pub(crate) const CSV_HEADER: [&str; 11] = [
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
        table::markdown(self)
    }

    /// Header row plus one record per row, RFC 4180: CRLF line ends, fields containing `,`,
    /// `"`, CR or LF quoted with `"` doubled. Numbers at full precision (shortest round-trip
    /// form; "inf" for +inf), empty cells for absent values. Title and notes are not included.
    pub fn to_csv(&self) -> String {
        csv_file::csv(self)
    }

    /// Standalone SVG 1.1 scatter plot: x = wall ms (log10 axis when the plotted times span
    /// more than a decade, linear otherwise), y = PSNR dB. Rows without a PSNR, with a NaN or
    /// -inf PSNR, or with a negative or non-finite wall time are not plotted. +inf PSNR is drawn
    /// at the top of the axis with an "inf" label. Each marker has a tooltip naming the row.
    pub fn to_svg(&self) -> String {
        plot::render(self)
    }

    /// The headline figures for a terminal: the renderer, then per capability and method (in
    /// table order) the number of rows, the median PSNR over rows that have one, and the median
    /// wall time. One line per method however many scenes and settings the table holds.
    pub fn summary(&self) -> String {
        summary::summary(self)
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
