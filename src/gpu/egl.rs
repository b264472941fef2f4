//! Headless OpenGL 4.5+ core context through EGL: the device platform first, Mesa surfaceless
//! as fallback. libEGL is loaded at run time, so a machine without it gets an ordinary error.

use super::devices::{self, EglDevice, HostProbe};
use super::khronos::{self, egl as ext};
use crate::error::{Error, Result};
use khronos_egl as egl;
use std::ffi::{c_void, CStr};

// Device strings from extensions newer than the Khronos registry gl_generator ships (khronos_api
// 3.1): EGL_EXT_device_persistent_id, EGL_EXT_device_query_name, EGL_EXT_device_drm_render_node.
const EGL_DRIVER_NAME_EXT: egl::Int = 0x335E;
const EGL_RENDERER_EXT: egl::Int = 0x335F;
const EGL_DRM_RENDER_NODE_FILE_EXT: egl::Int = 0x3377;

/// Which EGL device to render on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DeviceChoice {
    /// The CUDA_VISIBLE_DEVICES GPU when that is set and an NVIDIA device matches, else the
    /// first hardware device, else the first software one (EGL_MESA_device_software), else
    /// Mesa surfaceless. See [`devices::auto_order`].
    #[default]
    Auto,
    /// The n-th EGL device from `eglQueryDevicesEXT`.
    Index(usize),
    /// Skip device enumeration and use Mesa's surfaceless platform.
    Surfaceless,
}

/// A device string that is neither `auto`, `surfaceless` nor an EGL device index.
#[derive(Debug, thiserror::Error)]
#[error("'{value}': expected \"auto\", \"surfaceless\" or an index")]
pub struct DeviceChoiceError {
    /// The string given.
    pub value: String,
    /// Why it is no index.
    #[source]
    pub source: std::num::ParseIntError,
}

/// The one spelling of a device choice, shared by the CLI's `--device` and Python's `device=`:
/// `auto`, `surfaceless` or an index as `viewsynth info` lists them.
impl std::str::FromStr for DeviceChoice {
    type Err = DeviceChoiceError;

    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        match s {
            "auto" => Ok(DeviceChoice::Auto),
            "surfaceless" => Ok(DeviceChoice::Surfaceless),
            n => n.parse().map(DeviceChoice::Index).map_err(|source| DeviceChoiceError {
                value: n.to_string(),
                source,
            }),
        }
    }
}

/// What the context runs on, for `viewsynth info` and reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct GpuInfo {
    /// GL_VENDOR.
    pub vendor: String,
    /// GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    pub renderer: String,
    /// GL_VERSION.
    pub version: String,
    /// GL_SHADING_LANGUAGE_VERSION.
    pub glsl_version: String,
    /// EGL_VERSION of the display.
    pub egl_version: String,
    /// "device" or "surfaceless".
    pub platform: String,
    /// Index of the EGL device in use among those enumerated; None on the surfaceless platform.
    pub device_index: Option<usize>,
    /// EGL devices enumerated.
    pub device_count: usize,
    /// DRM device file of the device in use (e.g. /dev/dri/renderD128), when it has one.
    pub device_file: Option<String>,
    /// EGL device extensions of the device in use (space-separated; empty without a device).
    pub device_extensions: String,
    /// GL major version of the context.
    pub gl_major: i32,
    /// GL minor version of the context.
    pub gl_minor: i32,
    /// GL_MAX_TEXTURE_SIZE, texels per side.
    pub max_texture_size: i32,
    /// GL_MAX_VIEWPORT_DIMS, pixels (width, height).
    pub max_viewport: [i32; 2],
    /// Whether GL_TIME_ELAPSED timer queries give real values (false on llvmpipe).
    pub gpu_timers_meaningful: bool,
    /// Every EGL device `eglQueryDevicesEXT` lists, in its order.
    pub devices: Vec<EglDevice>,
    /// The device `--device auto` tries first (None: no device, Mesa surfaceless).
    pub auto_device: Option<usize>,
    /// The renderer is a software rasteriser (llvmpipe, softpipe, or a device with
    /// EGL_MESA_device_software).
    pub software: bool,
    /// Set when rendering runs on software although a hardware device or an NVIDIA driver is
    /// visible: callers print it (the CLI does, on stderr).
    pub software_warning: Option<crate::Message>,
}

/// An EGL display and a current GL context on this thread. Dropping it releases the context.
pub struct EglContext {
    egl: egl::DynamicInstance<egl::EGL1_4>,
    display: egl::Display,
    context: egl::Context,
    pub(super) gl: glow::Context,
    /// `glClipControl`, the one GL 4.5 entry point glow lacks.
    pub(super) clip_control: khronos::gl::Gl,
    /// What the context runs on, for `viewsynth info` and reports.
    pub info: GpuInfo,
}

