//! One camera of a `cameras.json` as the file gives it, and its conversion to GL matrices.
//!
//! A camera is either GL matrices (`view`: world -> GL eye, `proj`: GL eye -> clip) or the
//! computer-vision form: `K` (3x3 intrinsics in pixels, OpenCV pixel centres), `R`, `t`
//! (world -> camera, `x_cam = R x_world + t`, OpenCV axes: x right, y down, z forward), the image
//! `width`/`height` and the depth planes `near`/`far`. The forms may be mixed per camera (e.g. `K`
//! with a GL `view`). The conversion is exact in f64:
//! - view = diag(1, -1, -1, 1) [R | t]: the OpenCV -> GL axis flip is a sign change of two rows,
//!   the same product as [`crate::camera::Pose::gl_view`];
//! - proj = [`crate::camera::gl_projection`] of the pinhole camera under the file's conventions,
//!   the projection `viewsynth scene` writes, with the pixel-centre rule of ARCHITECTURE.md.
//!
//! Malformed matrices are refused with the field named (`left.R`, `middle.K`, ...): wrong shape,
//! non-finite values, skew or a non-canonical last row of K, an R that is not a rotation.

use crate::camera::mat4::Mat4;
use crate::camera::{gl_projection, Intrinsics, PinholeCamera};
use crate::convention::{Conventions, DepthPlanes};
use crate::error::{Error, Result};
use serde::Deserialize;

/// Largest |R Rᵀ - I| entry accepted: rotations printed with ~6 significant digits pass, a
/// scaled or sheared matrix does not. R is used as given (not re-orthonormalised).
pub const ROTATION_TOLERANCE: f64 = 1e-5;

/// One camera as written in cameras.json: GL matrices, the computer-vision form, or a mix.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// World -> GL eye transform, row-major.
    #[serde(default)]
    pub view: Option<Mat4>,
    /// GL eye -> clip projection, row-major.
    #[serde(default)]
    pub proj: Option<Mat4>,
    /// Read as nested lists so that a wrong shape is reported with the field's name.
    #[serde(default, rename = "K")]
    pub k: Option<Vec<Vec<f64>>>,
    /// Rotation of world -> camera (OpenCV axes), 3x3, rows.
    #[serde(default, rename = "R")]
    pub r: Option<Vec<Vec<f64>>>,
    /// Translation of world -> camera: `x_cam = R x_world + t`.
    #[serde(default)]
    pub t: Option<Vec<f64>>,
    /// Image width in pixels (required with `K`).
    #[serde(default)]
    pub width: Option<u32>,
    /// Image height in pixels (required with `K`).
    #[serde(default)]
    pub height: Option<u32>,
    /// Near plane for the projection built from `K`, view units.
    #[serde(default)]
    pub near: Option<f64>,
    /// Far plane for the projection built from `K`, view units (> near, finite).
    #[serde(default)]
    pub far: Option<f64>,
}

/// A camera in GL matrices; `view` is None where the file leaves it to be derived (middle only).
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedCamera {
    /// World -> GL eye transform; None where the file leaves it to be derived.
    pub view: Option<Mat4>,
    /// GL eye -> clip projection under the file's conventions, row-major.
    pub proj: Mat4,
    /// The image size the file states (`width`/`height`), if any.
    pub size: Option<[u32; 2]>,
}

impl CameraSpec {
    /// The GL matrices of the camera called `name` in the file, under the file's conventions.
    pub fn resolve(&self, name: &str, conv: &Conventions) -> Result<ResolvedCamera> {
        let field = |f: &str| format!("{name}.{f}");
        let size = match (self.width, self.height) {
            (Some(w), Some(h)) if w > 0 && h > 0 => Some([w, h]),
            (Some(_), Some(_)) => return Err(Error::param(field("width/height"), "must be at least 1")),
            (None, None) => None,
            (Some(_), None) => return Err(Error::param(field("height"), "missing (width is given)")),
            (None, Some(_)) => return Err(Error::param(field("width"), "missing (height is given)")),
        };
        let view = match (&self.view, &self.r, &self.t) {
            (Some(_), None, None) => self.view,
            (Some(_), _, _) => return Err(Error::param(field("view"), "give view or R and t, not both")),
            (None, Some(r), Some(t)) => Some(gl_view_from_rt(
                &rotation(r, &field("R"))?,
                &translation(t, &field("t"))?,
            )),
            (None, Some(_), None) => return Err(Error::param(field("t"), "missing (R is given)")),
            (None, None, Some(_)) => return Err(Error::param(field("R"), "missing (t is given)")),
            (None, None, None) => None,
        };
        let proj = match (&self.proj, &self.k) {
            (Some(_), Some(_)) => return Err(Error::param(field("proj"), "give proj or K, not both")),
            (Some(p), None) => {
                if self.near.is_some() || self.far.is_some() {
                    return Err(Error::param(
                        field("near/far"),
                        "go with K; a GL proj carries its own planes",
                    ));
                }
                *p
            }
            (None, Some(k)) => {
                let k = intrinsics(k, &field("K"))?;
                let [width, height] = size.ok_or_else(|| {
                    Error::param(
                        field("width/height"),
                        "needed with K (the projection depends on the image size)",
                    )
                })?;
                let planes = planes(self.near, self.far, name)?;
                gl_projection(&PinholeCamera { k, width, height }, &planes, conv)
            }
            (None, None) => return Err(Error::param(field("proj"), "missing: give proj or K")),
        };
        Ok(ResolvedCamera { view, proj, size })
    }
}

