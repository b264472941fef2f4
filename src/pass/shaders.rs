//! The shader library: every program the crate builds, named once, with its sources and its
//! `#define`s typed.
//!
//! Design: a capability asks for a [`ShaderProgram`] (conventions + a [`ProgramKind`] whose
//! fields are the program's compile-time switches) and a backend links it (GL: `gpu::Program`,
//! Vulkan: the SPIR-V variant of the same defines); it never
//! writes GLSL text or `#define` lines. The loader ([`ShaderProgram::preamble`]) renders every
//! define here, in one place: the conventions, the program's own switches and the shared
//! numeric constants (`shaders/common/depth.glsl` takes the background epsilon from the Rust
//! constant, so GLSL never retypes it). Shared GLSL lives in `shaders/common/` and is pulled in
//! per stage by listing it before the stage's own file; each file starts with a `#line 1 k`
//! directive so a compile error names the file (source string k) and its own line.
//! `ShaderProgram::all` lists every program under one set of conventions, which the
//! compile-all test (viewsynth_tests/tests/library/passes/shader_library.rs) links under all eight.

use crate::convention::{Conventions, NdcDepthRange, RowOrder};

/// A GLSL source file of the library (path below `shaders/`, text).
#[derive(Debug, Clone, Copy)]
pub struct ShaderFile {
    /// Path below `shaders/`, e.g. "refocus/fullscreen.frag".
    pub path: &'static str,
    /// The GLSL source, embedded at build time.
    pub text: &'static str,
}

/// The shader table (program, stages, files, switch values, Vulkan layer) that build.rs reads
/// too: one list of what each program is made of.
#[allow(dead_code)]
mod table {
    include!("../../shaders/programs.rs");
}

/// Every GLSL file below `shaders/`, embedded at build time (the table names them by path).
const FILES: &[ShaderFile] = &include!(concat!(env!("OUT_DIR"), "/shader_files.rs"));

/// The embedded file at `path` (below `shaders/`); the table and `FILES` come from the same
/// folder, so a miss is a build defect (caught by the unit test below).
fn file(path: &str) -> ShaderFile {
    FILES.iter().copied().find(|f| f.path == path).unwrap_or(ShaderFile {
        path: "missing",
        text: "",
    })
}

/// The values the shader table gives switch `name` of `program` (what build.rs compiles).
fn switch_values(program: &str, name: &str) -> &'static [i64] {
    table::PROGRAMS
        .iter()
        .find(|p| p.name == program)
        .and_then(|p| p.switches.iter().find(|(n, _)| *n == name))
        .map_or(&[], |(_, v)| *v)
}

/// Width of the R32UI texture holding kept-triangle codes for vertex pulling (refocus mesh and
/// cyclopean forward warp): a layout both the uploader and the shaders must agree on.
pub const TRI_TEX_WIDTH: u32 = table::TRI_TEX_WIDTH as u32;

/// A pipeline stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Vertex shader.
    Vertex,
    /// Fragment shader.
    Fragment,
    /// Compute shader.
    Compute,
}

/// How the reprojection shift reads its stored depth (`DEPTH_MODE` in reproject/shift.frag).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShiftDepth {
    /// View Z in metres (`DEPTH_MODE` 0).
    ViewZ,
    /// Window depth under the program's conventions (`DEPTH_MODE` 1).
    Device,
    /// Disparity in pixels (`DEPTH_MODE` 2).
    Disparity,
}

/// The stitch method compiled into stitch/stitch.frag (`METHOD`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StitchBlend {
    /// Linear feather over the overlap ([`crate::stitch::Method::Blend`]).
    Blend,
    /// The seed's border weight ([`crate::stitch::Method::BorderWeight`]).
    BorderWeight,
    /// Depth-aware reprojection along the ODS ray ([`crate::stitch::Method::Reproject`]).
    Reproject,
}

/// The stages of the stereo matchers (src/cyclopean/matcher/: census, then semi-global), one
/// compute program each.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatcherStage {
    /// Grey levels of both eyes.
    Grey,
    /// Census codes of both eyes.
    Census,
    /// Hamming costs of a chunk of disparities and the box's horizontal sums.
    Rows,
    /// The box's vertical sums and the fixed-point means.
    Columns,
    /// Winner takes all over a chunk, both eyes.
    Winner,
    /// The parabola's sub-pixel step.
    Subpixel,
    /// The left-right consistency check.
    LrCheck,
    /// The 3 x 3 median of the known values.
    Median,
    /// Each eye's confidence in its final disparity (where asked for).
    Confidence,
    /// Semi-global: the next coarser level's grey levels.
    SgmDownsample,
    /// Semi-global: one level's window starts and cost volume.
    SgmCost,
    /// Semi-global: one path direction's costs added into the sums.
    SgmPath,
    /// Semi-global: winner takes all on the sums, both eyes.
    SgmWinner,
    /// The semi-global disparities the census matcher's (or a flat window) supports, both eyes
    /// ([`crate::stereo::trust`]).
    Trust,
}

