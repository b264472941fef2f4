//! The GL side of [`GpuPolicy`] (`--require-gpu` and `VIEWSYNTH_REQUIRE_GPU`): refusing a
//! software EGL renderer, naming what hardware was visible. The policy itself is the pass
//! layer's, shared with Vulkan.

use super::devices::{visible_hardware, HostProbe};
use super::egl::GpuInfo;
use crate::error::{Error, Result};
use crate::pass::GpuPolicy;

// An inherent impl beside the GL code that it needs, so the shared type knows no backend.
impl GpuPolicy {
    /// Refuse `info` when hardware is required and the renderer is software.
    pub fn check(&self, info: &GpuInfo) -> Result<()> {
        if !self.require_hardware || !info.software {
            return Ok(());
        }
        self.check_with(info, &HostProbe::default().nvidia_evidence())
    }

    /// [`Self::check`] with the host's NVIDIA signs given (tests pass synthetic ones).
    pub fn check_with(&self, info: &GpuInfo, host_evidence: &[String]) -> Result<()> {
        if !self.require_hardware || !info.software {
            return Ok(());
        }
        let location = match info.device_index.and_then(|i| info.devices.get(i)) {
            Some(d) => d.label(),
            None => format!("the {} platform", info.platform),
        };
        let hardware = visible_hardware(&info.devices, host_evidence);
        let seen = if hardware.is_empty() {
            "no hardware EGL device or NVIDIA driver is visible (in Docker: --gpus all \
             -e NVIDIA_DRIVER_CAPABILITIES=graphics,utility)"
                .to_string()
        } else {
            format!("hardware visible but not used: {}", hardware.join("; "))
        };
        Err(Error::SoftwareRenderer {
            renderer: info.renderer.clone(),
            location,
            seen,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(renderer: &str, software: bool, devices: Vec<crate::gpu::EglDevice>) -> GpuInfo {
        GpuInfo {
            vendor: "v".into(),
            renderer: renderer.into(),
            version: "4.5".into(),
            glsl_version: "4.50".into(),
            egl_version: "1.5".into(),
            platform: "device".into(),
            device_index: Some(0),
            device_count: devices.len(),
            device_file: None,
            device_extensions: String::new(),
            gl_major: 4,
            gl_minor: 5,
            max_texture_size: 16384,
            max_viewport: [16384, 16384],
            gpu_timers_meaningful: !software,
            devices,
            auto_device: Some(0),
            software,
            software_warning: None,
        }
    }

    #[test]
    fn software_is_refused_only_when_hardware_is_required() {
        use crate::gpu::EglDevice;
        let sw = vec![EglDevice::new(0, "EGL_MESA_device_software")];
        let required = GpuPolicy { require_hardware: true };
        let e = required
            .check_with(&info("llvmpipe (LLVM 15)", true, sw.clone()), &[])
            .unwrap_err();
        assert!(matches!(e, Error::SoftwareRenderer { .. }));
        let text = e.to_string();
        assert!(
            text.contains("'llvmpipe (LLVM 15)'") && text.contains("EGL device 0 (software"),
            "{text}"
        );
        assert!(text.contains("no hardware EGL device"), "{text}");
        let text = required
            .check_with(&info("llvmpipe", true, sw.clone()), &["/dev/nvidia0".into()])
            .unwrap_err()
            .to_string();
        assert!(
            text.contains("hardware visible but not used: NVIDIA driver sign /dev/nvidia0"),
            "{text}"
        );
        GpuPolicy::default()
            .check_with(&info("llvmpipe", true, sw), &[])
            .unwrap();
        let hw = vec![EglDevice::new(0, "EGL_NV_device_cuda")];
        required.check_with(&info("NVIDIA H100", false, hw), &[]).unwrap();
    }
}