/// GL view matrix of a world -> OpenCV camera transform: rows 1 and 2 negated (y down -> up,
/// z forward -> backward), exact in f64.
pub fn gl_view_from_rt(r: &[[f64; 3]; 3], t: &[f64; 3]) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().take(3).enumerate() {
        let sign = if i == 0 { 1.0 } else { -1.0 };
        *row = [sign * r[i][0], sign * r[i][1], sign * r[i][2], sign * t[i]];
    }
    m[3] = [0.0, 0.0, 0.0, 1.0];
    m
}

fn finite(values: &[f64], field: &str) -> Result<()> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(Error::param(field, format!("{v} is not finite"))),
        None => Ok(()),
    }
}

fn matrix3(m: &[Vec<f64>], field: &str) -> Result<[[f64; 3]; 3]> {
    if m.len() != 3 || m.iter().any(|row| row.len() != 3) {
        let shape: Vec<String> = m.iter().map(|row| row.len().to_string()).collect();
        return Err(Error::param(
            field,
            format!(
                "expected a 3x3 matrix as 3 rows of 3 numbers, got {} rows of [{}]",
                m.len(),
                shape.join(", ")
            ),
        ));
    }
    let out = [0, 1, 2].map(|i| [m[i][0], m[i][1], m[i][2]]);
    finite(out.as_flattened(), field)?;
    Ok(out)
}

/// A proper rotation: R Rᵀ = I within [`ROTATION_TOLERANCE`] and det R = +1 (not a reflection).
pub fn rotation(m: &[Vec<f64>], field: &str) -> Result<[[f64; 3]; 3]> {
    let r = matrix3(m, field)?;
    let mut worst = 0.0f64;
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
            worst = worst.max((dot - if i == j { 1.0 } else { 0.0 }).abs());
        }
    }
    if worst > ROTATION_TOLERANCE {
        return Err(Error::param(
            field,
            format!("not orthonormal: R Rᵀ differs from the identity by {worst:.3e} (at most {ROTATION_TOLERANCE:e})"),
        ));
    }
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if det < 0.0 {
        return Err(Error::param(
            field,
            format!("determinant {det:.6}: a reflection, not a rotation (check the axis convention)"),
        ));
    }
    Ok(r)
}

fn translation(t: &[f64], field: &str) -> Result<[f64; 3]> {
    let t: [f64; 3] = t
        .try_into()
        .map_err(|_| Error::param(field, format!("expected 3 numbers, got {}", t.len())))?;
    finite(&t, field)?;
    Ok(t)
}

/// Pinhole intrinsics of a K without skew: [[fx, 0, cx], [0, fy, cy], [0, 0, 1]].
pub fn intrinsics(m: &[Vec<f64>], field: &str) -> Result<Intrinsics> {
    let k = matrix3(m, field)?;
    if k[0][1] != 0.0 {
        return Err(Error::param(
            field,
            format!("skew K[0][1] = {} is not supported", k[0][1]),
        ));
    }
    if k[1][0] != 0.0 || k[2] != [0.0, 0.0, 1.0] {
        return Err(Error::param(
            field,
            "expected [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (pixels)",
        ));
    }
    let intrinsics = Intrinsics {
        fx: k[0][0],
        fy: k[1][1],
        cx: k[0][2],
        cy: k[1][2],
    };
    intrinsics.validate(field)?;
    Ok(intrinsics)
}

