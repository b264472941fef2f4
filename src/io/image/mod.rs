//! The rasters ([`RgbImage`](types::RgbImage), [`DepthMap`](types::DepthMap),
//! [`Mask`](types::Mask)) and the loading and saving of colour images and masks.

pub(crate) mod colour;
pub(crate) mod mask;
pub(crate) mod rgb;
pub(crate) mod types;
