//! The colour attachments a pass renders into (multiple render targets, one per fragment
//! output location): attachments to COLOR_ATTACHMENT, dynamic rendering over the whole image
//! with the GL-matching viewport, then to GENERAL (compute steps may rewrite them) and the
//! copies into the submission's host buffers (flight.rs) with the transfer -> host barrier.

use super::context::Vk;
use super::resources::{Buffer, Image};
use crate::error::Result;
use ash::vk;

/// Colour attachments of one size.
pub struct ColorTargets {
    vk: Vk,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Per output location; None: no attachment (the shader's writes there are discarded).
    color: Vec<Option<Image>>,
}

impl ColorTargets {
    /// One attachment per format (in output-location order); none where `formats[i]` is None.
    pub fn with_slots(vk: &Vk, width: u32, height: u32, formats: &[Option<vk::Format>]) -> Result<Self> {
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        // RGBA8 and R32F support storage on every device (the spec's required formats), so a
        // compute step can rewrite what the draws wrote (the splat-gather edge pass).
        let storage = |f: vk::Format| match f {
            vk::Format::R8G8B8A8_UNORM | vk::Format::R32_SFLOAT => vk::ImageUsageFlags::STORAGE,
            _ => vk::ImageUsageFlags::empty(),
        };
        let color = formats
            .iter()
            .map(|f| {
                f.map(|f| Image::new(vk, width, height, f, usage | storage(f)))
                    .transpose()
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(ColorTargets {
            vk: vk.clone(),
            width,
            height,
            color,
        })
    }

    /// Record: attachments to COLOR_ATTACHMENT (contents discarded), begin dynamic rendering
    /// clearing them to zero (with `depth` as the depth attachment, if any), and set the
    /// viewport and scissor to the whole image.
    pub fn record_begin(&self, cb: vk::CommandBuffer, depth: Option<&vk::RenderingAttachmentInfo>) {
        use vk::{AccessFlags as A, ImageLayout as L, PipelineStageFlags as S};
        for c in self.color.iter().flatten() {
            c.transition(
                cb,
                L::UNDEFINED,
                L::COLOR_ATTACHMENT_OPTIMAL,
                S::TOP_OF_PIPE,
                A::empty(),
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
            );
        }
        let attachments: Vec<_> = self
            .color
            .iter()
            .map(|c| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(c.as_ref().map_or(vk::ImageView::null(), |c| c.view))
                    .image_layout(L::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue {
                        color: vk::ClearColorValue { float32: [0.0; 4] },
                    })
            })
            .collect();
        let (w, h) = (self.width, self.height);
        let area = vk::Rect2D {
            offset: vk::Offset2D { x: 0, y: 0 },
            extent: vk::Extent2D { width: w, height: h },
        };
        let mut rendering = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&attachments);
        if let Some(da) = depth {
            rendering = rendering.depth_attachment(da);
        }
        let d = &self.vk.device;
        // SAFETY: recording into `cb`; the attachments live until the submit has been waited for.
        unsafe {
            d.cmd_begin_rendering(cb, &rendering);
            // Viewport origin at memory row 0, positive height: NDC y = -1 -> row 0, as GL.
            let viewport = vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: w as f32,
                height: h as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            };
            d.cmd_set_viewport(cb, 0, &[viewport]);
            d.cmd_set_scissor(cb, 0, &[area]);
        }
    }

    /// Record, outside any rendering, after [`Self::record_end_to_general`] and the steps that
    /// followed (and a barrier making their writes visible): copy each attachment with a
    /// destination into it, and make the copies visible to the host.
    pub fn record_readback(&self, cb: vk::CommandBuffer, destinations: &[Option<&Buffer>]) {
        use vk::{AccessFlags as A, PipelineStageFlags as S};
        let d = &self.vk.device;
        // SAFETY: recording into `cb`; the images and buffers live until the submit has been
        // waited for.
        unsafe {
            for (c, buf) in self.color.iter().zip(destinations) {
                let (Some(c), Some(buf)) = (c, buf) else { continue };
                d.cmd_copy_image_to_buffer(cb, c.raw, vk::ImageLayout::GENERAL, buf.raw, &[c.copy_region()]);
            }
            let to_host = vk::MemoryBarrier::default()
                .src_access_mask(A::TRANSFER_WRITE)
                .dst_access_mask(A::HOST_READ);
            d.cmd_pipeline_barrier(
                cb,
                S::TRANSFER,
                S::HOST,
                vk::DependencyFlags::empty(),
                &[to_host],
                &[],
                &[],
            );
        }
    }

    /// Attachment `i`'s view (None without an attachment there).
    pub fn view(&self, i: usize) -> Option<vk::ImageView> {
        self.color.get(i).and_then(Option::as_ref).map(|c| c.view)
    }

    /// Record: end the rendering begun by [`Self::record_begin`] and move every attachment to
    /// GENERAL, where compute steps may load and store it and the readback copies it.
    pub fn record_end_to_general(&self, cb: vk::CommandBuffer) {
        use vk::{AccessFlags as A, ImageLayout as L, PipelineStageFlags as S};
        // SAFETY: recording into `cb` inside the rendering begun by record_begin.
        unsafe { self.vk.device.cmd_end_rendering(cb) };
        for c in self.color.iter().flatten() {
            c.transition(
                cb,
                L::COLOR_ATTACHMENT_OPTIMAL,
                L::GENERAL,
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
                S::ALL_COMMANDS,
                A::MEMORY_READ | A::MEMORY_WRITE,
            );
        }
    }
}

/// Record: `depth` to DEPTH_ATTACHMENT_OPTIMAL (its contents discarded) and return it as the
/// depth attachment of the next rendering, cleared to `clear` (the conventions' far value).
pub fn depth_attachment(cb: vk::CommandBuffer, depth: &Image, clear: f32) -> vk::RenderingAttachmentInfo<'static> {
    use vk::{AccessFlags as A, ImageLayout as L, PipelineStageFlags as S};
    depth.transition(
        cb,
        L::UNDEFINED,
        L::DEPTH_ATTACHMENT_OPTIMAL,
        S::TOP_OF_PIPE,
        A::empty(),
        S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
        A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
    );
    vk::RenderingAttachmentInfo::default()
        .image_view(depth.view)
        .image_layout(L::DEPTH_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::DONT_CARE)
        .clear_value(vk::ClearValue {
            depth_stencil: vk::ClearDepthStencilValue {
                depth: clear,
                stencil: 0,
            },
        })
}
