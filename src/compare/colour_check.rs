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

use super::colour::{flip_rows, srgb_decode, srgb_encode, Alpha, ChannelOrder, Transfer};
use super::Side;
use crate::convention::RowOrder;

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

/// The share of the selected pixels whose largest channel difference is within
/// [`AGREE_LEVELS`].
fn agreement(model: &[f64], cb: &[f64], selected: &[bool]) -> f64 {
    let (mut n, mut agree) = (0usize, 0usize);
    for ((x, y), _) in model
        .chunks_exact(3)
        .zip(cb.chunks_exact(3))
        .zip(selected)
        .filter(|(_, s)| **s)
    {
        n += 1;
        if x.iter().zip(y).all(|(x, y)| (x - y).abs() * 255.0 <= AGREE_LEVELS) {
            agree += 1;
        }
    }
    agree as f64 / n.max(1) as f64
}

/// `ca` with `f` applied to every channel value.
fn per_value(ca: &[f64], f: impl Fn(f64) -> f64) -> Vec<f64> {
    ca.iter().map(|v| f(*v)).collect()
}

/// The readings of B's colour besides the declared one: (what, the option that declares it,
/// is it the rows, A's colour as B would hold it under that reading).
fn readings(a: &Side, b: &Side, ca: &[f64]) -> Vec<(String, String, bool, Vec<f64>)> {
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
        format!("--b-rows {}", other_rows.name()),
        true,
        flip_rows(ca, a.color.width as usize * 3),
    ));
    let other_channels = match b.colour.channels {
        ChannelOrder::Rgb => ChannelOrder::Bgr,
        ChannelOrder::Bgr => ChannelOrder::Rgb,
    };
    let mut swapped = ca.to_vec();
    swapped.chunks_exact_mut(3).for_each(|p| p.swap(0, 2));
    out.push((
        format!(
            "red and blue swapped: channels {} (declared {}; a BGRA swapchain read back as RGBA)",
            other_channels.name(),
            b.colour.channels.name()
        ),
        format!("--b-channels {}", other_channels.name()),
        false,
        swapped,
    ));
    // One sRGB encoding short of A: B stored linear values where sRGB-encoded ones belong
    // (declared sRGB), or A holds sRGB values declared linear. B declared linear and still
    // short was decoded twice: no option reads that, so it is not offered.
    let short_fix = match (b.colour.transfer, a.colour.transfer) {
        (Transfer::Srgb, _) => Some("--b-transfer linear"),
        (Transfer::Linear, Transfer::Linear) => Some("--a-transfer srgb"),
        (Transfer::Linear, Transfer::Srgb) => None,
    };
    if let Some(fix) = short_fix {
        out.push((
            "linear values stored where sRGB is expected (a UNORM target where an SRGB one belongs)".to_string(),
            fix.to_string(),
            false,
            per_value(ca, srgb_decode),
        ));
    }
    // One encoding over A: B holds sRGB values declared linear, or A holds linear values
    // declared sRGB (A declared linear too would mean B was encoded twice: not offered).
    let over_fix = match (b.colour.transfer, a.colour.transfer) {
        (Transfer::Linear, _) => Some("--b-transfer srgb"),
        (Transfer::Srgb, Transfer::Srgb) => Some("--a-transfer linear"),
        (Transfer::Srgb, Transfer::Linear) => None,
    };
    if let Some(fix) = over_fix {
        out.push((
            "sRGB values where linear is expected (one sRGB encoding more than A)".to_string(),
            fix.to_string(),
            false,
            per_value(ca, srgb_encode),
        ));
    }
    if let Some(alpha) = alpha_top_down(b) {
        let (other, scale): (Alpha, fn(f64, f64) -> f64) = match b.colour.alpha {
            Alpha::Straight => (Alpha::Premultiplied, |v, a| v * a),
            Alpha::Premultiplied => (Alpha::Straight, |v, a| if a > 0.0 { v / a } else { v }),
        };
        // Premultiplication happens on the stored values: in linear light when B is declared
        // linear (its compared form is encoded afterwards).
        let linear = b.colour.transfer == Transfer::Linear;
        let mut model = ca.to_vec();
        for (p, a) in model.chunks_exact_mut(3).zip(&alpha) {
            for v in p.iter_mut() {
                *v = if linear {
                    srgb_encode(scale(srgb_decode(*v), *a))
                } else {
                    scale(*v, *a)
                };
            }
        }
        out.push((
            format!("{} alpha (declared {})", other.name(), b.colour.alpha.name()),
            format!("--b-alpha {}", other.name()),
            false,
            model,
        ));
    }
    out
}

/// B's alpha, rows top-down, when its file has alpha.
fn alpha_top_down(b: &Side) -> Option<Vec<f64>> {
    let a: Vec<f64> = b.color.alpha.as_ref()?.iter().map(|v| f64::from(*v)).collect();
    Some(match b.conv.row_order {
        RowOrder::TopDown => a,
        RowOrder::BottomUp => flip_rows(&a, b.color.width as usize),
    })
}

/// The reading of B's colour that fits A far better than the declared one, if any.
pub(super) fn suspicion(a: &Side, b: &Side, ca: &[f64], cb: &[f64], selected: &[bool]) -> Option<ColourSuspicion> {
    let declared = agreement(ca, cb, selected);
    if declared >= 1.0 - NAMED_GAIN {
        return None;
    }
    let (what, fix, rows, share) = readings(a, b, ca)
        .into_iter()
        .map(|(what, fix, rows, model)| (what, fix, rows, agreement(&model, cb, selected)))
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
