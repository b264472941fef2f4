//! `Renderer.reproject` on a parallel stereo rig: the library calls of the CLI's rig mode
//! (`viewsynth reproject --fx ... --baseline ...`), numpy in and out.

use crate::arrays;
use crate::backend::Backend;
use crate::errors;
use crate::shared::SameThread;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use viewsynth::camera::stereo::{Eye, StereoParams};
use viewsynth::camera::PinholeCamera;
use viewsynth::convention::{Conventions, DepthPlanes};
use viewsynth::depth::DepthEncoding;
use viewsynth::gpu::Timing;
use viewsynth::reproject::render::Reprojector;
use viewsynth::reproject::{
    Geometry, Method, ReprojectOutput, ReprojectOutputs, ReprojectParams, ReprojectSource, ShiftModel,
};

/// The arguments of one call, as Python gave them.
pub struct ReprojectArgs<'a, 'py> {
    pub rgb: &'a Bound<'py, PyAny>,
    pub depth: &'a Bound<'py, PyAny>,
    pub k: &'a Bound<'py, PyAny>,
    pub depth_kind: &'a str,
    pub baseline: Option<f64>,
    pub focal: Option<f64>,
    pub doffs: f64,
    pub separation: Option<f64>,
    pub convergence: Option<f64>,
    pub near: Option<f64>,
    pub far: Option<f64>,
    pub source: &'a str,
    pub target: &'a str,
    pub method: &'a str,
    pub steps: u32,
    pub tau_rel: f64,
    pub outputs: Option<&'a Bound<'py, PyAny>>,
}

fn eye_name(eye: Eye) -> &'static str {
    match eye {
        Eye::Left => "left",
        Eye::Right => "right",
    }
}

/// The source view (None = centre) and the target eyes, as the CLI's --from/--to.
fn views(source: &str, target: &str) -> PyResult<(Option<Eye>, Vec<Eye>)> {
    let from = match source {
        "left" => Some(Eye::Left),
        "centre" | "center" => None,
        "right" => Some(Eye::Right),
        _ => {
            return Err(errors::invalid(
                "source",
                format!("'{source}': expected \"left\", \"centre\" or \"right\""),
            ))
        }
    };
    let to = match target {
        "left" => vec![Eye::Left],
        "right" => vec![Eye::Right],
        "both" => vec![Eye::Left, Eye::Right],
        _ => {
            return Err(errors::invalid(
                "target",
                format!("'{target}': expected \"left\", \"right\" or \"both\""),
            ))
        }
    };
    if to.len() == 2 && from.is_some() {
        return Err(errors::invalid(
            "target",
            "\"both\" needs source=\"centre\" (from an eye, the only other view is the other eye)",
        ));
    }
    if to.len() == 1 && from == Some(to[0]) {
        return Err(errors::invalid(
            "target",
            "is the source view itself: nothing to reproject",
        ));
    }
    Ok((from, to))
}

fn method(name: &str, steps: u32) -> PyResult<Method> {
    Ok(match name {
        "shift-scan" => Method::ShiftScan,
        "shift" => Method::Shift { steps },
        "gather3d" => Method::Gather3d { steps },
        _ => {
            return Err(errors::invalid(
                "method",
                format!("'{name}': expected \"shift-scan\", \"shift\" or \"gather3d\""),
            ))
        }
    })
}

/// What the depth array holds, as the CLI's --depth-kind with its checks.
fn depth_input(a: &ReprojectArgs<'_, '_>, focal: f64) -> PyResult<DepthEncoding> {
    let kind = match a.depth_kind {
        "view-z" => DepthEncoding::ViewZ,
        "device" => {
            let (Some(near), Some(far)) = (a.near, a.far) else {
                return Err(errors::invalid(
                    "near",
                    "depth_kind=\"device\" needs near and far (the planes the depth buffer was written with)",
                ));
            };
            DepthEncoding::Device {
                planes: DepthPlanes { near, far },
            }
        }
        "disparity" => {
            let Some(baseline) = a.baseline else {
                return Err(errors::invalid(
                    "baseline",
                    "depth_kind=\"disparity\" needs baseline (metres; Z = baseline * focal / (d + doffs))",
                ));
            };
            DepthEncoding::Disparity {
                focal_px: focal,
                baseline,
                doffs: a.doffs,
            }
        }
        other => {
            return Err(errors::invalid(
                "depth_kind",
                format!("'{other}': expected \"view-z\", \"device\" or \"disparity\""),
            ))
        }
    };
    if a.depth_kind != "device" && (a.near.is_some() || a.far.is_some()) {
        return Err(errors::invalid("near", "near/far apply to depth_kind=\"device\" only"));
    }
    kind.validate().map_err(errors::from_library)?;
    Ok(kind)
}

type Rendered = Vec<(Eye, f64, ReprojectOutput, Timing)>;

