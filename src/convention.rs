//! Rendering conventions as runtime switches: NDC depth range, reversed-Z and image row order.
//!
//! Every pass takes a [`Conventions`] value; shaders receive it as a generated `#define` preamble
//! ([`Conventions::glsl_defines`]). The mapping between view-space distance and device depth lives
//! here once, in f64 (reference) and f32 (mirrors what the GPU computes).

use serde::{Deserialize, Serialize};

/// Range of NDC z after the perspective divide.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum NdcDepthRange {
    /// OpenGL default: z_ndc in [-1, 1], window depth = (z_ndc + 1) / 2.
    #[default]
    MinusOneToOne,
    /// Vulkan / D3D (GL with `glClipControl(.., GL_ZERO_TO_ONE)`): z_ndc in [0, 1] = window depth.
    ZeroToOne,
}

/// Memory order of image rows in framebuffers and readbacks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum RowOrder {
    /// OpenGL: framebuffer row 0 is the bottom of the picture, NDC y points up.
    #[default]
    BottomUp,
    /// Vulkan: row 0 is the top, NDC y points down.
    TopDown,
}

/// The full set of convention switches a pass runs under.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub struct Conventions {
    /// NDC depth range: GL [-1, 1] or Vulkan [0, 1].
    pub ndc_depth: NdcDepthRange,
    /// Near maps to the top of the depth range and far to the bottom (better float precision).
    pub reversed_z: bool,
    /// Row order of the GPU framebuffers (image files are always top-down).
    pub row_order: RowOrder,
}

impl Conventions {
    /// All 8 combinations, for tests and sweeps.
    pub fn all() -> [Conventions; 8] {
        let mut out = [Conventions::default(); 8];
        let mut i = 0;
        for ndc_depth in [NdcDepthRange::MinusOneToOne, NdcDepthRange::ZeroToOne] {
            for reversed_z in [false, true] {
                for row_order in [RowOrder::BottomUp, RowOrder::TopDown] {
                    out[i] = Conventions {
                        ndc_depth,
                        reversed_z,
                        row_order,
                    };
                    i += 1;
                }
            }
        }
        out
    }

    /// NDC z of the near plane and of the far plane.
    pub fn ndc_z_near_far(&self) -> (f64, f64) {
        let (lo, hi) = match self.ndc_depth {
            NdcDepthRange::MinusOneToOne => (-1.0, 1.0),
            NdcDepthRange::ZeroToOne => (0.0, 1.0),
        };
        if self.reversed_z {
            (hi, lo)
        } else {
            (lo, hi)
        }
    }

    /// Reversed-Z with the [0, 1] range: the one combination where float window depth keeps its
    /// relative precision at every distance (the others store ~1 - near/Z or go through
    /// 2 d - 1, whose absolute precision limits Z to ~eps Z / near).
    pub fn float_depth_keeps_relative_precision(&self) -> bool {
        self.reversed_z && self.ndc_depth == NdcDepthRange::ZeroToOne
    }

    /// Window depth the depth buffer is cleared to (the far value).
    pub fn clear_depth(&self) -> f64 {
        ndc_to_window_depth(self.ndc_depth, self.ndc_z_near_far().1)
    }

    /// `#define` lines injected after `#version` in every shader.
    pub fn glsl_defines(&self) -> String {
        let (zn, zf) = self.ndc_z_near_far();
        format!(
            "#define NDC_ZERO_TO_ONE {}\n#define REVERSED_Z {}\n#define ROWS_TOP_DOWN {}\n\
             #define NDC_Z_NEAR {:.1}\n#define NDC_Z_FAR {:.1}\n",
            (self.ndc_depth == NdcDepthRange::ZeroToOne) as u8,
            self.reversed_z as u8,
            (self.row_order == RowOrder::TopDown) as u8,
            zn,
            zf
        )
    }

    /// Short label, e.g. `gl-std-bu` or `vk-rev-td`.
    pub fn label(&self) -> String {
        format!(
            "{}-{}-{}",
            match self.ndc_depth {
                NdcDepthRange::MinusOneToOne => "gl",
                NdcDepthRange::ZeroToOne => "vk",
            },
            if self.reversed_z { "rev" } else { "std" },
            match self.row_order {
                RowOrder::BottomUp => "bu",
                RowOrder::TopDown => "td",
            }
        )
    }
}

