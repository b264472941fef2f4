//! The census matcher's GPU pass (see [`super`] for the rule and the stages): one run of compute
//! dispatches on a [`Device`], the two disparity maps read back as the run's outputs. A
//! [`Matcher`] is made for one image size and search range; its buffers are created once and
//! its input images rewritten for each pair, so a stream of pairs creates nothing.

pub use super::params::MatcherParams;
use super::sgm::gpu::{Planned, SgmStages};
use super::{check_pair, check_range, MatcherMethod};
use crate::convention::RowOrder;
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use crate::pass::shaders::MatcherStage;
use crate::pass::{
    Buffer, Device, Dispatch, Format, Groups, Image, ImageData, ImageId, Rendered, Step, StorageImage, Target, ToDevice,
};
use crate::pass::{ProgramKind, ShaderProgram};

/// Words a chunk buffer holds at most (64 MiB): under GL's guaranteed-in-practice storage-block
/// size (llvmpipe: 128 MiB) and Vulkan's storage-buffer range on the devices we run.
const CHUNK_WORDS: usize = 1 << 24;

/// One eye of [`Matcher::estimate_with_confidence`].
#[derive(Debug, Clone)]
pub struct EyeEstimate {
    /// Disparity in pixels, 0 = unknown (as [`Matcher::estimate`] gives it).
    pub disparity: DepthMap,
    /// Confidence in it, in [0, 1]; 0 where it is unknown.
    pub confidence: DepthMap,
}

/// Output `k` of a run, read back as a map.
fn disparity(out: &mut Rendered, k: usize) -> Result<DepthMap> {
    out.depth(k)?.ok_or_else(|| {
        out.api
            .readback_error(format!("stereo matcher: output {k} was not read back"))
    })
}

/// Largest pair the pass takes (8 Mpx, 4K UHD fits): its census codes (4 words a pixel) then
/// fill 128 MiB, llvmpipe's storage-block limit and the smallest we run on.
pub const MAX_PIXELS: usize = 1 << 23;

/// Estimates both eyes' disparities of rectified pairs of one size on a device.
pub struct Matcher {
    device: Device,
    width: u32,
    height: u32,
    max_disparity: u32,
    /// Disparity pairs (16-bit lanes of one word) per chunk.
    chunk_pairs: u32,
    inputs: [Option<Image>; 2],
    /// Both eyes' grey levels, one word a pixel.
    greys: Buffer,
    /// Census codes, 4 words a pixel.
    codes: Buffer,
    /// A chunk's fixed-point means.
    means: Buffer,
    /// A chunk's row sums.
    rows: Buffer,
    /// Each eye's winner so far, 4 words a pixel.
    winners: [Buffer; 2],
    /// Sub-pixel disparities, then the checked ones, both eyes (f32 bits).
    raw: Buffer,
    checked: Buffer,
    /// The semi-global stages' buffers, where the matcher is the semi-global one.
    sgm: Option<SgmStages>,
}

impl Matcher {
    /// A matcher for `width` x `height` pairs searching 0..=`max_disparity` px, on `device` (a
    /// [`Device`], or a GL context). Fails as [`super::estimate_disparities`] does on the range,
    /// and on a size the device cannot hold or above [`MAX_PIXELS`].
    pub fn new(device: impl ToDevice, width: u32, height: u32, max_disparity: u32) -> Result<Self> {
        Self::with_method(device, width, height, max_disparity, MatcherMethod::Census)
    }

