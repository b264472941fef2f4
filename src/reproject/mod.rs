//! reproject: one eye (or the centre view) to another view of a parallel stereo rig, from colour
//! and depth, with disocclusions left invalid (no hole filling). Issue 4 part 1, seeds 002/004.
//!
//! Methods ([`Method`]):
//! - [`Method::Shift`]: seed 002's texture-space shift as a gather. Source column s lands at
//!   `f(s) = s + a - b q(s)` in the target (q = 1/Z; [`ShiftModel`] holds a, b in pixels). A
//!   target pixel u walks the row to a fixed point `s <- u - a + b q(s)` (k steps), once from the
//!   zero-parallax guess s = u and once from the near bound (largest q in the frame), and
//!   accepts a walk's end only if a source segment [j, j+1] next to it covers u.
//! - [`Method::ShiftScan`]: the exact shift gather: every segment of the row whose source
//!   position can reach u (the frame's q range bounds it) is tested; all of them cover u.
//! - [`Method::Gather3d`]: the cyclopean 3-D walk ([`crate::stereo::gather`], unchanged) with the
//!   target as the "middle camera" and the source as the only eye (the other eye has no valid
//!   depth), run twice: from the zero-parallax (or mid-range) distance and from the nearest
//!   depth of the frame; the nearer result that passes cyclopean's 1 px projection check wins.
//!
//! Coverage and occlusion rule of the shift methods (a depth-tested 1-D mesh warp, evaluated as
//! a gather): source texels j and j+1 (same row, both with valid depth) form a segment from
//! f(j) to f(j+1) that covers target column u when u lies between them. Inverse depth and colour
//! are interpolated linearly along it (1/Z is affine along a row for a plane). A segment is a
//! *hole* (an unseen surface) when its depths differ by more than `tau_rel` of the nearer one (a
//! depth edge) or when it folds over (f(j+1) <= f(j): the target would see it from behind, so
//! something the source did not see is in front). Where the edge lies between the two samples is
//! unknown, so a hole also covers the gap (j, j+1) mapped at either end's depth, i.e. one pixel
//! beyond each end: pixels that might see either side stay invalid. When several segments cover u the one with the
//! largest interpolated q (the nearest) wins (at equal q a real surface beats a hole); if that is
//! a hole, u stays invalid (disocclusion), so a farther surface never shows through the gap.
//! Since s = u - a + b q, the nearest candidate is also the first met from the near side.
//!
//! [`pass`]: the pass/twin contract, [`pass::gpu`] and [`pass::reference`] over one
//! [`ReprojectInput`], both returning a [`crate::view::ViewOutput`].
//!
//! Degenerate inputs: depth NaN, +-inf, <= 0 (view Z), the far value (device depth), or a
//! disparity that is not finite and > 0 is invalid and never covers. Zero separation gives the
//! identity map. A point behind the camera cannot be stored (Z > 0 is required). All outputs
//! are finite: 0 colour and depth where the mask is 0.

pub mod pass;
pub mod reference;
pub mod render;

pub use pass::ReprojectInput;

use crate::camera::mat4::{self, Mat4};
use crate::camera::stereo::{Eye, StereoParams};
use crate::camera::{gl_projection, PinholeCamera, Pose};
use crate::convention::{Conventions, DepthPlanes};
use crate::depth::{DepthEncoding, DepthKind};
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use crate::stereo::{EyeInput, FrameDepth, MiddleCamera, StereoFrame};

/// The source view: colour and depth (rows top-down), what the depth holds, and the
/// conventions it was produced under (device depth, and the GPU pass's row order).
#[derive(Debug, Clone)]
pub struct ReprojectSource {
    /// 8-bit colour, rows top-down.
    pub color: RgbImage,
    /// Depth as `depth_kind` says, rows top-down.
    pub depth: DepthMap,
    /// What the depth holds: view Z, device depth or disparity.
    pub depth_kind: DepthEncoding,
    /// NDC depth range, reversed-Z and row order the source was produced under.
    pub conv: Conventions,
}

