//! An independent oracle for refocus, written from the seed (`003_d041d3aa6171a4c0.txt`, §2 and
//! §4) and nothing of the GPU path: no `Grid`, no `keep_mask`, no `source_point`, no f64 twin.
//! The twin (`refocus::reference`) shares those helpers with the GPU passes, so a wrong break
//! rule or pixel mapping would cancel out in every GPU-vs-twin test; here it cannot.
//!
//! From the seed, for a target pixel (i, j) of K' (OpenCV: pixel centres at integer u, v):
//! - the pose is unchanged, so the ray through (i, j) has X/Z = (i - cx') / fx' and
//!   Y/Z = (j - cy') / fy', and meets the source image at the source pixel position
//!   us = cx + fx (i - cx') / fx', vs = cy + fy (j - cy') / fy' (§2.1 inverted);
//! - the mesh has a vertex at each source pixel centre and, per cell (u, v), the triangles
//!   tri1 = v00 v10 v11 and tri2 = v00 v11 v01 (§2.3); in cell-local (a, b) = (us - u, vs - v),
//!   tri1 is b <= a and tri2 is a <= b;
//! - a triangle is kept when its three depths are valid (finite, > 0) and no edge breaks, an
//!   edge breaking when |za - zb| / min(za, zb) > tau_rel or |za - zb| > tau_abs (§2.4);
//! - the pixel is valid iff it lies in a kept triangle; the projection is an affine image of
//!   the source grid (same pose), so triangles never overlap and no depth test is needed;
//! - its metric depth is the triangle plane's Z on the ray: for a planar triangle 1/Z is affine
//!   in image coordinates, so 1/Z interpolates barycentrically in (a, b);
//! - its colour samples the source image bilinearly at (us, vs) (texture coordinates at pixel
//!   centres, §2.2, with GL_LINEAR, §9).
//!
//! Compared where the answer is not a tie: pixels whose (a, b) lie within `TIE` of a cell side
//! or of the diagonal are skipped (closed-edge conventions differ there by design), and so is
//! the half-pixel border ring the implementation adds outside the pixel centres (not in the
//! seed). Beyond the ring (outside [-0.5, W - 0.5]) nothing may be valid (§1, "new areas remain
//! invalid").

use viewsynth::camera::{Intrinsics, PinholeCamera};
use viewsynth::convention::Conventions;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusSource, Refocuser};
use viewsynth_tests::{gpu, real_frame};

/// Local coordinates closer than this to a cell side or the diagonal are ties (the GPU locates
/// points in f64 and tests them in f32 with a 1e-5 cell tolerance: 1e-4 leaves 10x room).
const TIE: f64 = 1e-4;
/// Colour: the exact bilinear value rounds to the stored byte; f32 weights and sums on values
/// <= 255 are off by ~255 x 2^-22 ~ 6e-5 level, so 0.5 + 0.01 leaves 100x room and still fails
/// any pixel a whole level off.
const COLOR_TOL: f64 = 0.51;
/// Depth: the GPU interpolates 1/Z in f32, a few ulps relative.
const DEPTH_REL_TOL: f64 = 1e-5;

/// What the seed says about one target pixel: not comparable (tie or ring), invalid, or valid
/// with (depth, colour).
enum Expect {
    Skip,
    Invalid,
    Valid(f64, [f64; 3]),
}

fn valid(z: f32) -> bool {
    z.is_finite() && z > 0.0
}

/// §2.4, as written: break when the relative or the absolute jump exceeds its threshold.
fn edge_breaks(za: f64, zb: f64, tau_rel: f64, tau_abs: f64) -> bool {
    let d = (za - zb).abs();
    d / za.min(zb) > tau_rel || d > tau_abs
}

