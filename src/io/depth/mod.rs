//! Depth and disparity files: loading and saving in every format, the values a depth may
//! hold, truncation, 16-bit PNG, previews, and the summaries and scale fit that check a map.

pub(crate) mod disparity_fit;
pub(crate) mod disparity_summary;
pub(crate) mod file;
pub(crate) mod png16;
pub(crate) mod preview;
pub(crate) mod ranks;
pub(crate) mod summary;
pub(crate) mod trunc;
pub(crate) mod values;
