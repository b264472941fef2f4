//! One rule for every command's outputs, checked before any work: an output never lands on one
//! of the run's inputs, nor on another output of the same run. Files are told apart by
//! identity, not spelling: an output path is its resolved folder plus its name, an input is the
//! file it resolves to, and an output whose name leads to an input's file (a hard link, a
//! symlink) is that input. A character
//! device or FIFO (`/dev/null`, `/dev/stdout`) is written in place, never replaced, and two
//! outputs may share one. Refusals name both options and the path.

use crate::error::{Error, Result};
use crate::field::{Field, Message};
use crate::io::Replaces;
use crate::msg;
use std::fs;
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Path, PathBuf};

/// A path a run reads or writes and the option that names it (`"--diff"`, `"--a-rgb"`).
pub type NamedPath<'a> = (Message, &'a Path);

/// Where an output will be: its folder resolved, and its own name.
fn output_key(path: &Path) -> Option<PathBuf> {
    if let Ok(m) = fs::symlink_metadata(path) {
        let t = m.file_type();
        if t.is_char_device() || t.is_fifo() || t.is_socket() || t.is_block_device() {
            return None;
        }
    }
    if let Ok(m) = fs::metadata(path) {
        if m.file_type().is_char_device() || m.file_type().is_fifo() {
            return None;
        }
    }
    let name = path.file_name()?;
    let parent = crate::io::parent_dir(path);
    let dir = fs::canonicalize(parent).unwrap_or_else(|_| parent.to_path_buf());
    Some(dir.join(name))
}

/// The file an input resolves to, and its (device, inode).
fn input_key(path: &Path) -> Option<(PathBuf, (u64, u64))> {
    let m = fs::metadata(path).ok()?;
    if !m.is_file() {
        return None;
    }
    Some((fs::canonicalize(path).ok()?, (m.dev(), m.ino())))
}

/// Refuses an output that is one of `inputs` or another of `outputs` (see the module notes).
pub fn check_outputs(inputs: &[NamedPath<'_>], outputs: &[NamedPath<'_>]) -> Result<()> {
    let ins: Vec<_> = inputs
        .iter()
        .filter_map(|(o, p)| input_key(p).map(|k| (o, *p, k)))
        .collect();
    let mut seen: Vec<(&Message, &Path, PathBuf)> = Vec::new();
    for (option, path) in outputs {
        let path = *path;
        let Some(key) = output_key(path) else { continue };
        if let Some((other, other_path, _)) = seen.iter().find(|(_, _, k)| *k == key) {
            return Err(Error::param(
                option,
                msg![
                    format!("{} is also ", path.display()),
                    *other,
                    format!(" {}: each output needs a file of its own", other_path.display())
                ],
            ));
        }
        let identity = fs::metadata(path)
            .ok()
            .filter(|m| m.is_file())
            .map(|m| (m.dev(), m.ino()));
        if let Some((input, input_path, _)) = ins
            .iter()
            .find(|(_, _, (real, id))| *real == key || Some(*id) == identity)
        {
            return Err(replaces_input(option.clone(), path, input, input_path));
        }
        seen.push((option, path, key));
    }
    Ok(())
}

