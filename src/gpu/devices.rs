//! What EGL says about each device, and the pure decisions taken over those descriptions:
//! the order `auto` tries devices in, whether a renderer is software, and whether a software
//! renderer deserves a warning because hardware is visible. Kept free of FFI so the decisions
//! are unit-tested with synthetic device lists.

use serde::Serialize;
use std::path::{Path, PathBuf};

/// The device extensions `viewsynth info` shows: they tell software from hardware and name the
/// DRM node or CUDA ordinal.
pub const NOTABLE_EXTENSIONS: [&str; 4] = [
    "EGL_MESA_device_software",
    "EGL_EXT_device_drm",
    "EGL_EXT_device_drm_render_node",
    "EGL_NV_device_cuda",
];

/// One EGL device as `eglQueryDevicesEXT` lists it, described without creating a context.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct EglDevice {
    /// Position in `eglQueryDevicesEXT`'s list: the `--device` index.
    pub index: usize,
    /// The device's EGL extension string.
    pub extensions: String,
    /// `EGL_DRIVER_NAME_EXT` (EGL_EXT_device_persistent_id), e.g. "nvidia" or "swrast".
    pub driver: Option<String>,
    /// `EGL_VENDOR` on the device (EGL_EXT_device_query_name).
    pub vendor: Option<String>,
    /// `EGL_RENDERER_EXT` on the device (EGL_EXT_device_query_name).
    pub renderer: Option<String>,
    /// `EGL_DRM_DEVICE_FILE_EXT`, e.g. /dev/dri/card0.
    pub drm_file: Option<String>,
    /// `EGL_DRM_RENDER_NODE_FILE_EXT`, e.g. /dev/dri/renderD128.
    pub render_node: Option<String>,
    /// `EGL_CUDA_DEVICE_NV`: the physical CUDA ordinal of an NVIDIA device.
    pub cuda_device: Option<i64>,
    /// True for Mesa's software device (EGL_MESA_device_software): llvmpipe or softpipe.
    pub software: bool,
}

impl EglDevice {
    /// A description from the queried strings; `software` follows from the extensions.
    pub fn new(index: usize, extensions: impl Into<String>) -> Self {
        let extensions = extensions.into();
        let software = has_extension(&extensions, "EGL_MESA_device_software");
        EglDevice {
            index,
            extensions,
            software,
            ..Default::default()
        }
    }

    /// Whether the device's extension string lists `name` (whole word).
    pub fn has_extension(&self, name: &str) -> bool {
        has_extension(&self.extensions, name)
    }

    /// "software" or "hardware".
    pub fn kind(&self) -> &'static str {
        if self.software {
            "software"
        } else {
            "hardware"
        }
    }

    /// The notable extensions this device has, space-separated ("-" when none).
    pub fn notable_extensions(&self) -> String {
        let found: Vec<&str> = NOTABLE_EXTENSIONS
            .iter()
            .copied()
            .filter(|e| self.has_extension(e))
            .collect();
        if found.is_empty() {
            "-".into()
        } else {
            found.join(" ")
        }
    }

    /// One line naming the device: index, kind, driver or vendor, file and CUDA ordinal.
    pub fn label(&self) -> String {
        let mut s = format!("EGL device {} ({}", self.index, self.kind());
        if let Some(d) = self.driver.as_deref().or(self.vendor.as_deref()) {
            s += &format!(", {d}");
        }
        if let Some(r) = &self.renderer {
            s += &format!(", {r}");
        }
        if let Some(f) = self.drm_file.as_deref().or(self.render_node.as_deref()) {
            s += &format!(", {f}");
        }
        if let Some(c) = self.cuda_device {
            s += &format!(", CUDA {c}");
        }
        s + ")"
    }
}

/// Exact-token match in an EGL extension string (EGL_EXT_device_drm must not match
/// EGL_EXT_device_drm_render_node).
pub fn has_extension(list: &str, name: &str) -> bool {
    list.split_whitespace().any(|e| e == name)
}

