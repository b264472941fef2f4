//! EGL extension and GL entry points that khronos-egl and glow do not wrap, generated at build
//! time by gl_generator from the Khronos XML registries (build.rs `write_khronos_bindings`).
//!
//! Each is a struct of function pointers filled by `load_with` from eglGetProcAddress; a name
//! the driver does not know stays unloaded (`is_loaded()` false) and panics if called, so
//! callers check `is_loaded()` (and the extension string) first. Generated code follows the C
//! names and is not held to this crate's lints.

#![allow(
    clippy::all,
    clippy::pedantic,
    dead_code,
    missing_docs,
    non_camel_case_types,
    non_snake_case,
    non_upper_case_globals,
    unused_imports
)]

/// EGL: device enumeration and query, platform displays, and the EGL 1.5 and extension enums.
pub mod egl {
    // The platform types the generated bindings leave to the includer (eglplatform.h and
    // khrplatform.h for Linux).
    pub type khronos_utime_nanoseconds_t = u64;
    pub type khronos_uint64_t = u64;
    pub type khronos_ssize_t = isize;
    pub type EGLint = i32;
    pub type EGLNativeDisplayType = *const std::ffi::c_void;
    pub type EGLNativePixmapType = *const std::ffi::c_void;
    pub type EGLNativeWindowType = *const std::ffi::c_void;
    pub type NativeDisplayType = EGLNativeDisplayType;
    pub type NativePixmapType = EGLNativePixmapType;
    pub type NativeWindowType = EGLNativeWindowType;

    include!(concat!(env!("OUT_DIR"), "/egl_ext_bindings.rs"));
}

/// GL: `glClipControl` (GL 4.5) and `glClearTexImage` (GL 4.4).
pub mod gl {
    include!(concat!(env!("OUT_DIR"), "/gl_ext_bindings.rs"));
}

/// The loader both structs take: eglGetProcAddress, null for an unknown name.
pub fn egl_loader(
    egl: &khronos_egl::DynamicInstance<khronos_egl::EGL1_4>,
) -> impl FnMut(&'static str) -> *const std::ffi::c_void + '_ {
    move |name| {
        egl.get_proc_address(name)
            .map_or(std::ptr::null(), |f| f as *const std::ffi::c_void)
    }
}
