//! GPU refocus, described once as pass steps (src/pass) and run by either executor: GL or
//! Vulkan, the same GLSL and parameter block (shaders/refocus/refocus_params.glsl).
//!
//! A source (colour, depth and its kept triangles) is uploaded into images that the next source
//! of the same size rewrites in place; each target size keeps its per-column and per-row lookup
//! images (located in f64 on the host, see `grid::axis_lookup`). The full-screen method is one
//! draw that evaluates the kept triangles per pixel; the mesh method draws the interior
//! triangles indexed and the boundary ones by vertex pulling, depth-tested under the
//! conventions (mesh.rs). Outputs not asked for get no attachment and no readback; the executor
//! reads the rest back top-down, with the RGB packing done on the GPU (GL) or while copying out.
//!
//! [`Refocuser::submit`] queues a target and returns at once; [`PendingRefocus::wait`] maps its
//! outputs later, so a caller can keep several targets (and frames) in flight.
//! [`Refocuser::render`] is the two in a row.

use super::mesh::{MeshGeometry, EXPAND_PX};
use super::{BreakRule, Method, OutputSet, RefocusSource};
use crate::camera::{clip_from_view_opencv, PinholeCamera};
use crate::convention::{Conventions, DepthPlanes};
use crate::error::{Error, Result};
use crate::io::{DepthMap, Mask, RgbImage};
use crate::mesh::{axis_lookup, Grid};
use crate::pass::{mat4_std140, Device, Draw, Format, Image, ImageData, ImageId, Pending, Step, Target, ToDevice};
use crate::pass::{ProgramKind, ShaderProgram, Timing};
use std::time::Instant;

/// Output sizes whose lookup images are kept (a batch uses one; a sweep over sizes a few).
const KEEP_TARGET_SIZES: usize = 4;

crate::param_block! {
    /// Every refocus draw's parameters: shaders/refocus/refocus_params.glsl, member for member.
    pub struct RefocusParams("RefocusParams") {
        u_clip_from_target: [[f32; 4]; 4],
        u_src_k: [f32; 4],
        u_src_size: [i32; 2],
        u_clip_z: [f32; 2],
        u_dst_size: [f32; 2],
        u_dst_height: i32,
        u_expand_px: f32,
    }
}

/// One refocused view. Images are top-down whatever the row-order convention.
pub struct RefocusOutput {
    /// The target camera: intrinsics and image size.
    pub camera: PinholeCamera,
    /// 8-bit colour, 0 where invalid; None when not requested.
    pub rgb: Option<RgbImage>,
    /// View-space Z in metres, 0 where invalid.
    pub depth: Option<DepthMap>,
    /// 1 where a kept triangle covers the pixel centre, 0 elsewhere (PNG: 255 / 0); None when not requested.
    pub mask: Option<Mask>,
    /// `wall_ms`: host time to record the draw and queue the reads (no wait); `gpu_ms`: the
    /// draw's GPU time from a timer query read after the fence, where the driver's timers are
    /// meaningful.
    pub render: Timing,
    /// Host time spent waiting for the GPU and mapping the outputs (on a software renderer the
    /// rasterisation itself happens here).
    pub readback_ms: f64,
}

impl RefocusOutput {
    /// Fraction of pixels that hold a value, as the manifest reports it: the mask's when one was
    /// rendered, else the depth's (Z > 0); None with colour alone (colour has no "invalid").
    pub fn coverage(&self) -> Option<f64> {
        match (&self.mask, &self.depth) {
            (Some(mask), _) => Some(mask.coverage()),
            (None, Some(depth)) => Some(depth.coverage()),
            (None, None) => None,
        }
    }
}

/// The uploaded source: its camera and the images that hold it (in [`SourceImages`]).
struct Source {
    camera: PinholeCamera,
    planes: DepthPlanes,
    /// Colour; the depth image when colour is not asked for (the programs then never read it:
    /// no upload, no texture).
    rgb: ImageId,
    depth: ImageId,
    geometry: Geometry,
}

/// Per method: the full-screen pass's coverage flags, or the mesh pass's triangles.
enum Geometry {
    Fullscreen { keep: ImageId },
    Mesh(MeshGeometry),
}

/// The images sources are written into, kept from source to source: rewritten in place while
/// the size stays (a batch frame makes none), all freed before a source of another size.
#[derive(Default)]
struct SourceImages {
    rgb: Option<Image>,
    depth: Option<Image>,
    /// The full-screen method's coverage flags.
    keep: Option<Image>,
}

/// The lookup images of one output size.
struct Lookups {
    size: (u32, u32),
    cols: Image,
    rows: Image,
}

