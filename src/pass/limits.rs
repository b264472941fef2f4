//! The one rule for image sizes on the GPU: every side in 1..=the context's limit
//! (`Gpu::max_image_side`: GL_MAX_TEXTURE_SIZE and GL_MAX_VIEWPORT_DIMS; 16384 on llvmpipe,
//! 32768 on NVIDIA). Every capability refuses through [`check_image_size`], so the error reads
//! the same everywhere: the parameter, the size and the limit.

use crate::error::{Error, Result};

/// Refuse `width` x `height` (of the parameter `name`) unless both sides are in 1..=`limit`.
/// Callers without a context yet pass the limit they will render under.
pub fn check_image_size(name: &str, width: u64, height: u64, limit: u32) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::param(name, format!("{width}x{height} has a zero side")));
    }
    if width > u64::from(limit) || height > u64::from(limit) {
        return Err(Error::ImageTooLarge {
            name: name.to_string(),
            width,
            height,
            limit,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sides_up_to_the_limit_pass_one_past_is_refused_naming_all_three() {
        check_image_size("output size", 16384, 1, 16384).unwrap();
        check_image_size("output size", 1, 16384, 16384).unwrap();
        for (w, h) in [(16385, 1), (1, 16385)] {
            let e = check_image_size("output size", w, h, 16384).unwrap_err();
            assert!(matches!(e, Error::ImageTooLarge { limit: 16384, .. }));
            assert_eq!(
                e.to_string(),
                format!("invalid output size: {w}x{h} exceeds this GPU's limit of 16384 px per side")
            );
        }
        check_image_size("middle size", 32768, 2, 32768).unwrap();
        let e = check_image_size("middle size", 0, 3, 16384).unwrap_err().to_string();
        assert_eq!(e, "invalid middle size: 0x3 has a zero side");
    }
}