    /// [`Matcher::new`] for the matcher `method` names: its disparities are that method's twin's
    /// ([`MatcherMethod::estimate_reference`]) bit for bit.
    pub fn with_method(
        device: impl ToDevice,
        width: u32,
        height: u32,
        max_disparity: u32,
        method: MatcherMethod,
    ) -> Result<Self> {
        check_range(width, max_disparity)?;
        let device = device.to_device()?;
        device.check_image_size("stereo pair", width, height)?;
        let n = width as usize * height as usize;
        if n > MAX_PIXELS {
            return Err(Error::param(
                "stereo pair",
                format!("{width}x{height}: the GPU matcher takes at most {MAX_PIXELS} pixels"),
            ));
        }
        let pairs = (max_disparity as usize + 1).div_ceil(2);
        let chunk_pairs = pairs.min((CHUNK_WORDS / n).max(1));
        let buffer = |words: usize, label: &str| device.create_buffer(words, label);
        let (sgm, chunk_words) = match method {
            MatcherMethod::Census => (None, chunk_pairs * n),
            MatcherMethod::Sgm => (Some(SgmStages::new(&device, width, height, max_disparity)?), 1),
        };
        Ok(Matcher {
            sgm,
            greys: buffer(n, "matcher grey levels")?,
            codes: buffer(4 * n, "matcher census codes")?,
            means: buffer(chunk_words, "matcher means")?,
            rows: buffer(chunk_words, "matcher row sums")?,
            winners: [
                buffer(4 * n, "matcher left winners")?,
                buffer(4 * n, "matcher right winners")?,
            ],
            raw: buffer(2 * n, "matcher sub-pixel disparities")?,
            checked: buffer(2 * n, "matcher checked disparities")?,
            chunk_pairs: chunk_pairs as u32,
            device,
            width,
            height,
            max_disparity,
            inputs: [None, None],
        })
    }

    /// Disparities of the left and right eye of `left` and `right` (the matcher's size), as
    /// [`super::estimate_disparities`] gives them, bit for bit.
    pub fn estimate(&mut self, left: &RgbImage, right: &RgbImage) -> Result<(DepthMap, DepthMap)> {
        let mut out = self.run(left, right, false)?;
        Ok((disparity(&mut out, 0)?, disparity(&mut out, 1)?))
    }

    /// [`Matcher::estimate`] with each eye's confidence in its disparities (in [0, 1], 0 where
    /// unknown; [`super::confidence`] holds the rule and the twin).
    pub fn estimate_with_confidence(&mut self, left: &RgbImage, right: &RgbImage) -> Result<[EyeEstimate; 2]> {
        let mut out = self.run(left, right, true)?;
        let mut eye = |k: usize| -> Result<EyeEstimate> {
            Ok(EyeEstimate {
                disparity: disparity(&mut out, k)?,
                confidence: disparity(&mut out, 2 + k)?,
            })
        };
        Ok([eye(0)?, eye(1)?])
    }

