//! Which reading of B's colour fits A: rows flipped, red and blue swapped (a BGRA swapchain
//! read back as RGBA), linear values stored where sRGB is expected and the reverse, and
//! premultiplied alpha taken for straight (and the reverse) when B has alpha.
//!
//! Each reading is a model of what B's compared form would hold if it were the truth, applied
//! to A's; it is scored by its agreement, the share of the compared pixels whose largest
//! channel difference from B is within [`AGREE_LEVELS`], as the depth check scores its
//! readings (a share does not move with one pixel nor with the image size). Comparing in B's
//! space keeps B's own quantisation out of the score: dark linear values stored in 8 bits are
//! many sRGB levels apart.

use super::colour::{srgb_decode, srgb_encode, Alpha, ChannelOrder, Transfer};
use super::Side;
use crate::convention::RowOrder;
use crate::field::{Field, Message};
use crate::msg;

/// A pixel agrees when no channel differs by more than this many 8-bit levels (rounding on
/// both sides and an sRGB step at 8 bits stay under it).
pub(super) const AGREE_LEVELS: f64 = 3.0;
/// A reading is named when it agrees on at least this share of the pixels ...
const NAMED_AGREEMENT: f64 = 0.5;
/// ... and on this much more of them than the declared reading.
const NAMED_GAIN: f64 = 0.25;

/// A named reading of B's colour.
pub(super) struct ColourSuspicion {
    /// The line printed.
    pub line: String,
    /// The reading is flipped rows (which misplace depth as well).
    pub rows: bool,
}

/// How a reading turns A's compared form into what B would hold under it, pixel by pixel (no
/// reading is materialised: each would be another image of f64s, and `compare` keeps its
/// memory per pixel bounded, issue 46).
enum Model<'a> {
    /// The declared reading: A as it is.
    Declared,
    /// Rows in the other order.
    Rows,
    /// Red and blue swapped.
    Swapped,
    /// Each value sRGB-decoded (B one encoding short).
    Decoded,
    /// Each value sRGB-encoded (B one encoding over).
    Encoded,
    /// Alpha applied the other way: B's alpha in its file's rows (`flipped`: bottom-up), each
    /// value premultiplied (or divided) by it, in linear light when `linear`.
    Alpha {
        alpha: &'a [f32],
        flipped: bool,
        premultiply: bool,
        linear: bool,
    },
}

impl Model<'_> {
    /// Pixel `i` (top-down) of the model over `ca`, an image `w` pixels wide and `h` high.
    fn pixel(&self, ca: &[f32], i: usize, w: usize, h: usize) -> [f64; 3] {
        let at = |j: usize| [0, 1, 2].map(|c| f64::from(ca[j * 3 + c]));
        let mirrored = |j: usize| (h - 1 - j / w) * w + j % w;
        match *self {
            Model::Declared => at(i),
            Model::Rows => at(mirrored(i)),
            Model::Swapped => {
                let [r, g, b] = at(i);
                [b, g, r]
            }
            Model::Decoded => at(i).map(srgb_decode),
            Model::Encoded => at(i).map(srgb_encode),
            Model::Alpha {
                alpha,
                flipped,
                premultiply,
                linear,
            } => {
                let a = f64::from(alpha[if flipped { mirrored(i) } else { i }]);
                let scale = |v: f64| {
                    if premultiply {
                        v * a
                    } else if a > 0.0 {
                        v / a
                    } else {
                        v
                    }
                };
                // Premultiplication happens on the stored values: in linear light when B is
                // declared linear (its compared form is encoded afterwards).
                at(i).map(|v| {
                    if linear {
                        srgb_encode(scale(srgb_decode(v)))
                    } else {
                        scale(v)
                    }
                })
            }
        }
    }
}

/// The share of the selected pixels whose largest channel difference between `model` (over
/// A's compared form `ca`) and B's `cb` is within [`AGREE_LEVELS`].
fn agreement(model: &Model, ca: &[f32], cb: &[f32], width: usize, selected: &[bool]) -> f64 {
    let h = selected.len() / width.max(1);
    let (mut n, mut agree) = (0usize, 0usize);
    for (i, (y, _)) in cb.chunks_exact(3).zip(selected).enumerate().filter(|(_, (_, s))| **s) {
        n += 1;
        let x = model.pixel(ca, i, width, h);
        if x.iter()
            .zip(y)
            .all(|(x, y)| (x - f64::from(*y)).abs() * 255.0 <= AGREE_LEVELS)
        {
            agree += 1;
        }
    }
    agree as f64 / n.max(1) as f64
}

