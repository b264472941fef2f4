//! TUM RGB-D style sequences as batch frames: `rgb.txt` and `depth.txt` list `timestamp path`
//! lines (`#` starts a comment), and each colour frame is paired with the depth frame nearest
//! in time, as TUM's `associate.py` pairs them: every pair closer than the tolerance is a
//! candidate, the closest first, each frame used once, the pairs then in colour-time order.

use super::manifest::BatchFrame;
use crate::camera::Intrinsics;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// TUM's `associate.py` default: 0.02 s, under one frame at 30 Hz.
pub const TUM_MAX_DIFFERENCE: f64 = 0.02;
/// TUM's 16-bit depth PNGs hold 5000 units per metre.
pub const TUM_DEPTH_SCALE: f64 = 5000.0;
/// Largest association listing read (a TUM listing is ~50 bytes a frame).
pub const MAX_LISTING_BYTES: u64 = 64 << 20;

/// One `timestamp path` line of a listing.
#[derive(Debug, Clone, PartialEq)]
struct Entry {
    /// Seconds, for pairing.
    time: f64,
    /// The timestamp as written: the frame's name (no float printing in between).
    text: String,
    /// As listed: relative to the sequence folder.
    path: PathBuf,
    /// 1-based, for messages.
    line: usize,
}

/// A sequence's frames, paired, with what was left unpaired.
#[derive(Debug, Clone)]
pub struct TumAssociation {
    /// One frame per pair, in colour-time order, named by the colour timestamp; paths are the
    /// sequence folder joined to the listed ones.
    pub frames: Vec<BatchFrame>,
    /// Lines of `rgb.txt` and of `depth.txt` that list a frame.
    pub listed: (usize, usize),
}

/// Pairs the frames that `rgb_list` and `depth_list` (paths relative to `dir`) list, each
/// colour frame with the depth frame nearest in time within `max_difference` seconds, into
/// frames with intrinsics `k` and `depth_scale`. Refuses a malformed line (naming the file and
/// line), a paired file that does not exist, and a sequence with no pair.
pub fn associate_tum(
    dir: &Path,
    rgb_list: &Path,
    depth_list: &Path,
    k: Intrinsics,
    depth_scale: f64,
    max_difference: f64,
) -> Result<TumAssociation> {
    if !(max_difference.is_finite() && max_difference > 0.0) {
        return Err(Error::param(
            "max_difference",
            format!("{max_difference}: a time in seconds above 0"),
        ));
    }
    if !(depth_scale.is_finite() && depth_scale > 0.0) {
        return Err(Error::param("depth_scale", format!("{depth_scale}: must be above 0")));
    }
    k.validate("intrinsics")?;
    let rgb = read_listing(rgb_list)?;
    let depth = read_listing(depth_list)?;
    let pairs = associate(&rgb, &depth, max_difference);
    if pairs.is_empty() {
        return Err(Error::decode(
            depth_list,
            format!(
                "no depth frame lies within {max_difference} s of any of the {} colour frames of {} \
                 (is it the same sequence? a larger tolerance?)",
                rgb.len(),
                rgb_list.display()
            ),
        ));
    }
    let mut frames = Vec::with_capacity(pairs.len());
    for (c, d) in pairs {
        let (c, d) = (&rgb[c], &depth[d]);
        for (list, e) in [(rgb_list, c), (depth_list, d)] {
            let p = dir.join(&e.path);
            if !p.is_file() {
                return Err(Error::decode(
                    list,
                    format!("line {}: {}: no such file", e.line, p.display()),
                ));
            }
        }
        frames.push(BatchFrame {
            name: Some(c.text.clone()),
            rgb: dir.join(&c.path),
            depth: dir.join(&d.path),
            fx: k.fx,
            fy: k.fy,
            cx: k.cx,
            cy: k.cy,
            depth_scale: Some(depth_scale),
            sun_bit_rotate: false,
        });
    }
    Ok(TumAssociation {
        frames,
        listed: (rgb.len(), depth.len()),
    })
}