impl MatcherStage {
    /// Every stage, in dispatch order.
    pub const ALL: [MatcherStage; 14] = [
        MatcherStage::Grey,
        MatcherStage::Census,
        MatcherStage::Rows,
        MatcherStage::Columns,
        MatcherStage::Winner,
        MatcherStage::Subpixel,
        MatcherStage::LrCheck,
        MatcherStage::Median,
        MatcherStage::Confidence,
        MatcherStage::SgmDownsample,
        MatcherStage::SgmCost,
        MatcherStage::SgmPath,
        MatcherStage::SgmWinner,
        MatcherStage::Trust,
    ];

    fn program_name(self) -> &'static str {
        match self {
            MatcherStage::Grey => "cyclopean/matcher_grey",
            MatcherStage::Census => "cyclopean/matcher_census",
            MatcherStage::Rows => "cyclopean/matcher_rows",
            MatcherStage::Columns => "cyclopean/matcher_columns",
            MatcherStage::Winner => "cyclopean/matcher_winner",
            MatcherStage::Subpixel => "cyclopean/matcher_subpixel",
            MatcherStage::LrCheck => "cyclopean/matcher_lr_check",
            MatcherStage::Median => "cyclopean/matcher_median",
            MatcherStage::Confidence => "cyclopean/matcher_confidence",
            MatcherStage::SgmDownsample => "cyclopean/matcher_sgm_downsample",
            MatcherStage::SgmCost => "cyclopean/matcher_sgm_cost",
            MatcherStage::SgmPath => "cyclopean/matcher_sgm_path",
            MatcherStage::SgmWinner => "cyclopean/matcher_sgm_winner",
            MatcherStage::Trust => "cyclopean/matcher_trust",
        }
    }
}

/// Every program of the crate with its compile-time switches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgramKind {
    /// refocus/fullscreen.frag: the analytic grid lookup, one full-screen pass.
    RefocusFullscreen {
        /// Colour is written as well as depth and mask (`WANT_RGB`).
        want_rgb: bool,
        /// Colour at every pixel inside the source frame, not only where covered
        /// (`RGB_EVERYWHERE`, `--rgb-everywhere`).
        rgb_everywhere: bool,
    },
    /// refocus/colour_everywhere.frag: the mesh path's first draw under `--rgb-everywhere`
    /// (colour inside the source frame, far depth, no mask).
    RefocusColourEverywhere,
    /// refocus/mesh_interior.*: interior grid triangles, indexed.
    RefocusMeshInterior {
        /// Colour is written as well as depth and mask (`WANT_RGB`).
        want_rgb: bool,
    },
    /// refocus/mesh_boundary.*: boundary triangles, pulled and pushed out, exact test.
    RefocusMeshBoundary {
        /// Colour is written as well as depth and mask (`WANT_RGB`).
        want_rgb: bool,
    },
    /// cyclopean/gather.frag: the fixed-point gather walk.
    CyclopeanGather {
        /// The eye depth textures hold window depth, not view Z.
        depth_is_device: bool,
        /// Refine method: check that the surface found projects back onto the middle pixel.
        refine: bool,
        /// Soft blend of the two eyes ([`crate::stereo::gather::Blend::Soft`]).
        blend_soft: bool,
    },
    /// cyclopean/forward.*: each eye's depth mesh warped into the middle camera.
    CyclopeanForward,
    /// cyclopean/splat.comp: nearest-first splat (compute).
    CyclopeanSplat,
    /// cyclopean/splat_gather.frag: the gather after the splat; lists the edge pixels.
    CyclopeanSplatGather,
    /// cyclopean/splat_edges.comp: the listed edge pixels' colour mixed over the pixel's width
    /// (compute, after the gather).
    CyclopeanSplatEdges,
    /// cyclopean/edge_snap.comp: depth breaks moved onto colour edges before the splat (compute).
    CyclopeanEdgeSnap,
    /// cyclopean/densify.frag: unknown disparities of one eye filled before rendering (`--fill`
    /// on two images alone).
    CyclopeanDensify,
    /// cyclopean/fill.frag: holes filled from the background side (`--fill`).
    CyclopeanFill,
    /// cyclopean/temporal_reproject.comp: the previous middle view moved into the current
    /// camera, nearest first (compute).
    CyclopeanTemporalReproject {
        /// The second stage (keep the winning texel), not the first (the nearest distance).
        /// Compiled in, not a uniform: lavapipe recompiles a shader whenever a uniform its
        /// control flow reads changes, and kept every compile (0.4 MB a frame of a sequence).
        winner: bool,
    },
    /// cyclopean/temporal_compose.frag: the current view accumulated with that history.
    CyclopeanTemporalCompose,
    /// cyclopean/matcher_*.comp: one stage of the census stereo matcher (compute).
    CyclopeanMatcher(MatcherStage),
    /// reproject/shift.frag: the row shift as a gather (walk, or the exact scan).
    ReprojectShift {
        /// How the stored source depth is read.
        depth: ShiftDepth,
        /// The exact scan over the row instead of the fixed-point walk.
        scan: bool,
        /// Extra segments scanned either side (`reproject::reference::SCAN_MARGIN`).
        scan_margin: u32,
    },
    /// scene/raytrace.frag: the ground-truth ray tracer.
    SceneRaytrace,
    /// stitch/stitch.frag: one eye of the ODS equirect.
    Stitch {
        /// How the overlapping faces are combined.
        method: StitchBlend,
        /// Fixed-point steps of the reproject method (`stitch::REPROJECT_STEPS`).
        reproject_steps: u32,
    },
}

