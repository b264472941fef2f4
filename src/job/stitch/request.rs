//! The stitch request: every ODS stitch setting both front ends give (the CLI's flags, Python's
//! keyword arguments), with one default and one set of checks.
//!
//! Why here: the Python binding used to resolve the face field of view and the seam overlap,
//! and the face depth's kind, planes and conventions, on its own; now both fill a
//! [`StitchRequest`] and [`StitchRequest::plan`] decides once.

use super::FaceDepth;
use crate::convention::{Conventions, NdcDepthRange, RowOrder};
use crate::depth::DepthEncoding;
use crate::io::{self};
use crate::job::error::OptionsContext;
use crate::job::reproject::device_depth;
use crate::job::ArgError;
use crate::output::OutputSet;
use crate::stitch::{FaceSet, Method, OdsRig, Side, StitchParams};
use serde::{Deserialize, Serialize};

/// The NDC depth range device depth was written with (`--ndc`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ndc {
    /// OpenGL: z in [-1, 1].
    #[default]
    Gl,
    /// Vulkan/D3D: z in [0, 1].
    Vulkan,
}

impl Ndc {
    /// The library's depth range.
    pub fn range(self) -> NdcDepthRange {
        match self {
            Ndc::Gl => NdcDepthRange::MinusOneToOne,
            Ndc::Vulkan => NdcDepthRange::ZeroToOne,
        }
    }
}

/// Every stitch setting a front end gives; [`Default`] holds the defaults of both.
#[derive(Debug, Clone, Serialize)]
pub struct StitchRequest {
    /// Face field of view, degrees (none: from `overlap`, else 110).
    pub fov: Option<f64>,
    /// Seam band half-width, degrees (none: from `fov`, else 10).
    pub overlap: Option<f64>,
    /// Stitch method.
    pub method: Method,
    /// Equirect width per eye.
    pub width: u32,
    /// Equirect height per eye.
    pub height: u32,
    /// Interpupillary distance, metres.
    pub ipd: f64,
    /// Latitude where the eye radius starts fading, degrees.
    pub pole_fade: f64,
    /// What face depth holds.
    pub depth_kind: FaceDepth,
    /// Near plane of device-depth faces.
    pub near: Option<f64>,
    /// Far plane of device-depth faces.
    pub far: Option<f64>,
    /// NDC depth range of device-depth faces and of the pass.
    pub ndc: Ndc,
    /// Reversed-Z device depth (and pass).
    pub reversed_z: bool,
    /// The outputs: rgb, depth (each eye's distance along its ODS rays); none: rgb.
    #[serde(serialize_with = "crate::job::outputs_text")]
    pub outputs: Option<OutputSet>,
}

impl Default for StitchRequest {
    fn default() -> Self {
        StitchRequest {
            fov: None,
            overlap: None,
            method: Method::Reproject,
            width: 2048,
            height: 1024,
            ipd: 0.064,
            pole_fade: 45.0,
            depth_kind: FaceDepth::ViewZ,
            near: None,
            far: None,
            ndc: Ndc::Gl,
            reversed_z: false,
            outputs: None,
        }
    }
}

/// A checked stitch: the faces' field of view, the rig, the pass and the face depth.
#[derive(Debug, Clone, Copy)]
pub struct StitchPlan {
    /// Face field of view, degrees.
    pub fov: f64,
    /// The ODS rig.
    pub rig: OdsRig,
    /// Method, overlap and size per eye.
    pub params: StitchParams,
    /// How face depth is read.
    pub depth_kind: DepthEncoding,
    /// Conventions of device-depth faces and of the pass.
    pub conventions: Conventions,
    /// The outputs asked for (rgb, depth).
    pub outputs: OutputSet,
}

impl StitchRequest {
    /// The outputs asked for: colour alone unless given.
    pub fn outputs(&self) -> OutputSet {
        self.outputs.unwrap_or(OutputSet::RGB)
    }

    /// The face field of view and the overlap: either alone sets the other.
    fn fov_and_overlap(&self) -> Result<(f64, f64), ArgError> {
        if let (None, Some(overlap)) = (self.fov, self.overlap) {
            if !(overlap > 0.0 && overlap < 44.0) {
                return Err(ArgError::Overlap(overlap));
            }
        }
        let (fov, overlap) = match (self.fov, self.overlap) {
            (None, None) => (110.0, 10.0),
            (Some(f), None) => (f, 0.5 * (f - 90.0)),
            (None, Some(v)) => (90.0 + 2.0 * v, v),
            (Some(f), Some(v)) => (f, v),
        };
        if !(fov > 90.0 && fov < 178.0) {
            return Err(ArgError::FaceFov(fov));
        }
        Ok((fov, overlap))
    }

    /// Checks the settings; `base` is the rig the faces come from (its ipd and pole fade are
    /// the request's), `rows` the pass's row order.
    pub fn plan(&self, base: OdsRig, rows: RowOrder) -> Result<StitchPlan, ArgError> {
        let (fov, overlap) = self.fov_and_overlap()?;
        let rig = OdsRig {
            ipd: self.ipd,
            pole_fade_start_deg: self.pole_fade,
            ..base
        };
        rig.validate()
            .for_options(crate::msg![crate::Field::Ipd, "/", crate::Field::PoleFade])?;
        let params = StitchParams {
            method: self.method,
            overlap_deg: overlap,
            width: self.width,
            height: self.height,
        };
        let template = FaceSet {
            rig,
            side: Side::Left,
            fov_deg: fov,
            faces: Vec::new(),
        };
        params.validate(&template).for_options(crate::msg![
            crate::Field::Overlap,
            "/",
            crate::Field::Fov,
            "/",
            crate::Field::Width,
            "/",
            crate::Field::Height
        ])?;
        // The GPU's limit is checked when rendering; the image files' bound is known now.
        let max = io::MAX_DIMENSION;
        if self.width > max || 2 * self.height as u64 > max as u64 {
            return Err(ArgError::TopBottomTooTall {
                width: self.width,
                height: self.height,
                max,
            });
        }
        io::check_output_pixels(
            crate::msg![crate::Field::Width, "/", crate::Field::Height, " (top-bottom)"],
            self.width,
            self.height.saturating_mul(2),
        )?;
        crate::stitch::render::check_outputs(self.outputs()).for_options(crate::Field::Outputs)?;
        let depth_kind = match (self.depth_kind, self.near, self.far) {
            (FaceDepth::ViewZ, None, None) => DepthEncoding::ViewZ,
            (FaceDepth::ViewZ, _, _) => return Err(ArgError::PlanesWithoutDevice),
            (FaceDepth::Device, near, far) => device_depth(near, far, "the faces' depth")?,
        };
        Ok(StitchPlan {
            fov,
            rig,
            params,
            depth_kind,
            conventions: Conventions {
                ndc_depth: self.ndc.range(),
                reversed_z: self.reversed_z,
                row_order: rows,
            },
            outputs: self.outputs(),
        })
    }
}