impl RowOrder {
    /// The name the CLI and the JSON files use: `bottom-up` or `top-down`.
    pub fn name(self) -> &'static str {
        match self {
            RowOrder::BottomUp => "bottom-up",
            RowOrder::TopDown => "top-down",
        }
    }

    /// The rows of `data` (rows of `row_bytes`, stored in this order) from the top down: what
    /// [`Self::convert_rows`] makes, read in place without a copy.
    pub fn top_down(self, data: &[u8], row_bytes: usize) -> impl Iterator<Item = &[u8]> {
        let h = data.len().checked_div(row_bytes).unwrap_or(0);
        let flip = self == RowOrder::BottomUp;
        (0..h).map(move |y| {
            let y = if flip { h - 1 - y } else { y };
            &data[y * row_bytes..(y + 1) * row_bytes]
        })
    }

    /// Convert between top-down image rows and this order's memory rows (the same operation
    /// both ways: a row flip for bottom-up, nothing for top-down). `row_bytes` is one row.
    pub fn convert_rows(self, mut data: Vec<u8>, row_bytes: usize) -> Vec<u8> {
        if self == RowOrder::BottomUp && row_bytes > 0 {
            let h = data.len() / row_bytes;
            for y in 0..h / 2 {
                let (a, b) = data.split_at_mut((h - 1 - y) * row_bytes);
                a[y * row_bytes..(y + 1) * row_bytes].swap_with_slice(&mut b[..row_bytes]);
            }
        }
        data
    }
}

fn ndc_to_window_depth(range: NdcDepthRange, z_ndc: f64) -> f64 {
    match range {
        NdcDepthRange::MinusOneToOne => 0.5 * (z_ndc + 1.0),
        NdcDepthRange::ZeroToOne => z_ndc,
    }
}

/// Near/far planes of a perspective depth mapping. `far = f64::INFINITY` is allowed
/// (an infinite far plane; exact with reversed-Z and float depth).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthPlanes {
    /// Near plane, view units (> 0).
    pub near: f64,
    /// Far plane, view units (> near; may be infinite).
    pub far: f64,
}

impl DepthPlanes {
    /// Coefficients (a, b) with z_clip = a * Z + b and w_clip = Z (Z = positive view distance
    /// along the optical axis), so that z_ndc = a + b / Z.
    ///
    /// Written through inverse depth t = (1/Z - 1/far) / (1/near - 1/far) (t = 1 at near,
    /// 0 at far): z_ndc = z_far + (z_near - z_far) * t. This form stays finite for far = inf.
    pub fn clip_z_coefficients(&self, conv: &Conventions) -> (f64, f64) {
        let (zn, zf) = conv.ndc_z_near_far();
        let inv_far = if self.far.is_infinite() { 0.0 } else { 1.0 / self.far };
        let k = (zn - zf) / (1.0 / self.near - inv_far);
        (zf - k * inv_far, k)
    }

    /// Device (NDC) z of a view distance Z, in f64.
    pub fn ndc_z_of_view_z(&self, conv: &Conventions, view_z: f64) -> f64 {
        let (a, b) = self.clip_z_coefficients(conv);
        a + b / view_z
    }

    /// View distance Z of an NDC z, in f64 (inverse of [`Self::ndc_z_of_view_z`]).
    pub fn view_z_of_ndc_z(&self, conv: &Conventions, ndc_z: f64) -> f64 {
        let (a, b) = self.clip_z_coefficients(conv);
        b / (ndc_z - a)
    }

    /// The same mapping evaluated in f32, as a shader would.
    pub fn ndc_z_of_view_z_f32(&self, conv: &Conventions, view_z: f32) -> f32 {
        let (a, b) = self.clip_z_coefficients(conv);
        (a as f32 * view_z + b as f32) / view_z
    }

    /// The planes of a GL-style perspective projection (row-major, GL eye space -> clip, clip
    /// w = -z_eye) made under `conv`: its depth row gives z_ndc = -m\[2\]\[2\] + m\[2\]\[3\] / Z, which
    /// is inverted at the near and far NDC values of `conv` (far = inf where the row never
    /// reaches it).
    ///
    /// Errors: not a perspective projection (w row other than (0, 0, -1, 0), depth row that
    /// depends on x or y), or planes that are not 0 < near < far.
    pub fn from_gl_projection(m: &[[f64; 4]; 4], conv: &Conventions) -> crate::Result<DepthPlanes> {
        let perspective = m[3] == [0.0, 0.0, -1.0, 0.0] && m[2][0] == 0.0 && m[2][1] == 0.0;
        if !perspective || !m.iter().flatten().all(|v| v.is_finite()) {
            return Err(crate::Error::param(
                "projection",
                "not a finite GL perspective projection (w row (0, 0, -1, 0), depth row in z and w only)",
            ));
        }
        let (a, b) = (-m[2][2], m[2][3]);
        let (zn, zf) = conv.ndc_z_near_far();
        let near = b / (zn - a);
        let far = if zf == a { f64::INFINITY } else { b / (zf - a) };
        if !(near.is_finite() && near > 0.0 && far > near) {
            return Err(crate::Error::param(
                "projection",
                format!(
                    "its depth row gives near {near}, far {far} under {}: not 0 < near < far",
                    conv.label()
                ),
            ));
        }
        Ok(DepthPlanes { near, far })
    }

