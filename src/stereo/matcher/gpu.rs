//! The census matcher's GPU pass (see [`super`] for the rule and the stages): one run of compute
//! dispatches on a [`Device`], the two disparity maps read back as the run's outputs. A
//! [`Matcher`] is made for one image size and search range; its buffers are created once and
//! its input images rewritten for each pair, so a stream of pairs creates nothing.
//!
//! A checked semi-global matcher ([`Matcher::checked`], the two-image path's default) runs the
//! census matcher's stages to their final disparities first, into a buffer of their own, then
//! the semi-global ones from the same grey levels and census codes, then the trust stage
//! ([`crate::stereo::trust`]) on both: one upload and one readback for the whole estimate.

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
use crate::stereo::trust::census_checked;

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

/// Which outputs a run writes besides both eyes' disparities.
#[derive(Debug, Clone, Copy)]
struct Outputs {
    confidence: bool,
    /// The census check and the trust stage (a checked matcher).
    matched: bool,
}

impl Outputs {
    const DISPARITY: Outputs = Outputs {
        confidence: false,
        matched: false,
    };
    const CONFIDENCE: Outputs = Outputs {
        confidence: true,
        matched: false,
    };
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
    /// A checked semi-global matcher ([`Matcher::checked`]): the census matcher's final
    /// disparities of the run, both eyes, for the trust stage (the census stages run only where
    /// [`census_checked`] holds for the search).
    census_check: Option<Buffer>,
}