impl ReprojectSource {
    /// Refuses colour and depth of different sizes, fewer than 2 columns, view distance as depth,
    /// bad encoding parameters and depth values outside the usable magnitudes
    /// ([`crate::depth::check_usable_depth`]).
    pub fn validate(&self) -> Result<()> {
        if (self.color.width, self.color.height) != (self.depth.width, self.depth.height) {
            return Err(Error::SizeMismatch {
                message: format!(
                    "reproject source: colour {}x{} vs depth {}x{}",
                    self.color.width, self.color.height, self.depth.width, self.depth.height
                ),
            });
        }
        if self.color.width < 2 {
            return Err(Error::param("source width", "at least 2 columns are needed"));
        }
        self.depth_kind.check_accepted(
            "source depth kind",
            &[DepthKind::ViewZ, DepthKind::Device, DepthKind::Disparity],
        )?;
        self.depth_kind.validate()?;
        crate::depth::check_usable_depth("source depth", &self.depth.data)
    }

    /// Per-pixel inverse depth (rows top-down), None where invalid.
    pub fn inverse_depths(&self) -> Vec<Option<f64>> {
        self.depth
            .data
            .iter()
            .map(|&d| self.depth_kind.inverse_depth(&self.conv, d as f64))
            .collect()
    }

    /// (min, max) inverse depth over valid pixels, None when no pixel is valid.
    pub fn inverse_depth_range(&self) -> Option<(f64, f64)> {
        self.inverse_depths()
            .into_iter()
            .flatten()
            .fold(None, |acc, q| match acc {
                None => Some((q, q)),
                Some((lo, hi)) => Some((f64::min(lo, q), f64::max(hi, q))),
            })
    }

    /// Refuse a source with no valid depth at all (nothing to reproject: every target pixel
    /// would be invalid); `read_as` names the encoding the depth was read as, for the message.
    pub fn require_valid_depth(&self, read_as: &str) -> std::result::Result<(f64, f64), NoValidDepth> {
        self.inverse_depth_range().ok_or_else(|| NoValidDepth {
            read_as: read_as.to_string(),
        })
    }
}

/// A reprojection source whose depth holds no valid pixel as it was read.
#[derive(Debug, thiserror::Error)]
#[error("no pixel holds valid depth as {read_as}")]
pub struct NoValidDepth {
    /// The encoding the depth was read as (e.g. `depth_kind="device"`).
    pub read_as: String,
}

/// The shift between two views of a parallel rig in pixels: source column s at inverse depth q
/// lands at `s + a - b q` in the target, on the same row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShiftModel {
    /// Constant term `a`, pixels: the shift of a point at infinite depth (q = 0).
    pub a_px: f64,
    /// Parallax coefficient `b`, pixels times view units: the shift per unit inverse depth.
    pub b_px: f64,
}

fn side(view: Option<Eye>) -> f64 {
    view.map_or(0.0, Eye::side)
}

impl ShiftModel {
    /// Seed 002 with seed 004's separation S and convergence c on an image `width` pixels wide:
    /// texture x moves by `(side_to - side_from) / 2 * S (1 - c / Z)`
    /// ([`crate::camera::stereo::reproject_texture_x`]); times `width` in pixels (a texture-space
    /// difference; the half-texel centre offset cancels). `None` is the centre view.
    pub fn seed(params: &StereoParams, width: u32, from: Option<Eye>, to: Option<Eye>) -> Self {
        let k = 0.5 * (side(to) - side(from)) * width as f64 * params.separation();
        ShiftModel {
            a_px: k,
            b_px: k * params.convergence(),
        }
    }

