//! Pixel layout conversions between the library's images and the texels a pass uploads: RGB8 images
//! travel as RGBA8 (GL has no 3-byte render target), f32 data as native-endian bytes.

/// RGB8 -> RGBA8 with opaque alpha.
pub fn rgb_to_rgba(rgb: &[u8]) -> Vec<u8> {
    rgb.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect()
}

/// RGBA8 -> RGB8 (alpha dropped).
pub fn rgba_to_rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
}

/// f32 values as native-endian bytes, for texture upload.
pub fn f32_to_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_ne_bytes()).collect()
}

/// Native-endian bytes (a readback) as f32 values.
pub fn bytes_to_f32(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_round_trip() {
        let rgb = [1, 2, 3, 4, 5, 6];
        assert_eq!(rgb_to_rgba(&rgb), vec![1, 2, 3, 255, 4, 5, 6, 255]);
        assert_eq!(rgba_to_rgb(&rgb_to_rgba(&rgb)), rgb.to_vec());
        let v = [1.5f32, -0.0, f32::INFINITY];
        assert_eq!(bytes_to_f32(&f32_to_bytes(&v)), v.to_vec());
    }
}