fn oracle(src: &RefocusSource, rule: &BreakRule, target: &PinholeCamera, i: u32, j: u32) -> Expect {
    let (w, h) = (src.rgb.width as i64, src.rgb.height as i64);
    let (k, t) = (&src.k, &target.k);
    let us = k.cx + k.fx * (i as f64 - t.cx) / t.fx;
    let vs = k.cy + k.fy * (j as f64 - t.cy) / t.fy;
    let (wf, hf) = (w as f64, h as f64);
    if us < -0.5 - TIE || vs < -0.5 - TIE || us > wf - 0.5 + TIE || vs > hf - 0.5 + TIE {
        return Expect::Invalid;
    }
    // The ring (and its edge with the interior) is the implementation's, not the seed's.
    if us <= TIE || vs <= TIE || us >= wf - 1.0 - TIE || vs >= hf - 1.0 - TIE {
        return Expect::Skip;
    }
    let (u, v) = (us.floor(), vs.floor());
    let (a, b) = (us - u, vs - v);
    if a < TIE || b < TIE || a > 1.0 - TIE || b > 1.0 - TIE || (a - b).abs() < TIE {
        return Expect::Skip;
    }
    let (u, v) = (u as i64, v as i64);
    let at = |du: i64, dv: i64| ((v + dv) * w + u + du) as usize;
    let z = |du, dv| src.depth.data[at(du, dv)];
    // Corners in the seed's order: tri1 = v00 v10 v11 (b < a), tri2 = v00 v11 v01 (a < b),
    // with their barycentric weights at (a, b).
    let (corners, weights) = if b < a {
        ([(0, 0), (1, 0), (1, 1)], [1.0 - a, a - b, b])
    } else {
        ([(0, 0), (1, 1), (0, 1)], [1.0 - b, a, b - a])
    };
    let zs = corners.map(|(du, dv)| z(du, dv));
    if !zs.iter().all(|z| valid(*z)) {
        return Expect::Invalid;
    }
    let zs = zs.map(f64::from);
    for (p, q) in [(0, 1), (1, 2), (2, 0)] {
        if edge_breaks(zs[p], zs[q], rule.tau_rel, rule.tau_abs) {
            return Expect::Invalid;
        }
    }
    let inv_z: f64 = (0..3).map(|n| weights[n] / zs[n]).sum();
    let c = |du, dv, ch: usize| src.rgb.data[at(du, dv) * 3 + ch] as f64;
    let color = [0, 1, 2].map(|ch| {
        (1.0 - a) * (1.0 - b) * c(0, 0, ch)
            + a * (1.0 - b) * c(1, 0, ch)
            + (1.0 - a) * b * c(0, 1, ch)
            + a * b * c(1, 1, ch)
    });
    Expect::Valid(1.0 / inv_z, color)
}

/// Every pixel of every target through both GPU paths against the oracle; returns how many
/// pixels were compared valid and invalid.
fn check(name: &str, src: &RefocusSource, rule: BreakRule, targets: &[PinholeCamera]) -> (usize, usize) {
    let g = gpu();
    let (mut n_valid, mut n_invalid) = (0, 0);
    for method in [Method::Fullscreen, Method::Mesh] {
        let mut r = Refocuser::new(&g, src, &rule, method, OutputSet::default(), Conventions::default()).unwrap();
        for t in targets {
            let out = r.render(t).unwrap();
            let (rgb, depth, mask) = (
                &out.rgb.as_ref().unwrap().data,
                &out.depth.as_ref().unwrap().data,
                &out.mask.as_ref().unwrap().data,
            );
            let (mut skipped, mut failures) = (0usize, Vec::new());
            for j in 0..t.height {
                for i in 0..t.width {
                    let p = (j * t.width + i) as usize;
                    let tag = || {
                        format!(
                            "{name} {method:?} fx'={:.3} {}x{} pixel ({i}, {j})",
                            t.k.fx, t.width, t.height
                        )
                    };
                    match oracle(src, &rule, t, i, j) {
                        Expect::Skip => skipped += 1,
                        Expect::Invalid => {
                            n_invalid += 1;
                            if mask[p] != 0 {
                                failures.push(format!("{}: valid, the seed says invalid", tag()));
                            }
                        }
                        Expect::Valid(z, color) => {
                            n_valid += 1;
                            if mask[p] == 0 {
                                failures.push(format!("{}: invalid, the seed says valid (Z {z})", tag()));
                                continue;
                            }
                            if ((depth[p] as f64 - z) / z).abs() > DEPTH_REL_TOL {
                                failures.push(format!("{}: depth {} vs {z}", tag(), depth[p]));
                            }
                            for ch in 0..3 {
                                if (rgb[p * 3 + ch] as f64 - color[ch]).abs() > COLOR_TOL {
                                    failures.push(format!(
                                        "{}: colour {:?} vs {color:?}",
                                        tag(),
                                        &rgb[p * 3..p * 3 + 3]
                                    ));
                                    break;
                                }
                            }
                        }
                    }
                }
            }
            let total = (t.width * t.height) as usize;
            assert!(
                failures.is_empty(),
                "{} of {total} pixels disagree with the seed, first: {:#?}",
                failures.len(),
                &failures[..failures.len().min(8)]
            );
            // Ties and the ring are a thin set: most pixels are compared.
            assert!(
                skipped * 10 < total,
                "{name} fx'={}: {skipped} of {total} skipped",
                t.k.fx
            );
        }
    }
    (n_valid, n_invalid)
}