    /// A rectified rig in pixels: eyes `baseline` apart, focal length `focal_px`, and the
    /// principal points differing by `doffs` (cx_right - cx_left, Middlebury 2014). Left to
    /// right: x_right = x_left + doffs - f B / Z = x_left - d. The centre view is halfway.
    pub fn rectified(focal_px: f64, baseline: f64, doffs: f64, from: Option<Eye>, to: Option<Eye>) -> Result<Self> {
        if !(focal_px.is_finite() && focal_px > 0.0 && baseline.is_finite() && baseline >= 0.0 && doffs.is_finite()) {
            return Err(Error::param(
                "rectified rig",
                format!("focal {focal_px} px, baseline {baseline}, doffs {doffs}: need f > 0, B >= 0, all finite"),
            ));
        }
        let k = 0.5 * (side(to) - side(from));
        Ok(ShiftModel {
            a_px: k * doffs,
            b_px: k * focal_px * baseline,
        })
    }

    /// Refuses non-finite coefficients.
    pub fn validate(&self) -> Result<()> {
        if !(self.a_px.is_finite() && self.b_px.is_finite()) {
            return Err(Error::param("shift model", format!("{self:?} is not finite")));
        }
        Ok(())
    }

    /// Target column of source column `s` at inverse depth `q`.
    pub fn forward(&self, s: f64, q: f64) -> f64 {
        s + self.a_px - self.b_px * q
    }
}

/// Where the target view is.
// A plain value built once per job: boxing the matrices would only add indirection.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
pub enum Geometry {
    /// A parallel rig: the target has the source's intrinsics with cx moved by `a_px`, and sits
    /// `b_px / fx` along the source camera's x axis (so that u_t = u_s + a - b / Z).
    Rig {
        /// Intrinsics and image size of the source camera.
        camera: PinholeCamera,
        /// Source column -> target column at each inverse depth.
        shift: ShiftModel,
    },
    /// Full GL matrices (world -> GL eye, eye -> clip under the source's conventions) of the
    /// source and the target camera. Only [`Method::Gather3d`] takes them.
    Matrices {
        /// World -> GL eye transform of the source, row-major.
        source_view: Mat4,
        /// GL eye -> clip projection of the source, row-major.
        source_proj: Mat4,
        /// The target camera (view, projection, output size).
        target: MiddleCamera,
    },
}

/// How a target pixel finds the source surface it sees (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Fixed-point walk along the row, `steps` steps from the zero-parallax guess and from the
    /// near bound, each end verified by segment coverage; the nearer verified one wins.
    Shift {
        /// Fixed-point steps per walk, 1..=16.
        steps: u32,
    },
    /// Exact: every segment the frame's depth range allows is tested; the nearest cover wins.
    ShiftScan,
    /// The cyclopean 3-D walk with one eye (refine with `steps`, projection check), from two
    /// starts (zero parallax, nearest depth); the nearer verified result wins.
    Gather3d {
        /// Refinement steps per walk, 1..=16.
        steps: u32,
    },
}

impl Method {
    /// Short name for reports, e.g. "shift walk 3".
    pub fn label(&self) -> String {
        match self {
            Method::Shift { steps } => format!("shift walk {steps}"),
            Method::ShiftScan => "shift scan".to_string(),
            Method::Gather3d { steps } => format!("3-D gather {steps}"),
        }
    }
}

/// Which target images to produce. The mask always is (it is what coverage is measured on);
/// colour and depth get no attachment and no readback when not requested.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReprojectOutputs {
    /// Produce the target colour.
    pub color: bool,
    /// Produce the target depth.
    pub depth: bool,
}

impl Default for ReprojectOutputs {
    fn default() -> Self {
        ReprojectOutputs {
            color: true,
            depth: true,
        }
    }
}

/// The settings of one reprojection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReprojectParams {
    /// How target pixels find their source surface.
    pub method: Method,
    /// Colour and/or depth (default both).
    pub outputs: ReprojectOutputs,
    /// A segment breaks where |Z_j - Z_j+1| > tau_rel * min(Z) (i.e. |q_j - q_j+1| > tau_rel * min(q)).
    pub tau_rel: f64,
}