/// Refocus for one set of settings on one device, ready to take any number of sources and
/// targets.
pub struct Refocuser {
    device: Device,
    conv: Conventions,
    outputs: OutputSet,
    rule: BreakRule,
    method: Method,
    /// `--rgb-everywhere`: colour at every target pixel inside the source frame.
    rgb_everywhere: bool,
    source: Option<Source>,
    images: SourceImages,
    /// Most recently used last.
    lookups: Vec<Lookups>,
}

/// A target queued on the GPU: its outputs arrive through [`PendingRefocus::wait`]. Tied to
/// the device's thread.
pub struct PendingRefocus {
    camera: PinholeCamera,
    outputs: OutputSet,
    run: Pending,
}

impl PendingRefocus {
    /// Whether every output has arrived (never blocks).
    pub fn is_ready(&self) -> bool {
        self.run.is_ready()
    }

    /// Wait for the outputs and hand them out: one copy out of each mapped buffer, no
    /// per-pixel conversion (the GPU packed RGB, flipped rows and wrote the mask as 0/1).
    pub fn wait(self) -> Result<RefocusOutput> {
        let t0 = Instant::now();
        let mut r = self.run.wait()?;
        let (w, h) = (self.camera.width, self.camera.height);
        let o = self.outputs;
        let rgb = if o.rgb { r.color(0)? } else { None };
        let depth = if o.depth { r.depth(1)? } else { None };
        let mask = match o.mask {
            true => Some(Mask::new(w, h, r.take(2, "refocus mask")?)?),
            false => None,
        };
        Ok(RefocusOutput {
            camera: self.camera,
            rgb,
            depth,
            mask,
            render: r.timing,
            readback_ms: t0.elapsed().as_secs_f64() * 1e3,
        }
        .finite())
    }
}

impl Refocuser {
    /// Open on `device` (a [`Device`], or a GL context) and upload `src`.
    pub fn new(
        device: impl ToDevice,
        src: &RefocusSource,
        rule: &BreakRule,
        method: Method,
        outputs: OutputSet,
        conv: Conventions,
    ) -> Result<Self> {
        let mut r = Refocuser::with_settings(device, rule, method, outputs, conv)?;
        r.set_source(src)?;
        Ok(r)
    }

    /// Refocus with these settings on `device`; a source comes with [`Refocuser::set_source`].
    /// The executor builds the programs at the first render and keeps them.
    pub fn with_settings(
        device: impl ToDevice,
        rule: &BreakRule,
        method: Method,
        outputs: OutputSet,
        conv: Conventions,
    ) -> Result<Self> {
        rule.validate()?;
        Ok(Refocuser {
            device: device.to_device()?,
            conv,
            outputs,
            rule: *rule,
            method,
            rgb_everywhere: false,
            source: None,
            images: SourceImages::default(),
            lookups: Vec::new(),
        })
    }

    /// Colour every target pixel inside the source frame (bilinear from the source whatever its
    /// depth: same pose, so where a source pixel lands does not depend on it), not only those a
    /// kept triangle covers; depth and mask are unchanged. Off by default (the seed's rule).
    pub fn set_rgb_everywhere(&mut self, on: bool) {
        self.rgb_everywhere = on;
    }

    /// Whether [`Refocuser::set_rgb_everywhere`] is on.
    pub fn rgb_everywhere(&self) -> bool {
        self.rgb_everywhere
    }

    /// The device this refocuser renders on.
    pub fn device(&self) -> &Device {
        &self.device
    }

    /// The renderer's name, for manifests.
    pub fn renderer(&self) -> String {
        self.device.renderer()
    }

