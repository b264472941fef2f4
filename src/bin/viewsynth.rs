//! viewsynth command line: parse and validate arguments, call the library. anyhow lives here only.

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use viewsynth::camera::Intrinsics;
use viewsynth::convention::{Conventions, NdcDepthRange, RowOrder};
use viewsynth::gpu::{DeviceChoice, Gpu};
use viewsynth::io::{self, DepthDecode};
use viewsynth::refocus::job::{self, DepthFormats, Manifest, RgbFormat, TargetSpec};
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusSource, Refocuser};

#[derive(Parser)]
#[command(
    name = "viewsynth",
    version,
    about = "Headless GPU view synthesis from RGB-D and stereo images"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the GPU, GL version, EGL platform/device and limits this machine renders with.
    Info {
        #[command(flatten)]
        gpu: GpuArgs,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Re-render RGB + metric depth at other focal lengths (same pose).
    #[command(allow_negative_numbers = true)]
    Refocus(Box<RefocusArgs>),
    /// Synthesise the middle (spectator) view of a stereo pair from each eye's colour and depth.
    #[command(allow_negative_numbers = true)]
    Cyclopean(Box<CyclopeanArgs>),
    /// Reproject one view of a parallel stereo rig (left eye, centre view or right eye) to the
    /// other eye(s) from colour + depth (view Z, device depth or disparity); disocclusions stay
    /// invalid (mask 0), nothing is hole-filled.
    #[command(allow_negative_numbers = true)]
    Reproject(Box<ReprojectArgs>),
    /// Stitch an omni-directional stereo (ODS) 360 equirect (top-bottom, left eye on top) from
    /// six over-wide cube faces per eye: the built-in scene's, or your own from --faces DIR.
    #[command(allow_negative_numbers = true)]
    Stitch(Box<StitchArgs>),
    /// Ray-trace a ground-truth scene (built-in or JSON) on the GPU from a stereo rig: left, right
    /// and middle colour, view distance and device depth, and a cameras.json that
    /// `viewsynth cyclopean` reads.
    Scene {
        /// `demo`, `boxes`, or a scene JSON file (src/scene/shapes.rs).
        #[arg(long, default_value = "demo")]
        scene: String,
        #[arg(long, default_value_t = 640)]
        width: u32,
        #[arg(long, default_value_t = 480)]
        height: u32,
        /// Interocular distance in metres.
        #[arg(long, default_value_t = 0.064)]
        ipd: f64,
        #[command(flatten)]
        conv: ConventionArgs,
        #[arg(long, default_value = "out/scene")]
        out_dir: PathBuf,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// Compare two renderings (e.g. ours and a Vulkan renderer's) after converting row order,
    /// NDC depth range, reversed-Z and device vs linear depth; names a convention that fits far
    /// better than the declared one. Writes a diff image.
    Compare(Box<CompareArgs>),
    /// Render the built-in scene, refocus it at 5 scales, synthesise the cyclopean middle view of
    /// a stereo pair with each method, and write every output plus the error/run-time report.
    Demo {
        #[arg(long, default_value = "out/demo")]
        out_dir: PathBuf,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// Measure every method's error against ground truth (built-in scene, and real data when
    /// --data-dir holds ../shared/data's sets) next to its run time: report.{md,csv,svg}.
    Report {
        #[arg(long, default_value = "out/report")]
        out_dir: PathBuf,
        /// Folder with middlebury2003_cones/ and middlebury2003_teddy/ (skipped when absent).
        #[arg(long)]
        data_dir: Option<PathBuf>,
        /// A user cyclopean case with a reference middle view, laid out as `viewsynth scene`
        /// writes it (cameras.json, {left,right}_rgb.png, *_device_depth.exr, middle_rgb.png).
        /// Repeatable.
        #[arg(long = "case")]
        cases: Vec<PathBuf>,
        /// Timed repetitions per row (the median is reported).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// Benchmark refocus (mesh and full-screen paths) and cyclopean (2 x 1280x720 eyes) and print
    /// median timings.
    Bench {
        /// Sizes WxH to measure.
        #[arg(long, value_delimiter = ',', default_value = "640x480,1280x720")]
        sizes: Vec<String>,
        /// Repetitions per measurement (the median is reported).
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// Sweep stiff and extreme cases of every capability (focal scales 0.05..20, 1 mm..100 km,
    /// near/far 1e-7, standard vs reversed-Z, NaN/Inf depth, 1x1 to the largest image, parallel
    /// gaze, zero IPD, ...): GPU f32 against the f64 reference, as a table with the first failing
    /// case. Exits 1 if any case fails.
    Stress {
        /// Smaller images and sub-cases (what the test suite runs).
        #[arg(long)]
        quick: bool,
        /// Capabilities to sweep.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "camera,refocus,cyclopean,reproject,stitch"
        )]
        only: Vec<String>,
        /// Also write the rows as JSON here.
        #[arg(long)]
        json: Option<PathBuf>,
        #[command(flatten)]
        gpu: GpuArgs,
    },
}

#[derive(Args, Clone)]
struct GpuArgs {
    /// EGL device: auto (CUDA_VISIBLE_DEVICES match, else first device, else Mesa
    /// surfaceless), an index from `viewsynth info`, or `surfaceless`.
    #[arg(long, default_value = "auto")]
    device: String,
}

impl GpuArgs {
    fn open(&self) -> Result<Gpu> {
        let choice = match self.device.as_str() {
            "auto" => DeviceChoice::Auto,
            "surfaceless" => DeviceChoice::Surfaceless,
            n => DeviceChoice::Index(
                n.parse()
                    .with_context(|| format!("--device '{n}': expected auto, surfaceless or an index"))?,
            ),
        };
        Ok(Gpu::new(choice)?)
    }
}

/// The convention switches of a rendering command.
#[derive(Args, Clone, Copy)]
struct ConventionArgs {
    #[arg(long, value_enum, default_value = "gl")]
    ndc: NdcArg,
    #[arg(long)]
    reversed_z: bool,
    #[arg(long, value_enum, default_value = "bottom-up")]
    rows: RowsArg,
}

impl ConventionArgs {
    fn conventions(&self) -> Conventions {
        conventions(self.ndc, self.reversed_z, self.rows)
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum NdcArg {
    /// OpenGL: NDC z in [-1, 1].
    Gl,
    /// Vulkan/D3D: NDC z in [0, 1].
    Vulkan,
}

#[derive(Clone, Copy, ValueEnum)]
enum RowsArg {
    BottomUp,
    TopDown,
}

#[derive(Clone, Copy, ValueEnum)]
enum MethodArg {
    Mesh,
    Fullscreen,
}

#[derive(Clone, Copy, ValueEnum)]
enum RgbFormatArg {
    Png,
    Jpeg,
    Exr,
}

/// Which outputs to write and in which file formats (refocus, batch and reproject).
#[derive(Args, Clone)]
struct FileOutputArgs {
    /// Outputs to produce: any of rgb (or color), depth, mask.
    #[arg(long, default_value = "rgb,depth,mask")]
    outputs: String,
    #[arg(long, value_enum, default_value = "png")]
    rgb_format: RgbFormatArg,
    /// Depth file formats: exr, npy or both.
    #[arg(long, default_value = "exr")]
    depth_format: String,
}

impl FileOutputArgs {
    fn parse(&self) -> Result<(OutputSet, RgbFormat, DepthFormats)> {
        let outputs = OutputSet::parse(&self.outputs.replace("colour", "rgb").replace("color", "rgb"))?;
        let rgb = match self.rgb_format {
            RgbFormatArg::Png => RgbFormat::Png,
            RgbFormatArg::Jpeg => RgbFormat::Jpeg,
            RgbFormatArg::Exr => RgbFormat::Exr,
        };
        Ok((outputs, rgb, parse_depth_formats(&self.depth_format)?))
    }
}

#[derive(Args)]
struct RefocusArgs {
    /// Source colour (PNG, JPEG, PPM, EXR).
    #[arg(long, required_unless_present = "batch")]
    rgb: Option<PathBuf>,
    /// Source metric depth, view-space Z (EXR, NPY f32/f64/u16, 16-bit PNG/PGM with --depth-scale, PFM).
    #[arg(long, required_unless_present = "batch")]
    depth: Option<PathBuf>,
    /// Refocus every frame of a CSV/JSON manifest (columns rgb,depth,fx,fy,cx,cy[,depth_scale,name];
    /// see src/refocus/batch.rs) into <out-dir>/<name>/, with one GL context, files encoded on
    /// writer threads, and resume.
    #[arg(long, conflicts_with_all = ["rgb", "depth"])]
    batch: Option<PathBuf>,
    /// With --batch: render frames that already have a manifest.json again.
    #[arg(long)]
    no_resume: bool,
    /// With --batch: threads encoding files while the GPU renders (0 = none).
    #[arg(long, default_value_t = 1)]
    writer_threads: usize,
    /// Raw units per metre for integer depth (5000 for TUM, 1000 for NYU/SUN); divides float depth too when given.
    #[arg(long)]
    depth_scale: Option<f64>,
    /// SUN RGB-D PNG depth: rotate the 16-bit value right by 3 bits before scaling.
    #[arg(long)]
    sun_bit_rotate: bool,
    #[arg(long, required_unless_present = "batch")]
    fx: Option<f64>,
    #[arg(long, required_unless_present = "batch")]
    fy: Option<f64>,
    #[arg(long, required_unless_present = "batch")]
    cx: Option<f64>,
    #[arg(long, required_unless_present = "batch")]
    cy: Option<f64>,
    #[arg(long)]
    out_dir: PathBuf,
    /// Target focal lengths fx' in pixels (fy' keeps the source fy/fx).
    #[arg(long, value_delimiter = ',', conflicts_with = "zoom_range")]
    focal_list: Option<Vec<f64>>,
    /// Target focal scales s (fx' = s fx).
    #[arg(long, value_delimiter = ',', default_value = "0.5,0.75,1,1.5,2")]
    zoom_range: Vec<f64>,
    /// Break an edge when |za - zb| > tau_rel * min(za, zb).
    #[arg(long, default_value_t = BreakRule::default().tau_rel)]
    tau_rel: f64,
    /// Break an edge when |za - zb| > tau_abs (metres; "inf" disables).
    #[arg(long, default_value_t = BreakRule::default().tau_abs)]
    tau_abs: f64,
    #[arg(long, requires = "height_out")]
    width_out: Option<u32>,
    #[arg(long, requires = "width_out")]
    height_out: Option<u32>,
    /// Output principal point (default: the source's offset from the image centre).
    #[arg(long, requires = "cy_out")]
    cx_out: Option<f64>,
    #[arg(long, requires = "cx_out")]
    cy_out: Option<f64>,
    #[command(flatten)]
    files: FileOutputArgs,
    #[arg(long, value_enum, default_value = "fullscreen")]
    method: MethodArg,
    #[command(flatten)]
    conv: ConventionArgs,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum DepthKindArg {
    /// Window depth in [0, 1] from a depth buffer, under the side's conventions.
    Device,
    /// Linear view distance in metres.
    ViewZ,
}

#[derive(Args)]
struct CompareArgs {
    #[arg(long)]
    a_rgb: PathBuf,
    #[arg(long)]
    b_rgb: PathBuf,
    #[arg(long, requires = "b_depth")]
    a_depth: Option<PathBuf>,
    #[arg(long, requires = "a_depth")]
    b_depth: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "view-z")]
    a_depth_kind: DepthKindArg,
    #[arg(long, value_enum, default_value = "view-z")]
    b_depth_kind: DepthKindArg,
    #[arg(long, value_enum, default_value = "gl")]
    a_ndc: NdcArg,
    #[arg(long, value_enum, default_value = "gl")]
    b_ndc: NdcArg,
    #[arg(long)]
    a_reversed_z: bool,
    #[arg(long)]
    b_reversed_z: bool,
    /// Row order each file is stored in (image files are normally top-down).
    #[arg(long, value_enum, default_value = "top-down")]
    a_rows: RowsArg,
    #[arg(long, value_enum, default_value = "top-down")]
    b_rows: RowsArg,
    /// Near/far planes of the device depth (metres; far may be inf).
    #[arg(long, default_value_t = 0.1)]
    near: f64,
    #[arg(long, default_value_t = 1000.0)]
    far: f64,
    /// Write |A - B| x 8 here.
    #[arg(long)]
    diff: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum BlendArg {
    Hard,
    Soft,
}

#[derive(Args)]
struct CyclopeanArgs {
    #[arg(long)]
    left_rgb: PathBuf,
    /// Left depth: device (window) depth or view distance, as `depth_kind` in the camera file.
    #[arg(long)]
    left_depth: PathBuf,
    #[arg(long)]
    right_rgb: PathBuf,
    #[arg(long)]
    right_depth: PathBuf,
    /// Camera JSON: per-eye view/projection, middle projection and size, gaze or fixation,
    /// conventions, depth kind (see src/cyclopean/camera_file.rs).
    #[arg(long)]
    cameras: PathBuf,
    /// Raw units per unit of depth for integer depth files.
    #[arg(long)]
    depth_scale: Option<f64>,
    /// 0 = the seed's single step; k >= 1 = k-step refinement with projection check.
    #[arg(long, default_value_t = 3)]
    refine_steps: u32,
    #[arg(long, value_enum, default_value = "hard")]
    blend: BlendArg,
    /// Middle-space depth disagreement (metres) treated as different surfaces (default: the
    /// seed's clamp(0.02 * fixation, 0.02, 0.25)).
    #[arg(long)]
    z_threshold: Option<f64>,
    /// Dominant eye and its blend weight, e.g. `left:0.7`.
    #[arg(long)]
    dominant: Option<String>,
    #[arg(long)]
    out_dir: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum ReprojectDepthArg {
    /// View-space Z (distance along the optical axis) in metres; <= 0, NaN, inf = no depth.
    #[value(alias = "metric")]
    ViewZ,
    /// Window depth in [0, 1] from a depth buffer, written with --near/--far under --ndc,
    /// --reversed-z; the far value is background.
    Device,
    /// Disparity in pixels of a rectified pair (Middlebury): Z = baseline * focal / (d + doffs);
    /// d <= 0 = unknown.
    Disparity,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum FromArg {
    Left,
    #[value(alias = "center")]
    Centre,
    Right,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum ToArg {
    Left,
    Right,
    /// Both eyes (from the centre view only).
    Both,
}

#[derive(Clone, Copy, ValueEnum)]
enum ReprojectMethodArg {
    /// Fixed-point walk along the row (--steps) from two starts, verified by segment coverage.
    Shift,
    /// Exact: every segment the frame's depth range allows is tested, the nearest wins.
    ShiftScan,
    /// The cyclopean 3-D walk with one eye (--steps), from two starts.
    Gather3d,
}

#[derive(Args)]
struct ReprojectArgs {
    /// Source colour (PNG, JPEG, PPM, EXR), rows top-down.
    #[arg(long, visible_alias = "rgb")]
    color: PathBuf,
    /// Source depth (EXR, NPY, 16-bit PNG/PGM with --depth-scale, PFM), holding --depth-kind.
    #[arg(long)]
    depth: PathBuf,
    #[arg(long, value_enum, default_value = "view-z")]
    depth_kind: ReprojectDepthArg,
    /// Raw units per unit of the depth file for integer files (1000 for mm, 4 for Middlebury 2003
    /// disparity PGMs); divides float depth too when given.
    #[arg(long)]
    depth_scale: Option<f64>,
    /// Near plane (metres) the device depth was written with (--depth-kind device).
    #[arg(long)]
    near: Option<f64>,
    /// Far plane (metres; may be inf) the device depth was written with (--depth-kind device).
    #[arg(long)]
    far: Option<f64>,
    /// Source intrinsics in pixels.
    #[arg(long)]
    fx: f64,
    #[arg(long)]
    fy: f64,
    #[arg(long)]
    cx: f64,
    #[arg(long)]
    cy: f64,
    /// Rectified rig: distance between the eyes in metres (x_right = x_left + doffs - f B / Z).
    /// Also the baseline of --depth-kind disparity.
    #[arg(long)]
    baseline: Option<f64>,
    /// Focal length (pixels) of the rectified rig and of disparity (default: --fx).
    #[arg(long)]
    focal: Option<f64>,
    /// cx_right - cx_left in pixels (Middlebury's doffs) of the rectified rig and of disparity.
    #[arg(long, default_value_t = 0.0)]
    doffs: f64,
    /// Seed 004's rig instead of --baseline: separation = interaxial / screen width (texture
    /// units; the eyes move +-S/2 (1 - c/Z) in texture x), with --convergence.
    #[arg(long, requires = "convergence")]
    separation: Option<f64>,
    /// Zero-parallax distance c in metres (with --separation).
    #[arg(long, requires = "separation")]
    convergence: Option<f64>,
    /// The source view.
    #[arg(long, value_enum, default_value = "left")]
    from: FromArg,
    /// The target view(s).
    #[arg(long, value_enum, default_value = "right")]
    to: ToArg,
    #[arg(long, value_enum, default_value = "shift-scan")]
    method: ReprojectMethodArg,
    /// Steps of the shift walk / 3-D gather (1..=16).
    #[arg(long, default_value_t = 3)]
    steps: u32,
    /// A row segment breaks (an unseen surface) where |Z_a - Z_b| > tau_rel * min(Z_a, Z_b).
    #[arg(long, default_value_t = 0.05)]
    tau_rel: f64,
    #[command(flatten)]
    files: FileOutputArgs,
    /// Writes <target>_rgb.png, <target>_depth.exr, <target>_mask.png (target = left, right).
    #[arg(long)]
    out_dir: PathBuf,
    #[command(flatten)]
    conv: ConventionArgs,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(Clone, Copy, ValueEnum)]
enum StitchMethodArg {
    /// Linear feather over the overlap.
    Blend,
    /// Seed 001's stitch with border weight.
    BorderWeight,
    /// Depth-aware reprojection along the ODS ray.
    Reproject,
}

#[derive(Args)]
struct StitchArgs {
    /// Ray-trace the faces of a built-in scene (only `demo`, the scene of the ODS rig).
    #[arg(long, required_unless_present = "faces", conflicts_with = "faces")]
    scene: Option<String>,
    /// Folder with the 12 faces: {left,right}_{pz,nz,px,nx,up,down}.png (colour) and
    /// {left,right}_{pz,nz,px,nx,up,down}_depth.exr (view-space Z, 0/NaN/inf = background);
    /// see README for the poses and orientations.
    #[arg(long)]
    faces: Option<PathBuf>,
    /// Face field of view in degrees, in (90, 178) (default 90 + 2 x overlap).
    #[arg(long)]
    fov: Option<f64>,
    /// Seam band half-width in degrees, in (0, (fov - 90) / 2] (default (fov - 90) / 2 with
    /// --fov, else 10).
    #[arg(long)]
    overlap: Option<f64>,
    #[arg(long, value_enum, default_value = "reproject")]
    method: StitchMethodArg,
    /// Equirect width per eye.
    #[arg(long, default_value_t = 2048)]
    width: u32,
    /// Equirect height per eye (the top-bottom image is twice as high).
    #[arg(long, default_value_t = 1024)]
    height: u32,
    /// Face side in pixels with --scene.
    #[arg(long, default_value_t = 512)]
    face_size: u32,
    /// Interpupillary distance (metres, the faces' units).
    #[arg(long, default_value_t = 0.064)]
    ipd: f64,
    /// Latitude (deg) above which the eye radius fades to 0 at the poles.
    #[arg(long, default_value_t = 45.0)]
    pole_fade: f64,
    /// Raw units per metre for integer face depth files.
    #[arg(long)]
    depth_scale: Option<f64>,
    /// Also write each eye's equirect (ods_left.png, ods_right.png).
    #[arg(long)]
    per_eye: bool,
    /// With --scene: ray-trace the ODS ground truth and print PSNR on the seam band and the
    /// whole image.
    #[arg(long)]
    truth: bool,
    /// Writes ods_top_bottom.png (left eye on top).
    #[arg(long)]
    out_dir: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info { gpu, json } => info(&gpu, json),
        Command::Refocus(args) => refocus(*args),
        Command::Cyclopean(args) => cyclopean(*args),
        Command::Reproject(args) => reproject(*args),
        Command::Stitch(args) => stitch(*args),
        Command::Compare(args) => compare(*args),
        Command::Demo { out_dir, gpu } => demo(&out_dir, &gpu),
        Command::Scene {
            scene,
            width,
            height,
            ipd,
            conv,
            out_dir,
            gpu,
        } => {
            let conv = conv.conventions();
            render_scene(&scene, width, height, ipd, conv, &out_dir, &gpu)
        }
        Command::Bench { sizes, repeats, gpu } => bench(&sizes, repeats, &gpu),
        Command::Stress { quick, only, json, gpu } => stress(quick, &only, json.as_deref(), &gpu),
        Command::Report {
            out_dir,
            data_dir,
            cases,
            repeats,
            gpu,
        } => report(&out_dir, data_dir.as_deref(), &cases, repeats, &gpu),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn info(gpu: &GpuArgs, json: bool) -> Result<()> {
    let gpu = gpu.open()?;
    let i = gpu.info();
    if json {
        println!("{}", serde_json::to_string_pretty(i)?);
        return Ok(());
    }
    println!("vendor:      {}", i.vendor);
    println!("renderer:    {}", i.renderer);
    println!(
        "GL version:  {} (core {}.{}), GLSL {}",
        i.version, i.gl_major, i.gl_minor, i.glsl_version
    );
    println!("EGL:         {} via {} platform", i.egl_version, i.platform);
    let dev = i.device_index.map_or("-".to_string(), |d| d.to_string());
    println!(
        "device:      {dev} of {} ({})",
        i.device_count,
        i.device_file.as_deref().unwrap_or("no DRM file")
    );
    println!(
        "device ext:  {}",
        if i.device_extensions.is_empty() {
            "-"
        } else {
            &i.device_extensions
        }
    );
    println!(
        "limits:      max texture {}, max viewport {}x{}",
        i.max_texture_size, i.max_viewport[0], i.max_viewport[1]
    );
    println!(
        "GPU timers:  {}",
        if i.gpu_timers_meaningful {
            "yes"
        } else {
            "no (wall clock with glFinish)"
        }
    );
    Ok(())
}

fn refocus(a: RefocusArgs) -> Result<()> {
    if let Some(manifest) = a.batch.clone() {
        return refocus_batch(&manifest, a);
    }
    // Everything that can be checked before touching the GPU or the output directory is.
    // (clap requires these without --batch.)
    let (Some(rgb_path), Some(depth_path), Some(fx), Some(fy), Some(cx), Some(cy)) =
        (a.rgb.clone(), a.depth.clone(), a.fx, a.fy, a.cx, a.cy)
    else {
        bail!("--rgb, --depth, --fx, --fy, --cx and --cy are required without --batch");
    };
    let k = Intrinsics { fx, fy, cx, cy };
    k.validate("source intrinsics")?;
    let rule = BreakRule {
        tau_rel: a.tau_rel,
        tau_abs: a.tau_abs,
    };
    rule.validate()?;
    let (outputs, rgb_format, depth_formats) = a.files.parse()?;
    let conv = a.conv.conventions();
    let method = match a.method {
        MethodArg::Mesh => Method::Mesh,
        MethodArg::Fullscreen => Method::Fullscreen,
    };
    let rgb = io::load_rgb(&rgb_path)?;
    let decode = DepthDecode {
        scale: a.depth_scale,
        sun_rgbd_bit_rotate: a.sun_bit_rotate,
        ..Default::default()
    };
    let depth = io::load_depth(&depth_path, &decode)?;
    let src = RefocusSource::new(rgb, depth, k)
        .with_context(|| format!("{} and {}", rgb_path.display(), depth_path.display()))?;
    let scales = match &a.focal_list {
        Some(list) => TargetSpec::scales_from_focal_list(&k, list),
        None => a.zoom_range.clone(),
    };
    let spec = TargetSpec {
        scales: scales.clone(),
        size: a.width_out.zip(a.height_out),
        principal: a.cx_out.zip(a.cy_out),
    };
    let targets = spec.targets(&src.camera())?;
    prepare_out_dir(&a.out_dir)?;

    let gpu = a.gpu.open()?;
    let mut refocuser = Refocuser::new(&gpu, &src, &rule, method, outputs, conv)?;
    let bar = indicatif::ProgressBar::new(targets.len() as u64);
    let mut entries = Vec::new();
    for (scale, target) in scales.iter().zip(&targets) {
        let out = refocuser.render(target)?;
        entries.push(job::write_output(
            &a.out_dir,
            *scale,
            &out,
            &outputs,
            rgb_format,
            depth_formats,
        )?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let manifest = Manifest {
        tool: format!("viewsynth {}", env!("CARGO_PKG_VERSION")),
        source: src.camera(),
        method,
        break_rule: rule,
        conventions: conv,
        renderer: gpu.info().renderer.clone(),
        notes: job::MANIFEST_NOTES.to_string(),
        outputs: entries,
    };
    let path = job::write_manifest(&a.out_dir, &manifest)?;
    for e in &manifest.outputs {
        println!(
            "s={:<6} fx'={:<9.3} {}x{} coverage {:>6.2}%  render {:>7.2} ms",
            e.scale,
            e.intrinsics.fx,
            e.width,
            e.height,
            e.coverage.unwrap_or(f64::NAN) * 100.0,
            e.render_ms
        );
    }
    println!("wrote {} targets; manifest {}", manifest.outputs.len(), path.display());
    Ok(())
}

fn demo(out_dir: &Path, gpu: &GpuArgs) -> Result<()> {
    let gpu = gpu.open()?;
    let report = viewsynth::demo::run(&gpu, out_dir)?;
    println!("{}", std::fs::read_to_string(&report)?);
    println!("demo outputs and report written to {}", out_dir.display());
    Ok(())
}

fn report(out_dir: &Path, data_dir: Option<&Path>, cases: &[PathBuf], repeats: usize, gpu: &GpuArgs) -> Result<()> {
    if let Some(d) = data_dir {
        if !d.is_dir() {
            bail!("--data-dir {}: not a directory", d.display());
        }
    }
    let gpu = gpu.open()?;
    let files = viewsynth::evaluation::run_report_with_cases(&gpu, out_dir, data_dir, cases, repeats)?;
    if let Some(md) = files.iter().find(|p| p.extension().is_some_and(|e| e == "md")) {
        println!("{}", std::fs::read_to_string(md)?);
    }
    for f in &files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

fn cyclopean(a: CyclopeanArgs) -> Result<()> {
    use viewsynth::cyclopean::camera_file::CameraFile;
    use viewsynth::cyclopean::render::CyclopeanRenderer;
    use viewsynth::cyclopean::{Blend, CyclopeanParams, Eye, EyeInput, Method as CMethod, StereoFrame};
    let cams = CameraFile::load(&a.cameras)?;
    let (mid, fixation) = cams.middle_and_fixation()?;
    let mut params = CyclopeanParams::seed(fixation);
    if a.refine_steps > 0 {
        params.method = CMethod::Refine { steps: a.refine_steps };
    }
    params.blend = match a.blend {
        BlendArg::Hard => Blend::Hard,
        BlendArg::Soft => Blend::Soft,
    };
    if let Some(t) = a.z_threshold {
        params.z_threshold = t;
    }
    if let Some(d) = &a.dominant {
        let (eye, w) = d
            .split_once(':')
            .with_context(|| format!("--dominant '{d}': expected left:W or right:W"))?;
        let eye = match eye {
            "left" => Eye::Left,
            "right" => Eye::Right,
            _ => bail!("--dominant '{d}': eye must be left or right"),
        };
        params.dominant = Some((eye, w.parse().with_context(|| format!("--dominant '{d}': weight"))?));
    }
    params.validate()?;
    let decode = DepthDecode {
        scale: a.depth_scale,
        ..Default::default()
    };
    let eye = |rgb: &Path, depth: &Path, cam: &viewsynth::cyclopean::camera_file::EyeCameras| -> Result<EyeInput> {
        Ok(EyeInput {
            color: io::load_rgb(rgb)?,
            depth: io::load_depth(depth, &decode)?,
            view: cam.view,
            proj: cam.proj,
        })
    };
    let frame = StereoFrame {
        left: eye(&a.left_rgb, &a.left_depth, &cams.left)?,
        right: eye(&a.right_rgb, &a.right_depth, &cams.right)?,
        depth_kind: cams.depth_kind,
        conv: cams.conventions,
    };
    frame.validate()?;
    prepare_out_dir(&a.out_dir)?;
    let gpu = a.gpu.open()?;
    let (out, timing) = CyclopeanRenderer::new(&gpu, &frame, params)?.render(&mid)?;
    io::save_rgb(&a.out_dir.join("middle_rgb.png"), &out.color)?;
    io::save_depth_exr(&a.out_dir.join("middle_depth.exr"), &out.depth)?;
    let mask = io::Mask::new(
        mid.width,
        mid.height,
        out.sources.iter().map(|s| (*s != 0) as u8).collect(),
    )?;
    io::save_mask_png(&a.out_dir.join("middle_mask.png"), &mask)?;
    let valid = out.sources.iter().filter(|s| **s != 0).count();
    println!(
        "middle view {}x{}: fixation {:.3} m, {:.1} % valid, render {:.1} ms; wrote middle_rgb.png, middle_depth.exr, middle_mask.png in {}",
        mid.width,
        mid.height,
        fixation,
        valid as f64 / out.sources.len() as f64 * 100.0,
        timing.wall_ms,
        a.out_dir.display()
    );
    Ok(())
}

fn conventions(ndc: NdcArg, reversed_z: bool, rows: RowsArg) -> Conventions {
    Conventions {
        ndc_depth: match ndc {
            NdcArg::Gl => NdcDepthRange::MinusOneToOne,
            NdcArg::Vulkan => NdcDepthRange::ZeroToOne,
        },
        reversed_z,
        row_order: match rows {
            RowsArg::BottomUp => RowOrder::BottomUp,
            RowsArg::TopDown => RowOrder::TopDown,
        },
    }
}

fn render_scene(
    name: &str,
    width: u32,
    height: u32,
    ipd: f64,
    conv: Conventions,
    out_dir: &Path,
    gpu: &GpuArgs,
) -> Result<()> {
    use viewsynth::camera::gl_projection;
    use viewsynth::cyclopean::scene_frame::StereoRig;
    use viewsynth::scene::gpu::{GlCamera, SceneRenderer};
    use viewsynth::scene::{builtin, Scene};
    let scene = if Path::new(name).extension().is_some_and(|e| e == "json") {
        Scene::load(Path::new(name))?
    } else {
        builtin(name)?
    };
    if !(ipd.is_finite() && ipd >= 0.0) {
        bail!("invalid ipd {ipd}: must be finite and >= 0");
    }
    let mut rig = StereoRig::demo(width, height);
    rig.camera.validate("scene camera")?;
    rig.ipd = ipd;
    prepare_out_dir(out_dir)?;
    let gpu = gpu.open()?;
    let mut renderer = SceneRenderer::new(&gpu, &scene)?;
    let proj = gl_projection(&rig.camera, &rig.planes, &conv);
    let mut cams = serde_json::Map::new();
    for (eye, side) in [("left", -1.0), ("right", 1.0), ("middle", 0.0)] {
        let view = rig.eye_pose(side).gl_view();
        let (img, timing) = renderer.render(&GlCamera {
            view,
            proj,
            width,
            height,
            conv,
        })?;
        io::save_rgb(&out_dir.join(format!("{eye}_rgb.png")), &img.color)?;
        io::save_depth_exr(&out_dir.join(format!("{eye}_view_z.exr")), &img.view_z)?;
        io::save_depth_exr(&out_dir.join(format!("{eye}_device_depth.exr")), &img.device_depth)?;
        let entry = if eye == "middle" {
            serde_json::json!({ "view": view, "proj": proj, "width": width, "height": height })
        } else {
            serde_json::json!({ "view": view, "proj": proj })
        };
        cams.insert(eye.to_string(), entry);
        println!("{eye}: {width}x{height} in {:.1} ms", timing.wall_ms);
    }
    cams.insert("conventions".into(), serde_json::to_value(conv)?);
    cams.insert("depth_kind".into(), "device".into());
    cams.insert("fixation_distance".into(), 3.0.into());
    let path = out_dir.join("cameras.json");
    let text = serde_json::to_string_pretty(&cams)?;
    io::atomic_write(&path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| viewsynth::Error::io(&path, e))
    })?;
    println!(
        "scene '{}' written to {} (cameras.json feeds `viewsynth cyclopean`)",
        scene.name,
        out_dir.display()
    );
    Ok(())
}

fn refocus_batch(manifest: &Path, a: RefocusArgs) -> Result<()> {
    use viewsynth::refocus::batch::{load_manifest, run_batch, BatchOptions};
    if a.focal_list.is_some() {
        bail!("--focal-list is per frame; with --batch give --zoom-range scales");
    }
    let frames = load_manifest(manifest)?;
    let (outputs, rgb_format, depth_formats) = a.files.parse()?;
    let opts = BatchOptions {
        scales: a.zoom_range.clone(),
        size: a.width_out.zip(a.height_out),
        principal: a.cx_out.zip(a.cy_out),
        rule: BreakRule {
            tau_rel: a.tau_rel,
            tau_abs: a.tau_abs,
        },
        method: match a.method {
            MethodArg::Mesh => Method::Mesh,
            MethodArg::Fullscreen => Method::Fullscreen,
        },
        outputs,
        conv: a.conv.conventions(),
        rgb_format,
        depth_formats,
        resume: !a.no_resume,
        writer_threads: a.writer_threads,
    };
    opts.rule.validate()?;
    prepare_out_dir(&a.out_dir)?;
    let gpu = a.gpu.open()?;
    let bar = indicatif::ProgressBar::new(frames.len() as u64);
    let summary = run_batch(&gpu, &frames, &a.out_dir, &opts, || bar.inc(1))?;
    bar.finish_and_clear();
    println!(
        "{} frames: {} rendered, {} already done (resume), {} failed; {:.1} s, {:.2} frames/s",
        frames.len(),
        summary.rendered,
        summary.skipped,
        summary.failed.len(),
        summary.wall_s,
        summary.rendered as f64 / summary.wall_s.max(1e-9)
    );
    if !summary.failed.is_empty() {
        for (name, e) in &summary.failed {
            eprintln!("failed: {name}: {e}");
        }
        bail!(
            "{} of {} frames failed (listed above); the others completed",
            summary.failed.len(),
            frames.len()
        );
    }
    Ok(())
}

fn compare(a: CompareArgs) -> Result<()> {
    use viewsynth::compare::{compare as run_compare, DepthStorage, Side};
    use viewsynth::convention::DepthPlanes;
    if !(a.near.is_finite() && a.near > 0.0 && a.far > a.near) {
        bail!("invalid --near {} / --far {}: need 0 < near < far", a.near, a.far);
    }
    let planes = DepthPlanes {
        near: a.near,
        far: a.far,
    };
    let side = |rgb: &Path, depth: Option<&Path>, kind: DepthKindArg, conv: Conventions| -> Result<Side> {
        Ok(Side {
            color: io::load_rgb(rgb)?,
            depth: depth.map(|d| io::load_depth(d, &DepthDecode::default())).transpose()?,
            storage: if kind == DepthKindArg::Device {
                DepthStorage::Device(planes)
            } else {
                DepthStorage::ViewZ
            },
            conv,
        })
    };
    let sa = side(
        &a.a_rgb,
        a.a_depth.as_deref(),
        a.a_depth_kind,
        conventions(a.a_ndc, a.a_reversed_z, a.a_rows),
    )?;
    let sb = side(
        &a.b_rgb,
        a.b_depth.as_deref(),
        a.b_depth_kind,
        conventions(a.b_ndc, a.b_reversed_z, a.b_rows),
    )?;
    let (cmp, diff) = run_compare(&sa, &sb)?;
    if let Some(p) = &a.diff {
        io::save_rgb(p, &diff)?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&cmp)?);
    } else {
        println!(
            "colour: PSNR {:.2} dB, max difference {} levels over {} pixels",
            cmp.psnr_db, cmp.max_color_diff, cmp.pixels
        );
        if let (Some(abs), Some(rel), Some(d)) = (cmp.depth_max_abs, cmp.depth_max_rel, cmp.mask_disagreement) {
            println!("depth: max abs {abs:.3e} m, max rel {rel:.3e}; valid in only one: {d} pixels");
        }
        if let Some(s) = &cmp.suspicion {
            println!("suspicion: {s}");
        }
    }
    Ok(())
}

fn parse_depth_formats(list: &str) -> Result<DepthFormats> {
    let mut f = DepthFormats { exr: false, npy: false };
    for item in list.split(',').map(str::trim) {
        match item {
            "exr" => f.exr = true,
            "npy" => f.npy = true,
            _ => bail!("invalid depth-format '{item}': expected exr, npy or exr,npy"),
        }
    }
    Ok(f)
}

fn prepare_out_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create output directory {}", dir.display()))?;
    // Probe writability now rather than after minutes of rendering.
    let probe = dir.join(format!(".viewsynth-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").with_context(|| format!("output directory {} is not writable", dir.display()))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

fn bench(sizes: &[String], repeats: usize, gpu: &GpuArgs) -> Result<()> {
    let mut parsed = Vec::new();
    for s in sizes {
        let (w, h) = s
            .split_once('x')
            .with_context(|| format!("--sizes '{s}': expected WxH"))?;
        parsed.push((w.parse::<u32>()?, h.parse::<u32>()?));
    }
    let gpu = gpu.open()?;
    let table = viewsynth::bench::refocus_bench(&gpu, &parsed, repeats.max(1))?;
    println!("{table}");
    println!(
        "{}",
        viewsynth::bench::cyclopean_bench(&gpu, 1280, 720, repeats.max(1))?
    );
    println!("{}", viewsynth::stitch::stitch_bench(&gpu)?);
    Ok(())
}

fn stress(quick: bool, only: &[String], json: Option<&Path>, gpu: &GpuArgs) -> Result<()> {
    let caps: Vec<&str> = only.iter().map(|s| s.trim()).filter(|s| !s.is_empty()).collect();
    if let Some(bad) = caps.iter().find(|c| !viewsynth::stress::CAPABILITIES.contains(c)) {
        anyhow::bail!(
            "--only '{bad}': expected a list of {}",
            viewsynth::stress::CAPABILITIES.join(", ")
        );
    }
    let gpu = gpu.open()?;
    let rows = viewsynth::stress::run_stress(&gpu, &caps, viewsynth::stress::StressOptions { quick })?;
    println!("{}", viewsynth::stress::table(&rows));
    if let Some(path) = json {
        viewsynth::io::atomic_write(path, |w| {
            serde_json::to_writer_pretty(w, &rows).map_err(|e| viewsynth::Error::param("json", e.to_string()))
        })
        .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(r) = viewsynth::stress::first_failure(&rows) {
        anyhow::bail!("stress case failed: {} / {} ({})", r.capability, r.case, r.worst);
    }
    Ok(())
}

/// An output file and the function writing it.
type WriteJob<'a> = (PathBuf, Box<dyn FnOnce(&Path) -> viewsynth::Result<()> + 'a>);

/// Writes every file or none: on the first failure the files already written are removed
/// (each write is atomic, so no partial file exists under a final name either).
fn write_all_or_none(jobs: Vec<WriteJob<'_>>) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for (path, write) in jobs {
        if let Err(e) = write(&path) {
            for p in &written {
                let _ = std::fs::remove_file(p);
            }
            return Err(e.into());
        }
        written.push(path);
    }
    Ok(written)
}

fn ms_text(t: &viewsynth::gpu::Timing) -> String {
    match t.gpu_ms {
        Some(g) => format!("{:.1} ms wall, {g:.1} ms GPU", t.wall_ms),
        None => format!("{:.1} ms wall", t.wall_ms),
    }
}

fn reproject(a: ReprojectArgs) -> Result<()> {
    use std::time::Instant;
    use viewsynth::camera::stereo::{Eye, StereoParams};
    use viewsynth::camera::PinholeCamera;
    use viewsynth::convention::DepthPlanes;
    use viewsynth::reproject::render::Reprojector;
    use viewsynth::reproject::{DepthInput, Geometry, Method as RMethod, ReprojectParams, ReprojectSource, ShiftModel};

    // Everything that can be checked before reading files, touching the GPU or the output
    // directory is.
    let k = Intrinsics {
        fx: a.fx,
        fy: a.fy,
        cx: a.cx,
        cy: a.cy,
    };
    k.validate("source intrinsics")?;
    let from = match a.from {
        FromArg::Left => Some(Eye::Left),
        FromArg::Centre => None,
        FromArg::Right => Some(Eye::Right),
    };
    let targets = match (a.from, a.to) {
        (FromArg::Centre, ToArg::Both) => vec![Eye::Left, Eye::Right],
        (_, ToArg::Both) => bail!("--to both needs --from centre (from an eye, the only other view is the other eye)"),
        (FromArg::Left, ToArg::Left) | (FromArg::Right, ToArg::Right) => {
            bail!("--to is the source view itself (--from): nothing to reproject")
        }
        (_, ToArg::Left) => vec![Eye::Left],
        (_, ToArg::Right) => vec![Eye::Right],
    };
    let focal = a.focal.unwrap_or(a.fx);
    let depth_kind = match a.depth_kind {
        ReprojectDepthArg::ViewZ => DepthInput::ViewZ,
        ReprojectDepthArg::Device => {
            let (Some(near), Some(far)) = (a.near, a.far) else {
                bail!("--depth-kind device needs --near and --far (the planes the depth buffer was written with)");
            };
            let kind = DepthInput::Device {
                planes: DepthPlanes { near, far },
            };
            kind.validate().context("--near/--far")?;
            kind
        }
        ReprojectDepthArg::Disparity => {
            let Some(baseline) = a.baseline else {
                bail!("--depth-kind disparity needs --baseline (metres; Z = baseline * focal / (d + doffs))");
            };
            let kind = DepthInput::Disparity {
                focal_px: focal,
                baseline,
                doffs: a.doffs,
            };
            kind.validate()
                .context("--depth-kind disparity: --focal/--baseline/--doffs")?;
            kind
        }
    };
    if a.depth_kind != ReprojectDepthArg::Device && (a.near.is_some() || a.far.is_some()) {
        bail!("--near/--far apply to --depth-kind device only");
    }
    let seed = match (a.separation, a.convergence) {
        (Some(s), Some(c)) => Some(StereoParams::new(s, c).context("--separation/--convergence")?),
        _ => None,
    };
    if seed.is_none() && a.baseline.is_none() {
        bail!("give the rig: --baseline B (rectified, metres) or --separation S --convergence C (seed 004)");
    }
    let method = match a.method {
        ReprojectMethodArg::Shift => RMethod::Shift { steps: a.steps },
        ReprojectMethodArg::ShiftScan => RMethod::ShiftScan,
        ReprojectMethodArg::Gather3d => RMethod::Gather3d { steps: a.steps },
    };
    let params = ReprojectParams {
        method,
        tau_rel: a.tau_rel,
    };
    params.validate().context("--steps/--tau-rel")?;
    let (outputs, rgb_format, depth_formats) = a.files.parse()?;
    let rgb_ext = rgb_format.extension();
    let conv = a.conv.conventions();

    let decode = DepthDecode {
        scale: a.depth_scale,
        ..Default::default()
    };
    let src = ReprojectSource {
        color: io::load_rgb(&a.color)?,
        depth: io::load_depth(&a.depth, &decode)?,
        depth_kind,
        conv,
    };
    src.validate()
        .with_context(|| format!("{} and {}", a.color.display(), a.depth.display()))?;
    if src.inverse_depth_range().is_none() {
        bail!(
            "{}: no pixel holds valid depth as --depth-kind {} (check --depth-kind, --depth-scale, --near/--far, conventions)",
            a.depth.display(),
            a.depth_kind.to_possible_value().map_or_else(String::new, |v| v.get_name().to_string())
        );
    }
    let camera = PinholeCamera {
        k,
        width: src.color.width,
        height: src.color.height,
    };
    camera.validate("source intrinsics")?;
    let mut geometries = Vec::new();
    for &to in &targets {
        let shift = match (&seed, a.baseline) {
            (Some(p), _) => ShiftModel::seed(p, camera.width, from, Some(to)),
            (None, Some(b)) => {
                ShiftModel::rectified(focal, b, a.doffs, from, Some(to)).context("--focal/--baseline/--doffs")?
            }
            (None, None) => unreachable!("checked above"),
        };
        shift.validate()?;
        geometries.push(Geometry::Rig { camera, shift });
    }
    prepare_out_dir(&a.out_dir)?;

    let gpu = a.gpu.open()?;
    let mut results = Vec::new();
    for (&to, geometry) in targets.iter().zip(&geometries) {
        let t0 = Instant::now();
        let mut r = Reprojector::new(&gpu, &src, geometry, params)?;
        let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
        let (out, timing) = r.render()?;
        results.push((to, out, timing, setup_ms));
    }
    let mut jobs: Vec<WriteJob> = Vec::new();
    for (to, out, _, _) in &results {
        let name = eye_name(Some(*to));
        if outputs.rgb {
            jobs.push((
                a.out_dir.join(format!("{name}_rgb.{rgb_ext}")),
                Box::new(move |p: &Path| io::save_rgb(p, &out.color)),
            ));
        }
        if outputs.depth && depth_formats.exr {
            jobs.push((
                a.out_dir.join(format!("{name}_depth.exr")),
                Box::new(move |p: &Path| io::save_depth_exr(p, &out.depth)),
            ));
        }
        if outputs.depth && depth_formats.npy {
            jobs.push((
                a.out_dir.join(format!("{name}_depth.npy")),
                Box::new(move |p: &Path| io::save_depth_npy(p, &out.depth)),
            ));
        }
        if outputs.mask {
            jobs.push((
                a.out_dir.join(format!("{name}_mask.png")),
                Box::new(move |p: &Path| {
                    let bits = out.mask.iter().map(|m| (*m != 0) as u8).collect();
                    io::save_mask_png(p, &io::Mask::new(out.color.width, out.color.height, bits)?)
                }),
            ));
        }
    }
    let written = write_all_or_none(jobs)?;
    for (to, out, timing, setup_ms) in &results {
        println!(
            "{} -> {} ({}): {}x{}, coverage {:.2} %, render {} (setup + shader compile {setup_ms:.1} ms)",
            eye_name(from),
            eye_name(Some(*to)),
            params.method.label(),
            out.color.width,
            out.color.height,
            out.coverage() * 100.0,
            ms_text(timing),
        );
    }
    let names: Vec<String> = written
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    println!("wrote {} in {}", names.join(", "), a.out_dir.display());
    Ok(())
}

fn eye_name(view: Option<viewsynth::camera::stereo::Eye>) -> &'static str {
    use viewsynth::camera::stereo::Eye;
    match view {
        Some(Eye::Left) => "left",
        Some(Eye::Right) => "right",
        None => "centre",
    }
}

/// File name tags of the cube faces in `--faces DIR`, in [`viewsynth::stitch::CubeFace::ALL`]
/// order (+Z, -Z, up, down, +X, -X).
const FACE_TAGS: [&str; 6] = ["pz", "nz", "up", "down", "px", "nx"];
const FACE_COLOR_EXTS: [&str; 5] = ["png", "jpg", "jpeg", "ppm", "exr"];
const FACE_DEPTH_EXTS: [&str; 4] = ["exr", "npy", "pfm", "png"];

/// `dir/stem.ext` for the first extension that exists; the error names the first candidate.
fn find_face_file(dir: &Path, stem: &str, exts: &[&str], what: &str) -> Result<PathBuf> {
    for e in exts {
        let p = dir.join(format!("{stem}.{e}"));
        if p.is_file() {
            return Ok(p);
        }
    }
    bail!(
        "--faces: missing {} ({what}; also looked for .{})",
        dir.join(format!("{stem}.{}", exts[0])).display(),
        exts[1..].join(", .")
    )
}

fn stitch(a: StitchArgs) -> Result<()> {
    use std::time::Instant;
    use viewsynth::stitch::eval::{score_eyes, split_top_bottom};
    use viewsynth::stitch::faces::{faces_from_images, scene_faces};
    use viewsynth::stitch::render::StitchRenderer;
    use viewsynth::stitch::truth::ods_truth;
    use viewsynth::stitch::{seam_band_mask, CubeFace, FaceSet, Method as SMethod, OdsRig, Side, StitchParams};

    if let (None, Some(o)) = (a.fov, a.overlap) {
        if !(o > 0.0 && o < 44.0) {
            bail!("--overlap {o}: must be in (0, 44) degrees (faces of 90 + 2 x overlap; or give --fov)");
        }
    }
    let (fov, overlap) = match (a.fov, a.overlap) {
        (None, None) => (110.0, 10.0),
        (Some(f), None) => (f, 0.5 * (f - 90.0)),
        (None, Some(o)) => (90.0 + 2.0 * o, o),
        (Some(f), Some(o)) => (f, o),
    };
    if !(fov > 90.0 && fov < 178.0) {
        bail!("--fov {fov}: the face field of view must be in (90, 178) degrees");
    }
    let rig = match &a.scene {
        Some(name) if name == "demo" => OdsRig {
            ipd: a.ipd,
            pole_fade_start_deg: a.pole_fade,
            ..OdsRig::demo()
        },
        Some(name) => {
            bail!("--scene '{name}': only the built-in `demo` scene has cube faces (use --faces DIR for your own)")
        }
        // The circle centre only translates the face eyes and the ODS rays together.
        None => OdsRig {
            centre: [0.0; 3],
            ipd: a.ipd,
            pole_fade_start_deg: a.pole_fade,
        },
    };
    rig.validate().context("--ipd/--pole-fade")?;
    if a.truth && a.scene.is_none() {
        bail!("--truth needs --scene demo (the ground truth is ray-traced from the built-in scene)");
    }
    let method = match a.method {
        StitchMethodArg::Blend => SMethod::Blend,
        StitchMethodArg::BorderWeight => SMethod::BorderWeight,
        StitchMethodArg::Reproject => SMethod::Reproject,
    };
    let params = StitchParams {
        method,
        overlap_deg: overlap,
        width: a.width,
        height: a.height,
    };
    let template = FaceSet {
        rig,
        side: Side::Left,
        fov_deg: fov,
        faces: Vec::new(),
    };
    params.validate(&template).context("--overlap/--fov/--width/--height")?;
    if 2 * a.height as u64 > viewsynth::io::MAX_DIMENSION as u64 {
        bail!(
            "--height {}: the top-bottom image ({} rows) exceeds {}",
            a.height,
            2 * a.height,
            viewsynth::io::MAX_DIMENSION
        );
    }

    let t0 = Instant::now();
    let (left, right, source) = if let Some(dir) = &a.faces {
        if !dir.is_dir() {
            bail!("--faces {}: not a directory", dir.display());
        }
        let decode = DepthDecode {
            scale: a.depth_scale,
            ..Default::default()
        };
        let load = |side: Side| -> Result<FaceSet> {
            let eye = match side {
                Side::Left => "left",
                Side::Right => "right",
            };
            let mut images = Vec::new();
            for (face, tag) in CubeFace::ALL.iter().zip(FACE_TAGS) {
                let what = format!("the {eye} eye's {} face", face.label());
                let c = find_face_file(
                    dir,
                    &format!("{eye}_{tag}"),
                    &FACE_COLOR_EXTS,
                    &format!("colour of {what}"),
                )?;
                let d = find_face_file(
                    dir,
                    &format!("{eye}_{tag}_depth"),
                    &FACE_DEPTH_EXTS,
                    &format!("view-space Z of {what}"),
                )?;
                images.push((io::load_rgb(&c)?, io::load_depth(&d, &decode)?));
            }
            faces_from_images(&rig, side, fov, images).with_context(|| format!("--faces {}: {eye} eye", dir.display()))
        };
        let (l, r) = (load(Side::Left)?, load(Side::Right)?);
        if l.size() != r.size() {
            bail!(
                "--faces {}: size mismatch: left faces {n}x{n}, right faces {m}x{m}",
                dir.display(),
                n = l.size(),
                m = r.size()
            );
        }
        let what = format!("loaded 12 faces of {n}x{n} from {}", dir.display(), n = l.size());
        (l, r, what)
    } else {
        let n = a.face_size;
        let l = scene_faces(&rig, Side::Left, n, fov).context("--face-size")?;
        let r = scene_faces(&rig, Side::Right, n, fov).context("--face-size")?;
        (l, r, format!("ray-traced 12 faces of {n}x{n} (CPU)"))
    };
    let faces_ms = t0.elapsed().as_secs_f64() * 1e3;
    prepare_out_dir(&a.out_dir)?;

    let gpu = a.gpu.open()?;
    let t0 = Instant::now();
    let mut renderer = StitchRenderer::new(&gpu, &left, &right)?;
    let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
    let (img, timing) = renderer.render(&params)?;
    let eyes = if a.per_eye {
        let half = img.data.len() / 2;
        Some([
            io::RgbImage::new(a.width, a.height, img.data[..half].to_vec())?,
            io::RgbImage::new(a.width, a.height, img.data[half..].to_vec())?,
        ])
    } else {
        None
    };
    let mut jobs: Vec<WriteJob> = vec![(
        a.out_dir.join("ods_top_bottom.png"),
        Box::new(|p: &Path| io::save_rgb(p, &img)),
    )];
    if let Some([l, r]) = &eyes {
        jobs.push((
            a.out_dir.join("ods_left.png"),
            Box::new(move |p: &Path| io::save_rgb(p, l)),
        ));
        jobs.push((
            a.out_dir.join("ods_right.png"),
            Box::new(move |p: &Path| io::save_rgb(p, r)),
        ));
    }
    let written = write_all_or_none(jobs)?;
    println!("faces: {source}, FOV {fov} deg, in {faces_ms:.0} ms");
    println!("upload + shader compile {setup_ms:.1} ms");
    println!(
        "stitch ({}, overlap {overlap} deg, IPD {} m): {}x{} per eye, top-bottom {}x{}, render {}",
        method.label(),
        rig.ipd,
        a.width,
        a.height,
        img.width,
        img.height,
        ms_text(&timing)
    );
    if a.truth {
        let t0 = Instant::now();
        let (tl, tr) = std::thread::scope(|s| {
            let l = s.spawn(|| ods_truth(&rig, Side::Left, a.width, a.height));
            let r = ods_truth(&rig, Side::Right, a.width, a.height);
            (l.join().expect("ODS truth does not panic"), r)
        });
        let (tl, tr) = (tl?, tr?);
        let [el, er] = split_top_bottom(&img);
        let band = seam_band_mask(a.width, a.height, overlap);
        let s = score_eyes([&el, &er], [&tl, &tr], &band);
        println!(
            "vs ODS ground truth (ray-traced in {:.0} ms): seam band PSNR {:.2} dB (MAE {:.2}, {} px per eye), whole image PSNR {:.2} dB (MAE {:.2})",
            t0.elapsed().as_secs_f64() * 1e3,
            s.seam_psnr_db,
            s.seam_mae,
            s.seam_pixels,
            s.whole_psnr_db,
            s.whole_mae
        );
    }
    for p in &written {
        println!("wrote {}", p.display());
    }
    Ok(())
}
