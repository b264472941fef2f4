// The shader library's one table: every program, its stages with the files each concatenates
// (shared ones first), the values its own `#define` switches take, and whether it is compiled
// to SPIR-V for the Vulkan backend. Read by build.rs (which compiles every Vulkan variant with
// glslangValidator) and by src/pass/shaders.rs (the GL loader's file lists), through `include!`,
// so the two cannot drift. Plain data only: no crate items are visible here.
//
// Switch order is the order `ProgramKind::defines` renders them in; the SPIR-V lookup is by the
// exact preamble text, so a drift fails loudly (tests in src/vulkan/pipeline.rs).

/// One program of the library.
#[allow(dead_code)]
pub struct ProgramEntry {
    /// `ProgramKind::name()`, e.g. "reproject/shift".
    pub name: &'static str,
    /// Per stage ("vert", "frag", "comp"): files below `shaders/`, concatenated in order.
    pub stages: &'static [(&'static str, &'static [&'static str])],
    /// Each switch's `#define` name and every value it takes.
    pub switches: &'static [(&'static str, &'static [i64])],
    /// Compiled for Vulkan, with these files (below `shaders/`) between the common Vulkan layer
    /// and the body; `None`: GL only.
    pub vulkan: Option<&'static [&'static str]>,
}

/// Width of the R32UI texture holding kept-triangle codes (refocus mesh, forward warp).
pub const TRI_TEX_WIDTH: i64 = 4096;

const FULLSCREEN_VERT: &[&str] = &["common/fullscreen.vert"];
const REFOCUS_FRAG: [&str; 5] = [
    "refocus/refocus_params.glsl",
    "common/bilinear.glsl",
    "common/grid_mesh.glsl",
    "common/refocus_grid.glsl",
    "common/refocus_sample.glsl",
];
const REFOCUS_SWITCHES: &[(&str, &[i64])] = &[("WANT_RGB", &[0, 1]), ("TRI_TEX_WIDTH", &[TRI_TEX_WIDTH])];
/// The full-screen pass also colours every in-frame pixel under `--rgb-everywhere`.
const REFOCUS_FULLSCREEN_SWITCHES: &[(&str, &[i64])] =
    &[("WANT_RGB", &[0, 1]), ("RGB_EVERYWHERE", &[0, 1]), ("TRI_TEX_WIDTH", &[TRI_TEX_WIDTH])];
const SPLAT_GATHER_COMMON: [&str; 5] = [
    "common/bindings.glsl",
    "common/camera.glsl",
    "common/bilinear.glsl",
    "cyclopean/edge_list.glsl",
    "cyclopean/splat_gather.glsl",
];
/// Every stage of the census matcher: storage bindings, then the shared block and constants.
const MATCHER_COMMON: [&str; 2] = ["common/bindings.glsl", "cyclopean/matcher_params.glsl"];