impl ReprojectParams {
    /// `method` with both outputs and `tau_rel` 0.05.
    pub fn new(method: Method) -> Self {
        ReprojectParams {
            method,
            outputs: ReprojectOutputs::default(),
            tau_rel: 0.05,
        }
    }

    /// Refuses a negative or non-finite `tau_rel` and walk steps outside 1..=16.
    pub fn validate(&self) -> Result<()> {
        if !(self.tau_rel.is_finite() && self.tau_rel >= 0.0) {
            return Err(Error::param(
                "tau_rel",
                format!("{} must be finite and >= 0", self.tau_rel),
            ));
        }
        match self.method {
            Method::Shift { steps } | Method::Gather3d { steps } if steps == 0 || steps > 16 => {
                Err(Error::param("steps", format!("{steps} outside 1..=16")))
            }
            _ => Ok(()),
        }
    }
}

/// The target view, rows top-down.
#[derive(Debug, Clone)]
pub struct ReprojectOutput {
    /// 0 where the mask is 0; None when not requested.
    pub color: Option<RgbImage>,
    /// Target view Z in metres; 0 where the mask is 0; None when not requested.
    pub depth: Option<DepthMap>,
    /// 255 valid, 0 invalid (disocclusion, outside the source, invalid source depth).
    pub mask: Vec<u8>,
}

impl ReprojectOutput {
    /// Fraction of target pixels the mask marks valid.
    pub fn coverage(&self) -> f64 {
        crate::metrics::valid_fraction(&self.mask, |m| *m != 0)
    }
}

/// Source depth as cyclopean input: device depth stays device depth (same conventions), the
/// rest becomes view Z (0 = invalid).
fn cyclopean_depth(src: &ReprojectSource) -> (DepthMap, FrameDepth) {
    match src.depth_kind {
        DepthEncoding::Device { .. } => (src.depth.clone(), FrameDepth::Device),
        _ => {
            // Disparity -> view Z can leave the usable magnitudes: those become holes.
            let mut z = src.depth_kind.view_z_map(&src.conv, &src.depth);
            crate::depth::clear_unusable_depth(&mut z.data);
            (z, FrameDepth::ViewZ)
        }
    }
}

/// Planes for the GL projections of the 3-D path (only device depth depends on them).
fn planes_of(kind: &DepthEncoding) -> DepthPlanes {
    match kind {
        DepthEncoding::Device { planes } => *planes,
        _ => DepthPlanes { near: 0.01, far: 1e4 },
    }
}

/// The one-eye stereo frame and target camera of [`Method::Gather3d`]: the source is the left
/// eye; the right eye is a copy with no valid depth, so the cyclopean walk never takes it.
pub fn one_eye_frame(src: &ReprojectSource, geometry: &Geometry) -> Result<(StereoFrame, MiddleCamera)> {
    src.validate()?;
    let (depth, kind) = cyclopean_depth(src);
    let (view, proj, target) = match *geometry {
        Geometry::Rig { camera, shift } => {
            shift.validate()?;
            camera.validate("rig camera")?;
            if (camera.width, camera.height) != (src.color.width, src.color.height) {
                return Err(Error::SizeMismatch {
                    message: format!(
                        "rig camera {}x{} vs source {}x{}",
                        camera.width, camera.height, src.color.width, src.color.height
                    ),
                });
            }
            let planes = planes_of(&src.depth_kind);
            let mut tcam = camera;
            tcam.k.cx += shift.a_px;
            // OpenCV x of the target in the source frame: u_t = u_s - fx t / Z + a.
            let t = shift.b_px / camera.k.fx;
            let target = MiddleCamera {
                view: Pose::at([t, 0.0, 0.0]).gl_view(),
                proj: gl_projection(&tcam, &planes, &src.conv),
                width: camera.width,
                height: camera.height,
            };
            (
                Pose::IDENTITY.gl_view(),
                gl_projection(&camera, &planes, &src.conv),
                target,
            )
        }
        Geometry::Matrices {
            source_view,
            source_proj,
            target,
        } => {
            for (what, m) in [("target view", &target.view), ("target projection", &target.proj)] {
                if m.iter().flatten().any(|v| !v.is_finite()) || mat4::inverse(m).is_none() {
                    return Err(Error::param(what, "not finite or not invertible"));
                }
            }
            (source_view, source_proj, target)
        }
    };
    let far = match kind {
        FrameDepth::Device => src.conv.clear_depth() as f32,
        FrameDepth::ViewZ => 0.0,
    };
    let eye = EyeInput {
        color: src.color.clone(),
        depth,
        view,
        proj,
    };
    let mut empty = eye.clone();
    empty.depth.data.iter_mut().for_each(|z| *z = far);
    let frame = StereoFrame {
        left: eye,
        right: empty,
        depth_kind: kind,
        conv: src.conv,
    };
    frame.validate()?;
    Ok((frame, target))
}

