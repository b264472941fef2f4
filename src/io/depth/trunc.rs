//! Depth truncation, as Open3D's `depth_trunc`: input depth beyond a distance is treated as
//! invalid (far readings of RGB-D sensors are the noisiest).

use crate::error::{Error, Result};
use crate::io::image::types::DepthMap;

/// Checks a truncation distance: finite and > 0 metres.
pub fn check_depth_trunc(max_m: f64) -> Result<()> {
    if max_m.is_finite() && max_m > 0.0 {
        Ok(())
    } else {
        Err(Error::param(
            "depth-trunc",
            format!("{max_m}: expected metres, finite and > 0"),
        ))
    }
}

/// Sets depth beyond `max_m` metres to 0 (invalid) and returns how many pixels it changed.
/// Apply it to decoded metric depth, after any scale.
pub fn truncate_depth(depth: &mut DepthMap, max_m: f64) -> Result<usize> {
    check_depth_trunc(max_m)?;
    let mut n = 0;
    for z in &mut depth.data {
        if f64::from(*z) > max_m {
            *z = 0.0;
            n += 1;
        }
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beyond_the_distance_becomes_invalid() {
        let mut d = DepthMap::new(5, 1, vec![1.0, 2.5, 2.51, f32::INFINITY, 0.0]).unwrap();
        assert_eq!(truncate_depth(&mut d, 2.5).unwrap(), 2);
        assert_eq!(d.data, vec![1.0, 2.5, 0.0, 0.0, 0.0]);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = truncate_depth(&mut d, bad).unwrap_err().to_string();
            assert!(e.contains("depth-trunc"), "{e}");
        }
    }
}
