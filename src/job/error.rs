//! The two ways a job fails: its options do not make a job ([`ArgError`], found before any
//! work), or running it failed ([`JobError`]). Each message names the option or file at fault,
//! worded as the command line gives them.

use crate::field::{Field, Message, Spelling};
use crate::msg;
use std::path::PathBuf;

/// Options that do not make a valid job: refused in the conversion from the command line,
/// before any input is read, GPU opened or file written. The options named are [`Field`]s:
/// `Display` spells them as the command line does, [`ArgError::spelled`] as a front end does.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ArgError {
    /// A library rule refused a value (intrinsics, break rule, outputs, sizes, ...).
    #[error(transparent)]
    Invalid(#[from] crate::Error),
    /// A library rule refused the value of the options named.
    #[error("{options}")]
    InvalidOptions {
        /// The options, e.g. `--near/--far`.
        options: Message,
        /// Why the library refused them.
        #[source]
        source: crate::Error,
    },
    /// `--device` is neither `auto`, `surfaceless` nor an index.
    #[error("{}", self.message())]
    Device {
        /// The value given.
        value: String,
        /// Why it is no index.
        #[source]
        source: std::num::ParseIntError,
    },
    /// An entry of `--depth-format` names no depth file format.
    #[error("{}", self.message())]
    DepthFormat(String),
    /// `--depth-preview` without a depth output to colour.
    #[error("{}", self.message())]
    PreviewWithoutDepth,
    /// A source intrinsic (`--fx`, `--fy`, `--cx` or `--cy`) is given neither by flag nor by
    /// `--intrinsics`.
    #[error("{}", self.message())]
    MissingIntrinsic(Field),
    /// A command that also takes full eye matrices got neither intrinsics nor `--cameras`.
    #[error("{}", self.message())]
    MissingIntrinsicsOrCameras,
    /// Device depth without the planes it was written with.
    #[error("{}", self.message())]
    DevicePlanesMissing(&'static str),
    /// `--near/--far` with a depth kind that has no planes.
    #[error("{}", self.message())]
    PlanesWithoutDevice,
    /// One frame's colour or depth is missing (clap requires both without `--batch`).
    #[error("{}", self.message())]
    PerFrameInput,
    /// An option that holds for one frame given to a batch.
    #[error("{0}")]
    PerFrameInBatch(PerFrameOption),
    /// More CPU threads than a pool takes.
    #[error("{}", self.message())]
    TooManyJobs {
        /// Threads asked for.
        jobs: usize,
        /// The most a pool takes.
        max: usize,
    },
    /// Cyclopean disparities and depth input both given.
    #[error("{}", self.message())]
    DisparityAndDepth,
    /// Cyclopean depth input without one of its three parts.
    #[error("{}", self.message())]
    DepthInputMissing(Field),
    /// A disparity-rig value without its partner.
    #[error("{}", self.message())]
    RigPartner(Field, Field),
    /// `--depth-scale` with disparity inputs.
    #[error("{}", self.message())]
    DepthScaleWithDisparity,
    /// A disparity-rig option given with a camera file.
    #[error("{}", self.message())]
    RigOptionWithCameraFile(Field),
    /// `--dominant` without the `eye:weight` form.
    #[error("{}", self.message())]
    DominantForm(String),
    /// `--dominant` names no eye.
    #[error("{}", self.message())]
    DominantEye(String),
    /// `--dominant`'s weight is no number.
    #[error("{}", self.message())]
    DominantWeight {
        /// The value given.
        value: String,
        /// Why the weight is no number.
        #[source]
        source: std::num::ParseFloatError,
    },
    /// A seed/refine option with another cyclopean method.
    #[error("{}", self.message())]
    GatherOptionOnly(Field),
    /// A decoding option for disparity or depth files with two images alone.
    #[error("{}", self.message())]
    DecodeWithoutMaps(Field),
    /// A matcher option with disparities or depth given.
    #[error("{}", self.message())]
    MatcherOptionWithMaps(Field),
    /// A metric depth output asked of disparities without a calibration.
    #[error("{}", self.message())]
    DepthOutputNotMetric,
    /// `--to both` from an eye.
    #[error("{}", self.message())]
    BothFromEye,
    /// The target view is the source view.
    #[error("{}", self.message())]
    TargetIsSource,
    /// Disparity depth without the baseline that makes it metric.
    #[error("{}", self.message())]
    DisparityWithoutBaseline,
    /// A reprojection rig neither rectified nor game-engine.
    #[error("{}", self.message())]
    NoRig,
    /// Both rigs given.
    #[error("{}", self.message())]
    RigConflict,
    /// A scale option outside (0, inf).
    #[error("{}", self.message())]
    Scale {
        /// The option, e.g. `--disparity-scale`.
        option: Field,
        /// The value given.
        value: f64,
    },
    /// A camera file's source must be an eye.
    #[error("{}", self.message())]
    CameraFileFromCentre,
    /// Full eye matrices with a shift method.
    #[error("{}", self.message())]
    CameraFileNeedsGather,
    /// The middle camera is a camera file's.
    #[error("{}", self.message())]
    CentreTargetNeedsCameras,
    /// Depth kind or conventions given with a camera file that carries its own.
    #[error("{}", self.message())]
    CameraFileOverridden,
    /// `--overlap` alone outside the faces it implies.
    #[error("{}", self.message())]
    Overlap(f64),
    /// The face field of view outside (90, 178) degrees.
    #[error("{}", self.message())]
    FaceFov(f64),
    /// `scene --face-fov` outside (90, 178) degrees.
    #[error("{}", self.message())]
    CubeFaceFov(f64),
    /// A scene other than `demo` for stitching.
    #[error("{}", self.message())]
    StitchScene(String),
    /// Stitch ground truth without the built-in scene.
    #[error("{}", self.message())]
    TruthWithoutScene,
    /// A top-bottom ODS image taller than image files hold.
    #[error("{}", self.message())]
    TopBottomTooTall {
        /// Width per eye.
        width: u32,
        /// Height per eye.
        height: u32,
        /// The image files' side limit.
        max: u32,
    },
    /// `--faces` is no folder.
    #[error("{}", self.message())]
    FacesNotADirectory(PathBuf),
    /// `--depth-kind` with the built-in scene's faces.
    #[error("{}", self.message())]
    FaceDepthKindWithoutFaces,
    /// A negative or non-finite interocular distance.
    #[error("invalid ipd {0}: must be finite and >= 0")]
    Ipd(f64),
    /// Compare's planes out of order.
    #[cfg(feature = "compare")]
    #[error("{}", self.message())]
    ComparePlanes {
        /// The options, e.g. `--b-near/--b-far`.
        options: Message,
        /// The near plane given.
        near: f64,
        /// The far plane given.
        far: f64,
    },
    /// A compare side's device or NDC depth without the planes it was written with.
    #[cfg(feature = "compare")]
    #[error("{}", self.message())]
    ComparePlanesMissing {
        /// `A` or `B`.
        side: char,
        /// `device` or `ndc`.
        kind: &'static str,
    },
    /// A compare convention option that cannot change the reading of the side it names.
    #[cfg(feature = "compare")]
    #[error("{}", self.message())]
    CompareNotApplicable {
        /// The option, e.g. `--b-ndc`.
        option: Message,
        /// Why it changes nothing there.
        why: Message,
    },
}

/// "give the source intrinsics: --intrinsics FILE or --fx --fy --cx --cy", the start of two
/// refusals.
fn give_intrinsics() -> Message {
    msg![
        "give the source intrinsics: ",
        Field::Intrinsics,
        " FILE or ",
        Field::Fx,
        " ",
        Field::Fy,
        " ",
        Field::Cx,
        " ",
        Field::Cy
    ]
}

impl ArgError {
    /// The refusal with the options it names as fields; the wrappers of a library error
    /// (`Invalid`, `InvalidOptions`) give their own text (see [`ArgError::spelled`]).
    fn message(&self) -> Message {
        use Field as F;
        match self {
            ArgError::Invalid(e) => msg![e.to_string()],
            ArgError::InvalidOptions { options, .. } => options.clone(),
            ArgError::Device { value, .. } => {
                msg![F::Device, format!(" '{value}': expected auto, surfaceless or an index")]
            }
            ArgError::DepthFormat(v) => {
                msg![F::DepthFormat, format!(" '{v}': expected exr, npy, png16 or a list such as exr,png16")]
            }
            ArgError::PreviewWithoutDepth => {
                msg![F::DepthPreview, " colours the depth output: add depth to ", F::Outputs]
            }
            ArgError::MissingIntrinsic(f) => msg![give_intrinsics(), " (", *f, " is missing)"],
            ArgError::MissingIntrinsicsOrCameras => {
                msg![give_intrinsics(), " (or full eye matrices: ", F::Cameras, " FILE)"]
            }
            ArgError::DevicePlanesMissing(what) => msg![
                F::DepthKind,
                " device needs ",
                F::Near,
                " and ",
                F::Far,
                format!(" (the planes {what} was written with)")
            ],
            ArgError::PlanesWithoutDevice => {
                msg![F::Near, "/", F::Far, " apply to ", F::DepthKind, " device only"]
            }
            ArgError::PerFrameInput => msg![F::Rgb, " and ", F::Depth, " are required without ", F::Batch],
            ArgError::PerFrameInBatch(o) => o.message(),
            ArgError::TooManyJobs { jobs, max } => msg![F::Jobs, format!(" {jobs}: at most {max}")],
            ArgError::DisparityAndDepth => msg![
                "give disparities (",
                F::LeftDisparity,
                ", ",
                F::RightDisparity,
                ") or depth (",
                F::LeftDepth,
                ", ",
                F::RightDepth,
                ", ",
                F::Cameras,
                "), not both"
            ],
            ArgError::DepthInputMissing(f) => msg![
                *f,
                " is missing: depth input needs ",
                F::LeftDepth,
                ", ",
                F::RightDepth,
                " and ",
                F::Cameras
            ],
            ArgError::RigPartner(a, b) => {
                msg![*a, " needs ", *b, " too (both or neither: together they make depth metric)"]
            }
            ArgError::DepthScaleWithDisparity => msg![
                F::DepthScale,
                " is for ",
                F::LeftDepth,
                "/",
                F::RightDepth,
                "; use ",
                F::DisparityScale,
                " with disparities"
            ],
            ArgError::RigOptionWithCameraFile(f) => msg![
                *f,
                " is for ",
                F::LeftDisparity,
                "/",
                F::RightDisparity,
                "; the camera file places the view"
            ],
            ArgError::DominantForm(v) => msg![F::Dominant, format!(" '{v}': expected left:W or right:W")],
            ArgError::DominantEye(v) => msg![F::Dominant, format!(" '{v}': eye must be left or right")],
            ArgError::DominantWeight { value, .. } => msg![F::Dominant, format!(" '{value}': weight")],
            ArgError::GatherOptionOnly(f) => msg![*f, " applies to ", F::Method, " seed or refine only"],
            ArgError::DecodeWithoutMaps(f) => msg![
                *f,
                " decodes disparity or depth files; with two images alone the disparities are estimated"
            ],
            ArgError::MatcherOptionWithMaps(f) => {
                msg![*f, " applies to two images alone (the disparities are then estimated)"]
            }
            ArgError::DepthOutputNotMetric => msg![
                F::Outputs,
                " depth needs ",
                F::Focal,
                " and ",
                F::Baseline,
                " (the depth is metric)"
            ],
            ArgError::BothFromEye => msg![
                F::To,
                " both needs ",
                F::From,
                " centre (from an eye, the only other view is the other eye)"
            ],
            ArgError::TargetIsSource => msg![F::To, " is the source view itself (", F::From, "): nothing to reproject"],
            ArgError::DisparityWithoutBaseline => msg![
                F::DepthKind,
                " disparity needs ",
                F::Baseline,
                " (metres; Z = baseline * focal / (d + doffs))"
            ],
            ArgError::NoRig => msg![
                "give the rig: ",
                F::Baseline,
                " B (rectified, metres) or ",
                F::Separation,
                " S ",
                F::Convergence,
                " C (game-engine stereo)"
            ],
            ArgError::RigConflict => msg![
                F::Baseline,
                " (rectified rig) and ",
                F::Separation,
                "/",
                F::Convergence,
                " (game-engine rig) conflict: give one (",
                F::Baseline,
                " goes with ",
                F::Separation,
                " only to make ",
                F::DepthKind,
                " disparity metric)"
            ],
            ArgError::Scale { option, value } => msg!["invalid ", *option, format!(" {value}: must be finite and > 0")],
            ArgError::CameraFileFromCentre => msg![F::Cameras, " holds the two eyes: ", F::From, " left or right"],
            ArgError::CameraFileNeedsGather => msg![
                F::Cameras,
                " (full eye matrices) renders by ",
                F::Method,
                " gather3d (its default): the shift methods need a parallel rig"
            ],
            ArgError::CentreTargetNeedsCameras => msg![
                F::To,
                " centre (middle) needs ",
                F::Cameras,
                ": a rig's centre is a source (",
                F::From,
                " centre), not a target"
            ],
            ArgError::CameraFileOverridden => msg![
                F::Cameras,
                ": the depth kind and the conventions come from the file; drop ",
                F::DepthKind,
                "/",
                F::Ndc,
                "/",
                F::ReversedZ,
                "/",
                F::Rows
            ],
            ArgError::Overlap(v) => msg![
                F::Overlap,
                format!(" {v}: must be in (0, 44) degrees (faces of 90 + 2 x overlap; or give "),
                F::Fov,
                ")"
            ],
            ArgError::FaceFov(v) => msg![F::Fov, format!(" {v}: the face field of view must be in (90, 178) degrees")],
            ArgError::CubeFaceFov(v) => msg![
                F::FaceFov,
                format!(" {v}: the cube faces' field of view must be in (90, 178) degrees (stitch "),
                F::Faces,
                " needs over-wide faces)"
            ],
            ArgError::StitchScene(v) => msg![
                F::Scene,
                format!(" '{v}': only the built-in `demo` scene has cube faces (use "),
                F::Faces,
                " DIR for your own)"
            ],
            ArgError::TruthWithoutScene => msg![
                F::Truth,
                " needs ",
                F::Scene,
                " demo (the ground truth is ray-traced from the built-in scene)"
            ],
            ArgError::TopBottomTooTall { width, height, max } => msg![
                F::Width,
                "/",
                F::Height,
                format!(
                    " {width}x{height}: the top-bottom image ({width}x{}) exceeds the image files' limit of {max} px per side",
                    2 * *height as u64
                )
            ],
            ArgError::FacesNotADirectory(p) => msg![F::Faces, format!(" {}: not a directory", p.display())],
            ArgError::FaceDepthKindWithoutFaces => msg![
                F::DepthKind,
                " applies to ",
                F::Faces,
                " (the built-in scene's faces hold view Z)"
            ],
            ArgError::Ipd(v) => msg![format!("invalid ipd {v}: must be finite and >= 0")],
            #[cfg(feature = "compare")]
            ArgError::ComparePlanes { options, near, far } => msg![
                "invalid ",
                options,
                format!(" {near} / {far}: need 0 < near < far (far may be inf)")
            ],
            #[cfg(feature = "compare")]
            ArgError::ComparePlanesMissing { side, kind } => {
                let (near, far) = match side {
                    'A' => (F::ANear, F::AFar),
                    _ => (F::BNear, F::BFar),
                };
                msg![
                    format!("{side}'s depth is {kind} depth: give the planes it was written with, "),
                    near,
                    " N ",
                    far,
                    " F (far may be inf; ",
                    F::Near,
                    "/",
                    F::Far,
                    " set both sides)"
                ]
            }
            #[cfg(feature = "compare")]
            ArgError::CompareNotApplicable { option, why } => msg![option, " does not apply: ", why],
        }
    }

    /// The refusal with the options it names spelled as `spelling` writes them (`Display` is
    /// [`Spelling::Cli`]'s). A library error inside is spelled the same way; its own source
    /// (an I/O error, ...) is not part of it.
    pub fn spelled(&self, spelling: Spelling) -> String {
        match self {
            ArgError::Invalid(e) => e.spelled(spelling),
            other => other.message().spelled(spelling),
        }
    }

    /// The fields the refusal names, in order (for a library error inside, its own).
    pub fn fields(&self) -> Vec<Field> {
        match self {
            ArgError::Invalid(e) => e.fields(),
            other => other.message().fields().collect(),
        }
    }

    /// Whether the command line itself is at fault (exit 2): true for every refusal except
    /// one found reading a file an option names (`--intrinsics FILE` that does not parse,
    /// does not exist, ...), which is an input found while running (exit 1).
    pub fn is_usage(&self) -> bool {
        let lib = match self {
            ArgError::Invalid(e) | ArgError::InvalidOptions { source: e, .. } => e,
            _ => return true,
        };
        !matches!(lib, crate::Error::Io { .. } | crate::Error::Decode { .. })
    }
}

/// Options that hold for one frame, refused with `refocus --batch`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PerFrameOption {
    /// `--intrinsics`, `--fx`, `--fy`, `--cx`, `--cy` (kept for callers; refocus --batch now
    /// takes them as defaults of rows lacking them).
    Intrinsics,
    /// `--focal-list`.
    FocalList,
    /// `--sun-bit-rotate` (a manifest column).
    SunBitRotate,
    /// `--npz-key`.
    NpzKey,
}