/// The entries of a listing: blank lines and `#` comments skipped; a line is a timestamp, then
/// whitespace, then the path (which may hold spaces).
fn read_listing(path: &Path) -> Result<Vec<Entry>> {
    let (file, len) = crate::io::open_regular(path)?;
    crate::io::check_file_len(path, len, MAX_LISTING_BYTES, "an association listing")?;
    let mut text = String::new();
    std::io::Read::read_to_string(&mut std::io::Read::take(file, MAX_LISTING_BYTES), &mut text)
        .map_err(|e| Error::io(path, e))?;
    let mut entries = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (stamp, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let bad = |why: String| Error::decode(path, format!("line {line_no}: {why} (expected 'timestamp path')"));
        let time: f64 = stamp
            .parse()
            .ok()
            .filter(|t: &f64| t.is_finite())
            .ok_or_else(|| bad(format!("'{}' is not a timestamp", crate::error::excerpt(stamp))))?;
        let rest = rest.trim();
        if rest.is_empty() {
            return Err(bad("no path after the timestamp".into()));
        }
        entries.push(Entry {
            time,
            text: stamp.to_string(),
            path: PathBuf::from(rest),
            line: line_no,
        });
    }
    if entries.is_empty() {
        return Err(Error::decode(path, "lists no frame (only comments or blank lines)"));
    }
    Ok(entries)
}

/// associate.py's pairing: candidates within `max_difference`, closest first, each entry used
/// once; the pairs in colour-time order. Depth entries are sorted once, so each colour entry
/// finds its candidates by binary search rather than against every depth entry.
fn associate(rgb: &[Entry], depth: &[Entry], max_difference: f64) -> Vec<(usize, usize)> {
    let mut by_time: Vec<usize> = (0..depth.len()).collect();
    by_time.sort_by(|&a, &b| depth[a].time.total_cmp(&depth[b].time));
    let mut candidates = Vec::new();
    for (c, e) in rgb.iter().enumerate() {
        let first = by_time.partition_point(|&d| depth[d].time <= e.time - max_difference);
        for &d in by_time[first..]
            .iter()
            .take_while(|&&d| depth[d].time < e.time + max_difference)
        {
            candidates.push(((e.time - depth[d].time).abs(), c, d));
        }
    }
    // Ties broken by position, so the pairing does not depend on the sort's stability.
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let (mut rgb_used, mut depth_used) = (vec![false; rgb.len()], vec![false; depth.len()]);
    let mut pairs = Vec::new();
    for (_, c, d) in candidates {
        if !rgb_used[c] && !depth_used[d] {
            rgb_used[c] = true;
            depth_used[d] = true;
            pairs.push((c, d));
        }
    }
    pairs.sort_by(|a, b| rgb[a.0].time.total_cmp(&rgb[b.0].time).then(a.0.cmp(&b.0)));
    pairs
}

/// Writes `frames` as the CSV manifest `refocus --batch` reads, atomically (a failed write
/// leaves the previous file). A path under the manifest's folder is written relative to it, so
/// the manifest moves with its sequence; any other path is written absolute.
pub fn write_manifest_csv(path: &Path, frames: &[BatchFrame]) -> Result<()> {
    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let base = std::path::absolute(folder).map_err(|e| Error::io(path, e))?;
    let cell = |p: &Path| -> Result<String> {
        let abs = std::path::absolute(p).map_err(|e| Error::io(p, e))?;
        let shown = abs.strip_prefix(&base).map(Path::to_path_buf).unwrap_or(abs);
        shown
            .to_str()
            .map(str::to_string)
            .ok_or_else(|| Error::decode(p, "the path is not UTF-8, which a CSV manifest cannot hold"))
    };
    let mut rows = Vec::with_capacity(frames.len());
    for f in frames {
        let (rgb, depth) = (cell(&f.rgb)?, cell(&f.depth)?);
        rows.push((f, rgb, depth));
    }
    crate::io::atomic_write(path, |out| {
        let mut csv = csv::Writer::from_writer(out);
        let fail = |e: csv::Error| Error::decode(path, e.to_string());
        csv.write_record(["rgb", "depth", "fx", "fy", "cx", "cy", "depth_scale", "name"])
            .map_err(fail)?;
        for (f, rgb, depth) in &rows {
            let num = |v: f64| v.to_string();
            csv.write_record([
                rgb.as_str(),
                depth.as_str(),
                &num(f.fx),
                &num(f.fy),
                &num(f.cx),
                &num(f.cy),
                &f.depth_scale.map(num).unwrap_or_default(),
                f.name.as_deref().unwrap_or(""),
            ])
            .map_err(fail)?;
        }
        csv.flush().map_err(|e| Error::io(path, e))
    })
}

#[cfg(test)]
#[path = "tum_tests.rs"]
mod tests;