/// The maps of one [`Matcher::estimate_checked`] run, each eye's.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The semi-global disparities (0 = unknown), inferred ones included.
    pub disparity: [DepthMap; 2],
    /// Those the census matcher's (or a flat window) supports, the others 0
    /// ([`crate::stereo::trust`]).
    pub matched: [DepthMap; 2],
    /// The confidence in `disparity`, where asked for.
    pub confidence: Option<[DepthMap; 2]>,
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
        Self::make(device, width, height, max_disparity, method, false)
    }

    /// A semi-global matcher whose run also splits its disparities into matched and inferred
    /// ([`Matcher::estimate_checked`], the rule in [`crate::stereo::trust`]): the census
    /// matcher's stages and the trust stage in the same run, on the same grey levels and census
    /// codes. Fails as [`Matcher::with_method`] does.
    pub fn checked(device: impl ToDevice, width: u32, height: u32, max_disparity: u32) -> Result<Self> {
        check_range(width, max_disparity)?;
        let device = device.to_device()?;
        Self::make(device, width, height, max_disparity, MatcherMethod::Sgm, true)
    }

    fn make(
        device: Device,
        width: u32,
        height: u32,
        max_disparity: u32,
        method: MatcherMethod,
        census_check: bool,
    ) -> Result<Self> {
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
        // The census stages run in a census matcher, and in a checked one within the bound.
        let census_stages = match method {
            MatcherMethod::Census => true,
            MatcherMethod::Sgm => census_check && census_checked(max_disparity),
        };
        let chunk_words = if census_stages { chunk_pairs * n } else { 1 };
        let sgm = match method {
            MatcherMethod::Census => None,
            MatcherMethod::Sgm => Some(SgmStages::new(&device, width, height, max_disparity)?),
        };
        let census_check = match census_check {
            true => Some(buffer(2 * n, "matcher census disparities")?),
            false => None,
        };
        Ok(Matcher {
            sgm,
            census_check,
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
        let mut out = self.run(left, right, Outputs::DISPARITY)?;
        Ok((disparity(&mut out, 0)?, disparity(&mut out, 1)?))
    }

    /// [`Matcher::estimate`] with each eye's confidence in its disparities (in [0, 1], 0 where
    /// unknown; [`super::confidence`] holds the rule and the twin).
    pub fn estimate_with_confidence(&mut self, left: &RgbImage, right: &RgbImage) -> Result<[EyeEstimate; 2]> {
        let mut out = self.run(left, right, Outputs::CONFIDENCE)?;
        let mut eye = |k: usize| -> Result<EyeEstimate> {
            Ok(EyeEstimate {
                disparity: disparity(&mut out, k)?,
                confidence: disparity(&mut out, 2 + k)?,
            })
        };
        Ok([eye(0)?, eye(1)?])
    }

    /// A [`Matcher::checked`] matcher's semi-global disparities split into matched and inferred
    /// ([`Checked`]), with their confidence `with_confidence`: the census matcher's disparities
    /// ([`super::estimate_disparities`]'s, where the search is within
    /// [`CENSUS_CHECK_SEARCH`](crate::stereo::trust::CENSUS_CHECK_SEARCH)) and the trust rule's
    /// ([`crate::stereo::trust_reference::trust_reference`]'s) bit for bit, in one run.
    pub fn estimate_checked(&mut self, left: &RgbImage, right: &RgbImage, with_confidence: bool) -> Result<Checked> {
        if self.census_check.is_none() {
            return Err(Error::param(
                "stereo matcher",
                "estimate_checked needs a matcher made by Matcher::checked",
            ));
        }
        let mut out = self.run(
            left,
            right,
            Outputs {
                confidence: with_confidence,
                matched: true,
            },
        )?;
        let mut pair =
            |k: usize| -> Result<[DepthMap; 2]> { Ok([disparity(&mut out, k)?, disparity(&mut out, k + 1)?]) };
        let (disparity, matched) = (pair(0)?, pair(2)?);
        let confidence = match with_confidence {
            true => Some(pair(4)?),
            false => None,
        };
        Ok(Checked {
            disparity,
            matched,
            confidence,
        })
    }

    /// One run of every stage, and the census check and the trust stage or the confidence where
    /// asked for: outputs 0 and 1 the disparities, then the matched ones, then the confidences.
    fn run(&mut self, left: &RgbImage, right: &RgbImage, wanted: Outputs) -> Result<Rendered> {
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
        // The trust stage's u_pairs: 1 when the census disparities were matched in the run
        // (`wanted.matched` only on a checked matcher: estimate_checked).
        let census_ran = wanted.matched && census_checked(self.max_disparity);
        let trust_params = params(0, census_ran as u32);
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
        // A checked matcher's census disparities go to their own buffer for the trust stage.
        let (census_median_buffers, trust_buffers) = match &self.census_check {
            Some(census) => (ids(&[&self.checked, census]), ids(&[&self.raw, census, &self.greys])),
            None => (vec![], vec![]),
        };
        let outputs = [StorageImage::Output(0), StorageImage::Output(1)];
        let matched_outputs = [StorageImage::Output(2), StorageImage::Output(3)];
        let k = if wanted.matched { 4 } else { 2 };
        let confidence_outputs = [StorageImage::Output(k), StorageImage::Output(k + 1)];
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
        // The census matcher's chunks: rows and columns one invocation per row (column) and
        // disparity pair, then the winners.
        let mut census_chunks: Vec<Planned> = chunks
            .iter()
            .flat_map(|chunk| {
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
            .collect();
        let winners: Vec<Planned> = match &self.sgm {
            Some(sgm) => sgm.dispatches(&self.greys, &self.codes, [&self.winners[0], &self.winners[1]]),
            None => std::mem::take(&mut census_chunks),
        };
        // A checked matcher runs the census matcher to its final disparities first (into their
        // own buffer), then the semi-global one: each from its winners through the sub-pixel
        // step, the left-right check and the median.
        let mut runs = Vec::new();
        if census_ran {
            runs.push((&census_chunks, &census_median_buffers));
        }
        runs.push((&winners, &median_buffers));
        for (planned, median_buffers) in runs {
            for p in planned {
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
            // The median also stores into outputs 0 and 1: a checked matcher's census disparities
            // there are overwritten by the semi-global ones (full barriers order the writes).
            steps.push(Step::Dispatch(Dispatch {
                storage_images: &outputs,
                ..dispatch(MatcherStage::Median, &whole, median_buffers, pixels)
            }));
        }
        if wanted.confidence {
            steps.push(Step::Dispatch(Dispatch {
                storage_images: &confidence_outputs,
                ..dispatch(MatcherStage::Confidence, &whole, &confidence_buffers, pixels)
            }));
        }
        if wanted.matched {
            steps.push(Step::Dispatch(Dispatch {
                storage_images: &matched_outputs,
                ..dispatch(MatcherStage::Trust, &trust_params, &trust_buffers, pixels)
            }));
        }
        // Memory rows are the images' top-down rows (the rule is symmetric in y): no flip.
        let count = 2 + 2 * (wanted.matched as usize) + 2 * (wanted.confidence as usize);
        let target = Target {
            width: w,
            height: h,
            outputs: vec![Some(Format::R32F); count],
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