    /// Window depth (what a depth buffer stores) of an NDC z.
    pub fn window_depth_of_ndc_z(conv: &Conventions, ndc_z: f64) -> f64 {
        ndc_to_window_depth(conv.ndc_depth, ndc_z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_and_far_map_to_the_ends_of_the_range_under_every_convention() {
        let planes = DepthPlanes { near: 0.1, far: 1000.0 };
        for conv in Conventions::all() {
            let (zn, zf) = conv.ndc_z_near_far();
            assert!((planes.ndc_z_of_view_z(&conv, 0.1) - zn).abs() < 1e-12, "{conv:?}");
            assert!((planes.ndc_z_of_view_z(&conv, 1000.0) - zf).abs() < 1e-12, "{conv:?}");
            // Round trip view Z -> NDC -> view Z, relative error bounded by f64 rounding
            // amplified by the near/far ratio (1e4 here).
            for z in [0.1, 0.37, 5.0, 999.0] {
                let back = planes.view_z_of_ndc_z(&conv, planes.ndc_z_of_view_z(&conv, z));
                assert!((back - z).abs() / z < 1e-10, "{conv:?} z={z} back={back}");
            }
        }
    }

    #[test]
    fn planes_come_back_from_the_gl_projection_under_every_convention() {
        let cam = crate::world::demo_camera(64, 48);
        for conv in Conventions::all() {
            for planes in [
                DepthPlanes { near: 0.05, far: 100.0 },
                DepthPlanes {
                    near: 1e-3,
                    far: f64::INFINITY,
                },
            ] {
                let m = crate::camera::gl_projection(&cam, &planes, &conv);
                let back = DepthPlanes::from_gl_projection(&m, &conv).unwrap();
                assert!((back.near / planes.near - 1.0).abs() < 1e-12, "{conv:?} {back:?}");
                assert!(
                    back.far == planes.far || (back.far / planes.far - 1.0).abs() < 1e-9,
                    "{conv:?} {back:?}"
                );
            }
        }
        let mut ortho = crate::camera::mat4::IDENTITY;
        ortho[2][2] = -0.1;
        assert!(DepthPlanes::from_gl_projection(&ortho, &Conventions::default()).is_err());
    }

    #[test]
    fn infinite_far_is_finite_and_reaches_far_value_only_at_infinity() {
        let planes = DepthPlanes {
            near: 0.05,
            far: f64::INFINITY,
        };
        for conv in Conventions::all() {
            let (a, b) = planes.clip_z_coefficients(&conv);
            assert!(a.is_finite() && b.is_finite());
            let (zn, zf) = conv.ndc_z_near_far();
            assert!((planes.ndc_z_of_view_z(&conv, 0.05) - zn).abs() < 1e-12);
            assert!((planes.ndc_z_of_view_z(&conv, 1e300) - zf).abs() < 1e-12);
        }
    }

    #[test]
    fn reversed_z_keeps_far_depths_distinct_in_f32_where_standard_z_collapses_them() {
        // Two surfaces at 10 km and 10.01 km with near = 1 cm: a ratio of 1e6.
        let planes = DepthPlanes { near: 0.01, far: 1e5 };
        let vk = |reversed_z| Conventions {
            ndc_depth: NdcDepthRange::ZeroToOne,
            reversed_z,
            row_order: RowOrder::TopDown,
        };
        let std_a = planes.ndc_z_of_view_z_f32(&vk(false), 10_000.0);
        let std_b = planes.ndc_z_of_view_z_f32(&vk(false), 10_010.0);
        let rev_a = planes.ndc_z_of_view_z_f32(&vk(true), 10_000.0);
        let rev_b = planes.ndc_z_of_view_z_f32(&vk(true), 10_010.0);
        assert_eq!(std_a, std_b, "standard Z is expected to collapse here");
        assert!(rev_a > rev_b, "reversed Z must order them: {rev_a} vs {rev_b}");
    }

    #[test]
    fn row_conversion_flips_bottom_up_only_and_is_its_own_inverse() {
        let img: Vec<u8> = (0..12).collect(); // 3 rows of 4 bytes
        assert_eq!(RowOrder::TopDown.convert_rows(img.clone(), 4), img);
        let flipped = RowOrder::BottomUp.convert_rows(img.clone(), 4);
        assert_eq!(flipped, vec![8, 9, 10, 11, 4, 5, 6, 7, 0, 1, 2, 3]);
        assert_eq!(RowOrder::BottomUp.convert_rows(flipped, 4), img);
        for rows in [RowOrder::TopDown, RowOrder::BottomUp] {
            let read: Vec<u8> = rows.top_down(&img, 4).flatten().copied().collect();
            assert_eq!(read, rows.convert_rows(img.clone(), 4));
        }
    }

    #[test]
    fn defines_name_each_switch() {
        let conv = Conventions {
            ndc_depth: NdcDepthRange::ZeroToOne,
            reversed_z: true,
            row_order: RowOrder::TopDown,
        };
        let d = conv.glsl_defines();
        assert!(d.contains("#define NDC_ZERO_TO_ONE 1"));
        assert!(d.contains("#define REVERSED_Z 1"));
        assert!(d.contains("#define ROWS_TOP_DOWN 1"));
        assert!(d.contains("#define NDC_Z_NEAR 1.0") && d.contains("#define NDC_Z_FAR 0.0"));
        assert_eq!(conv.clear_depth(), 0.0);
        assert_eq!(Conventions::default().clear_depth(), 1.0);
    }
}
