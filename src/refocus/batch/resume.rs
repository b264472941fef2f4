//! Resume: what a frame's manifest records of the settings and inputs that made it, and
//! whether a frame's folder holds a finished set made from the same inputs with the same
//! settings.
//!
//! Inputs are judged by identity, not by the path spelt in the batch manifest: a file is the
//! one recorded when its size matches and either its mtime matches (the make/rsync rule: no
//! read) or its CRC-32, computed at render time, does (a copy with a new mtime, say in a
//! container). The recorded path is the canonical one, for people; it is never compared, so
//! `out/frames.csv`, `./out/frames.csv`, an absolute path, another working folder or another
//! mount point of the same data all resume.

use super::{BatchFrame, BatchOptions};
use std::path::Path;

/// The recorded inputs of a frame's settings: the keys compared by identity.
const INPUT_KEYS: [&str; 2] = ["rgb", "depth"];

/// One input's identity at render time: canonical path (not compared), size, mtime and CRC-32
/// of the content (crc32fast through flate2, already used for the outputs' records: several
/// GB/s, and the decoder has just read the file, so it comes from the page cache).
pub(super) fn input_identity(p: &Path) -> serde_json::Value {
    let Ok(m) = std::fs::metadata(p) else {
        return serde_json::json!({ "path": p.to_string_lossy() });
    };
    let path = std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let mut id = serde_json::json!({ "path": path.to_string_lossy(), "bytes": m.len(), "mtime_ns": mtime_ns(&m) });
    if let Ok(crc) = crate::output::file_crc32(p) {
        id["crc32"] = crc.into();
    }
    id
}

/// Both inputs' identities, computed where the frame is decoded (a decode thread).
pub(super) fn frame_inputs(frame: &BatchFrame) -> [serde_json::Value; 2] {
    [input_identity(&frame.rgb), input_identity(&frame.depth)]
}

fn mtime_ns(m: &std::fs::Metadata) -> Option<String> {
    m.modified()
        .ok()
        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
        .map(|d| d.as_nanos().to_string())
}

/// What a frame's manifest records of the settings that produced it, inputs aside: a rerun
/// with anything different (other scales, outputs, formats, conventions) redoes it.
fn settings_without_inputs(frame: &BatchFrame, opts: &BatchOptions) -> serde_json::Value {
    let mut settings = serde_json::json!({
        "intrinsics": [frame.fx, frame.fy, frame.cx, frame.cy],
        "depth_scale": frame.depth_scale,
        "sun_bit_rotate": frame.sun_bit_rotate,
        "scales": opts.scales,
        "size": opts.size,
        "principal": opts.principal,
        "break_rule": opts.rule,
        "method": opts.method,
        "conventions": opts.conv,
        "files": opts.files,
    });
    // Only when given, so batches made before the option resume.
    if let Some(m) = opts.depth_trunc {
        settings["depth_trunc"] = m.into();
    }
    if let Some(z) = &opts.zoom_random {
        let name = frame.name.as_deref().unwrap_or_default();
        settings["zoom_random"] = serde_json::json!({
            "range": [z.lo, z.hi],
            "samples": z.samples,
            "seed": z.seed,
            "distribution": "log-uniform",
            "scales": z.scales(name),
        });
        settings["scales"] = serde_json::Value::Null;
    }
    if opts.rgb_everywhere {
        settings["rgb_everywhere"] = true.into();
    }
    settings
}

/// The settings a frame's manifest records: [`settings_without_inputs`] plus the inputs'
/// identities from [`frame_inputs`].
pub(super) fn frame_settings(
    frame: &BatchFrame,
    opts: &BatchOptions,
    inputs: [serde_json::Value; 2],
) -> serde_json::Value {
    let mut settings = settings_without_inputs(frame, opts);
    for (key, id) in INPUT_KEYS.into_iter().zip(inputs) {
        settings[key] = id;
    }
    settings
}