impl PerFrameOption {
    /// The refusal, naming the options.
    fn message(self) -> Message {
        use Field as F;
        match self {
            PerFrameOption::Intrinsics => msg![
                F::Intrinsics,
                "/",
                F::Fx,
                "/",
                F::Fy,
                "/",
                F::Cx,
                "/",
                F::Cy,
                " are per frame: with ",
                F::Batch,
                " they come from the manifest"
            ],
            PerFrameOption::FocalList => msg![
                F::FocalList,
                " is per frame; with ",
                F::Batch,
                " give ",
                F::ZoomRange,
                " scales"
            ],
            PerFrameOption::SunBitRotate => msg![
                F::SunBitRotate,
                " is per frame: with ",
                F::Batch,
                " give the manifest a sun_bit_rotate column"
            ],
            PerFrameOption::NpzKey => msg![
                F::NpzKey,
                " is per frame: with ",
                F::Batch,
                " give depth files the key is not needed for"
            ],
        }
    }
}

impl std::fmt::Display for PerFrameOption {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.message().fmt(f)
    }
}

/// A job that failed while running; nothing of its output was written (files are all-or-none).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum JobError {
    /// The library failed (a file, the GPU, a value found in the data).
    #[error(transparent)]
    Lib(#[from] crate::Error),
    /// An option checked against the data or the file system while running.
    #[error(transparent)]
    Arg(#[from] ArgError),
    /// The library failed on the inputs named.
    #[error("{context}")]
    In {
        /// What was being done, e.g. the two files of a source.
        context: Message,
        /// The failure.
        #[source]
        source: crate::Error,
    },
    /// Frames of a batch failed while the others completed.
    #[error("{failed} of {total} frames failed (listed above); the others completed")]
    FramesFailed {
        /// Frames that failed.
        failed: usize,
        /// Frames in the manifest.
        total: usize,
    },
    /// The two eyes' faces differ in size.
    #[error("{}", msg![Field::Faces, format!(" {}: size mismatch: left faces {left}x{left}, right faces {right}x{right}", .dir.display())])]
    FaceSizes {
        /// The face folder.
        dir: PathBuf,
        /// Left face side.
        left: u32,
        /// Right face side.
        right: u32,
    },
}

/// Attaches what was being done to a library error (the binary prints "context: error").
pub trait InContext<T> {
    /// The error, if any, as [`JobError::In`].
    fn within<C: Into<Message>>(self, context: impl FnOnce() -> C) -> Result<T, JobError>;
}

impl<T> InContext<T> for crate::Result<T> {
    fn within<C: Into<Message>>(self, context: impl FnOnce() -> C) -> Result<T, JobError> {
        self.map_err(|source| JobError::In {
            context: context().into(),
            source,
        })
    }
}

/// As [`InContext`], for refusals found in the conversion.
pub(crate) trait OptionsContext<T> {
    /// The error, if any, as [`ArgError::InvalidOptions`] naming `options`.
    fn for_options(self, options: impl Into<Message>) -> Result<T, ArgError>;
}

impl<T> OptionsContext<T> for crate::Result<T> {
    fn for_options(self, options: impl Into<Message>) -> Result<T, ArgError> {
        self.map_err(|source| ArgError::InvalidOptions {
            options: options.into(),
            source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refusal_names_its_options_in_each_front_ends_spelling() {
        let e = ArgError::BothFromEye;
        assert_eq!(
            e.to_string(),
            "--to both needs --from centre (from an eye, the only other view is the other eye)"
        );
        assert_eq!(
            e.spelled(Spelling::Python),
            "target both needs source centre (from an eye, the only other view is the other eye)"
        );
        assert_eq!(e.fields(), [Field::To, Field::From]);
        let e = ArgError::RigPartner(Field::Focal, Field::Baseline);
        assert!(
            e.spelled(Spelling::Python).starts_with("focal needs baseline too"),
            "{e}"
        );
        // A library error inside is spelled the same way; a text name stays as written.
        let e = ArgError::Invalid(crate::Error::param(msg![Field::Near, "/", Field::Far], "0 / 0"));
        assert_eq!(e.to_string(), "invalid --near/--far: 0 / 0");
        assert_eq!(e.spelled(Spelling::Python), "invalid near/far: 0 / 0");
        assert_eq!(e.fields(), [Field::Near, Field::Far]);
        let e = ArgError::Invalid(crate::Error::param("tau-rel", "-1 must be >= 0"));
        assert_eq!(e.spelled(Spelling::Python), "invalid tau-rel: -1 must be >= 0");
        assert!(e.fields().is_empty());
    }
}