pub const PROGRAMS: &[ProgramEntry] = &[
    ProgramEntry {
        name: "refocus/fullscreen",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            (
                "frag",
                &[REFOCUS_FRAG[0], REFOCUS_FRAG[1], REFOCUS_FRAG[2], REFOCUS_FRAG[3], REFOCUS_FRAG[4], "refocus/fullscreen.frag"],
            ),
        ],
        switches: REFOCUS_FULLSCREEN_SWITCHES,
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "refocus/colour_everywhere",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            (
                "frag",
                &[REFOCUS_FRAG[0], REFOCUS_FRAG[1], REFOCUS_FRAG[2], REFOCUS_FRAG[3], REFOCUS_FRAG[4], "refocus/colour_everywhere.frag"],
            ),
        ],
        switches: &[("TRI_TEX_WIDTH", &[TRI_TEX_WIDTH])],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "refocus/mesh_interior",
        stages: &[
            (
                "vert",
                &[
                    "refocus/refocus_params.glsl",
                    "common/grid_mesh.glsl",
                    "common/refocus_grid.glsl",
                    "refocus/mesh_interior.vert",
                ],
            ),
            (
                "frag",
                &[REFOCUS_FRAG[0], REFOCUS_FRAG[1], REFOCUS_FRAG[2], REFOCUS_FRAG[3], REFOCUS_FRAG[4], "refocus/mesh_interior.frag"],
            ),
        ],
        switches: REFOCUS_SWITCHES,
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "refocus/mesh_boundary",
        stages: &[
            (
                "vert",
                &[
                    "refocus/refocus_params.glsl",
                    "common/grid_mesh.glsl",
                    "common/mesh_pull.glsl",
                    "common/refocus_grid.glsl",
                    "refocus/mesh_boundary.vert",
                ],
            ),
            (
                "frag",
                &[REFOCUS_FRAG[0], REFOCUS_FRAG[1], REFOCUS_FRAG[2], REFOCUS_FRAG[3], REFOCUS_FRAG[4], "refocus/mesh_boundary.frag"],
            ),
        ],
        switches: REFOCUS_SWITCHES,
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/gather",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            (
                "frag",
                &[
                    "common/camera.glsl",
                    "common/depth.glsl",
                    "common/bilinear.glsl",
                    "cyclopean/gather_params.glsl",
                    "cyclopean/gather.frag",
                ],
            ),
        ],
        switches: &[("DEPTH_IS_DEVICE", &[0, 1]), ("REFINE", &[0, 1]), ("BLEND_SOFT", &[0, 1])],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/densify",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            ("frag", &["cyclopean/densify_params.glsl", "cyclopean/directions.glsl", "cyclopean/densify.frag"]),
        ],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/fill",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            ("frag", &["cyclopean/fill_params.glsl", "cyclopean/directions.glsl", "cyclopean/fill.frag"]),
        ],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/temporal_reproject",
        stages: &[(
            "comp",
            &["common/bindings.glsl", "common/camera.glsl", "cyclopean/temporal_params.glsl", "cyclopean/temporal_reproject.comp"],
        )],
        switches: &[("WINNER_STAGE", &[0, 1])],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/temporal_compose",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            ("frag", &["cyclopean/temporal_params.glsl", "cyclopean/temporal_compose.frag"]),
        ],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/forward",
        stages: &[
            (
                "vert",
                &[
                    "common/camera.glsl",
                    "common/grid_mesh.glsl",
                    "common/mesh_pull.glsl",
                    "cyclopean/forward_params.glsl",
                    "cyclopean/forward.vert",
                ],
            ),
            (
                "frag",
                &[
                    "common/bilinear.glsl",
                    "common/grid_mesh.glsl",
                    "cyclopean/forward_params.glsl",
                    "cyclopean/forward.frag",
                ],
            ),
        ],
        switches: &[("TRI_TEX_WIDTH", &[TRI_TEX_WIDTH])],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/splat",
        stages: &[("comp", &["common/bindings.glsl", "common/camera.glsl", "cyclopean/splat.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/splat_gather",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            (
                "frag",
                &[
                    SPLAT_GATHER_COMMON[0],
                    SPLAT_GATHER_COMMON[1],
                    SPLAT_GATHER_COMMON[2],
                    SPLAT_GATHER_COMMON[3],
                    SPLAT_GATHER_COMMON[4],
                    "cyclopean/splat_gather.frag",
                ],
            ),
        ],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/splat_edges",
        stages: &[(
            "comp",
            &[
                SPLAT_GATHER_COMMON[0],
                SPLAT_GATHER_COMMON[1],
                SPLAT_GATHER_COMMON[2],
                SPLAT_GATHER_COMMON[3],
                SPLAT_GATHER_COMMON[4],
                "cyclopean/splat_edges.comp",
            ],
        )],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/edge_snap",
        stages: &[("comp", &["common/bindings.glsl", "cyclopean/edge_snap.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_grey",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_grey.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_census",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_census.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_rows",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_rows.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_columns",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_columns.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_winner",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_winner.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_subpixel",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_subpixel.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_lr_check",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_lr_check.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_median",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_median.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_confidence",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_confidence.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_trust",
        stages: &[("comp", &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_trust.comp"])],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_sgm_downsample",
        stages: &[(
            "comp",
            &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_sgm.glsl", "cyclopean/matcher_sgm_downsample.comp"],
        )],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_sgm_cost",
        stages: &[(
            "comp",
            &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_sgm.glsl", "cyclopean/matcher_sgm_cost.comp"],
        )],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_sgm_path",
        stages: &[(
            "comp",
            &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_sgm.glsl", "cyclopean/matcher_sgm_path.comp"],
        )],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "cyclopean/matcher_sgm_winner",
        stages: &[(
            "comp",
            &[MATCHER_COMMON[0], MATCHER_COMMON[1], "cyclopean/matcher_sgm.glsl", "cyclopean/matcher_sgm_winner.comp"],
        )],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "reproject/shift",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            ("frag", &["common/depth.glsl", "reproject/reproject_params.glsl", "reproject/shift.frag"]),
        ],
        switches: &[("DEPTH_MODE", &[0, 1, 2]), ("SCAN", &[0, 1]), ("SCAN_MARGIN", &[1])],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "scene/raytrace",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            (
                "frag",
                &[
                    "common/camera.glsl",
                    "common/depth.glsl",
                    "common/ods.glsl",
                    "scene/scene_params.glsl",
                    "scene/raytrace.frag",
                ],
            ),
        ],
        switches: &[],
        vulkan: Some(&[]),
    },
    ProgramEntry {
        name: "stitch/stitch",
        stages: &[
            ("vert", FULLSCREEN_VERT),
            (
                "frag",
                &["common/bilinear.glsl", "common/ods.glsl", "stitch/stitch_params.glsl", "stitch/stitch.frag"],
            ),
        ],
        switches: &[("METHOD", &[0, 1, 2]), ("REPROJECT_STEPS", &[3])],
        vulkan: Some(&[]),
    },
];