fn render(
    gpu: &Backend,
    src: &ReprojectSource,
    targets: &[(Eye, Geometry)],
    params: ReprojectParams,
) -> viewsynth::Result<Rendered> {
    let mut results = Vec::new();
    for (to, geometry) in targets {
        let t0 = std::time::Instant::now();
        let mut r = Reprojector::new(gpu, src, geometry, params)?;
        let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
        let (out, timing) = r.render()?;
        results.push((*to, setup_ms, out, timing));
    }
    Ok(results)
}

/// Validates `a`, renders every target with the GIL released, and returns {eye name: dict}.
pub fn reproject<'py>(py: Python<'py>, gpu: Backend, a: ReprojectArgs<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let params = ReprojectParams {
        method: method(a.method, a.steps)?,
        outputs: ReprojectOutputs::default(),
        tau_rel: a.tau_rel,
    };
    params.validate().map_err(errors::from_library)?;
    let outputs = crate::shared::output_set(a.outputs)?;
    let params = ReprojectParams {
        outputs: ReprojectOutputs {
            color: outputs.rgb,
            depth: outputs.depth,
        },
        ..params
    };
    let (from, targets) = views(a.source, a.target)?;
    let k = arrays::intrinsics(a.k, "K")?;
    let focal = a.focal.unwrap_or(k.fx);
    let depth_kind = depth_input(&a, focal)?;
    let seed = match (a.separation, a.convergence) {
        (Some(s), Some(c)) => Some(StereoParams::new(s, c).map_err(errors::from_library)?),
        (None, None) => None,
        (Some(_), None) => return Err(errors::invalid("convergence", "separation needs convergence (metres)")),
        (None, Some(_)) => return Err(errors::invalid("separation", "convergence needs separation")),
    };
    if seed.is_none() && a.baseline.is_none() {
        return Err(errors::invalid(
            "baseline",
            "give the rig: baseline=B (rectified, metres) or separation=S, convergence=C (game-engine stereo)",
        ));
    }
    let src = ReprojectSource {
        color: arrays::rgb_image(a.rgb, "rgb")?,
        depth: arrays::float_map(a.depth, "depth")?,
        depth_kind,
        conv: Conventions::default(),
    };
    let (w, h) = (src.color.width, src.color.height);
    if (src.depth.width, src.depth.height) != (w, h) {
        return Err(errors::invalid(
            "depth",
            format!(
                "{}x{} (W x H) differs from rgb's {w}x{h}",
                src.depth.width, src.depth.height
            ),
        ));
    }
    src.validate().map_err(errors::from_library)?;
    gpu.check_image_size("rgb", src.color.width, src.color.height)
        .map_err(errors::from_library)?;
    if src.inverse_depth_range().is_none() {
        return Err(errors::invalid(
            "depth",
            format!("no pixel holds valid depth as depth_kind=\"{}\"", a.depth_kind),
        ));
    }
    let camera = PinholeCamera {
        k,
        width: src.color.width,
        height: src.color.height,
    };
    camera.validate("K").map_err(errors::from_library)?;
    let mut geometries = Vec::new();
    for &to in &targets {
        let shift = match (&seed, a.baseline) {
            (Some(p), _) => ShiftModel::seed(p, camera.width, from, Some(to)),
            (None, Some(b)) => {
                ShiftModel::rectified(focal, b, a.doffs, from, Some(to)).map_err(errors::from_library)?
            }
            (None, None) => unreachable!("refused above"),
        };
        shift.validate().map_err(errors::from_library)?;
        geometries.push((to, Geometry::Rig { camera, shift }));
    }

    // The inputs were copied out of numpy above; see SameThread for why the move is sound.
    let work = SameThread((gpu, src, geometries));
    let result = py.detach(move || {
        let work = work;
        let (gpu, src, geometries) = work.0;
        SameThread(render(&gpu, &src, &geometries, params))
    });
    let rendered = result.0.map_err(errors::from_library)?;

    let views = PyDict::new(py);
    for (to, setup_ms, out, timing) in rendered {
        let d = PyDict::new(py);
        d.set_item("coverage", out.coverage())?;
        let timings = PyDict::new(py);
        timings.set_item("setup_ms", setup_ms)?;
        timings.set_item("render_ms", timing.wall_ms)?;
        timings.set_item("gpu_ms", timing.gpu_ms)?;
        d.set_item("timings", timings)?;
        if let Some(img) = out.color {
            d.set_item("rgb", arrays::rgb_array(py, img))?;
        }
        if let Some(z) = out.depth {
            d.set_item("depth", arrays::depth_array(py, z))?;
        }
        if outputs.mask {
            let bits = out.mask.iter().map(|m| (*m != 0) as u8).collect();
            let mask = viewsynth::io::Mask::new(w, h, bits).map_err(errors::from_library)?;
            d.set_item("mask", arrays::mask_array(py, mask))?;
        }
        views.set_item(eye_name(to), d)?;
    }
    Ok(views)
}