    /// One run of every stage (and the confidence where asked for): outputs 0 and 1 the
    /// disparities, 2 and 3 the confidences.
    fn run(&mut self, left: &RgbImage, right: &RgbImage, confidence: bool) -> Result<Rendered> {
        check_pair(left, right)?;
        let (w, h) = (self.width, self.height);
        if (left.width, left.height) != (w, h) {
            return Err(Error::SizeMismatch {
                message: format!(
                    "stereo matching: a {}x{} pair given to a matcher made for {w}x{h}",
                    left.width, left.height
                ),
            });
        }
        let images = self.set_inputs(left, right)?;
        let params = |first_d: u32, pairs: u32| MatcherParams {
            u_size: [w as i32, h as i32],
            u_max_disparity: self.max_disparity as i32,
            u_first_d: first_d as i32,
            u_pairs: pairs as i32,
            u_window: 0,
            u_direction: [0, 0],
            u_other_size: [0, 0],
            u_final: 0,
            u_pad: 0,
        };
        let pairs = (self.max_disparity + 1).div_ceil(2);
        let chunks: Vec<MatcherParams> = (0..pairs.div_ceil(self.chunk_pairs))
            .map(|c| {
                let first = c * self.chunk_pairs;
                params(2 * first, self.chunk_pairs.min(pairs - first))
            })
            .collect();
        let whole = params(0, 0);
        let ids = |b: &[&Buffer]| b.iter().map(|b| b.id()).collect::<Vec<_>>();
        let grey_buffers = ids(&[&self.greys]);
        let census_buffers = ids(&[&self.greys, &self.codes]);
        let rows_buffers = ids(&[&self.codes, &self.rows]);
        let columns_buffers = ids(&[&self.rows, &self.means]);
        let winner_buffers = ids(&[&self.means, &self.winners[0], &self.winners[1]]);
        let subpixel_buffers = ids(&[&self.winners[0], &self.winners[1], &self.raw]);
        let check_buffers = ids(&[&self.raw, &self.checked]);
        // The median stores the final disparities into `raw` too (free after the check).
        let median_buffers = ids(&[&self.checked, &self.raw]);
        let confidence_buffers = ids(&[&self.raw]);
        let outputs = [StorageImage::Output(0), StorageImage::Output(1)];
        let confidence_outputs = [StorageImage::Output(2), StorageImage::Output(3)];
        let pixels = Groups::Fixed([w.div_ceil(8), h.div_ceil(8)]);
        let dispatch = |stage, block, buffers, groups| Dispatch {
            program: ShaderProgram::new(Default::default(), ProgramKind::CyclopeanMatcher(stage)),
            params: bytemuck::bytes_of(block),
            images: &[],
            storage_images: &[],
            buffers,
            groups,
        };
        let mut steps = vec![
            Step::Dispatch(Dispatch {
                images: &images,
                ..dispatch(MatcherStage::Grey, &whole, &grey_buffers, pixels)
            }),
            Step::Dispatch(dispatch(MatcherStage::Census, &whole, &census_buffers, pixels)),
        ];
        let planned: Vec<Planned> = match &self.sgm {
            Some(sgm) => sgm.dispatches(&self.greys, &self.codes, [&self.winners[0], &self.winners[1]]),
            None => chunks
                .iter()
                .flat_map(|chunk| {
                    // Rows and columns: one invocation per row (column) and disparity pair.
                    let lines = |n: u32| Groups::Fixed([n.div_ceil(8), (chunk.u_pairs as u32).div_ceil(8)]);
                    [
                        (MatcherStage::Rows, &rows_buffers, lines(h)),
                        (MatcherStage::Columns, &columns_buffers, lines(w)),
                        (MatcherStage::Winner, &winner_buffers, pixels),
                    ]
                    .map(|(stage, buffers, groups)| Planned {
                        stage,
                        params: *chunk,
                        buffers: buffers.clone(),
                        groups,
                    })
                })
                .collect(),
        };
        for p in &planned {
            steps.push(Step::Dispatch(dispatch(p.stage, &p.params, &p.buffers, p.groups)));
        }
        steps.push(Step::Dispatch(dispatch(
            MatcherStage::Subpixel,
            &whole,
            &subpixel_buffers,
            pixels,
        )));
        steps.push(Step::Dispatch(dispatch(
            MatcherStage::LrCheck,
            &whole,
            &check_buffers,
            pixels,
        )));
        steps.push(Step::Dispatch(Dispatch {
            storage_images: &outputs,
            ..dispatch(MatcherStage::Median, &whole, &median_buffers, pixels)
        }));
        if confidence {
            steps.push(Step::Dispatch(Dispatch {
                storage_images: &confidence_outputs,
                ..dispatch(MatcherStage::Confidence, &whole, &confidence_buffers, pixels)
            }));
        }
        // Memory rows are the images' top-down rows (the rule is symmetric in y): no flip.
        let target = Target {
            width: w,
            height: h,
            outputs: vec![Some(Format::R32F); if confidence { 4 } else { 2 }],
            rows: RowOrder::TopDown,
            depth_test: None,
        };
        self.device.run(Some(&target), &steps)
    }

    /// The pair on the device: uploaded the first time, rewritten in place after.
    fn set_inputs(&mut self, left: &RgbImage, right: &RgbImage) -> Result<[ImageId; 2]> {
        let image = |bytes, label| ImageData {
            width: self.width,
            height: self.height,
            format: Format::Rgba8,
            bytes,
            label,
        };
        let (l, r) = (
            crate::pass::pixels::rgb_to_rgba(&left.data),
            crate::pass::pixels::rgb_to_rgba(&right.data),
        );
        let [left_slot, right_slot] = &mut self.inputs;
        Ok([
            self.device.put_image(left_slot, &image(&l, "matcher left image"))?,
            self.device.put_image(right_slot, &image(&r, "matcher right image"))?,
        ])
    }
}