/// Refuses an `--out-dir` run whose files would replace or remove one of `inputs`: an input
/// directly in the folder under a name the run writes (`writes(name)`) or may remove as a file
/// of the previous run's set (`replaces`, the one deletion rule), or such a name that is already
/// the input's file under another name (a hard link, a symlink).
pub fn check_out_dir(
    out_dir: &Path,
    writes: impl Fn(&str) -> bool,
    replaces: &Replaces,
    inputs: &[NamedPath<'_>],
) -> Result<()> {
    // A folder not made yet holds no input.
    let Ok(dir) = fs::canonicalize(out_dir) else {
        return Ok(());
    };
    let removes = replaces.may_remove(&dir);
    let writes = |name: &str| writes(name) || removes.iter().any(|n| n == name);
    let ins: Vec<_> = inputs
        .iter()
        .filter_map(|(o, p)| input_key(p).map(|k| (o, *p, k)))
        .collect();
    for &(option, path, (ref real, _)) in &ins {
        let name = real.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        if real.parent() == Some(dir.as_path()) && writes(name) {
            return Err(replaces_input(Field::OutDir.into(), &out_dir.join(name), option, path));
        }
    }
    if ins.is_empty() {
        return Ok(());
    }
    // The folder's own names the run writes, by identity (one listing; an unreadable folder
    // fails later, where the run prepares it, with its own message).
    let Ok(entries) = fs::read_dir(&dir) else { return Ok(()) };
    for e in entries.flatten() {
        let Some(name) = e.file_name().to_str().map(str::to_string) else {
            continue;
        };
        if !writes(&name) {
            continue;
        }
        let Some(id) = fs::metadata(e.path())
            .ok()
            .filter(|m| m.is_file())
            .map(|m| (m.dev(), m.ino()))
        else {
            continue;
        };
        if let Some(&(option, path, _)) = ins.iter().find(|(_, _, (_, input))| *input == id) {
            return Err(replaces_input(Field::OutDir.into(), &out_dir.join(&name), option, path));
        }
    }
    Ok(())
}

fn replaces_input(option: Message, path: &Path, input: &Message, input_path: &Path) -> Error {
    Error::param(
        option,
        msg![
            format!("{} is the input ", path.display()),
            input,
            format!(
                " {}: an output never replaces an input (write elsewhere or move the input)",
                input_path.display()
            )
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::scratch_dir;

    #[test]
    fn outputs_on_inputs_or_on_each_other_are_refused_by_identity() {
        let dir = scratch_dir("output-paths");
        let a = dir.join("a.png");
        fs::write(&a, "a").unwrap();
        std::os::unix::fs::symlink(&a, dir.join("link.png")).unwrap();
        fs::hard_link(&a, dir.join("hard.png")).unwrap();
        let x = dir.join("x.png");
        let inputs = [(Field::ARgb.into(), a.as_path())];
        let none = Replaces::recorded("none");
        // The same name twice, even spelled differently.
        let e = check_outputs(
            &inputs,
            &[(Field::Diff.into(), &x), (Field::Json.into(), &dir.join("./x.png"))],
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("--json") && e.to_string().contains("--diff"),
            "{e}"
        );
        // An input itself, through a hard link, and spelled otherwise.
        for out in [a.clone(), dir.join("hard.png"), dir.join(".").join("a.png")] {
            let e = check_outputs(&inputs, &[(Field::Json.into(), &out)])
                .unwrap_err()
                .to_string();
            assert!(e.contains("--a-rgb") && e.contains("--json"), "{}: {e}", out.display());
        }
        // A symlink to an input names the input: refused too (the rename would replace only the
        // link, but the user named the input's file).
        assert!(check_outputs(&inputs, &[(Field::Json.into(), &dir.join("link.png"))]).is_err());
        // Devices are written in place, never replaced.
        let null = Path::new("/dev/null");
        assert!(check_outputs(&inputs, &[(Field::Diff.into(), null), (Field::Json.into(), null)]).is_ok());
        // An out-dir that would write one of its inputs' names.
        let e = check_out_dir(&dir, |n| n.starts_with("a."), &none, &inputs)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--out-dir") && e.contains("--a-rgb"), "{e}");
        assert!(check_out_dir(&dir, |n| n.starts_with("s2_"), &none, &inputs).is_ok());
        assert!(check_out_dir(&dir.join("missing"), |_| true, &none, &inputs).is_ok());
        // A name the run writes that is the input under another name: a hard link, a symlink.
        for alias in ["hard.png", "link.png"] {
            let e = check_out_dir(&dir, |n| n == alias, &none, &inputs)
                .unwrap_err()
                .to_string();
            assert!(e.contains(alias) && e.contains("--a-rgb"), "{alias}: {e}");
        }
        assert!(check_out_dir(&dir, |n| n == "x.png", &none, &inputs).is_ok());
        // An input the previous run's set lists: removed at commit if not written again.
        std::fs::write(dir.join(".viewsynth.t.set"), "a.png\n").unwrap();
        let e = check_out_dir(&dir, |n| n == "x.png", &Replaces::recorded("t"), &inputs)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--out-dir") && e.contains("--a-rgb"), "{e}");
    }
}