/// The readings of B's colour besides the declared one: (what, the option that declares it,
/// is it the rows, the model of B under it).
fn readings<'a>(a: &Side, b: &'a Side) -> Vec<(String, Message, bool, Model<'a>)> {
    let mut out = Vec::new();
    let other_rows = match b.conv.row_order {
        RowOrder::BottomUp => RowOrder::TopDown,
        RowOrder::TopDown => RowOrder::BottomUp,
    };
    out.push((
        format!(
            "rows read as {} (declared {})",
            other_rows.name(),
            b.conv.row_order.name()
        ),
        msg![Field::BRows, format!(" {}", other_rows.name())],
        true,
        Model::Rows,
    ));
    let other_channels = match b.colour.channels {
        ChannelOrder::Rgb => ChannelOrder::Bgr,
        ChannelOrder::Bgr => ChannelOrder::Rgb,
    };
    out.push((
        format!(
            "red and blue swapped: channels {} (declared {}; a BGRA swapchain read back as RGBA)",
            other_channels.name(),
            b.colour.channels.name()
        ),
        msg![Field::BChannels, format!(" {}", other_channels.name())],
        false,
        Model::Swapped,
    ));
    // One sRGB encoding short of A: B stored linear values where sRGB-encoded ones belong
    // (declared sRGB), or A holds sRGB values declared linear. B declared linear and still
    // short was decoded twice: no option reads that, so it is not offered.
    let short_fix = match (b.colour.transfer, a.colour.transfer) {
        (Transfer::Srgb, _) => Some(msg![Field::BTransfer, " linear"]),
        (Transfer::Linear, Transfer::Linear) => Some(msg![Field::ATransfer, " srgb"]),
        (Transfer::Linear, Transfer::Srgb) => None,
    };
    if let Some(fix) = short_fix {
        out.push((
            "linear values stored where sRGB is expected (a UNORM target where an SRGB one belongs)".to_string(),
            fix,
            false,
            Model::Decoded,
        ));
    }
    // One encoding over A: B holds sRGB values declared linear, or A holds linear values
    // declared sRGB (A declared linear too would mean B was encoded twice: not offered).
    let over_fix = match (b.colour.transfer, a.colour.transfer) {
        (Transfer::Linear, _) => Some(msg![Field::BTransfer, " srgb"]),
        (Transfer::Srgb, Transfer::Srgb) => Some(msg![Field::ATransfer, " linear"]),
        (Transfer::Srgb, Transfer::Linear) => None,
    };
    if let Some(fix) = over_fix {
        out.push((
            "sRGB values where linear is expected (one sRGB encoding more than A)".to_string(),
            fix,
            false,
            Model::Encoded,
        ));
    }
    if let Some(alpha) = b.color.alpha.as_deref() {
        let other = match b.colour.alpha {
            Alpha::Straight => Alpha::Premultiplied,
            Alpha::Premultiplied => Alpha::Straight,
        };
        out.push((
            format!("{} alpha (declared {})", other.name(), b.colour.alpha.name()),
            msg![Field::BAlpha, format!(" {}", other.name())],
            false,
            Model::Alpha {
                alpha,
                flipped: b.conv.row_order == RowOrder::BottomUp,
                premultiply: b.colour.alpha == Alpha::Straight,
                linear: b.colour.transfer == Transfer::Linear,
            },
        ));
    }
    out
}

/// The reading of B's colour that fits A far better than the declared one, if any.
pub(super) fn suspicion(a: &Side, b: &Side, ca: &[f32], cb: &[f32], selected: &[bool]) -> Option<ColourSuspicion> {
    let width = a.color.width as usize;
    let declared = agreement(&Model::Declared, ca, cb, width, selected);
    if declared >= 1.0 - NAMED_GAIN {
        return None;
    }
    let (what, fix, rows, share) = readings(a, b)
        .into_iter()
        .map(|(what, fix, rows, model)| (what, fix, rows, agreement(&model, ca, cb, width, selected)))
        .max_by(|x, y| x.3.total_cmp(&y.3))?;
    (share >= NAMED_AGREEMENT && share >= declared + NAMED_GAIN).then(|| ColourSuspicion {
        line: format!(
            "B's colour fits {what} ({fix}): {:.1} % of the pixels agree with A within {AGREE_LEVELS} \
             levels, {:.1} % as declared",
            share * 100.0,
            declared * 100.0
        ),
        rows,
    })
}
