//! Linked shader programs, built only from the shader library (`shaders.rs`): the loader adds
//! `#version` and the library's `#define`s, and compile errors come back naming the file and
//! with numbered source so the line in the message can be found.

use super::census::GlObject;
use super::{Gpu, StorageBuffer};
use crate::error::{Error, Result};
use crate::pass::shaders::{ShaderFile, ShaderProgram, Stage};
use glow::HasContext;

/// A linked GL program of the shader library, owning its GL object (deleted on drop).
pub struct Program {
    gpu: Gpu,
    raw: glow::Program,
    name: &'static str,
}

/// `#version`, and the parameter block's kind: a uniform block under GL (Vulkan's layer,
/// shaders/common/vulkan.glsl, makes it a read-only storage buffer and says why).
const VERSION: &str = "#version 450 core\n#define PARAM_BLOCK uniform\n";

/// The files of one stage, each numbered by its own lines, for compile errors.
fn numbered(files: &[ShaderFile]) -> String {
    let mut out = String::new();
    for (k, f) in files.iter().enumerate() {
        out.push_str(&format!("--- source {k}: shaders/{}\n", f.path));
        for (i, l) in f.text.lines().enumerate() {
            out.push_str(&format!("{:4} | {l}\n", i + 1));
        }
    }
    out
}

/// One stage's text: `#version`, the defines, then each file after `#line 1 k`, so the
/// compiler's "k:line" names file k of the stage and its own line.
fn stage_source(preamble: &str, files: &[ShaderFile]) -> String {
    let mut source = format!("{VERSION}{preamble}");
    for (k, f) in files.iter().enumerate() {
        source.push_str(&format!("#line 1 {k}\n{}\n", f.text));
    }
    source
}

/// The GL shader type of `stage`.
fn gl_stage(stage: Stage) -> u32 {
    match stage {
        Stage::Vertex => glow::VERTEX_SHADER,
        Stage::Fragment => glow::FRAGMENT_SHADER,
        Stage::Compute => glow::COMPUTE_SHADER,
    }
}

// The shader library's build step sits here, beside the program it makes, so the library
// (`shaders.rs`, the programs as data) never names the GL program.
impl ShaderProgram {
    /// Compile and link on `gpu`.
    pub fn build(&self, gpu: &Gpu) -> Result<Program> {
        Program::from_library(gpu, self)
    }
}

impl Program {
    /// Compile and link a program of the library.
    pub(super) fn from_library(gpu: &Gpu, spec: &ShaderProgram) -> Result<Self> {
        let gl = gpu.gl();
        let name = spec.kind.name();
        let preamble = spec.preamble();
        let stages = spec.sources();
        // SAFETY: standard shader/program creation on the current context; every handle created
        // is deleted on every path.
        unsafe {
            let program = gl.create_program().map_err(Error::Gl)?;
            gpu.created(GlObject::Program);
            let mut shaders = Vec::new();
            for (stage, files) in &stages {
                let shader = gl.create_shader(gl_stage(*stage)).map_err(Error::Gl)?;
                gl.shader_source(shader, &stage_source(&preamble, files));
                gl.compile_shader(shader);
                if !gl.get_shader_compile_status(shader) {
                    let log = gl.get_shader_info_log(shader);
                    gl.delete_shader(shader);
                    for s in shaders {
                        gl.delete_shader(s);
                    }
                    gl.delete_program(program);
                    gpu.deleted(GlObject::Program);
                    return Err(Error::Gl(format!(
                        "compiling {name} ({stage:?} stage):\n{log}\npreamble:\n{preamble}{}",
                        numbered(files)
                    )));
                }
                gl.attach_shader(program, shader);
                shaders.push(shader);
            }
            gl.link_program(program);
            for s in shaders {
                gl.detach_shader(program, s);
                gl.delete_shader(s);
            }
            if !gl.get_program_link_status(program) {
                let log = gl.get_program_info_log(program);
                gl.delete_program(program);
                gpu.deleted(GlObject::Program);
                return Err(Error::Gl(format!("linking {name}: {log}")));
            }
            gpu.label(glow::PROGRAM, program.0.get(), name);
            Ok(Program {
                gpu: gpu.clone(),
                raw: program,
                name,
            })
        }
    }

    /// The library name of this program (e.g. `refocus/fullscreen`).
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// Run this compute program over `groups` work groups (x, y), binding it first.
    pub fn dispatch(&self, groups: [u32; 2]) {
        self.bind();
        // SAFETY: a compute program is bound; its images and textures are bound by the caller.
        unsafe { self.gpu.gl().dispatch_compute(groups[0], groups[1], 1) }
    }

    /// Dispatch as many work groups as the 3 words at `offset_words` of `args` say (x, y, z),
    /// which an earlier pass wrote; the writes must be made visible first
    /// (`Gpu::memory_barrier`).
    pub fn dispatch_indirect(&self, args: &StorageBuffer, offset_words: usize) {
        self.bind();
        args.bind_dispatch_indirect();
        // SAFETY: a compute program is bound; `args` holds 3 words at the offset (the caller
        // sized it), 4-byte aligned.
        unsafe {
            let gl = self.gpu.gl();
            gl.dispatch_compute_indirect(offset_words as i32 * 4);
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, None);
        }
    }

    /// The std140 layout the GL compiler gave uniform block `block`: its data size and each
    /// active member's name (arrays as `name[0]`) and byte offset, sorted by offset; None when
    /// the program has no such block. For the test that holds every Rust parameter block
    /// against its GLSL mirror.
    pub fn uniform_block_layout(&self, block: &str) -> Option<(usize, Vec<(String, usize)>)> {
        let gl = self.gpu.gl();
        // SAFETY: introspection queries on a linked program; the index slice is sized by the
        // count GL reports.
        unsafe {
            let index = gl.get_uniform_block_index(self.raw, block)?;
            let size = gl.get_active_uniform_block_parameter_i32(self.raw, index, glow::UNIFORM_BLOCK_DATA_SIZE);
            let n = gl.get_active_uniform_block_parameter_i32(self.raw, index, glow::UNIFORM_BLOCK_ACTIVE_UNIFORMS);
            let mut members = vec![0i32; n.max(0) as usize];
            gl.get_active_uniform_block_parameter_i32_slice(
                self.raw,
                index,
                glow::UNIFORM_BLOCK_ACTIVE_UNIFORM_INDICES,
                &mut members,
            );
            let members: Vec<u32> = members.into_iter().map(|m| m as u32).collect();
            let offsets = gl.get_active_uniforms_parameter(self.raw, &members, glow::UNIFORM_OFFSET);
            let mut out: Vec<(String, usize)> = members
                .iter()
                .zip(offsets)
                .filter_map(|(&m, o)| Some((gl.get_active_uniform(self.raw, m)?.name, o as usize)))
                .collect();
            out.sort_by_key(|(_, o)| *o);
            Some((size as usize, out))
        }
    }

    /// Makes this the current program (glUseProgram).
    pub fn bind(&self) {
        // SAFETY: valid program handle.
        unsafe { self.gpu.gl().use_program(Some(self.raw)) }
    }
}

impl Drop for Program {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_program(self.raw) }
        self.gpu.deleted(GlObject::Program);
    }
}