/// A program of the library compiled under a set of conventions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShaderProgram {
    /// NDC depth range, reversed-Z and row order compiled in.
    pub conv: Conventions,
    /// Which program, with its switches.
    pub kind: ProgramKind,
}

/// One `#define` value; rendered by [`Define::line`] only.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Value {
    Flag(bool),
    Int(i64),
    Float(f64),
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Define {
    name: &'static str,
    value: Value,
}

impl Define {
    fn line(&self) -> String {
        let v = match self.value {
            Value::Flag(b) => (b as u8).to_string(),
            Value::Int(i) => i.to_string(),
            // `{:?}` always writes a '.' or an exponent (1.0, -1.0, 1e-6): a float literal.
            Value::Float(f) => format!("{f:?}"),
        };
        format!("#define {} {v}\n", self.name)
    }
}

fn flag(name: &'static str, b: bool) -> Define {
    Define {
        name,
        value: Value::Flag(b),
    }
}

fn int(name: &'static str, i: i64) -> Define {
    Define {
        name,
        value: Value::Int(i),
    }
}

fn float(name: &'static str, f: f64) -> Define {
    Define {
        name,
        value: Value::Float(f),
    }
}

/// Device depth within this of the far value is background (seed 000 3.1).
const DEVICE_DEPTH_FAR_EPS: f64 = crate::depth::FAR_EPS;

