//! Shader programs: the loader adds `#version` and the conventions preamble, and compile errors
//! come back with numbered source so the line in the message can be found.

use super::Gpu;
use crate::error::{Error, Result};
use glow::HasContext;
use std::cell::RefCell;
use std::collections::HashMap;

pub struct Program {
    gpu: Gpu,
    raw: glow::Program,
    /// Uniform locations by name, looked up once: a steady stream of frames then costs no
    /// glGetUniformLocation.
    locations: RefCell<HashMap<String, Option<glow::UniformLocation>>>,
}

const VERSION: &str = "#version 450 core\n";

fn numbered(source: &str) -> String {
    source
        .lines()
        .enumerate()
        .map(|(i, l)| format!("{:4} | {l}\n", i + 1))
        .collect()
}

impl Program {
    /// Compile and link `stages` (GL stage enum, name for messages, source without `#version`).
    /// `defines` is inserted after `#version`; `#line 1` keeps error line numbers those of the file.
    pub fn new(gpu: &Gpu, defines: &str, stages: &[(u32, &str, &str)]) -> Result<Self> {
        let gl = gpu.gl();
        // SAFETY: standard shader/program creation on the current context; every handle created
        // is deleted on every path.
        unsafe {
            let program = gl.create_program().map_err(Error::Gl)?;
            let mut shaders = Vec::new();
            for &(stage, name, body) in stages {
                let source = format!("{VERSION}{defines}#line 1\n{body}");
                let shader = gl.create_shader(stage).map_err(Error::Gl)?;
                gl.shader_source(shader, &source);
                gl.compile_shader(shader);
                if !gl.get_shader_compile_status(shader) {
                    let log = gl.get_shader_info_log(shader);
                    gl.delete_shader(shader);
                    for s in shaders {
                        gl.delete_shader(s);
                    }
                    gl.delete_program(program);
                    return Err(Error::Gl(format!(
                        "compiling {name}:\n{log}\npreamble:\n{defines}source:\n{}",
                        numbered(body)
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
                let names: Vec<_> = stages.iter().map(|s| s.1).collect();
                return Err(Error::Gl(format!("linking {}: {log}", names.join(" + "))));
            }
            super::label(
                gl,
                glow::PROGRAM,
                program.0.get(),
                stages.first().map_or("program", |s| s.1),
            );
            Ok(Program {
                gpu: gpu.clone(),
                raw: program,
                locations: RefCell::default(),
            })
        }
    }

    /// A full-screen pass: the shared one-triangle vertex shader and `frag` (named `name` in
    /// compile errors).
    pub fn fullscreen(gpu: &Gpu, defines: &str, name: &str, frag: &str) -> Result<Self> {
        const FULLSCREEN_VERT: &str = include_str!("../../shaders/common/fullscreen.vert");
        Program::new(
            gpu,
            defines,
            &[
                (glow::VERTEX_SHADER, "fullscreen.vert", FULLSCREEN_VERT),
                (glow::FRAGMENT_SHADER, name, frag),
            ],
        )
    }

    pub fn bind(&self) {
        // SAFETY: valid program handle.
        unsafe { self.gpu.gl().use_program(Some(self.raw)) }
    }

    fn location(&self, name: &str) -> Option<glow::UniformLocation> {
        if let Some(l) = self.locations.borrow().get(name) {
            return *l;
        }
        // SAFETY: valid program handle.
        let l = unsafe { self.gpu.gl().get_uniform_location(self.raw, name) };
        self.locations.borrow_mut().insert(name.to_string(), l);
        l
    }

    /// Set uniforms by name on the bound program. Unknown names are ignored (the GLSL compiler
    /// drops unused uniforms), so a convention that compiles a uniform away still works.
    pub fn set_f32(&self, name: &str, v: f32) {
        // SAFETY: location belongs to this program, which the caller has bound.
        unsafe { self.gpu.gl().uniform_1_f32(self.location(name).as_ref(), v) }
    }
    pub fn set_i32(&self, name: &str, v: i32) {
        // SAFETY: as above.
        unsafe { self.gpu.gl().uniform_1_i32(self.location(name).as_ref(), v) }
    }
    pub fn set_ivec2(&self, name: &str, v: [i32; 2]) {
        // SAFETY: as above.
        unsafe { self.gpu.gl().uniform_2_i32(self.location(name).as_ref(), v[0], v[1]) }
    }
    pub fn set_vec2(&self, name: &str, v: [f32; 2]) {
        // SAFETY: as above.
        unsafe { self.gpu.gl().uniform_2_f32(self.location(name).as_ref(), v[0], v[1]) }
    }
    pub fn set_vec3(&self, name: &str, v: [f32; 3]) {
        // SAFETY: as above.
        unsafe {
            self.gpu
                .gl()
                .uniform_3_f32(self.location(name).as_ref(), v[0], v[1], v[2])
        }
    }
    pub fn set_vec4(&self, name: &str, v: [f32; 4]) {
        // SAFETY: as above.
        unsafe {
            self.gpu
                .gl()
                .uniform_4_f32(self.location(name).as_ref(), v[0], v[1], v[2], v[3])
        }
    }
    /// A 4x4 matrix given row-major (as written on paper); uploaded transposed for GLSL.
    pub fn set_mat4_rows(&self, name: &str, rows: &[[f64; 4]; 4]) {
        let mut cols = [0f32; 16];
        for (r, row) in rows.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                cols[c * 4 + r] = *v as f32;
            }
        }
        // SAFETY: as above; 16 floats.
        unsafe {
            self.gpu
                .gl()
                .uniform_matrix_4_f32_slice(self.location(name).as_ref(), false, &cols)
        }
    }
}

impl Drop for Program {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_program(self.raw) }
    }
}