/// Initial distance of the 3-D walk: the zero-parallax distance b / a where it lies inside the
/// frame's depth range, else the harmonic middle of that range.
pub fn fixation_distance(src: &ReprojectSource, geometry: &Geometry) -> f64 {
    let (q_lo, q_hi) = src.inverse_depth_range().unwrap_or((1.0, 1.0));
    if let Geometry::Rig { shift, .. } = geometry {
        if shift.a_px != 0.0 {
            let q0 = shift.a_px / shift.b_px;
            if q0.is_finite() && q0 >= q_lo && q0 <= q_hi {
                return 1.0 / q0;
            }
        }
    }
    2.0 / (q_lo + q_hi)
}

/// Cyclopean parameters of the two walks of [`Method::Gather3d`]: from the fixation distance
/// above and from the nearest depth of the frame (1 / q_max). The cyclopean walk converges to
/// one fixed point of its start; starting also from the near side finds a foreground surface
/// the first walk slides past, and [`merge_nearer`] keeps the nearer verified result.
pub fn gather3d_params(
    src: &ReprojectSource,
    geometry: &Geometry,
    steps: u32,
) -> [crate::stereo::gather::CyclopeanParams; 2] {
    let fix = fixation_distance(src, geometry);
    let near = src.inverse_depth_range().map_or(fix, |(_, q_hi)| 1.0 / q_hi);
    [fix, near].map(|f| crate::stereo::gather::CyclopeanParams {
        method: crate::stereo::gather::Method::Refine { steps },
        ..crate::stereo::gather::CyclopeanParams::seed(f)
    })
}

/// Per pixel, whether the second of two results replaces the first: it is valid and the first
/// is not, or both are and it is strictly nearer (ties keep the first).
pub fn merge_nearer(first: (bool, f64), second: (bool, f64)) -> bool {
    second.0 && (!first.0 || second.1 < first.1)
}