/// Targets at focal scales whose pixel centres fall inside cells (not on the diagonal: scale
/// 0.5 with a half-integer principal point puts every centre on it), some with another size
/// and principal point.
fn targets(k: Intrinsics, w: u32, h: u32) -> Vec<PinholeCamera> {
    let mut v = Vec::new();
    for (s, (tw, th), shift) in [
        (0.62, (w, h), 0.0),
        (0.87, (w + 17, h - 9), 3.3),
        (1.0, (w, h), 0.37),
        (1.37, (w, h), 0.0),
        (2.29, (w - 11, h + 7), -2.1),
    ] {
        v.push(PinholeCamera {
            k: Intrinsics {
                fx: k.fx * s,
                fy: k.fy * s,
                cx: k.cx + (tw as f64 - w as f64) / 2.0 + shift,
                cy: k.cy + (th as f64 - h as f64) / 2.0 - shift,
            },
            width: tw,
            height: th,
        });
    }
    v
}

/// A small deterministic generator (64-bit LCG, top bits).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Depth built to sit on both sides of both thresholds: three bands (1 m, where the relative
/// rule binds: 5 % = 5 cm < 20 cm; 3 m, about even; 7 m, where the absolute rule binds: 20 cm =
/// 2.9 %), each pixel a random factor within +-5.5 % of its band, so neighbouring ratios spread
/// over 0..11 % and about half the edges break, by one rule or the other; plus holes (0, NaN,
/// -1, +inf).
fn adversarial(w: u32, h: u32) -> RefocusSource {
    let mut rng = Lcg(27);
    let mut depth = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let band = [1.0, 3.0, 7.0][(x * 3 / w) as usize];
            let z = band * (1.0 + 0.11 * (rng.next() - 0.5));
            let hole = rng.next();
            depth.push(if hole < 0.01 {
                0.0
            } else if hole < 0.015 {
                f32::NAN
            } else if hole < 0.02 {
                -1.0
            } else if hole < 0.025 {
                f32::INFINITY
            } else {
                z as f32
            });
            let _ = y;
        }
    }
    let rgb: Vec<u8> = (0..w * h * 3).map(|_| (rng.next() * 256.0) as u8).collect();
    let k = Intrinsics {
        fx: 0.9 * w as f64,
        fy: 0.9 * w as f64,
        cx: (w as f64 - 1.0) / 2.0 + 0.23,
        cy: (h as f64 - 1.0) / 2.0 - 0.41,
    };
    RefocusSource::new(
        RgbImage::new(w, h, rgb).unwrap(),
        DepthMap::new(w, h, depth).unwrap(),
        k,
    )
    .unwrap()
}

#[test]
fn adversarial_depth_matches_the_seed_oracle_under_three_break_rules() {
    let src = adversarial(97, 71);
    let k = src.k;
    for rule in [
        BreakRule::default(),
        // Relative rule alone, and absolute rule alone (the other disabled).
        BreakRule {
            tau_rel: 0.03,
            tau_abs: f64::INFINITY,
        },
        BreakRule {
            tau_rel: f64::INFINITY,
            tau_abs: 0.1,
        },
    ] {
        let (v, inv) = check(&format!("adversarial {rule:?}"), &src, rule, &targets(k, 97, 71));
        // Both outcomes are exercised in volume.
        assert!(v > 5_000 && inv > 5_000, "{rule:?}: {v} valid, {inv} invalid compared");
    }
}

#[test]
fn tum_frame_matches_the_seed_oracle() {
    let src = real_frame("TUM");
    let (v, inv) = check("TUM", &src, BreakRule::default(), &targets(src.k, 640, 480));
    assert!(v > 500_000 && inv > 10_000, "{v} valid, {inv} invalid compared");
}
