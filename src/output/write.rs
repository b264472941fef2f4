//! [`write_view`]: the outputs of one synthesised view asked for become files in a
//! [`FileSet`] (atomic, all or none) and the manifest entry naming them.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use super::{FileFormats, ViewFiles, ViewNames};
use crate::error::{Error, Result};
use crate::io::{self, FileSet, FileWriter};
use crate::view::ViewOutput;

/// Writes the outputs of `view` that `formats` asks for into `set`, named by `names`, and
/// returns the entry naming them. An output asked for that the view does not hold is an
/// error naming it (never a file silently left out); errors name the final paths.
pub fn write_view(set: &mut FileSet, names: &ViewNames, view: &ViewOutput, formats: &FileFormats) -> Result<ViewFiles> {
    write_view_in(set, names, view, formats)
}

fn missing(what: &str) -> Error {
    Error::param(
        "outputs",
        format!("{what} was asked for but the view has none (the pass did not produce it)"),
    )
}

fn write_view_in(set: &mut FileSet, names: &ViewNames, view: &ViewOutput, formats: &FileFormats) -> Result<ViewFiles> {
    formats.validate()?;
    let (outputs, enc) = (formats.outputs, formats.encoding);
    let mut entry = ViewFiles::default();
    // Filled by the jobs, so declared before them.
    let (mut clipped, mut preview) = (None, None);
    // The view's files are encoded side by side, straight into the set (FileSet::write_all).
    let mut jobs: Vec<(String, FileWriter)> = Vec::new();
    if outputs.rgb {
        let rgb = view.color.as_ref().ok_or_else(|| missing("rgb"))?;
        let ext = formats.rgb.extension();
        let name = format!("{}.{ext}", names.rgb);
        jobs.push(job(set, &name, move |p, out| io::encode_rgb(p, out, rgb, ext, &enc)));
        entry.rgb = Some(name);
    }
    if outputs.depth {
        let depth = view.depth.as_ref().ok_or_else(|| missing("depth"))?;
        if formats.depth.exr {
            let name = format!("{}.exr", names.depth);
            jobs.push(job(set, &name, move |p, out| {
                io::encode_depth_exr(p, out, depth, enc.exr)
            }));
            entry.depth_exr = Some(name);
        }
        if formats.depth.npy {
            let name = format!("{}.npy", names.depth);
            jobs.push(job(set, &name, move |p, out| io::encode_depth_npy(p, out, depth)));
            entry.depth_npy = Some(name);
        }
        if formats.depth.png16 {
            let name = format!("{}.png", names.depth);
            let count = &mut clipped;
            let units = formats.depth.png16_units;
            jobs.push(job(set, &name, move |p, out| {
                *count = Some(io::encode_depth_png16(p, out, depth, units, enc.png)?);
                Ok(())
            }));
            entry.depth_png16 = Some(name);
            entry.depth_png16_units_per_metre = Some(units.get());
        }
        if formats.depth_preview {
            let range = io::depth_preview_range(depth);
            let image = preview.insert(io::depth_preview(depth, range));
            let name = format!("{}_preview.png", names.depth);
            jobs.push(job(set, &name, move |p, out| {
                io::encode_rgb(p, out, image, "png", &enc)
            }));
            entry.depth_preview = Some(name);
            entry.depth_preview_range_m = range;
        }
        // With a mask, coverage is the mask's (below): the depth is not counted again.
        if !outputs.mask {
            entry.coverage = Some(depth.coverage());
        }
    }
    if outputs.mask {
        let mask = view.mask.as_ref().ok_or_else(|| missing("mask"))?;
        let name = format!("{}.png", names.mask);
        jobs.push(job(set, &name, move |p, out| {
            io::encode_mask_png(p, out, mask, enc.png)
        }));
        entry.mask = Some(name);
        entry.coverage = Some(mask.coverage());
    }
    set.write_all(jobs)?;
    entry.depth_png16_clipped = clipped;
    Ok(entry)
}

/// A job of [`FileSet::write_all`]: `name` and its encoder, handed the final path for errors.
fn job<'a>(
    set: &FileSet,
    name: &str,
    encode: impl FnOnce(&Path, &mut BufWriter<File>) -> Result<()> + Send + 'a,
) -> (String, FileWriter<'a>) {
    let shown = set.final_path(name);
    (name.to_string(), Box::new(move |out| encode(&shown, out)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{DepthMap, Mask, OutDir, RgbImage};
    use crate::output::{DepthFormats, OutputSet};

    fn view(z: Vec<f32>) -> ViewOutput {
        let (w, h) = (z.len() as u32, 1);
        ViewOutput {
            width: w,
            height: h,
            color: Some(RgbImage::new(w, h, vec![128; (w * h * 3) as usize]).unwrap()),
            depth: Some(DepthMap::new(w, h, z).unwrap()),
            mask: Some(Mask::new(w, h, vec![1, 0, 1, 1]).unwrap()),
            timing: None,
            exact: None,
        }
    }

    #[test]
    fn every_format_asked_for_is_written_and_nothing_else() {
        let dir = crate::io::test_util::scratch_dir("outputs");
        let out = OutDir::prepare(&dir).unwrap();
        let mut set = out.file_set().unwrap();
        let formats = FileFormats {
            depth: DepthFormats {
                exr: false,
                npy: true,
                png16: true,
                png16_units: Default::default(),
            },
            depth_preview: true,
            ..Default::default()
        };
        let v = view(vec![1.5, 0.0, 70.0, 2.0]);
        let e = write_view(&mut set, &ViewNames::tagged("right"), &v, &formats).unwrap();
        let names: Vec<&String> = e.names().collect();
        assert_eq!(
            names,
            [
                "right_rgb.png",
                "right_depth.npy",
                "right_depth.png",
                "right_depth_preview.png",
                "right_mask.png"
            ]
        );
        assert_eq!(e.depth_png16_clipped, Some(1));
        assert_eq!(e.coverage, Some(0.75));
        set.commit().unwrap();
        let mut on_disk = crate::io::test_util::list_dir(&dir);
        on_disk.retain(|n| !n.starts_with('.'));
        let mut want: Vec<String> = names.into_iter().cloned().collect();
        want.sort();
        assert_eq!(on_disk, want);
        let back = crate::io::load_depth(
            &dir.join("right_depth.png"),
            &crate::io::DepthDecode {
                scale: Some(1000.0),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(back.data, vec![1.5, 0.0, 0.0, 2.0]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn an_output_the_view_lacks_or_a_preview_without_depth_is_refused_by_name() {
        let dir = crate::io::test_util::scratch_dir("outputs-missing");
        let out = OutDir::prepare(&dir).unwrap();
        let mut set = out.file_set().unwrap();
        let mut v = view(vec![1.0; 4]);
        v.mask = None;
        let e = write_view(&mut set, &ViewNames::tagged("a"), &v, &FileFormats::default()).unwrap_err();
        assert!(e.to_string().contains("mask"), "{e}");
        let formats = FileFormats {
            outputs: OutputSet::parse("rgb").unwrap(),
            depth_preview: true,
            ..Default::default()
        };
        let e = write_view(&mut set, &ViewNames::tagged("b"), &view(vec![1.0; 4]), &formats).unwrap_err();
        assert!(e.to_string().contains("depth-preview"), "{e}");
        drop(set);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
