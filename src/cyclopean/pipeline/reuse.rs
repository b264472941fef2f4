//! What a sequence keeps on its device from one frame to the next: the matchers (two images
//! alone), the default method's renderer (its eye images rewritten in place), the fill,
//! and the temporal history. So a
//! sequence's next frame of the same size creates no GPU object, where one pair alone makes
//! its renderers and drops them.

use crate::convention::Conventions;
use crate::cyclopean::fill::Filler;
use crate::cyclopean::splat::{SplatParams, SplatRenderer};
use crate::cyclopean::temporal::{Accumulator, DEPTH_TOLERANCE, FILL_ONLY};
use crate::error::Result;
use crate::pass::Device;
use crate::stereo::densify::Densifier;
use crate::stereo::gather::CyclopeanOutputs;
use crate::stereo::matcher::{Matcher, MatcherMethod};
use crate::stereo::StereoFrame;

/// The width, height and search range a matcher was made for.
type MatcherKey = (u32, u32, u32);

/// A sequence's renderers, made at its first frame and reused (see the module notes).
#[derive(Default)]
pub struct Reused {
    /// A matcher per method (the semi-global one checked: [`Matcher::checked`]), each with the
    /// width, height and search range it was made for.
    matchers: [Option<(MatcherKey, Matcher)>; 2],
    splat: Option<SplatRenderer>,
    filler: Option<Filler>,
    densifier: Option<Densifier>,
    history: Option<(Conventions, Accumulator)>,
}

impl Reused {
    /// The splat-gather renderer holding `frame`'s eyes: the last one with the eyes replaced,
    /// or a new one where there is none or the conventions changed. A renderer whose eyes
    /// could not be replaced is dropped, never kept half-written.
    pub(crate) fn splat(
        &mut self,
        device: &Device,
        frame: &StereoFrame,
        outputs: CyclopeanOutputs,
    ) -> Result<&mut SplatRenderer> {
        let renderer = match self.splat.take() {
            Some(mut r) if r.conventions() == frame.conv => {
                r.set_frame(frame)?;
                r
            }
            old => {
                drop(old);
                SplatRenderer::new(device, frame, SplatParams::default(), outputs)?
            }
        };
        Ok(self.splat.insert(renderer))
    }

    /// The `method` matcher for `width` x `height` pairs searching 0..=`max_disparity` px: the
    /// last one where those match (its inputs are rewritten in place), else a new one (the old
    /// one freed first).
    pub(crate) fn matcher(
        &mut self,
        device: &Device,
        width: u32,
        height: u32,
        max_disparity: u32,
        method: MatcherMethod,
    ) -> Result<&mut Matcher> {
        let key = (width, height, max_disparity);
        let slot = &mut self.matchers[match method {
            MatcherMethod::Census => 0,
            MatcherMethod::Sgm => 1,
        }];
        let matcher = match slot.take() {
            Some((k, m)) if k == key => m,
            old => {
                drop(old);
                Self::make_matcher(device, width, height, max_disparity, method)?
            }
        };
        Ok(&mut slot.insert((key, matcher)).1)
    }

    /// The matcher the two-image path runs for `method`: the census one, or the semi-global
    /// one with its census check ([`Matcher::checked`]).
    pub(crate) fn make_matcher(
        device: &Device,
        width: u32,
        height: u32,
        max_disparity: u32,
        method: MatcherMethod,
    ) -> Result<Matcher> {
        match method {
            MatcherMethod::Census => Matcher::with_method(device, width, height, max_disparity, method),
            MatcherMethod::Sgm => Matcher::checked(device, width, height, max_disparity),
        }
    }

    /// The densifier (two images alone with the fill).
    pub(crate) fn densifier(&mut self, device: &Device) -> Result<&mut Densifier> {
        let densifier = match self.densifier.take() {
            Some(d) => d,
            None => Densifier::new(device)?,
        };
        Ok(self.densifier.insert(densifier))
    }

    /// The fill.
    pub(crate) fn filler(&mut self, device: &Device) -> Result<&mut Filler> {
        let filler = match self.filler.take() {
            Some(f) => f,
            None => Filler::new(device)?,
        };
        Ok(self.filler.insert(filler))
    }

    /// The temporal history for frames under `conv`: made again when the conventions change
    /// (the rows and depth it reads follow them).
    pub(crate) fn history(&mut self, device: &Device, conv: Conventions) -> Result<&mut Accumulator> {
        let history = match self.history.take() {
            Some((c, h)) if c == conv => h,
            _ => Accumulator::new(device, FILL_ONLY, DEPTH_TOLERANCE, conv)?,
        };
        Ok(&mut self.history.insert((conv, history)).1)
    }
}
