//! The two ways a job fails: its options do not make a job ([`ArgError`], found before any
//! work), or running it failed ([`JobError`]). Each message names the option or file at fault,
//! worded as the command line gives them.

use std::path::PathBuf;

/// Options that do not make a valid job: refused in the conversion from the command line,
/// before any input is read, GPU opened or file written.
#[derive(Debug, thiserror::Error)]
pub enum ArgError {
    /// A library rule refused a value (intrinsics, break rule, outputs, sizes, ...).
    #[error(transparent)]
    Invalid(#[from] crate::Error),
    /// A library rule refused the value of the options named.
    #[error("{options}")]
    InvalidOptions {
        /// The options, e.g. `--near/--far`.
        options: String,
        /// Why the library refused them.
        #[source]
        source: crate::Error,
    },
    /// `--device` is neither `auto`, `surfaceless` nor an index.
    #[error("--device '{value}': expected auto, surfaceless or an index")]
    Device {
        /// The value given.
        value: String,
        /// Why it is no index.
        #[source]
        source: std::num::ParseIntError,
    },
    /// An entry of `--depth-format` names no depth file format.
    #[error("--depth-format '{0}': expected exr, npy, png16 or a list such as exr,png16")]
    DepthFormat(String),
    /// `--depth-preview` without a depth output to colour.
    #[error("--depth-preview colours the depth output: add depth to --outputs")]
    PreviewWithoutDepth,
    /// A source intrinsic is given neither by flag nor by `--intrinsics`.
    #[error("give the source intrinsics: --intrinsics FILE or --fx --fy --cx --cy (--{0} is missing)")]
    MissingIntrinsic(&'static str),
    /// A command that also takes full eye matrices got neither intrinsics nor `--cameras`.
    #[error(
        "give the source intrinsics: --intrinsics FILE or --fx --fy --cx --cy (or full eye matrices: --cameras FILE)"
    )]
    MissingIntrinsicsOrCameras,
    /// Device depth without the planes it was written with.
    #[error("--depth-kind device needs --near and --far (the planes {0} was written with)")]
    DevicePlanesMissing(&'static str),
    /// `--near/--far` with a depth kind that has no planes.
    #[error("--near/--far apply to --depth-kind device only")]
    PlanesWithoutDevice,
    /// One frame's colour or depth is missing (clap requires both without `--batch`).
    #[error("--rgb and --depth are required without --batch")]
    PerFrameInput,
    /// An option that holds for one frame given to a batch.
    #[error("{0}")]
    PerFrameInBatch(PerFrameOption),
    /// More CPU threads than a pool takes.
    #[error("--jobs {jobs}: at most {max}")]
    TooManyJobs {
        /// Threads asked for.
        jobs: usize,
        /// The most a pool takes.
        max: usize,
    },
    /// Cyclopean disparities and depth input both given.
    #[error(
        "give disparities (--left-disparity, --right-disparity) or depth (--left-depth, --right-depth, --cameras), not both"
    )]
    DisparityAndDepth,
    /// Cyclopean depth input without one of its three parts.
    #[error("{0} is missing: depth input needs --left-depth, --right-depth and --cameras")]
    DepthInputMissing(&'static str),
    /// A disparity-rig value without its partner.
    #[error("{0} needs {1} too (both or neither: together they make depth metric)")]
    RigPartner(&'static str, &'static str),
    /// `--depth-scale` with disparity inputs.
    #[error("--depth-scale is for --left-depth/--right-depth; use --disparity-scale with disparities")]
    DepthScaleWithDisparity,
    /// A disparity-rig option given with a camera file.
    #[error("{0} is for --left-disparity/--right-disparity; the camera file places the view")]
    RigOptionWithCameraFile(&'static str),
    /// `--dominant` without the `eye:weight` form.
    #[error("--dominant '{0}': expected left:W or right:W")]
    DominantForm(String),
    /// `--dominant` names no eye.
    #[error("--dominant '{0}': eye must be left or right")]
    DominantEye(String),
    /// `--dominant`'s weight is no number.
    #[error("--dominant '{value}': weight")]
    DominantWeight {
        /// The value given.
        value: String,
        /// Why the weight is no number.
        #[source]
        source: std::num::ParseFloatError,
    },
    /// A seed/refine option with another cyclopean method.
    #[error("{0} applies to --method seed or refine only")]
    GatherOptionOnly(&'static str),
    /// A decoding option for disparity or depth files with two images alone.
    #[error("{0} decodes disparity or depth files; with two images alone the disparities are estimated")]
    DecodeWithoutMaps(&'static str),
    /// A matcher option with disparities or depth given.
    #[error("{0} applies to two images alone (the disparities are then estimated)")]
    MatcherOptionWithMaps(&'static str),
    /// A metric depth output asked of disparities without a calibration.
    #[error("--outputs depth needs --focal and --baseline (the depth is metric)")]
    DepthOutputNotMetric,
    /// `--to both` from an eye.
    #[error("--to both needs --from centre (from an eye, the only other view is the other eye)")]
    BothFromEye,
    /// The target view is the source view.
    #[error("--to is the source view itself (--from): nothing to reproject")]
    TargetIsSource,
    /// Disparity depth without the baseline that makes it metric.
    #[error("--depth-kind disparity needs --baseline (metres; Z = baseline * focal / (d + doffs))")]
    DisparityWithoutBaseline,
    /// A reprojection rig neither rectified nor game-engine.
    #[error("give the rig: --baseline B (rectified, metres) or --separation S --convergence C (game-engine stereo)")]
    NoRig,
    /// Both rigs given.
    #[error(
        "--baseline (rectified rig) and --separation/--convergence (game-engine rig) conflict: give one \
         (--baseline goes with --separation only to make --depth-kind disparity metric)"
    )]
    RigConflict,
    /// A scale option outside (0, inf).
    #[error("invalid {option} {value}: must be finite and > 0")]
    Scale {
        /// The option, e.g. `--disparity-scale`.
        option: &'static str,
        /// The value given.
        value: f64,
    },
    /// A camera file's source must be an eye.
    #[error("--cameras holds the two eyes: --from left or right")]
    CameraFileFromCentre,
    /// Full eye matrices with a shift method.
    #[error(
        "--cameras (full eye matrices) renders by --method gather3d (its default): the shift methods need a parallel rig"
    )]
    CameraFileNeedsGather,
    /// The middle camera is a camera file's.
    #[error("--to centre (middle) needs --cameras: a rig's centre is a source (--from centre), not a target")]
    CentreTargetNeedsCameras,
    /// Depth kind or conventions given with a camera file that carries its own.
    #[error(
        "--cameras: the depth kind and the conventions come from the file; drop --depth-kind/--ndc/--reversed-z/--rows"
    )]
    CameraFileOverridden,
    /// `--overlap` alone outside the faces it implies.
    #[error("--overlap {0}: must be in (0, 44) degrees (faces of 90 + 2 x overlap; or give --fov)")]
    Overlap(f64),
    /// The face field of view outside (90, 178) degrees.
    #[error("--fov {0}: the face field of view must be in (90, 178) degrees")]
    FaceFov(f64),
    /// `scene --face-fov` outside (90, 178) degrees.
    #[error("--face-fov {0}: the cube faces' field of view must be in (90, 178) degrees (stitch --faces needs over-wide faces)")]
    CubeFaceFov(f64),
    /// A scene other than `demo` for stitching.
    #[error("--scene '{0}': only the built-in `demo` scene has cube faces (use --faces DIR for your own)")]
    StitchScene(String),
    /// Stitch ground truth without the built-in scene.
    #[error("--truth needs --scene demo (the ground truth is ray-traced from the built-in scene)")]
    TruthWithoutScene,
    /// A top-bottom ODS image taller than image files hold.
    #[error(
        "--width/--height {width}x{height}: the top-bottom image ({width}x{}) exceeds the image files' limit of {max} px per side",
        2 * *height as u64
    )]
    TopBottomTooTall {
        /// Width per eye.
        width: u32,
        /// Height per eye.
        height: u32,
        /// The image files' side limit.
        max: u32,
    },
    /// `--faces` is no folder.
    #[error("--faces {}: not a directory", .0.display())]
    FacesNotADirectory(PathBuf),
    /// `--depth-kind` with the built-in scene's faces.
    #[error("--depth-kind applies to --faces (the built-in scene's faces hold view Z)")]
    FaceDepthKindWithoutFaces,
    /// A negative or non-finite interocular distance.
    #[error("invalid ipd {0}: must be finite and >= 0")]
    Ipd(f64),
    /// Compare's planes out of order.
    #[cfg(feature = "compare")]
    #[error("invalid {options} {near} / {far}: need 0 < near < far (far may be inf)")]
    ComparePlanes {
        /// The options, e.g. `--b-near/--b-far`.
        options: String,
        /// The near plane given.
        near: f64,
        /// The far plane given.
        far: f64,
    },
    /// A compare side's device or NDC depth without the planes it was written with.
    #[cfg(feature = "compare")]
    #[error(
        "{side}'s depth is {kind} depth: give the planes it was written with, --{s}-near N --{s}-far F \
         (far may be inf; --near/--far set both sides)",
        s = side.to_ascii_lowercase()
    )]
    ComparePlanesMissing {
        /// `A` or `B`.
        side: char,
        /// `device` or `ndc`.
        kind: &'static str,
    },
    /// A compare convention option that cannot change the reading of the side it names.
    #[cfg(feature = "compare")]
    #[error("{option} does not apply: {why}")]
    CompareNotApplicable {
        /// The option, e.g. `--b-ndc`.
        option: String,
        /// Why it changes nothing there.
        why: String,
    },
}