/// The order `--device auto` tries devices in: the CUDA_VISIBLE_DEVICES match first (its first
/// entry is a physical CUDA ordinal, which NVIDIA's EGL reports), then hardware devices, then
/// software ones, each group in enumeration order. So the vendor-file order (glvnd lists Mesa's
/// software device before NVIDIA's when 50_mesa.json sorts first) never decides.
pub fn auto_order(devices: &[EglDevice], cuda_visible_devices: Option<&str>) -> Vec<usize> {
    let cuda = cuda_visible_devices.and_then(|v| v.split(',').next().and_then(|s| s.trim().parse::<i64>().ok()));
    let cuda_match = cuda.and_then(|c| devices.iter().position(|d| d.cuda_device == Some(c)));
    let mut order: Vec<usize> = (0..devices.len()).collect();
    // Stable: within a rank the enumeration order is kept.
    order.sort_by_key(|&i| (Some(i) != cuda_match, devices[i].software));
    order
}

/// Whether a GL_RENDERER string names a software rasteriser.
pub fn renderer_is_software(renderer: &str) -> bool {
    let r = renderer.to_ascii_lowercase();
    ["llvmpipe", "softpipe", "swrast", "software rasterizer", "lavapipe"]
        .iter()
        .any(|s| r.contains(s))
}

/// Where to look for signs of an NVIDIA driver on this host (or in this container).
#[derive(Debug, Clone)]
pub struct HostProbe {
    /// Device nodes whose presence means an NVIDIA driver is installed (e.g. /dev/nvidia0).
    pub device_nodes: Vec<PathBuf>,
    /// File holding the NVIDIA kernel driver's version (/proc/driver/nvidia/version).
    pub driver_version_file: PathBuf,
    /// glvnd EGL vendor folders; a JSON there naming NVIDIA's library counts when that library
    /// is present (an image may ship the JSON for the NVIDIA toolkit to fill in).
    pub egl_vendor_dirs: Vec<PathBuf>,
    /// Where a vendor JSON's bare library name is looked for.
    pub library_dirs: Vec<PathBuf>,
}

impl Default for HostProbe {
    /// The standard places, plus `__EGL_VENDOR_LIBRARY_DIRS` when set (glvnd reads it instead).
    fn default() -> Self {
        let mut egl_vendor_dirs: Vec<PathBuf> = match std::env::var_os("__EGL_VENDOR_LIBRARY_DIRS") {
            Some(v) => std::env::split_paths(&v).collect(),
            None => Vec::new(),
        };
        egl_vendor_dirs.extend(["/etc/glvnd/egl_vendor.d", "/usr/share/glvnd/egl_vendor.d"].map(PathBuf::from));
        let mut library_dirs: Vec<PathBuf> = match std::env::var_os("LD_LIBRARY_PATH") {
            Some(v) => std::env::split_paths(&v).collect(),
            None => Vec::new(),
        };
        library_dirs.extend(
            [
                "/usr/lib/x86_64-linux-gnu",
                "/usr/lib/aarch64-linux-gnu",
                "/usr/lib64",
                "/usr/lib",
                "/usr/local/nvidia/lib64",
                "/usr/local/nvidia/lib",
            ]
            .map(PathBuf::from),
        );
        HostProbe {
            device_nodes: vec![PathBuf::from("/dev/nvidia0")],
            driver_version_file: PathBuf::from("/proc/driver/nvidia/version"),
            egl_vendor_dirs,
            library_dirs,
        }
    }
}

impl HostProbe {
    /// Human-readable evidence of an NVIDIA driver, one entry per sign found.
    pub fn nvidia_evidence(&self) -> Vec<String> {
        let mut found = Vec::new();
        for node in &self.device_nodes {
            if node.exists() {
                found.push(node.display().to_string());
            }
        }
        if let Ok(text) = std::fs::read_to_string(&self.driver_version_file) {
            let first = text.lines().next().unwrap_or("").trim();
            found.push(format!("{} ({first})", self.driver_version_file.display()));
        }
        for dir in &self.egl_vendor_dirs {
            for (json, lib) in self.nvidia_vendor_files(dir) {
                found.push(format!("{} -> {}", json.display(), lib.display()));
            }
        }
        found
    }

    /// NVIDIA vendor JSONs in `dir` whose library exists, with that library's path.
    fn nvidia_vendor_files(&self, dir: &Path) -> Vec<(PathBuf, PathBuf)> {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return Vec::new();
        };
        let mut jsons: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "json"))
            .collect();
        jsons.sort();
        jsons
            .into_iter()
            .filter_map(|json| {
                let text = std::fs::read_to_string(&json).ok()?;
                let value: serde_json::Value = serde_json::from_str(&text).ok()?;
                let lib = value["ICD"]["library_path"].as_str()?;
                if !lib.to_ascii_lowercase().contains("nvidia") {
                    return None;
                }
                let found = if lib.contains('/') {
                    Some(PathBuf::from(lib)).filter(|p| p.exists())
                } else {
                    self.library_dirs.iter().map(|d| d.join(lib)).find(|p| p.exists())
                };
                found.map(|lib| (json, lib))
            })
            .collect()
    }
}