impl ProgramKind {
    /// The name a program carries in errors and debugger labels.
    pub fn name(&self) -> &'static str {
        match self {
            ProgramKind::RefocusFullscreen { .. } => "refocus/fullscreen",
            ProgramKind::RefocusColourEverywhere => "refocus/colour_everywhere",
            ProgramKind::RefocusMeshInterior { .. } => "refocus/mesh_interior",
            ProgramKind::RefocusMeshBoundary { .. } => "refocus/mesh_boundary",
            ProgramKind::CyclopeanGather { .. } => "cyclopean/gather",
            ProgramKind::CyclopeanForward => "cyclopean/forward",
            ProgramKind::CyclopeanSplat => "cyclopean/splat",
            ProgramKind::CyclopeanSplatGather => "cyclopean/splat_gather",
            ProgramKind::CyclopeanSplatEdges => "cyclopean/splat_edges",
            ProgramKind::CyclopeanEdgeSnap => "cyclopean/edge_snap",
            ProgramKind::CyclopeanDensify => "cyclopean/densify",
            ProgramKind::CyclopeanFill => "cyclopean/fill",
            ProgramKind::CyclopeanTemporalReproject { .. } => "cyclopean/temporal_reproject",
            ProgramKind::CyclopeanTemporalCompose => "cyclopean/temporal_compose",
            ProgramKind::CyclopeanMatcher(stage) => stage.program_name(),
            ProgramKind::ReprojectShift { .. } => "reproject/shift",
            ProgramKind::SceneRaytrace => "scene/raytrace",
            ProgramKind::Stitch { .. } => "stitch/stitch",
        }
    }

    /// The program's own switches.
    fn defines(&self) -> Vec<Define> {
        match *self {
            ProgramKind::RefocusFullscreen {
                want_rgb,
                rgb_everywhere,
            } => vec![
                flag("WANT_RGB", want_rgb),
                flag("RGB_EVERYWHERE", rgb_everywhere),
                int("TRI_TEX_WIDTH", TRI_TEX_WIDTH.into()),
            ],
            ProgramKind::RefocusColourEverywhere => vec![int("TRI_TEX_WIDTH", TRI_TEX_WIDTH.into())],
            ProgramKind::RefocusMeshInterior { want_rgb } | ProgramKind::RefocusMeshBoundary { want_rgb } => {
                vec![flag("WANT_RGB", want_rgb), int("TRI_TEX_WIDTH", TRI_TEX_WIDTH.into())]
            }
            ProgramKind::CyclopeanGather {
                depth_is_device,
                refine,
                blend_soft,
            } => vec![
                flag("DEPTH_IS_DEVICE", depth_is_device),
                flag("REFINE", refine),
                flag("BLEND_SOFT", blend_soft),
            ],
            ProgramKind::CyclopeanForward => vec![int("TRI_TEX_WIDTH", TRI_TEX_WIDTH.into())],
            ProgramKind::CyclopeanTemporalReproject { winner } => vec![flag("WINNER_STAGE", winner)],
            ProgramKind::CyclopeanSplat
            | ProgramKind::CyclopeanSplatGather
            | ProgramKind::CyclopeanSplatEdges
            | ProgramKind::CyclopeanEdgeSnap
            | ProgramKind::CyclopeanDensify
            | ProgramKind::CyclopeanFill
            | ProgramKind::CyclopeanTemporalCompose
            | ProgramKind::CyclopeanMatcher(_)
            | ProgramKind::SceneRaytrace => vec![],
            ProgramKind::ReprojectShift {
                depth,
                scan,
                scan_margin,
            } => vec![
                int(
                    "DEPTH_MODE",
                    match depth {
                        ShiftDepth::ViewZ => 0,
                        ShiftDepth::Device => 1,
                        ShiftDepth::Disparity => 2,
                    },
                ),
                flag("SCAN", scan),
                int("SCAN_MARGIN", scan_margin.into()),
            ],
            ProgramKind::Stitch {
                method,
                reproject_steps,
            } => vec![
                int(
                    "METHOD",
                    match method {
                        StitchBlend::Blend => 0,
                        StitchBlend::BorderWeight => 1,
                        StitchBlend::Reproject => 2,
                    },
                ),
                int("REPROJECT_STEPS", reproject_steps.into()),
            ],
        }
    }

    /// The stages and, per stage, the files concatenated in order (shared ones first), from
    /// the shader table.
    fn stages(&self) -> Vec<(Stage, Vec<ShaderFile>)> {
        let name = self.name();
        let Some(entry) = table::PROGRAMS.iter().find(|p| p.name == name) else {
            return Vec::new();
        };
        entry
            .stages
            .iter()
            .map(|(stage, files)| {
                let stage = match *stage {
                    "vert" => Stage::Vertex,
                    "frag" => Stage::Fragment,
                    _ => Stage::Compute,
                };
                (stage, files.iter().map(|f| file(f)).collect())
            })
            .collect()
    }

    /// Whether build.rs compiled this program to SPIR-V (the Vulkan backend runs it).
    pub fn on_vulkan(&self) -> bool {
        let name = self.name();
        table::PROGRAMS.iter().any(|p| p.name == name && p.vulkan.is_some())
    }
}

impl ShaderProgram {
    /// The program `kind` compiled under `conv`.
    pub fn new(conv: Conventions, kind: ProgramKind) -> Self {
        ShaderProgram { conv, kind }
    }

