//! Resume: what a frame's manifest records of the settings that made it, and whether a
//! frame's folder holds a finished set made with the same settings.

use super::{BatchFrame, BatchOptions};
use std::path::Path;

/// What a frame's manifest records of the settings that produced it: a rerun with anything
/// different (inputs changed on disk, other scales, outputs, formats, conventions) redoes it.
pub(super) fn frame_settings(frame: &BatchFrame, opts: &BatchOptions) -> serde_json::Value {
    let stamp = |p: &Path| -> serde_json::Value {
        match std::fs::metadata(p) {
            Ok(m) => {
                let mtime = m
                    .modified()
                    .ok()
                    .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                    .map(|d| d.as_nanos().to_string());
                serde_json::json!({ "path": p.to_string_lossy(), "bytes": m.len(), "mtime_ns": mtime })
            }
            Err(_) => serde_json::json!({ "path": p.to_string_lossy() }),
        }
    };
    let mut settings = serde_json::json!({
        "rgb": stamp(&frame.rgb),
        "depth": stamp(&frame.depth),
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

/// A frame is finished when its folder is a plain folder (not a symlink: it would resolve
/// outside --out-dir; writing it again refuses it by name), its manifest was written with the
/// same settings, and every file it lists is there, regular, with the size and CRC-32 it
/// recorded (files of another run under the same names, left by a kill, make it unfinished).
pub(super) fn frame_finished(dir: &Path, settings: &serde_json::Value) -> bool {
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
    if m.get("settings") != Some(settings) {
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
                && crate::io::file_crc32(&dir.join(name)).is_ok_and(|c| u64::from(c) == crc)
        })
}
