//! The report's rows as RFC 4180 CSV through the `csv` crate: CRLF line ends, cells quoted
//! where they hold `,`, `"`, CR or LF. Numbers are written by Rust's shortest round-trip form
//! (`0.000000001`, `inf`), not the crate's, so the files stay as before.

use super::{Report, CSV_HEADER};
use serde::Serialize;

/// One CSV record; the field names are the header ([`CSV_HEADER`]).
#[derive(Serialize)]
struct Record<'a> {
    capability: &'a str,
    scene: &'a str,
    method: &'a str,
    setting: &'a str,
    psnr_db: Option<String>,
    ssim: Option<String>,
    depth_abs_mean_m: Option<String>,
    depth_rel_mean: Option<String>,
    coverage: Option<String>,
    gpu_ms: Option<String>,
    wall_ms: String,
}

pub(super) fn csv(report: &Report) -> String {
    let num = |v: Option<f64>| v.map(|v| v.to_string());
    let mut w = csv::WriterBuilder::new()
        .terminator(csv::Terminator::CRLF)
        .from_writer(Vec::new());
    if report.rows.is_empty() {
        // serde writes the header with the first record: an empty report still has one.
        w.write_record(CSV_HEADER).expect("write to memory");
    }
    for r in &report.rows {
        w.serialize(Record {
            capability: &r.capability,
            scene: &r.scene,
            method: &r.method,
            setting: &r.setting,
            psnr_db: num(r.psnr_db),
            ssim: num(r.ssim),
            depth_abs_mean_m: num(r.depth_abs_mean),
            depth_rel_mean: num(r.depth_rel_mean),
            coverage: num(r.coverage),
            gpu_ms: num(r.gpu_ms),
            wall_ms: r.wall_ms.to_string(),
        })
        .expect("write to memory");
    }
    let bytes = w.into_inner().expect("flush to memory");
    String::from_utf8(bytes).expect("CSV of UTF-8 strings is UTF-8")
}
