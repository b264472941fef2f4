//! The optical-flow peer in the report (issue 38): what a user without viewsynth writes in ten
//! lines of OpenCV (DIS optical flow both ways, a backward warp of each image by half its flow,
//! the mean of the two). viewsynth does not run it (OpenCV is no dependency of the crate):
//! `python/peers/flow_interpolation.py` writes its middle view of each real pair with a true
//! middle view into a folder, one PNG per pair named by [`FlowPeerPair::file`], and
//! `viewsynth report --flow-peer DIR` scores those over all pixels against the same truth as
//! viewsynth's rows, in a row beside them. A pair whose data the data folder holds must have its
//! file: a missing one is an error naming it, never a silent gap in the comparison.

use crate::report::ReportRow;
use std::path::{Path, PathBuf};
use viewsynth::error::{Error, Result};
use viewsynth::io::{self, RgbImage};

/// Report name of the peer's rows.
pub const FLOW_PEER_NAME: &str = "DIS flow interpolation";

/// Report setting of the peer's rows.
pub const FLOW_PEER_SETTING: &str =
    "two images alone (python/peers/flow_interpolation.py, OpenCV DIS preset MEDIUM); all pixels";

/// Report name of viewsynth's complete frame from the two images, beside the peer's.
pub const FILL_TWO_IMAGES_NAME: &str = "viewsynth cyclopean --fill";

/// Report setting of those rows.
pub const FILL_TWO_IMAGES_SETTING: &str =
    "two images alone (range estimated, census matcher, densify, render, 2-D fill; the CLI's defaults); all pixels";

/// A real pair with a true middle view, as the report names it.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowPeerPair {
    /// The peer's image of this pair in the `--flow-peer` folder, e.g. `cones_2_6_4.png`.
    pub file: &'static str,
    /// The report's scene name (the same as viewsynth's rows of the pair).
    pub scene: String,
    /// The left image, the right image and the true middle view, in the data folder.
    pub left: PathBuf,
    /// See `left`.
    pub right: PathBuf,
    /// See `left`.
    pub truth: PathBuf,
}

/// The pairs with a true middle view whose set `data_dir` holds: Cones im2 + im6 -> im4,
/// Tsukuba 2 + 4 -> 3 and 1 + 5 -> 3 (the same as the report's rows on estimated disparities).
pub fn flow_peer_pairs(data_dir: &Path) -> Vec<FlowPeerPair> {
    let mut pairs = Vec::new();
    let cones = data_dir.join("middlebury2003_cones");
    if cones.is_dir() {
        pairs.push(FlowPeerPair {
            file: "cones_2_6_4.png",
            scene: super::cyclopean::CONES_SCENE.into(),
            left: cones.join("im2.png"),
            right: cones.join("im6.png"),
            truth: cones.join("im4.png"),
        });
    }
    let tsukuba = data_dir.join("tsukuba_5view_no_gt");
    if tsukuba.is_dir() {
        for (file, a, b) in [("tsukuba_2_4_3.png", 2, 4), ("tsukuba_1_5_3.png", 1, 5)] {
            pairs.push(FlowPeerPair {
                file,
                scene: super::cyclopean::tsukuba_scene(a, b),
                left: tsukuba.join(format!("tsukuba{a}.png")),
                right: tsukuba.join(format!("tsukuba{b}.png")),
                truth: tsukuba.join("tsukuba3.png"),
            });
        }
    }
    pairs
}

/// Every pair's peer image in `peer_dir` exists, is a regular image file and has its true
/// middle view's size, all from the headers: else an error naming the first file at fault and
/// why (checked before any row is measured).
pub fn check_flow_peer(data_dir: &Path, peer_dir: &Path) -> Result<()> {
    if !peer_dir.is_dir() {
        return Err(Error::param(
            "--flow-peer",
            format!(
                "{} is no folder (the peer's middle views, one PNG per pair; see docs/report.md)",
                peer_dir.display()
            ),
        ));
    }
    for pair in flow_peer_pairs(data_dir) {
        let path = peer_dir.join(pair.file);
        // Missing only when nothing is there: a FIFO, a device or a folder is named as such.
        if std::fs::symlink_metadata(&path).is_err() {
            return Err(missing(&path, &pair));
        }
        let (w, h) = io::rgb_dimensions(&path)
            .map_err(|e| Error::param("--flow-peer", format!("{e} (the peer's middle view of {})", pair.scene)))?;
        let (tw, th) = io::rgb_dimensions(&pair.truth)?;
        check_size(&path, (w, h), (tw, th), &pair.scene)?;
    }
    Ok(())
}

/// An image of `size` made from `path` has the true middle view's size `truth`.
fn check_size(path: &Path, size: (u32, u32), truth: (u32, u32), scene: &str) -> Result<()> {
    if size != truth {
        return Err(Error::SizeMismatch {
            message: format!(
                "{} is {}x{}, the true middle view of {scene} {}x{}",
                path.display(),
                size.0,
                size.1,
                truth.0,
                truth.1
            ),
        });
    }
    Ok(())
}

