//! The usable magnitudes of a stored depth value: **valid implies finite** (the one rule, for
//! every capability; see [`crate::depth`]). It sits with the loaders, which turn every value
//! outside it into a hole as they read a file; the depth vocabulary re-exports it.

/// Smallest magnitude of a stored depth value (any kind, after `--depth-scale`) that is not a
/// hole: below it the reciprocal overflows f32 near the subnormals (which GPUs flush to zero,
/// so a 1e-40 became 0 on the GPU, 0/0 = NaN, while the f64 twin called it valid), and it is
/// 1 um of view Z, 1e-6 px of disparity, or within [`crate::depth::FAR_EPS`] of a reversed-Z far plane.
pub const MIN_DEPTH_VALUE: f32 = 1e-6;
/// Largest magnitude of a stored depth value that is not a hole: the bound of every
/// real-valued option and file number (`job::MAX_OPTION_MAGNITUDE`, `io::MAX_JSON_MAGNITUDE`);
/// beyond it back-projection times focal lengths, and squared distances, overflow f32.
/// Renderers' sentinels (Blender's 1e10 background) fall here and are holes, like +-Inf.
pub const MAX_DEPTH_VALUE: f32 = 1e6;

/// Whether a stored depth value is within the magnitudes every pass computes finitely; 0 is
/// left to each encoding (a hole for view Z, the near plane for device depth).
#[inline]
pub fn usable_depth_value(v: f32) -> bool {
    v == 0.0 || (v.is_finite() && (MIN_DEPTH_VALUE..=MAX_DEPTH_VALUE).contains(&v.abs()))
}

/// Whether `v` is finite but outside [`usable_depth_value`]: the values the rule turns into
/// holes (NaN and infinities are holes already and are kept as they are).
#[inline]
fn out_of_range(v: f32) -> bool {
    v.is_finite() && !usable_depth_value(v)
}

/// Makes every stored value outside [`usable_depth_value`] a hole (NaN), the one rule that
/// every depth input (files, Python arrays, stress cases) goes through before a pass sees it,
/// so that a pixel the mask calls valid has finite outputs. Returns how many were changed.
pub fn clear_unusable_depth(data: &mut [f32]) -> usize {
    let mut n = 0;
    for v in data.iter_mut().filter(|v| out_of_range(**v)) {
        *v = f32::NAN;
        n += 1;
    }
    n
}

/// Refuses a depth map holding a finite value outside [`usable_depth_value`] (the values
/// [`clear_unusable_depth`] makes holes), naming `what`, how many and the first one.
///
/// This is the input check of every pass (refocus, cyclopean, reproject, stitch): the loaders
/// and the Python bindings apply [`clear_unusable_depth`] first, so only a library caller who
/// builds a [`crate::io::DepthMap`] by hand can meet it, and gets an error instead of NaN where
/// the mask says valid. NaN and +-Inf are holes and pass.
pub fn check_usable_depth(what: &str, data: &[f32]) -> crate::Result<()> {
    let mut bad = data.iter().enumerate().filter(|(_, v)| out_of_range(**v));
    let Some((i, v)) = bad.next() else {
        return Ok(());
    };
    let n = 1 + bad.count();
    Err(crate::Error::param(
        what,
        format!(
            "{n} value(s) outside the usable magnitudes [{MIN_DEPTH_VALUE:e}, {MAX_DEPTH_VALUE:e}] \
             (first {v:e} at index {i}); make them holes first with \
             viewsynth::depth::clear_unusable_depth, as the loaders do"
        ),
    ))
}