    /// Upload a new source, rewriting the previous source's images when the size matches.
    pub fn set_source(&mut self, src: &RefocusSource) -> Result<()> {
        src.validate()?;
        let (w, h) = (src.rgb.width, src.rgb.height);
        // The grid's cells include a half-pixel border ring: (w + 1) x (h + 1) of them, each a
        // texel of the coverage image, so the source side is one less than the device's limit.
        let max_side = self.device.max_image_side();
        crate::pass::check_image_size("source size", w.into(), h.into(), max_side.saturating_sub(1))?;
        let grid = Grid { width: w, height: h };
        let keep = grid.keep_mask(&src.depth.data, &self.rule);
        if self
            .source
            .as_ref()
            .is_some_and(|s| (s.camera.width, s.camera.height) != (w, h))
        {
            self.images = SourceImages::default(); // free a differently sized source before allocating
        }
        self.source = None; // and the previous triangles before uploading new ones
        let rgba: Option<Vec<u8>> = self
            .outputs
            .rgb
            .then(|| crate::pass::pixels::rgb_to_rgba(&src.rgb.data));
        let (cx, cy) = (grid.cells_x() as u32, grid.cells_y() as u32);
        let (d, images) = (&self.device, &mut self.images);
        let rgb = match &rgba {
            Some(texels) => Some(d.put_image(&mut images.rgb, &ImageData::rgba8(w, h, texels, "refocus source rgb"))?),
            None => None,
        };
        let depth = d.put_image(
            &mut images.depth,
            &ImageData::r32f(w, h, &src.depth.data, "refocus source depth"),
        )?;
        let geometry = match self.method {
            Method::Fullscreen => {
                let flags = grid.coverage_flags(&keep);
                let data = ImageData::r8ui(cx, cy, &flags, "refocus coverage flags");
                Geometry::Fullscreen {
                    keep: d.put_image(&mut images.keep, &data)?,
                }
            }
            Method::Mesh => Geometry::Mesh(MeshGeometry::new(d, &grid, &keep, max_side)?),
        };
        // Every kept vertex lies in [min, max] of the valid depths; the factor 2 leaves room for
        // the expanded border of each triangle (which the vertex shader keeps within it).
        let planes = match src.depth_range() {
            Some((lo, hi)) => DepthPlanes {
                near: 0.25 * lo,
                far: 4.0 * hi,
            },
            None => DepthPlanes { near: 1.0, far: 2.0 },
        };
        self.source = Some(Source {
            camera: src.camera(),
            planes,
            rgb: rgb.unwrap_or(depth),
            depth,
            geometry,
        });
        Ok(())
    }

    /// Number of kept triangles (mesh path) for reports.
    pub fn triangle_count(&self) -> Option<usize> {
        match &self.source.as_ref()?.geometry {
            Geometry::Mesh(mesh) => Some(mesh.triangle_count()),
            Geometry::Fullscreen { .. } => None,
        }
    }

    /// The lookups of output size w x h, written with `cols` and `rows`; most recently used
    /// last, made on first use.
    fn lookups(&mut self, w: u32, h: u32, cols: &[[f32; 4]], rows: &[[f32; 4]]) -> Result<&Lookups> {
        let (cols, rows): (&[u8], &[u8]) = (bytemuck::cast_slice(cols), bytemuck::cast_slice(rows));
        if let Some(i) = self.lookups.iter().position(|l| l.size == (w, h)) {
            let l = self.lookups.remove(i);
            self.device.write_image(&l.cols, cols)?;
            self.device.write_image(&l.rows, rows)?;
            self.lookups.push(l);
        } else {
            if self.lookups.len() >= KEEP_TARGET_SIZES {
                self.lookups.remove(0); // free the least recently used before allocating
            }
            let image = |n, bytes, label| self.device.upload(&ImageData::new(n, 1, Format::Rgba32F, bytes, label));
            let l = Lookups {
                size: (w, h),
                cols: image(w, cols, "refocus column lookup")?,
                rows: image(h, rows, "refocus row lookup")?,
            };
            self.lookups.push(l);
        }
        Ok(self.lookups.last().expect("pushed above"))
    }

    /// Render `target` (same pose as the source) and read back the requested outputs.
    pub fn render(&mut self, target: &PinholeCamera) -> Result<RefocusOutput> {
        self.submit(target)?.wait()
    }