/// Hardware EGL devices and NVIDIA driver signs, one line each.
pub fn visible_hardware(devices: &[EglDevice], host_evidence: &[String]) -> Vec<String> {
    let mut seen: Vec<String> = devices.iter().filter(|d| !d.software).map(EglDevice::label).collect();
    seen.extend(host_evidence.iter().map(|e| format!("NVIDIA driver sign {e}")));
    seen
}

/// The warning to print when rendering runs on software although hardware is visible: `None`
/// when the renderer is hardware, or when nothing suggests a GPU. Names the software renderer
/// and every hardware device or NVIDIA sign seen, plus why hardware devices were not used.
pub fn software_warning(
    renderer: &str,
    chosen: Option<&EglDevice>,
    devices: &[EglDevice],
    host_evidence: &[String],
    failed_attempts: &[String],
) -> Option<crate::Message> {
    let software = renderer_is_software(renderer) || chosen.is_some_and(|d| d.software);
    if !software {
        return None;
    }
    let seen = visible_hardware(devices, host_evidence);
    if seen.is_empty() {
        return None;
    }
    let mut text = format!(
        "rendering on the software renderer '{renderer}' although hardware is visible: {}",
        seen.join("; ")
    );
    if !failed_attempts.is_empty() {
        text += &format!(". Tried first: {}", failed_attempts.join("; "));
    }
    text += ". Pick a device with ";
    Some(crate::msg![
        text,
        crate::Field::Device,
        " N (see `viewsynth info`); in Docker run with --gpus all \
         -e NVIDIA_DRIVER_CAPABILITIES=graphics,utility so NVIDIA's EGL is mounted; ",
        crate::Field::RequireGpu,
        " (or VIEWSYNTH_REQUIRE_GPU=1) turns this into an error"
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesa_software(index: usize) -> EglDevice {
        EglDevice {
            driver: Some("swrast".into()),
            ..EglDevice::new(index, "EGL_MESA_device_software EGL_EXT_device_drm_render_node")
        }
    }

    fn nvidia(index: usize, cuda: i64) -> EglDevice {
        EglDevice {
            driver: Some("nvidia".into()),
            drm_file: Some(format!("/dev/dri/card{cuda}")),
            cuda_device: Some(cuda),
            ..EglDevice::new(index, "EGL_NV_device_cuda EGL_EXT_device_drm EGL_EXT_device_query_name")
        }
    }

    #[test]
    fn software_is_told_from_the_extension_token_exactly() {
        assert!(mesa_software(0).software);
        assert!(!nvidia(0, 0).software);
        assert!(!EglDevice::new(0, "EGL_MESA_device_software_x").software);
        assert!(has_extension("A EGL_EXT_device_drm B", "EGL_EXT_device_drm"));
        assert!(!has_extension("EGL_EXT_device_drm_render_node", "EGL_EXT_device_drm"));
    }

    #[test]
    fn auto_prefers_hardware_whatever_the_enumeration_order() {
        let devices = [mesa_software(0), nvidia(1, 0)];
        assert_eq!(auto_order(&devices, None), vec![1, 0]);
        let devices = [nvidia(0, 0), mesa_software(1)];
        assert_eq!(auto_order(&devices, None), vec![0, 1]);
    }

    #[test]
    fn auto_takes_software_when_it_is_all_there_is() {
        assert_eq!(auto_order(&[mesa_software(0)], None), vec![0]);
        assert_eq!(auto_order(&[mesa_software(0), mesa_software(1)], Some("0")), vec![0, 1]);
        assert!(auto_order(&[], Some("0")).is_empty());
    }

    #[test]
    fn auto_puts_the_cuda_visible_gpu_first() {
        let devices = [mesa_software(0), nvidia(1, 0), nvidia(2, 3), nvidia(3, 1)];
        // CUDA_VISIBLE_DEVICES lists physical ordinals; its first entry is the one to use.
        assert_eq!(auto_order(&devices, Some("3,1")), vec![2, 1, 3, 0]);
        assert_eq!(auto_order(&devices, Some(" 1 ")), vec![3, 1, 2, 0]);
        // No match (or a UUID form) keeps hardware-then-software.
        assert_eq!(auto_order(&devices, Some("7")), vec![1, 2, 3, 0]);
        assert_eq!(auto_order(&devices, Some("GPU-1234")), vec![1, 2, 3, 0]);
    }

    #[test]
    fn software_renderers_are_recognised() {
        assert!(renderer_is_software("llvmpipe (LLVM 15.0.6, 256 bits)"));
        assert!(renderer_is_software("softpipe"));
        assert!(!renderer_is_software("NVIDIA H100 80GB HBM3/PCIe/SSE2"));
        assert!(!renderer_is_software(
            "AMD Radeon RX 7900 XTX (radeonsi, navi31, LLVM 15.0.7)"
        ));
    }

    #[test]
    fn warning_names_the_software_renderer_and_the_hardware_seen() {
        let devices = [mesa_software(0), nvidia(1, 0)];
        let attempts = ["device 1: eglInitialize: BadAlloc".to_string()];
        let w = software_warning("llvmpipe (LLVM 15)", Some(&devices[0]), &devices, &[], &attempts)
            .expect("hardware device visible")
            .to_string();
        assert!(w.contains("llvmpipe (LLVM 15)"), "{w}");
        assert!(
            w.contains("EGL device 1 (hardware, nvidia, /dev/dri/card0, CUDA 0)"),
            "{w}"
        );
        assert!(w.contains("BadAlloc"), "{w}");

        let evidence = ["/dev/nvidia0".to_string()];
        let only_sw = [mesa_software(0)];
        let w = software_warning("llvmpipe", Some(&only_sw[0]), &only_sw, &evidence, &[])
            .expect("driver seen")
            .to_string();
        assert!(w.contains("llvmpipe") && w.contains("/dev/nvidia0"), "{w}");
    }

    #[test]
    fn no_warning_on_hardware_or_when_no_gpu_is_visible() {
        let devices = [mesa_software(0), nvidia(1, 0)];
        let ev = ["/dev/nvidia0".to_string()];
        assert_eq!(
            software_warning("NVIDIA H100", Some(&devices[1]), &devices, &ev, &[]),
            None
        );
        let only_sw = [mesa_software(0)];
        assert_eq!(
            software_warning("llvmpipe", Some(&only_sw[0]), &only_sw, &[], &[]),
            None
        );
        // Surfaceless (no device) with a software GL_RENDERER still warns when a GPU is seen.
        assert!(software_warning("llvmpipe", None, &[], &ev, &[]).is_some());
    }

    #[test]
    fn host_probe_finds_nvidia_vendor_files_and_driver_version() {
        let dir = std::env::temp_dir().join(format!("viewsynth-host-probe-{}", std::process::id()));
        let vendor = dir.join("egl_vendor.d");
        std::fs::create_dir_all(&vendor).unwrap();
        std::fs::write(
            vendor.join("50_mesa.json"),
            r#"{"ICD":{"library_path":"libEGL_mesa.so.0"}}"#,
        )
        .unwrap();
        let libs = dir.join("lib");
        std::fs::create_dir_all(&libs).unwrap();
        let probe = HostProbe {
            device_nodes: vec![dir.join("nvidia0")],
            driver_version_file: dir.join("version"),
            egl_vendor_dirs: vec![vendor.clone(), dir.join("absent")],
            library_dirs: vec![libs.clone()],
        };
        assert!(probe.nvidia_evidence().is_empty());
        // A vendor JSON whose library is absent (an image shipping the JSON, run without
        // --gpus) is no sign of a driver.
        std::fs::write(
            vendor.join("10_nvidia.json"),
            r#"{"ICD":{"library_path":"libEGL_nvidia.so.0"}}"#,
        )
        .unwrap();
        assert!(probe.nvidia_evidence().is_empty());
        std::fs::write(libs.join("libEGL_nvidia.so.0"), "").unwrap();
        std::fs::write(
            dir.join("version"),
            "NVRM version: NVIDIA UNIX x86_64 Kernel Module  550.54\nGCC\n",
        )
        .unwrap();
        std::fs::write(dir.join("nvidia0"), "").unwrap();
        let ev = probe.nvidia_evidence();
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(ev.len(), 3, "{ev:?}");
        assert!(ev[0].ends_with("nvidia0"));
        assert!(ev[1].contains("Kernel Module  550.54"), "{ev:?}");
        assert!(
            ev[2].contains("10_nvidia.json -> ") && ev[2].ends_with("libEGL_nvidia.so.0"),
            "{ev:?}"
        );
    }
}
