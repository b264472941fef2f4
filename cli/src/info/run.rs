//! `viewsynth info`: the GPU, GL version, EGL platform/device and limits, as text or JSON.

use super::args::InfoRequest;
use crate::host::CliHost;
use crate::options::BackendArg;
use anyhow::Result;
use viewsynth::gpu::GpuInfo;
use viewsynth::job::Host;

pub(crate) fn info(request: &InfoRequest) -> Result<()> {
    if request.backend == BackendArg::Vulkan {
        return info_vulkan(request);
    }
    let gpu = CliHost::default().open_gpu(&request.gpu)?;
    let i = gpu.info();
    if request.json {
        outln!("{}", serde_json::to_string_pretty(i)?);
        return Ok(());
    }
    outln!("vendor:      {}", i.vendor);
    outln!("renderer:    {}", i.renderer);
    outln!(
        "GL version:  {} (core {}.{}), GLSL {}",
        i.version,
        i.gl_major,
        i.gl_minor,
        i.glsl_version
    );
    outln!("EGL:         {} via {} platform", i.egl_version, i.platform);
    let dev = i.device_index.map_or("-".to_string(), |d| d.to_string());
    outln!(
        "device:      {dev} of {} ({})",
        i.device_count,
        i.device_file.as_deref().unwrap_or("no DRM file")
    );
    outln!(
        "device ext:  {}",
        if i.device_extensions.is_empty() {
            "-"
        } else {
            &i.device_extensions
        }
    );
    outln!(
        "limits:      max texture {}, max viewport {}x{}",
        i.max_texture_size,
        i.max_viewport[0],
        i.max_viewport[1]
    );
    outln!(
        "GPU timers:  {}",
        if i.gpu_timers_meaningful {
            "yes"
        } else {
            "no (wall clock with glFinish)"
        }
    );
    outln!("rendering:   {}", if i.software { "software" } else { "hardware" });
    out!("{}", device_table(i));
    Ok(())
}

/// Every EGL device, one line each, and the one `--device auto` picks.
fn device_table(i: &GpuInfo) -> String {
    let auto = match i.auto_device {
        Some(d) => format!("device {d} ({})", i.devices[d].kind()),
        None => "Mesa surfaceless (no EGL device)".into(),
    };
    let mut s = format!("EGL devices: {} (auto picks {auto})\n", i.devices.len());
    for d in &i.devices {
        let or_dash = |v: &Option<String>| v.clone().unwrap_or_else(|| "-".into());
        s += &format!(
            "  [{}] {}{}  driver {}  vendor {}  file {}  CUDA {}  ext {}\n",
            d.index,
            d.kind(),
            if i.device_index == Some(d.index) {
                " (in use)"
            } else {
                ""
            },
            or_dash(&d.driver),
            or_dash(&d.vendor),
            or_dash(&d.drm_file.clone().or(d.render_node.clone())),
            d.cuda_device.map_or("-".into(), |c| c.to_string()),
            d.notable_extensions()
        );
    }
    s
}

/// `info --backend vulkan`: every Vulkan physical device and the one `--device auto` opens.
fn info_vulkan(request: &InfoRequest) -> Result<()> {
    let devices = viewsynth::vulkan::list_devices()?;
    let auto = viewsynth::vulkan::auto_pick(&devices);
    if request.json {
        let v = serde_json::json!({ "devices": devices, "auto_device": auto });
        outln!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        outln!("Vulkan devices: {}", devices.len());
        for d in &devices {
            outln!(
                "  {}: {} ({}, {}), API {}, driver {} {}, max image {}{}{}",
                d.index,
                d.name,
                d.device_type,
                if d.software { "software" } else { "hardware" },
                d.api_version,
                d.driver_name,
                d.driver_info,
                d.max_image_dimension_2d,
                if d.depth_clip_control {
                    ""
                } else {
                    ", no depth clip control (--ndc gl mesh pass unavailable)"
                },
                if d.usable {
                    ""
                } else {
                    ", UNUSABLE (needs 1.3, dynamic rendering, depth clamp)"
                }
            );
        }
        match auto {
            Some(i) => outln!("auto picks: device {i}"),
            None => outln!("auto picks: none (no usable device)"),
        }
    }
    // The same refusal a rendering command would give.
    if request.open_vulkan {
        CliHost::default().open_vulkan(&request.gpu)?;
    }
    Ok(())
}