    /// Record the draws of `target` and queue the reads of its outputs; returns without waiting.
    pub fn submit(&mut self, target: &PinholeCamera) -> Result<PendingRefocus> {
        target.validate("target camera")?;
        self.device
            .check_image_size("output size", target.width, target.height)?;
        let Some(source) = &self.source else {
            return Err(Error::param("refocus source", "no source uploaded (set_source)"));
        };
        let (src_cam, planes, conv) = (source.camera, source.planes, self.conv);
        let (sk, tk) = (src_cam.k, target.k);
        // The pixel -> source-point map in f64, per column and per row (it is separable).
        let cols = axis_lookup(src_cam.width, sk.cx, tk.cx, sk.fx / tk.fx, target.width);
        let rows = axis_lookup(src_cam.height, sk.cy, tk.cy, sk.fy / tk.fy, target.height);
        let (cols_id, rows_id) = {
            let l = self.lookups(target.width, target.height, &cols, &rows)?;
            (l.cols.id(), l.rows.id())
        };
        let source = self.source.as_ref().expect("checked above");
        let (a, b) = planes.clip_z_coefficients(&conv);
        let params = RefocusParams {
            u_clip_from_target: mat4_std140(&clip_from_view_opencv(target, &planes, &conv)),
            u_src_k: [sk.fx as f32, sk.fy as f32, sk.cx as f32, sk.cy as f32],
            u_src_size: [src_cam.width as i32, src_cam.height as i32],
            u_clip_z: [a as f32, b as f32],
            u_dst_size: [target.width as f32, target.height as f32],
            u_dst_height: target.height as i32,
            u_expand_px: EXPAND_PX,
        };
        let params = bytemuck::bytes_of(&params);
        let want_rgb = self.outputs.rgb;
        let program = |kind| ShaderProgram::new(conv, kind);
        let shared = [source.rgb, source.depth, cols_id, rows_id];
        let with = |extra| [shared[0], shared[1], shared[2], shared[3], extra];
        let viewport = [0, 0, target.width, target.height];
        let draw = |kind, images, triangles, indices| {
            Step::Draw(Draw {
                program: program(kind),
                params,
                images,
                buffers: &[],
                viewport,
                triangles,
                indices,
            })
        };
        let (keep_images, interior_images, pulled_images);
        let mut steps = Vec::with_capacity(3);
        match &source.geometry {
            Geometry::Fullscreen { keep } => {
                keep_images = with(*keep);
                steps.push(draw(
                    ProgramKind::RefocusFullscreen {
                        want_rgb,
                        rgb_everywhere: want_rgb && self.rgb_everywhere,
                    },
                    &keep_images[..],
                    1,
                    None,
                ));
            }
            Geometry::Mesh(mesh) => {
                let m = mesh.draws((tk.fx / sk.fx).min(tk.fy / sk.fy));
                interior_images = shared;
                if want_rgb && self.rgb_everywhere {
                    // Colour inside the frame at the far depth first; the kept triangles then
                    // overwrite what they cover.
                    steps.push(draw(
                        ProgramKind::RefocusColourEverywhere,
                        &interior_images[..],
                        1,
                        None,
                    ));
                }
                if let Some((indices, count)) = m.interior {
                    steps.push(draw(
                        ProgramKind::RefocusMeshInterior { want_rgb },
                        &interior_images[..],
                        count,
                        Some(indices),
                    ));
                }
                pulled_images = m.pulled.map(|(codes, _)| with(codes));
                if let (Some((_, count)), Some(images)) = (m.pulled, &pulled_images) {
                    steps.push(draw(
                        ProgramKind::RefocusMeshBoundary { want_rgb },
                        &images[..],
                        count,
                        None,
                    ));
                }
            }
        }
        let o = self.outputs;
        let pass_target = Target {
            width: target.width,
            height: target.height,
            outputs: vec![
                o.rgb.then_some(Format::Rgba8),
                o.depth.then_some(Format::R32F),
                o.mask.then_some(Format::R8),
            ],
            rows: conv.row_order,
            // Depth clamp (no near/far clipping) and LEQUAL/GEQUAL come with the depth test: with
            // a 1e8 depth ratio, standard-Z f32 puts far surfaces on the far plane, where
            // clipping or a strict test would drop them.
            depth_test: (self.method == Method::Mesh).then_some(conv),
        };
        let run = self.device.submit(Some(&pass_target), &steps)?;
        Ok(PendingRefocus {
            camera: *target,
            outputs: o,
            run,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;

    fn output(depth: Option<Vec<f32>>, mask: Option<Vec<u8>>) -> RefocusOutput {
        RefocusOutput {
            camera: PinholeCamera {
                k: Intrinsics {
                    fx: 2.0,
                    fy: 2.0,
                    cx: 1.0,
                    cy: 1.0,
                },
                width: 2,
                height: 2,
            },
            rgb: None,
            depth: depth.map(|d| DepthMap::new(2, 2, d).unwrap()),
            mask: mask.map(|m| Mask::new(2, 2, m).unwrap()),
            render: Timing {
                gpu_ms: None,
                wall_ms: 0.0,
            },
            readback_ms: 0.0,
        }
    }

    #[test]
    fn coverage_is_the_masks_else_the_depths() {
        // The mask decides when both are there (here it disagrees with the depth on purpose).
        let both = output(Some(vec![1.0, 1.0, 1.0, 0.0]), Some(vec![1, 0, 0, 0]));
        assert_eq!(both.coverage(), Some(0.25));
        assert_eq!(output(Some(vec![1.0, 1.0, 1.0, 0.0]), None).coverage(), Some(0.75));
        assert_eq!(output(None, None).coverage(), None);
    }
}