/// Whether the file at `p` is the input `recorded` names: same size, and the same mtime or
/// (when the mtime differs, or always with `verify`) the same content CRC-32. A record
/// without a CRC (batches made before identities) matches on size and mtime alone.
fn same_input(p: &Path, recorded: &serde_json::Value, verify: bool) -> bool {
    let Ok(m) = std::fs::metadata(p) else {
        return false;
    };
    if recorded.get("bytes").and_then(|b| b.as_u64()) != Some(m.len()) {
        return false;
    }
    let crc = recorded.get("crc32").and_then(|c| c.as_u64());
    let same_mtime = recorded.get("mtime_ns").and_then(|t| t.as_str()) == mtime_ns(&m).as_deref();
    if same_mtime && !(verify && crc.is_some()) {
        return true;
    }
    crc.is_some_and(|crc| crate::output::file_crc32(p).is_ok_and(|c| u64::from(c) == crc))
}

/// Whether a frame's manifest `m` records this run's settings for `frame` and inputs that are
/// the same files (see the module notes; with `opts.verify`, by content).
pub(super) fn made_from(m: &serde_json::Value, frame: &BatchFrame, opts: &BatchOptions) -> bool {
    let Some(mut recorded) = m.get("settings").cloned() else {
        return false;
    };
    let Some(recorded_map) = recorded.as_object_mut() else {
        return false;
    };
    let inputs = INPUT_KEYS.map(|k| recorded_map.remove(k));
    if recorded != settings_without_inputs(frame, opts) {
        return false;
    }
    let [Some(rgb), Some(depth)] = inputs else {
        return false;
    };
    same_input(&frame.rgb, &rgb, opts.verify) && same_input(&frame.depth, &depth, opts.verify)
}

/// A frame is finished when its folder is a plain folder (not a symlink: it would resolve
/// outside --out-dir; writing it again refuses it by name), its manifest was written with the
/// same settings from the same inputs (see the module notes), and every file it lists is
/// there, regular, with the size it recorded. The commit journal makes a set all-or-none, so
/// that costs a manifest read and a few `stat`s; `verify` also checks each file's CRC-32 and
/// each input's content (files of another run under the same names, say copied in by hand).
pub(super) fn frame_finished(dir: &Path, frame: &BatchFrame, opts: &BatchOptions) -> bool {
    if !std::fs::symlink_metadata(dir).is_ok_and(|m| m.is_dir()) {
        return false;
    }
    // A set a killed run had journalled is finished first (rolled forward), so what is judged
    // is what the folder will hold.
    crate::io::remove_orphan_temporaries(dir);
    let path = dir.join(crate::io::MANIFEST_NAME);
    // A manifest is a few kB; anything far larger, or not a regular file, is not ours.
    if std::fs::symlink_metadata(&path).map_or(true, |m| !m.is_file() || m.len() > 16 << 20) {
        return false;
    }
    let Ok(text) = crate::io::read_text(&path, 16 << 20) else {
        return false;
    };
    let Ok(m) = serde_json::from_str::<serde_json::Value>(&text) else {
        return false;
    };
    if !made_from(&m, frame, opts) {
        return false;
    }
    let Some(files) = m.get("files").and_then(|f| f.as_array()) else {
        return false;
    };
    !files.is_empty()
        && files.iter().all(|f| {
            let (Some(name), Some(bytes), Some(crc)) = (
                f.get("name").and_then(|v| v.as_str()),
                f.get("bytes").and_then(|v| v.as_u64()),
                f.get("crc32").and_then(|v| v.as_u64()),
            ) else {
                return false;
            };
            // Names are ours (scale tags); refuse anything that would leave the folder.
            !name.contains('/')
                && !name.starts_with('.')
                && std::fs::symlink_metadata(dir.join(name)).is_ok_and(|m| m.is_file() && m.len() == bytes)
                && (!opts.verify || crate::output::file_crc32(&dir.join(name)).is_ok_and(|c| u64::from(c) == crc))
        })
}