fn planes(near: Option<f64>, far: Option<f64>, name: &str) -> Result<DepthPlanes> {
    let (Some(near), Some(far)) = (near, far) else {
        return Err(Error::param(
            format!("{name}.near/far"),
            "needed with K (the depth planes of the projection)",
        ));
    };
    if !(near.is_finite() && far.is_finite() && near > 0.0 && far > near) {
        return Err(Error::param(
            format!("{name}.near/far"),
            format!("{near}/{far}: need 0 < near < far, finite"),
        ));
    }
    Ok(DepthPlanes { near, far })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{mat4, Pose};
    use crate::convention::RowOrder;
    use crate::stereo::camera_file::CameraFile;
    use serde_json::{json, Value};

    const K: [[f64; 3]; 3] = [[525.0, 0.0, 319.5], [0.0, 520.0, 239.25], [0.0, 0.0, 1.0]];
    const SIZE: [u32; 2] = [640, 480];
    const PLANES: DepthPlanes = DepthPlanes { near: 0.1, far: 50.0 };

    /// A pose yawed and tilted, as world -> camera R, t (rows of R: the camera axes in world).
    fn pose() -> Pose {
        let mut p = Pose::yawed(0.3, [0.12, -0.4, 1.5]);
        let (s, c) = 0.2f64.sin_cos();
        let tilt = [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]];
        let r = p.rotation;
        p.rotation = [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| r[i][k] * tilt[k][j]).sum()));
        p
    }

    fn rt(p: &Pose) -> ([[f64; 3]; 3], [f64; 3]) {
        let m = p.camera_from_world();
        (
            [0, 1, 2].map(|i| [m[i][0], m[i][1], m[i][2]]),
            [m[0][3], m[1][3], m[2][3]],
        )
    }

    fn cv_camera(p: &Pose) -> Value {
        let (r, t) = rt(p);
        json!({ "K": K, "R": r, "t": t, "width": SIZE[0], "height": SIZE[1], "near": PLANES.near, "far": PLANES.far })
    }

    fn pinhole() -> PinholeCamera {
        PinholeCamera {
            k: Intrinsics {
                fx: K[0][0],
                fy: K[1][1],
                cx: K[0][2],
                cy: K[1][2],
            },
            width: SIZE[0],
            height: SIZE[1],
        }
    }

    fn file(left: Value, conv: Conventions) -> Value {
        let gl = json!({ "view": mat4::IDENTITY, "proj": gl_projection(&pinhole(), &PLANES, &conv) });
        json!({ "conventions": conv, "depth_kind": "device", "left": left, "right": gl,
                "middle": { "K": K, "width": SIZE[0], "height": SIZE[1], "near": 0.1, "far": 50.0 },
                "fixation_distance": 2.0 })
    }

    #[test]
    fn k_r_t_gives_the_closed_form_gl_matrices() {
        let p = pose();
        let (r, t) = rt(&p);
        let conv = Conventions::default();
        let f: CameraFile = serde_json::from_value(file(cv_camera(&p), conv)).unwrap();
        // View: [R | t] with the y and z rows negated (OpenCV -> GL eye axes).
        for i in 0..3 {
            let s = if i == 0 { 1.0 } else { -1.0 };
            assert_eq!(f.left.view[i], [s * r[i][0], s * r[i][1], s * r[i][2], s * t[i]]);
        }
        assert_eq!(f.left.view[3], [0.0, 0.0, 0.0, 1.0]);
        // Projection: the GL frustum with the principal point moved to the pixel centre
        // (x_ndc = 2 (u + 0.5) / W - 1, rows bottom-up), depth row -(f+n)/(f-n), -2fn/(f-n).
        let (w, h, n, fa) = (640.0, 480.0, PLANES.near, PLANES.far);
        let expect = [
            [2.0 * K[0][0] / w, 0.0, 1.0 - (2.0 * K[0][2] + 1.0) / w, 0.0],
            [0.0, 2.0 * K[1][1] / h, (2.0 * K[1][2] + 1.0) / h - 1.0, 0.0],
            [0.0, 0.0, -(fa + n) / (fa - n), -2.0 * fa * n / (fa - n)],
            [0.0, 0.0, -1.0, 0.0],
        ];
        for (row, e) in f.left.proj.iter().zip(&expect) {
            for (v, x) in row.iter().zip(e) {
                // Different operation orders: a few ulps of the entry's magnitude.
                assert!((v - x).abs() <= 1e-14 * x.abs().max(1.0), "{row:?} vs {e:?}");
            }
        }
        assert_eq!(f.left.size, Some(SIZE));
        assert_eq!(f.middle.proj, f.right.proj);
        assert_eq!((f.middle.width, f.middle.height, f.middle.view), (640, 480, None));
    }

    #[test]
    fn both_forms_of_a_camera_give_the_same_matrices_under_every_convention() {
        let p = pose();
        let cam = pinhole();
        let world = {
            let d = p.ray(&cam, 100.25, 300.5);
            [0, 1, 2].map(|i| p.position[i] + 2.5 * d[i])
        };
        for conv in Conventions::all() {
            let f: CameraFile = serde_json::from_value(file(cv_camera(&p), conv)).unwrap();
            // The GL form `viewsynth scene` writes for the same camera.
            assert_eq!(f.left.view, p.gl_view(), "{conv:?}");
            assert_eq!(f.left.proj, gl_projection(&cam, &PLANES, &conv), "{conv:?}");
            // And the pixel-centre rule: pixel (u, v) centre at window (u + 0.5, row + 0.5).
            let ndc = mat4::transform_point(&mat4::mul(&f.left.proj, &f.left.view), world);
            let x = (ndc[0] + 1.0) * 0.5 * 640.0 - 0.5;
            let y = (ndc[1] + 1.0) * 0.5 * 480.0 - 0.5;
            let v = match conv.row_order {
                RowOrder::TopDown => y,
                RowOrder::BottomUp => 479.0 - y,
            };
            assert!(
                (x - 100.25).abs() < 1e-9 && (v - 300.5).abs() < 1e-9,
                "{conv:?}: {x} {v}"
            );
        }
    }

    fn error_of(left: Value) -> String {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cams.json");
        std::fs::write(&path, file(left, Conventions::default()).to_string()).unwrap();
        let e = CameraFile::load(&path).unwrap_err().to_string();
        assert!(e.contains("cams.json"), "the file is named: {e}");
        e
    }

    #[test]
    fn malformed_k_r_t_are_refused_naming_the_file_and_field() {
        let with = |key: &str, v: Value| {
            let mut c = cv_camera(&pose());
            c[key] = v;
            c
        };
        let scaled = [[1.01, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let e = error_of(with("R", json!(scaled)));
        assert!(e.contains("left.R") && e.contains("not orthonormal"), "{e}");
        let mirrored = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]];
        let e = error_of(with("R", json!(mirrored)));
        assert!(e.contains("left.R") && e.contains("reflection"), "{e}");
        let e = error_of(with("R", json!([[1, 0, 0, 0], [0, 1, 0], [0, 0, 1]])));
        assert!(e.contains("left.R") && e.contains("3x3"), "{e}");
        let e = error_of(with("K", json!([[525, 0, 319.5], [0, 520, 239.5]])));
        assert!(e.contains("left.K") && e.contains("3x3"), "{e}");
        let e = error_of(with("K", json!([[525, 1, 319.5], [0, 520, 239.5], [0, 0, 1]])));
        assert!(e.contains("left.K") && e.contains("skew"), "{e}");
        let e = error_of(with("K", json!([[-525, 0, 319.5], [0, 520, 239.5], [0, 0, 1]])));
        assert!(e.contains("left.K fx"), "{e}");
        let e = error_of(with("t", json!([0, 1])));
        assert!(e.contains("left.t") && e.contains("3 numbers"), "{e}");
        let mut far_before_near = with("near", json!(5.0));
        far_before_near["far"] = json!(1.0);
        let e = error_of(far_before_near);
        assert!(e.contains("left.near/far"), "{e}");
        let mut both = cv_camera(&pose());
        both["view"] = json!(mat4::IDENTITY);
        let e = error_of(both);
        assert!(e.contains("left.view") && e.contains("not both"), "{e}");
        let mut no_size = cv_camera(&pose());
        no_size.as_object_mut().unwrap().remove("height");
        assert!(error_of(no_size).contains("left.height"));
        let mut no_t = cv_camera(&pose());
        no_t.as_object_mut().unwrap().remove("t");
        assert!(error_of(no_t).contains("left.t"));
        // Non-finite values cannot be written in JSON; the library check covers other callers.
        let e = rotation(&[vec![f64::NAN, 0.0, 0.0], vec![0.0; 3], vec![0.0; 3]], "R").unwrap_err();
        assert!(e.to_string().contains("not finite"), "{e}");
        let e = intrinsics(&[vec![1.0, 0.0, f64::INFINITY], vec![0.0; 3], vec![0.0; 3]], "K").unwrap_err();
        assert!(e.to_string().contains("not finite"), "{e}");
    }
}