fn egl_err(what: &str, e: egl::Error) -> Error {
    Error::Egl(format!("{what}: {e}"))
}

impl EglContext {
    /// Open a display and create a GL 4.6 core context (4.5 if 4.6 is refused), current on
    /// this thread.
    pub fn new(choice: DeviceChoice) -> Result<Self> {
        // SAFETY: loading libEGL runs its initialisers; this is the documented use of the crate.
        let egl = unsafe { egl::DynamicInstance::<egl::EGL1_4>::load_required() }.map_err(|e| {
            Error::Egl(format!(
                "cannot load libEGL ({e}); install libegl1 with a vendor library \
                 (Mesa: libegl-mesa0 libgl1-mesa-dri; NVIDIA: the driver's EGL via glvnd)"
            ))
        })?;
        let client_ext = egl
            .query_string(None, egl::EXTENSIONS)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let entry = ext::Egl::load_with(khronos::egl_loader(&egl));
        if !entry.GetPlatformDisplayEXT.is_loaded() {
            return Err(Error::Egl(
                "libEGL lacks eglGetPlatformDisplayEXT (EGL_EXT_platform_base)".into(),
            ));
        }
        let get_platform_display = |platform: egl::Enum, native: *mut c_void| {
            // SAFETY: loaded above; the attribute list is just EGL_NONE, the native display a
            // device handle from eglQueryDevicesEXT or EGL_DEFAULT_DISPLAY.
            unsafe { entry.GetPlatformDisplayEXT(platform, native, [egl::NONE].as_ptr()) as *mut c_void }
        };

        let mut attempts = Vec::new();
        let mut chosen = None;
        let handles = enumerate_devices(&entry, &client_ext);
        let devices = describe_devices(&entry, &handles);
        let cuda_visible = std::env::var("CUDA_VISIBLE_DEVICES").ok();
        let auto = devices::auto_order(&devices, cuda_visible.as_deref());
        if choice != DeviceChoice::Surfaceless && client_ext.contains("EGL_EXT_platform_device") {
            let order = match choice {
                DeviceChoice::Index(i) if i >= devices.len() => {
                    return Err(Error::param(
                        "device",
                        format!("index {i} out of range: {} EGL device(s)", devices.len()),
                    ))
                }
                DeviceChoice::Index(i) => vec![i],
                _ => auto.clone(),
            };
            for index in order {
                let ptr = get_platform_display(ext::PLATFORM_DEVICE_EXT, handles[index] as *mut c_void);
                let label = devices[index].label();
                if ptr.is_null() {
                    attempts.push(format!("{label}: no display"));
                    continue;
                }
                // SAFETY: non-null EGLDisplay returned by EGL.
                let display = unsafe { egl::Display::from_ptr(ptr) };
                match create_context(&egl, display) {
                    Ok(ctx) => {
                        chosen = Some((display, ctx, "device", Some(index)));
                        break;
                    }
                    Err(e) => attempts.push(format!("{label}: {e}")),
                }
            }
            if chosen.is_none() && matches!(choice, DeviceChoice::Index(_)) {
                return Err(Error::Egl(format!(
                    "requested EGL device failed: {}",
                    attempts.join("; ")
                )));
            }
        } else if let DeviceChoice::Index(i) = choice {
            return Err(Error::Egl(format!(
                "EGL device {i} requested but libEGL has no EGL_EXT_platform_device"
            )));
        }
        if chosen.is_none() {
            if client_ext.contains("EGL_MESA_platform_surfaceless") {
                // EGL_DEFAULT_DISPLAY with the surfaceless platform is the documented use.
                let ptr = get_platform_display(ext::PLATFORM_SURFACELESS_MESA, std::ptr::null_mut());
                if ptr.is_null() {
                    attempts.push("surfaceless: no display".into());
                } else {
                    // SAFETY: non-null EGLDisplay returned by EGL.
                    let display = unsafe { egl::Display::from_ptr(ptr) };
                    match create_context(&egl, display) {
                        Ok(ctx) => chosen = Some((display, ctx, "surfaceless", None)),
                        Err(e) => attempts.push(format!("surfaceless: {e}")),
                    }
                }
            } else {
                attempts.push("no EGL_MESA_platform_surfaceless".into());
            }
        }
        let Some((display, context, platform, device_index)) = chosen else {
            return Err(Error::Egl(format!(
                "no EGL display gave a GL 4.5 core context ({})",
                attempts.join("; ")
            )));
        };
        let chosen_device = device_index.map(|i| &devices[i]);

        // SAFETY: the context is current on this thread; EGL returns GL entry points for it.
        let gl = unsafe {
            glow::Context::from_loader_function(|name| {
                egl.get_proc_address(name)
                    .map_or(std::ptr::null(), |f| f as *const c_void)
            })
        };
        let clip_control = khronos::gl::Gl::load_with(khronos::egl_loader(&egl));
        if !clip_control.ClipControl.is_loaded() || !clip_control.ClearTexImage.is_loaded() {
            return Err(Error::Egl(
                "glClipControl or glClearTexImage missing (needs GL 4.5)".into(),
            ));
        }
        let egl_version = egl
            .query_string(Some(display), egl::VERSION)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let mut info = gl_info(&gl, egl_version, platform, device_index, chosen_device);
        info.software = devices::renderer_is_software(&info.renderer) || chosen_device.is_some_and(|d| d.software);
        if info.software {
            info.software_warning = devices::software_warning(
                &info.renderer,
                chosen_device,
                &devices,
                &HostProbe::default().nvidia_evidence(),
                &attempts,
            );
        }
        info.device_count = devices.len();
        info.auto_device = auto.first().copied();
        info.devices = devices;
        if (info.gl_major, info.gl_minor) < (4, 5) {
            return Err(Error::Egl(format!(
                "GL {}.{} < 4.5: {}",
                info.gl_major, info.gl_minor, info.renderer
            )));
        }
        Ok(EglContext {
            egl,
            display,
            context,
            gl,
            clip_control,
            info,
        })
    }
}