    /// Every program of the library (each switch at each value) under `conv`.
    pub fn all(conv: Conventions) -> Vec<ShaderProgram> {
        let mut kinds = Vec::new();
        kinds.push(ProgramKind::RefocusColourEverywhere);
        for want_rgb in [false, true] {
            for rgb_everywhere in [false, true] {
                kinds.push(ProgramKind::RefocusFullscreen {
                    want_rgb,
                    rgb_everywhere,
                });
            }
            kinds.push(ProgramKind::RefocusMeshInterior { want_rgb });
            kinds.push(ProgramKind::RefocusMeshBoundary { want_rgb });
        }
        for bits in 0..8u8 {
            kinds.push(ProgramKind::CyclopeanGather {
                depth_is_device: bits & 1 != 0,
                refine: bits & 2 != 0,
                blend_soft: bits & 4 != 0,
            });
        }
        kinds.extend([
            ProgramKind::CyclopeanForward,
            ProgramKind::CyclopeanSplat,
            ProgramKind::CyclopeanSplatGather,
            ProgramKind::CyclopeanSplatEdges,
            ProgramKind::CyclopeanEdgeSnap,
            ProgramKind::CyclopeanDensify,
            ProgramKind::CyclopeanFill,
            ProgramKind::CyclopeanTemporalReproject { winner: false },
            ProgramKind::CyclopeanTemporalReproject { winner: true },
            ProgramKind::CyclopeanTemporalCompose,
            ProgramKind::SceneRaytrace,
        ]);
        kinds.extend(MatcherStage::ALL.map(ProgramKind::CyclopeanMatcher));
        for depth in [ShiftDepth::ViewZ, ShiftDepth::Device, ShiftDepth::Disparity] {
            for scan in [false, true] {
                for &scan_margin in switch_values("reproject/shift", "SCAN_MARGIN") {
                    kinds.push(ProgramKind::ReprojectShift {
                        depth,
                        scan,
                        scan_margin: scan_margin as u32,
                    });
                }
            }
        }
        for method in [StitchBlend::Blend, StitchBlend::BorderWeight, StitchBlend::Reproject] {
            for &steps in switch_values("stitch/stitch", "REPROJECT_STEPS") {
                kinds.push(ProgramKind::Stitch {
                    method,
                    reproject_steps: steps as u32,
                });
            }
        }
        kinds.into_iter().map(|kind| ShaderProgram { conv, kind }).collect()
    }

    /// Every define of this program: conventions, shared constants, the program's switches.
    fn defines(&self) -> Vec<Define> {
        let c = self.conv;
        let (zn, zf) = c.ndc_z_near_far();
        let mut d = vec![
            flag("NDC_ZERO_TO_ONE", c.ndc_depth == NdcDepthRange::ZeroToOne),
            flag("REVERSED_Z", c.reversed_z),
            flag("ROWS_TOP_DOWN", c.row_order == RowOrder::TopDown),
            float("NDC_Z_NEAR", zn),
            float("NDC_Z_FAR", zf),
            float("DEVICE_DEPTH_FAR_EPS", DEVICE_DEPTH_FAR_EPS),
        ];
        d.extend(self.kind.defines());
        d
    }

    /// The `#define` lines inserted after `#version` in every stage.
    pub fn preamble(&self) -> String {
        self.defines().iter().map(Define::line).collect()
    }

    /// Per stage: the stage and its files in order (shared ones first).
    pub fn sources(&self) -> Vec<(Stage, Vec<ShaderFile>)> {
        self.kind.stages()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preamble_renders_each_switch_once_as_a_define_line() {
        let conv = Conventions {
            ndc_depth: NdcDepthRange::ZeroToOne,
            reversed_z: true,
            row_order: RowOrder::TopDown,
        };
        let p = ShaderProgram::new(
            conv,
            ProgramKind::ReprojectShift {
                depth: ShiftDepth::Disparity,
                scan: true,
                scan_margin: 2,
            },
        )
        .preamble();
        for line in [
            "#define NDC_ZERO_TO_ONE 1\n",
            "#define REVERSED_Z 1\n",
            "#define ROWS_TOP_DOWN 1\n",
            "#define NDC_Z_NEAR 1.0\n",
            "#define NDC_Z_FAR 0.0\n",
            "#define DEVICE_DEPTH_FAR_EPS 1e-6\n",
            "#define DEPTH_MODE 2\n",
            "#define SCAN 1\n",
            "#define SCAN_MARGIN 2\n",
        ] {
            assert_eq!(p.matches(line).count(), 1, "{line:?} in\n{p}");
        }
    }

    #[test]
    fn the_far_epsilon_define_is_the_rust_constant() {
        let p = ShaderProgram::new(Conventions::default(), ProgramKind::SceneRaytrace).preamble();
        let v: f64 = p
            .lines()
            .find_map(|l| l.strip_prefix("#define DEVICE_DEPTH_FAR_EPS "))
            .unwrap()
            .parse()
            .unwrap();
        assert_eq!(v, crate::depth::FAR_EPS);
    }

    #[test]
    fn every_listed_shader_file_exists_and_every_program_has_a_distinct_switch_set() {
        let all = ShaderProgram::all(Conventions::default());
        for (i, a) in all.iter().enumerate() {
            assert!(!a.sources().is_empty());
            for b in &all[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }
}
