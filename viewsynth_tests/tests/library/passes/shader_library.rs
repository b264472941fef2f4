//! The shader library: every program of the crate compiles and links under every convention
//! (NDC range x reversed-Z x row order) on this context, and every GLSL file under shaders/ is
//! used by some program (a file no program lists would never be compiled by any test).

use std::collections::BTreeSet;
use viewsynth::convention::Conventions;
use viewsynth::pass::ShaderProgram;

use viewsynth_tests::gpu;

#[test]
fn every_program_compiles_and_links_under_every_convention() {
    let g = gpu();
    let mut built = 0;
    for conv in Conventions::all() {
        for program in ShaderProgram::all(conv) {
            let p = program
                .build(&g)
                .unwrap_or_else(|e| panic!("{} under {}: {e}", program.kind.name(), conv.label()));
            assert_eq!(p.name(), program.kind.name());
            built += 1;
        }
    }
    // 8 conventions x (refocus: full-screen 2 x 2 (colour, colour everywhere), mesh 2 x 2,
    // colour everywhere 1 + gather 8 + forward, splat, splat gather, splat edges, edge snap,
    // densify, trust, fill, temporal reprojection's 2 stages and compose, scene 12 + shift 3 x 2
    // + stitch 3 + the matchers' 13 stages: census 9, semi-global 4).
    assert_eq!(built, 8 * (9 + 8 + 12 + 6 + 3 + 13));
}

#[test]
fn every_shader_file_belongs_to_some_program() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders");
    let mut on_disk = BTreeSet::new();
    for dir in std::fs::read_dir(&root).unwrap() {
        let dir = dir.unwrap().path();
        // shaders/programs.rs is the table itself, not GLSL.
        if !dir.is_dir() {
            continue;
        }
        for f in std::fs::read_dir(&dir).unwrap() {
            let f = f.unwrap().path();
            on_disk.insert(f.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/"));
        }
    }
    // The Vulkan layers (build.rs compiles them into the SPIR-V of the programs the table marks
    // for Vulkan, between the preamble and the GL sources; src/vulkan tests that every variant
    // exists).
    let mut used: BTreeSet<String> = ["common/vulkan.glsl"].map(String::from).into();
    for program in ShaderProgram::all(Conventions::default()) {
        for (_, files) in program.sources() {
            for f in files {
                used.insert(f.path.to_string());
            }
        }
    }
    assert_eq!(on_disk, used, "shaders/ and the library's file lists differ");
}