impl Drop for EglContext {
    fn drop(&mut self) {
        // The display is not terminated: EGL displays are per-process singletons, and other
        // contexts (other threads, other tests) may still use it.
        let _ = self.egl.make_current(self.display, None, None, None);
        let _ = self.egl.destroy_context(self.display, self.context);
    }
}

fn create_context(egl: &egl::DynamicInstance<egl::EGL1_4>, display: egl::Display) -> Result<egl::Context> {
    egl.initialize(display).map_err(|e| egl_err("eglInitialize", e))?;
    let ext = egl
        .query_string(Some(display), egl::EXTENSIONS)
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    if !ext.contains("EGL_KHR_surfaceless_context") {
        return Err(Error::Egl("display lacks EGL_KHR_surfaceless_context".into()));
    }
    egl.bind_api(egl::OPENGL_API)
        .map_err(|e| egl_err("eglBindAPI(OpenGL)", e))?;
    let config = if ext.contains("EGL_KHR_no_config_context") {
        // SAFETY: EGL_NO_CONFIG_KHR is the null config, valid with EGL_KHR_no_config_context.
        unsafe { egl::Config::from_ptr(std::ptr::null_mut()) }
    } else {
        egl.choose_first_config(display, &[egl::RENDERABLE_TYPE, egl::OPENGL_BIT, egl::NONE])
            .map_err(|e| egl_err("eglChooseConfig", e))?
            .ok_or_else(|| Error::Egl("no EGL config with OpenGL".into()))?
    };
    let mut last = None;
    for (major, minor) in [(4, 6), (4, 5)] {
        let attribs = [
            egl::CONTEXT_MAJOR_VERSION,
            major,
            egl::CONTEXT_MINOR_VERSION,
            minor,
            egl::CONTEXT_OPENGL_PROFILE_MASK,
            ext::CONTEXT_OPENGL_CORE_PROFILE_BIT as egl::Int,
            egl::NONE,
        ];
        match egl.create_context(display, config, None, &attribs) {
            Ok(ctx) => {
                egl.make_current(display, None, None, Some(ctx))
                    .map_err(|e| egl_err("eglMakeCurrent", e))?;
                return Ok(ctx);
            }
            Err(e) => last = Some(format!("GL {major}.{minor} core: {e}")),
        }
    }
    Err(Error::Egl(last.unwrap_or_default()))
}

fn enumerate_devices(entry: &ext::Egl, client_ext: &str) -> Vec<ext::types::EGLDeviceEXT> {
    if !client_ext.contains("EGL_EXT_device_enumeration") && !client_ext.contains("EGL_EXT_device_base") {
        return Vec::new();
    }
    if !entry.QueryDevicesEXT.is_loaded() {
        return Vec::new();
    }
    let mut devices = vec![std::ptr::null(); 32];
    let mut count = 0;
    // SAFETY: loaded above; the buffer holds 32 handles and we pass that capacity.
    if unsafe { entry.QueryDevicesEXT(devices.len() as egl::Int, devices.as_mut_ptr(), &mut count) } == 0 {
        return Vec::new();
    }
    devices.truncate(count.max(0) as usize);
    devices
}

