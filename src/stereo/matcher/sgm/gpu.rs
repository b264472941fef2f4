//! The semi-global matcher's GPU stages (shaders/cyclopean/matcher_sgm_*.comp), run by
//! [`Matcher`](crate::stereo::matcher::Matcher) made with
//! [`MatcherMethod::Sgm`](crate::stereo::matcher::MatcherMethod::Sgm) between its census
//! stage and its sub-pixel stage: the coarser levels' grey levels and census codes, then per
//! level from the coarsest the cost volume, the 8 path directions and the winners (guides for
//! the next level, the census matcher's winner words at the pair's own level). Integers
//! throughout, so the disparities are [`super::reference`]'s bit for bit.

use super::{Plan, DIRECTIONS};
use crate::error::{Error, Result};
use crate::pass::shaders::MatcherStage;
use crate::pass::{Buffer, BufferId, Device, Groups};
use crate::stereo::matcher::params::MatcherParams;

/// Words one cost or sum buffer may hold (128 MiB, llvmpipe's storage-block limit).
const MAX_BUFFER_WORDS: usize = 1 << 25;

/// One dispatch of the semi-global stages, owned (the matcher borrows it into its steps).
pub(crate) struct Planned {
    pub stage: MatcherStage,
    pub params: MatcherParams,
    pub buffers: Vec<BufferId>,
    pub groups: Groups,
}

/// The semi-global stages' buffers for one pair size and search (level 0's grey levels and
/// census codes are the matcher's own).
pub(crate) struct SgmStages {
    plan: Plan,
    /// Levels 1.. : grey levels of both eyes, one word a pixel.
    greys: Vec<Buffer>,
    /// Levels 1.. : census codes, 4 words a pixel.
    codes: Vec<Buffer>,
    /// Each pixel's first searched disparity, both eyes (the level being matched).
    starts: Buffer,
    /// The last level's winners, both eyes, guiding the next finer one.
    guides: Buffer,
    /// The level's cost volume and its sums over the paths.
    costs: Buffer,
    sums: Buffer,
}

impl SgmStages {
    /// Buffers for a `width` x `height` pair searched over 0..=`max_disparity`; fails where a
    /// level's cost volume would pass a storage buffer's size.
    pub(crate) fn new(device: &Device, width: u32, height: u32, max_disparity: u32) -> Result<Self> {
        let plan = Plan::new(width, height, max_disparity);
        let cells = plan.levels.iter().map(|l| l.cells()).max().unwrap_or(1);
        if cells > MAX_BUFFER_WORDS {
            return Err(Error::param(
                "stereo pair",
                format!(
                    "{width}x{height}: the semi-global matcher's cost volume ({cells} cells) passes its \
                     {MAX_BUFFER_WORDS}; the census matcher takes pairs this large"
                ),
            ));
        }
        let pixels = |l: usize| plan.levels[l].width as usize * plan.levels[l].height as usize;
        let mut greys = Vec::new();
        let mut codes = Vec::new();
        for l in 1..plan.levels.len() {
            greys.push(device.create_buffer(pixels(l), "semi-global grey levels")?);
            codes.push(device.create_buffer(4 * pixels(l), "semi-global census codes")?);
        }
        let coarse = if plan.levels.len() > 1 { pixels(1) } else { 1 };
        Ok(SgmStages {
            greys,
            codes,
            starts: device.create_buffer(2 * pixels(0), "semi-global window starts")?,
            guides: device.create_buffer(2 * coarse, "semi-global guides")?,
            costs: device.create_buffer(cells, "semi-global costs")?,
            sums: device.create_buffer(cells, "semi-global sums")?,
            plan,
        })
    }

    /// The dispatches after level 0's census stage (which filled `grey0` and `codes0`), ending
    /// with level 0's winners in `winners`.
    pub(crate) fn dispatches(&self, grey0: &Buffer, codes0: &Buffer, winners: [&Buffer; 2]) -> Vec<Planned> {
        let levels = &self.plan.levels;
        let greys: Vec<&Buffer> = std::iter::once(grey0).chain(&self.greys).collect();
        let codes: Vec<&Buffer> = std::iter::once(codes0).chain(&self.codes).collect();
        let size = |l: usize| [levels[l].width as i32, levels[l].height as i32];
        let params = |l: usize| MatcherParams {
            u_size: size(l),
            u_max_disparity: levels[l].max_disparity as i32,
            u_first_d: 0,
            u_pairs: 0,
            u_window: levels[l].window as i32,
            u_direction: [0, 0],
            u_other_size: [0, 0],
            u_final: (l == 0) as i32,
            u_pad: 0,
        };
        let pixels = |l: usize| Groups::Fixed([levels[l].width.div_ceil(8), levels[l].height.div_ceil(8)]);
        let mut out = Vec::new();
        for l in 1..levels.len() {
            out.push(Planned {
                stage: MatcherStage::SgmDownsample,
                params: MatcherParams {
                    u_other_size: size(l - 1),
                    ..params(l)
                },
                buffers: vec![greys[l - 1].id(), greys[l].id()],
                groups: pixels(l),
            });
            out.push(Planned {
                stage: MatcherStage::Census,
                params: params(l),
                buffers: vec![greys[l].id(), codes[l].id()],
                groups: pixels(l),
            });
        }
        for l in (0..levels.len()).rev() {
            let coarser = match l + 1 < levels.len() {
                true => size(l + 1),
                false => [0, 0],
            };
            out.push(Planned {
                stage: MatcherStage::SgmCost,
                params: MatcherParams {
                    u_other_size: coarser,
                    ..params(l)
                },
                buffers: [codes[l], &self.guides, &self.starts, &self.costs, &self.sums]
                    .map(Buffer::id)
                    .to_vec(),
                groups: pixels(l),
            });
            let (w, h) = (levels[l].width, levels[l].height);
            for [dx, dy] in DIRECTIONS {
                let lines = match (dx, dy) {
                    (_, 0) => h,
                    (0, _) => w,
                    _ => w + h - 1,
                };
                out.push(Planned {
                    stage: MatcherStage::SgmPath,
                    params: MatcherParams {
                        u_direction: [dx, dy],
                        ..params(l)
                    },
                    buffers: [&self.costs, &self.starts, greys[l], &self.sums]
                        .map(Buffer::id)
                        .to_vec(),
                    // One invocation per path, 64 a group (matcher_sgm_path.comp).
                    groups: Groups::Fixed([lines.div_ceil(64), 1]),
                });
            }
            out.push(Planned {
                stage: MatcherStage::SgmWinner,
                params: params(l),
                buffers: [&self.sums, &self.starts, &self.guides, winners[0], winners[1]]
                    .map(Buffer::id)
                    .to_vec(),
                groups: pixels(l),
            });
        }
        out
    }
}