impl ArgError {
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

impl std::fmt::Display for PerFrameOption {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            PerFrameOption::Intrinsics => {
                "--intrinsics/--fx/--fy/--cx/--cy are per frame: with --batch they come from the manifest"
            }
            PerFrameOption::FocalList => "--focal-list is per frame; with --batch give --zoom-range scales",
            PerFrameOption::SunBitRotate => {
                "--sun-bit-rotate is per frame: with --batch give the manifest a sun_bit_rotate column"
            }
            PerFrameOption::NpzKey => "--npz-key is per frame: with --batch give depth files the key is not needed for",
        })
    }
}

/// A job that failed while running; nothing of its output was written (files are all-or-none).
#[derive(Debug, thiserror::Error)]
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
        context: String,
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
    #[error("--faces {}: size mismatch: left faces {left}x{left}, right faces {right}x{right}", .dir.display())]
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
    fn within(self, context: impl FnOnce() -> String) -> Result<T, JobError>;
}

impl<T> InContext<T> for crate::Result<T> {
    fn within(self, context: impl FnOnce() -> String) -> Result<T, JobError> {
        self.map_err(|source| JobError::In {
            context: context(),
            source,
        })
    }
}

/// As [`InContext`], for refusals found in the conversion.
pub(crate) trait OptionsContext<T> {
    /// The error, if any, as [`ArgError::InvalidOptions`] naming `options`.
    fn for_options(self, options: &str) -> Result<T, ArgError>;
}

impl<T> OptionsContext<T> for crate::Result<T> {
    fn for_options(self, options: &str) -> Result<T, ArgError> {
        self.map_err(|source| ArgError::InvalidOptions {
            options: options.to_string(),
            source,
        })
    }
}