fn device_string(entry: &ext::Egl, device: ext::types::EGLDeviceEXT, name: egl::Int) -> Option<String> {
    // Without eglQueryDeviceStringEXT no device has strings (as when enumeration failed).
    if !entry.QueryDeviceStringEXT.is_loaded() {
        return None;
    }
    // SAFETY: loaded above; a valid device handle; EGL returns a static NUL-terminated string
    // or null.
    let p = unsafe { entry.QueryDeviceStringEXT(device, name) };
    // SAFETY: checked non-null above; EGL strings are NUL-terminated.
    (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

/// What each device says about itself. Strings an extension does not promise are not asked
/// for.
fn describe_devices(entry: &ext::Egl, handles: &[ext::types::EGLDeviceEXT]) -> Vec<EglDevice> {
    handles
        .iter()
        .enumerate()
        .map(|(index, &handle)| {
            let string = |name: u32| device_string(entry, handle, name as egl::Int);
            let mut d = EglDevice::new(index, string(ext::EXTENSIONS).unwrap_or_default());
            if d.has_extension("EGL_EXT_device_drm") {
                d.drm_file = string(ext::DRM_DEVICE_FILE_EXT);
            }
            if d.has_extension("EGL_EXT_device_drm_render_node") {
                d.render_node = string(EGL_DRM_RENDER_NODE_FILE_EXT as u32);
            }
            if d.has_extension("EGL_EXT_device_persistent_id") {
                d.driver = string(EGL_DRIVER_NAME_EXT as u32);
            }
            if d.has_extension("EGL_EXT_device_query_name") {
                d.vendor = string(ext::VENDOR);
                d.renderer = string(EGL_RENDERER_EXT as u32);
            }
            // Asked of every device, as before the descriptions existed: a device without
            // EGL_NV_device_cuda just answers false (and EGL's last error is per call).
            if entry.QueryDeviceAttribEXT.is_loaded() {
                let mut value: isize = -1;
                // SAFETY: loaded; valid device handle and out-pointer.
                if unsafe { entry.QueryDeviceAttribEXT(handle, ext::CUDA_DEVICE_NV as egl::Int, &mut value) } != 0 {
                    d.cuda_device = Some(value as i64);
                }
            }
            d
        })
        .collect()
}

fn gl_info(
    gl: &glow::Context,
    egl_version: String,
    platform: &str,
    device_index: Option<usize>,
    device: Option<&EglDevice>,
) -> GpuInfo {
    use glow::HasContext;
    // SAFETY: plain state queries on the current context.
    unsafe {
        let renderer = gl.get_parameter_string(glow::RENDERER);
        let mut vp = [0i32; 2];
        gl.get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut vp);
        GpuInfo {
            vendor: gl.get_parameter_string(glow::VENDOR),
            gpu_timers_meaningful: !renderer.contains("llvmpipe") && !renderer.contains("softpipe"),
            renderer,
            version: gl.get_parameter_string(glow::VERSION),
            glsl_version: gl.get_parameter_string(glow::SHADING_LANGUAGE_VERSION),
            egl_version,
            platform: platform.to_string(),
            device_index,
            device_count: 0,
            device_file: device.and_then(|d| d.drm_file.clone()),
            device_extensions: device.map(|d| d.extensions.clone()).unwrap_or_default(),
            gl_major: gl.get_parameter_i32(glow::MAJOR_VERSION),
            gl_minor: gl.get_parameter_i32(glow::MINOR_VERSION),
            max_texture_size: gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE),
            max_viewport: vp,
            devices: Vec::new(),
            auto_device: None,
            software: false,
            software_warning: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::DeviceChoice;

    #[test]
    fn device_choice_parses_auto_surfaceless_or_an_index() {
        assert_eq!("auto".parse::<DeviceChoice>().unwrap(), DeviceChoice::Auto);
        assert_eq!(
            "surfaceless".parse::<DeviceChoice>().unwrap(),
            DeviceChoice::Surfaceless
        );
        assert_eq!("3".parse::<DeviceChoice>().unwrap(), DeviceChoice::Index(3));
        for bad in ["gpu0", "-1", "", "Auto"] {
            let e = bad.parse::<DeviceChoice>().unwrap_err();
            assert_eq!(e.value, bad);
            assert_eq!(
                e.to_string(),
                format!("'{bad}': expected \"auto\", \"surfaceless\" or an index")
            );
        }
    }
}