fn missing(path: &Path, pair: &FlowPeerPair) -> Error {
    Error::param(
        "--flow-peer",
        format!(
            "{} is missing: the peer's middle view of {} (write it with python/peers/flow_interpolation.py {} {} {}; \
             docs/report.md has the loop for every pair)",
            path.display(),
            pair.scene,
            pair.left.display(),
            pair.right.display(),
            path.display()
        ),
    )
}

/// What the CLI's cyclopean job tells its user: nothing here (the report runs it on its own
/// device, which `open_gpu` is never asked for).
struct Quiet;

impl viewsynth::job::Host for Quiet {
    fn open_gpu(&self, _: &viewsynth::job::GpuRequest) -> Result<viewsynth::gpu::Gpu> {
        Err(Error::Gl(
            "the report's cyclopean --fill row runs on the report's device".into(),
        ))
    }
    fn event(&self, _: viewsynth::job::Event<'_>) {}
}

/// One row per pair of [`flow_peer_pairs`]: `viewsynth cyclopean --left-rgb L --right-rgb R
/// --fill` as the CLI runs it (the same job, on `device`), scored over all pixels against the true
/// middle view: what the peer's row stands beside. Timed once, reading the images included.
pub fn fill_two_images_rows(device: &viewsynth::pass::Device, data_dir: &Path) -> Result<Vec<ReportRow>> {
    use viewsynth::job::cyclopean::{CyclopeanJob, CyclopeanOptions, CyclopeanRequest};
    let mut rows = Vec::new();
    for pair in flow_peer_pairs(data_dir) {
        let job = CyclopeanJob::new(CyclopeanOptions {
            left_rgb: pair.left.clone(),
            right_rgb: pair.right.clone(),
            request: CyclopeanRequest {
                fill: true,
                ..Default::default()
            },
            // Never written: the job renders only.
            out_dir: std::env::temp_dir().join("viewsynth-report-fill"),
            ..Default::default()
        })
        .map_err(|e| Error::param("report", format!("{}: {e}", pair.scene)))?;
        let t0 = std::time::Instant::now();
        let view = job.render_only(device, &Quiet)?.view;
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        let image = view
            .color
            .ok_or_else(|| Error::Gl(format!("{}: the --fill view has no colour", pair.scene)))?;
        let truth = io::load_rgb(&pair.truth)?;
        rows.push(all_pixels_row(
            &pair.scene,
            (FILL_TWO_IMAGES_NAME, FILL_TWO_IMAGES_SETTING, wall_ms),
            &image,
            &truth,
            &pair.left,
        )?);
    }
    Ok(rows)
}

/// One row per pair of [`flow_peer_pairs`]: the peer's image in `peer_dir` scored over all
/// pixels against the pair's true middle view. Not timed (it ran outside viewsynth): wall time
/// NaN, shown as "-".
pub fn flow_peer_rows(data_dir: &Path, peer_dir: &Path) -> Result<Vec<ReportRow>> {
    let mut rows = Vec::new();
    for pair in flow_peer_pairs(data_dir) {
        let path = peer_dir.join(pair.file);
        if !path.is_file() {
            return Err(missing(&path, &pair));
        }
        let image = io::load_rgb(&path)?;
        let truth = io::load_rgb(&pair.truth)?;
        rows.push(flow_peer_row(&pair.scene, &image, &truth, &path)?);
    }
    Ok(rows)
}

/// The peer's row of one pair: `image` (read from `path`) against `truth`, over all pixels.
pub fn flow_peer_row(scene: &str, image: &RgbImage, truth: &RgbImage, path: &Path) -> Result<ReportRow> {
    all_pixels_row(scene, (FLOW_PEER_NAME, FLOW_PEER_SETTING, f64::NAN), image, truth, path)
}

/// A row of `scene` for `method` (name, setting, wall ms): `image` (made from `path`) against
/// `truth`, over all pixels; an image of another size is an error naming `path`.
fn all_pixels_row(
    scene: &str,
    (name, setting, wall_ms): (&str, &str, f64),
    image: &RgbImage,
    truth: &RgbImage,
    path: &Path,
) -> Result<ReportRow> {
    check_size(path, (image.width, image.height), (truth.width, truth.height), scene)?;
    let mut row = ReportRow::new("cyclopean", scene, name, setting, wall_ms);
    let all = vec![true; (truth.width * truth.height) as usize];
    super::score(image, None, &all, truth, None, &mut row);
    Ok(row)
}

/// Puts each of `peer` right after the last row of its scene in `rows` (beside viewsynth's rows
/// of the same pair), or at the end where the report has no row of that scene.
pub fn place_beside(rows: &mut Vec<ReportRow>, peer: Vec<ReportRow>) {
    for row in peer {
        match rows
            .iter()
            .rposition(|r| r.capability == row.capability && r.scene == row.scene)
        {
            Some(i) => rows.insert(i + 1, row),
            None => rows.push(row),
        }
    }
}