/// Checks shared by both implementations; returns the shift model for the shift methods.
pub(crate) fn check(
    src: &ReprojectSource,
    geometry: &Geometry,
    params: &ReprojectParams,
) -> Result<Option<ShiftModel>> {
    src.validate()?;
    params.validate()?;
    match (params.method, geometry) {
        (Method::Gather3d { .. }, _) => Ok(None),
        (_, Geometry::Rig { camera, shift }) => {
            shift.validate()?;
            if (camera.width, camera.height) != (src.color.width, src.color.height) {
                return Err(Error::SizeMismatch {
                    message: format!(
                        "rig camera {}x{} vs source {}x{}",
                        camera.width, camera.height, src.color.width, src.color.height
                    ),
                });
            }
            Ok(Some(*shift))
        }
        (_, Geometry::Matrices { .. }) => Err(Error::param(
            "method",
            "the shift methods need a parallel rig (Geometry::Rig); use Gather3d with full matrices",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::stereo::reproject_texture_x;

    #[test]
    fn a_source_without_valid_depth_is_refused_by_name() {
        let source = |z: Vec<f32>| ReprojectSource {
            color: RgbImage::new(2, 1, vec![0; 6]).unwrap(),
            depth: DepthMap::new(2, 1, z).unwrap(),
            depth_kind: DepthEncoding::ViewZ,
            conv: Conventions::default(),
        };
        let e = source(vec![0.0, f32::NAN]).require_valid_depth("view Z").unwrap_err();
        assert_eq!(e.to_string(), "no pixel holds valid depth as view Z");
        let (lo, hi) = source(vec![2.0, 4.0]).require_valid_depth("view Z").unwrap();
        assert_eq!((lo, hi), (0.25, 0.5));
    }

    #[test]
    fn seed_model_matches_reproject_texture_x_in_pixels() {
        let p = StereoParams::new(0.03, 2.5).unwrap();
        let w = 640u32;
        let views = [Some(Eye::Left), None, Some(Eye::Right)];
        for from in views {
            for to in views {
                let m = ShiftModel::seed(&p, w, from, to);
                for (u, z) in [(10.0, 0.7), (320.0, 2.5), (600.25, 40.0)] {
                    let tex = (u + 0.5) / w as f64;
                    let want = reproject_texture_x(tex, from, to, 0.03, 2.5, z).unwrap() * w as f64 - 0.5;
                    let got = m.forward(u, 1.0 / z);
                    assert!((got - want).abs() < 1e-9, "{from:?}->{to:?}: {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn rectified_model_is_middlebury_disparity() {
        let (f, b, doffs) = (994.978, 0.193001, 31.086);
        let m = ShiftModel::rectified(f, b, doffs, Some(Eye::Left), Some(Eye::Right)).unwrap();
        let kind = DepthEncoding::Disparity {
            focal_px: f,
            baseline: b,
            doffs,
        };
        let conv = Conventions::default();
        for d in [7.19, 30.0, 59.91] {
            let q = kind.inverse_depth(&conv, d).unwrap();
            assert!((m.forward(400.0, q) - (400.0 - d)).abs() < 1e-9);
        }
        for bad in [0.0, -1.0, f64::INFINITY, f64::NAN] {
            assert!(kind.inverse_depth(&conv, bad).is_none(), "{bad}");
        }
        assert!(ShiftModel::rectified(0.0, b, doffs, None, Some(Eye::Right)).is_err());
    }

    #[test]
    fn device_depth_inverse_is_exact_under_every_convention() {
        let planes = DepthPlanes { near: 0.05, far: 100.0 };
        let kind = DepthEncoding::Device { planes };
        for conv in Conventions::all() {
            for z in [0.06, 1.0, 6.0, 90.0] {
                let ndc = planes.ndc_z_of_view_z(&conv, z);
                let d = DepthPlanes::window_depth_of_ndc_z(&conv, ndc);
                let q = kind.inverse_depth(&conv, d).unwrap();
                assert!((q * z - 1.0).abs() < 1e-9, "{conv:?} {z}: {}", 1.0 / q);
            }
            assert!(kind.inverse_depth(&conv, conv.clear_depth()).is_none());
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(ReprojectParams::new(Method::Shift { steps: 0 }).validate().is_err());
        assert!(ReprojectParams::new(Method::Gather3d { steps: 17 }).validate().is_err());
        let p = ReprojectParams {
            tau_rel: f64::NAN,
            ..ReprojectParams::new(Method::ShiftScan)
        };
        assert!(p.validate().is_err());
        assert!(DepthEncoding::Device {
            planes: DepthPlanes { near: 0.0, far: 1.0 }
        }
        .validate()
        .is_err());
        assert!(DepthEncoding::Disparity {
            focal_px: 1.0,
            baseline: 1.0,
            doffs: f64::NAN
        }
        .validate()
        .is_err());
    }
}
